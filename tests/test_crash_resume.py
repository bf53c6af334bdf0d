"""Crash test: SIGKILL of the driver at random moments (start-up, mid-run, while writing the
outputs), then --resume, gives the table of a run never killed (with one worker thread).
Two kills for two kinds by default, for all four with -m slow, and 20 per kind marked
slow."""

import os
import random
import signal
import subprocess
import sys
import time
from pathlib import Path

import pandas as pd
import pytest

from chaoscam.cli import main

ROOT = Path(__file__).resolve().parents[1]
SLOW = "tests.sweep._helpers:SlowSpreadClassifier"  # 50 ms a run

COMMANDS = {
    "regime-map": (
        [
            "regime-map",
            "--mu",
            "0.006:0.010:3",
            "--sigma",
            "0:0.002:2",
            "--realizations",
            "6",
            "--seed",
            "3",
            "--duration",
            "1",
            "--classifier",
            SLOW,
            "--workers",
            "2",
            "--checkpoint-interval",
            "0",
            "--quiet",
        ],
        ("", ".cells"),
    ),
    "regime-map-verdict": (  # the package's verdict, batches on every core
        [
            "regime-map",
            "--mu",
            "0.006:0.010:3",
            "--sigma",
            "0:0.002:2",
            "--realizations",
            "6",
            "--seed",
            "3",
            "--duration",
            "2",
            "--checkpoint-interval",
            "0",
            "--quiet",
        ],
        ("", ".cells"),
    ),
    "bifurcation": (
        [
            "bifurcation",
            "--param",
            "l_lambda",
            "--values",
            "0.006:0.010:12",
            "--initial-conditions",
            "2",
            "--duration",
            "1",
            "--classifier",
            SLOW,
            "--workers",
            "2",
            "--checkpoint-interval",
            "0",
            "--quiet",
        ],
        ("", ".verdicts"),
    ),
    "ensemble": (  # two batch threads: several batches, each checkpointed as it ends
        [
            "ensemble",
            "--members",
            "24",
            "--duration",
            "1",
            "--set",
            "l_lambda_sigma=0.002",
            "--seed",
            "5",
            "--workers",
            "2",
            "--checkpoint-interval",
            "0",
            "--quiet",
        ],
        ("", ".sections"),
    ),
}


def _start(args):
    code = "import sys; from chaoscam.cli import main; sys.exit(main(sys.argv[1:]))"
    return subprocess.Popen(
        [sys.executable, "-c", code, *args],
        cwd=ROOT,
        env=dict(os.environ, PYTHONPATH=str(ROOT)),
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
    )


def _tables(out, companions):
    return [pd.read_parquet(out.with_name(out.stem + c + ".parquet")) for c in companions]


@pytest.fixture(scope="module")
def references(tmp_path_factory):
    cache = {}

    def get(kind):
        if kind not in cache:
            args, comp = COMMANDS[kind]
            out = tmp_path_factory.mktemp(kind) / "ref.parquet"
            workers = ["--workers", "1"] if "--workers" in args else []
            assert main([*args, "--out", str(out), *workers]) == 0  # the same with 1 worker
            cache[kind] = _tables(out, comp)
        return cache[kind]

    return get


def _crash_and_resume(tmp_path, kind, kills, rng, reference):
    args, comp = COMMANDS[kind]
    out = tmp_path / "run.parquet"
    resume = []
    for _ in range(kills):
        proc = _start([*args, "--out", str(out), *resume])
        time.sleep(rng.uniform(0.2, 2.2))
        os.kill(proc.pid, signal.SIGKILL)
        _, err = proc.communicate(timeout=60)
        assert proc.returncode in (0, -signal.SIGKILL), err
        resume = ["--resume"]
    proc = _start([*args, "--out", str(out), "--resume"])
    _, err = proc.communicate(timeout=300)
    assert proc.returncode == 0, err
    assert "Traceback" not in err
    for got, want in zip(_tables(out, comp), reference, strict=True):
        pd.testing.assert_frame_equal(got, want, check_exact=True)
    assert not [p for p in tmp_path.iterdir() if p.suffix == ".ckpt" or p.name.startswith(".tmp")]


# Two kinds by default; the verdict's map and the diagram are killed in the slow variants
# below, and test_sw_cli kills a map (SIGKILL and SIGINT) too.
QUICK = ["regime-map", "ensemble"]


@pytest.mark.parametrize(
    "kind", [k if k in QUICK else pytest.param(k, marks=pytest.mark.slow) for k in COMMANDS]
)
def test_kills_then_resume_identical(tmp_path, kind, references):
    """Two SIGKILLs at random moments, then --resume: the uninterrupted tables."""
    _crash_and_resume(tmp_path, kind, 2, random.Random(f"{kind}-quick"), references(kind))


@pytest.mark.slow
@pytest.mark.parametrize("kind", list(COMMANDS))
def test_twenty_kills_then_resume_identical(tmp_path, kind, references):
    """Twenty SIGKILLs at random moments (one resumed run after another), then --resume."""
    _crash_and_resume(tmp_path, kind, 20, random.Random(f"{kind}-slow"), references(kind))
