"""The bifurcation and regime-map commands: bad input, SIGKILL and Ctrl-C with --resume."""

import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pandas as pd
import pytest

from chaoscam.cli import main
from chaoscam.sweep import Axis, checkpoint_dir, regime_map

from ._helpers import SpreadClassifier, frames_equal

ROOT = Path(__file__).resolve().parents[2]
CLS = "tests.sweep._helpers:SpreadClassifier"
SLOW = "tests.sweep._helpers:SlowSpreadClassifier"  # 50 ms a run, the same labels
MAP = [
    "regime-map",
    "--mu",
    "0.006:0.010:3",
    "--sigma",
    "0:0.002:2",
    "--realizations",
    "10",
    "--seed",
    "3",
    "--duration",
    "2",
    "--transient",
    "1",
    "--classifier",
    CLS,
    "--quiet",
]


@pytest.fixture(scope="module")
def uninterrupted():
    return regime_map(
        Axis.parse("l_lambda=0.006:0.010:3"),
        Axis.parse("l_lambda_sigma=0:0.002:2"),
        realizations=10,
        seed=3,
        duration=2.0,
        transient=1.0,
        classify=SpreadClassifier(),
        workers=1,
    )


def _start(args, batch: int | None = None):
    """The command line on ``args`` in a process of its own; ``batch``: that many runs per
    batch (the engine's CPU batch holds about two seconds of estimated work, every run of
    these small sweeps on one worker)."""
    env = dict(os.environ, PYTHONPATH=str(ROOT))
    code = "import sys; from chaoscam.cli import main; sys.exit(main(sys.argv[1:]))"
    if batch is not None:
        code = (
            f"from chaoscam.sweep import _engine; _engine.batch_size = lambda *a, **k: {batch}; "
            + code
        )
    return subprocess.Popen(
        [sys.executable, "-c", code, *args],
        cwd=ROOT,
        env=env,
        start_new_session=True,
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
    )


def _wait_for_parts(out: Path, n: int, proc, timeout=60.0) -> None:
    ckpt = checkpoint_dir(out)
    t0 = time.monotonic()
    while time.monotonic() - t0 < timeout:
        if ckpt.is_dir() and len(list(ckpt.glob("part-*.jsonl"))) >= n:
            return
        if proc.poll() is not None:
            raise AssertionError(f"finished before it could be stopped: {proc.stderr.read()}")
        time.sleep(0.01)
    raise AssertionError("no checkpoint appeared")


@pytest.mark.parametrize("sig", [signal.SIGKILL, signal.SIGINT], ids=["SIGKILL", "SIGINT"])
def test_stopped_run_resumes_to_the_identical_table(tmp_path, uninterrupted, sig):
    """Killed (SIGKILL) or Ctrl-C'd mid-run with 2 workers, --resume ends with the table of
    an uninterrupted run: nothing lost, nothing duplicated. Ctrl-C says how to resume."""
    out = tmp_path / "m.parquet"
    args = [*MAP, "--workers", "2", "--checkpoint-interval", "0", "--out", str(out)]
    args[args.index(CLS)] = SLOW
    proc = _start(args)
    _wait_for_parts(out, 3, proc)
    os.killpg(proc.pid, sig)
    _, err = proc.communicate(timeout=60)
    assert not out.exists()
    if sig == signal.SIGINT:
        assert proc.returncode == 130 and "--resume" in err, err
    else:
        assert proc.returncode == -signal.SIGKILL
    saved = sum(len(p.read_text().splitlines()) for p in checkpoint_dir(out).glob("part-*"))
    assert 3 <= saved < 60
    proc = _start([*args, "--resume"])
    _, err = proc.communicate(timeout=120)
    assert proc.returncode == 0, err
    frames_equal(pd.read_parquet(out), uninterrupted.realizations)
    frames_equal(pd.read_parquet(tmp_path / "m.cells.parquet"), uninterrupted.cells)
    assert not checkpoint_dir(out).exists()


@pytest.mark.parametrize(
    "change",
    [
        ["--mu", "0.006:0.010:0"],  # NUM < 1
        ["--sigma=-0.001:0.002:2"],  # sigma < 0
        ["--mu", "0:0.010:3"],  # mu <= 0
        ["--mu", "0.010:0.006:3"],  # stop < start
        ["--set", "omegaa=3"],  # unknown parameter
        ["--x", "xi=0.1:0.5:2"],  # --mu and --x together
        ["--workers", "0"],
    ],
)
def test_bad_input_exits_2_and_writes_nothing(tmp_path, change, capsys):
    """Bad ranges and settings: exit code 2, a message, no file."""
    out = tmp_path / "m.parquet"
    args = [*MAP, "--out", str(out)]
    if change[0] in args and len(change) == 2:  # replace a flag's value, or add flags
        i = args.index(change[0])
        args[i + 1] = change[1]
    else:
        args += change
    assert main(args) == 2
    assert "error" in capsys.readouterr().err
    assert list(tmp_path.iterdir()) == []


def test_existing_output_and_foreign_checkpoint_exit_2(tmp_path, capsys):
    """An existing output without --resume, or a checkpoint of another configuration with
    it: exit 2, nothing overwritten."""
    out = tmp_path / "b.parquet"
    base = [
        "bifurcation",
        "--param",
        "xi",
        "--values",
        "0.3:0.5:2",
        "--duration",
        "1",
        "--classifier",
        CLS,
        "--workers",
        "1",
        "--quiet",
        "--out",
        str(out),
    ]
    assert main(base) == 0
    before = out.read_bytes()
    assert main(base) == 2
    assert "--resume" in capsys.readouterr().err
    assert main([*base, "--resume"]) == 0  # the same run: reused as is
    assert main([a for a in base if a != "--quiet"] + ["--resume"]) == 0
    assert "already finished" in capsys.readouterr().err  # and says so
    assert main([*base[:4], "0.3:0.6:2", *base[5:], "--resume"]) == 2
    assert out.read_bytes() == before
    ckpt = checkpoint_dir(tmp_path / "c.parquet")
    ckpt.mkdir()
    (ckpt / "manifest.json").write_text('{"hash": "something else"}')
    assert main([*base[:-1], str(tmp_path / "c.parquet"), "--resume"]) == 2
    assert "different configuration" in capsys.readouterr().err
    assert main([*base[:-1], str(tmp_path / "c.parquet")]) == 2


def test_regime_map_with_other_axes_and_plot(tmp_path, capsys):
    """--x/--y over omega x xi writes both tables and a figure; the summary says that its
    deterministic cells (sigma = 0) ran once each, whatever --realizations asked."""
    out = tmp_path / "r.parquet"
    args = [
        "regime-map",
        "--x",
        "omega=28.7:40:2",
        "--y",
        "xi=0.42:0.9:2",
        "--duration",
        "2",
        "--transient",
        "0.5",
        "--classifier",
        CLS,
        "--workers",
        "1",
        "--quiet",
        "--out",
        str(out),
        "--plot",
        str(tmp_path / "r.png"),
    ]
    assert main(args) == 0
    cells = pd.read_parquet(tmp_path / "r.cells.parquet")
    assert set(cells.columns) >= {"omega", "xi", "dominant", "p_chaotic_lo", "p_chaotic_hi"}
    assert "left_reach" in set(pd.read_parquet(out)["label"])
    assert (tmp_path / "r.png").stat().st_size > 0
    assert "4 cells, 4 realizations (4 deterministic cell(s), sigma = 0: one run each)" in (
        capsys.readouterr().out
    )


@pytest.mark.parametrize(
    "argv, name",
    [
        (["regime-map", "--mu", "0.008", "--sigma", "0", "--set", "l_lambda=0.01"], "--mu"),
        (["regime-map", "--x", "xi=0.2", "--y", "omega=20", "--set", "omega=30"], "--y"),
        (["bifurcation", "--param", "xi", "--values", "0.2", "--set", "xi=0.3"], "--param"),
    ],
)
def test_setting_a_swept_parameter_is_refused(tmp_path, capsys, argv, name):
    """--set for a parameter the sweep varies was silently overridden by the axis: exit 2,
    naming the axis option, before any work."""
    assert main([*argv, "--out", str(tmp_path / "s.parquet")]) == 2
    err = capsys.readouterr().err
    assert f"is swept by {name}" in err and "Traceback" not in err
    assert list(tmp_path.iterdir()) == []
