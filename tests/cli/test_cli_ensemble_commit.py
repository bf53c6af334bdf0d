"""``chaoscam ensemble``: a torn checkpoint part is computed again, and a run stopped between
its output files, or before its checkpoint is removed, is finished by --resume."""

import os

import pandas as pd
import pytest

from chaoscam.cli import main
from chaoscam.sweep import checkpoint_dir

ARGS = [
    "ensemble",
    "--members",
    "5",
    "--duration",
    "1.0",
    "--transient",
    "0.5",
    "--set",
    "l_lambda_sigma=0.002",
    "--seed",
    "4",
    "--workers",
    "1",
    "--quiet",
]
NAMES = ("", ".sections")


@pytest.fixture(scope="module")
def whole(tmp_path_factory):
    out = tmp_path_factory.mktemp("ens") / "whole.parquet"
    assert main([*ARGS, "--out", str(out)]) == 0
    return {n: pd.read_parquet(out.with_name(f"whole{n}.parquet")) for n in NAMES}


def _same(out, whole):
    for n in NAMES:
        pd.testing.assert_frame_equal(pd.read_parquet(out.with_name(f"e{n}.parquet")), whole[n])
    assert not checkpoint_dir(out).exists()


def _stop_at(monkeypatch, target):
    """os.replace or os.link (a fresh output is linked into place, never over a file)
    raises KeyboardInterrupt (a kill) when it would create ``target``."""
    for name in ("replace", "link"):
        real = getattr(os, name)

        def make(src, dst, real=real):
            if os.fspath(dst) == os.fspath(target):
                raise KeyboardInterrupt
            real(src, dst)

        monkeypatch.setattr(os, name, make)


@pytest.mark.parametrize("stop", ["members", "sections", "checkpoint removal"])
def test_stopped_between_output_files_resumes(tmp_path, monkeypatch, whole, stop, capsys):
    """A stop before any of the renames that place the outputs (or before the checkpoint is
    removed): exit 130 with every run kept, and --resume finishes to the outputs of an
    uninterrupted run."""
    out = tmp_path / "e.parquet"
    target = {
        "members": out,
        "sections": out.with_name("e.sections.parquet"),
        "checkpoint removal": tmp_path / f".tmp-{os.getpid()}-removed-e.parquet.ckpt",
    }[stop]
    _stop_at(monkeypatch, target)
    assert main([*ARGS, "--out", str(out)]) == 130
    monkeypatch.undo()
    assert "5 of 5 runs are saved" in capsys.readouterr().err
    assert checkpoint_dir(out).is_dir()
    assert main([*ARGS, "--out", str(out), "--resume"]) == 0, capsys.readouterr().err
    _same(out, whole)


def test_torn_part_is_computed_again(tmp_path, monkeypatch, whole, capsys):
    """A checkpoint part cut short (a kill while it was written, a full disk) is found, its
    runs computed again with a notice, and the result is the uninterrupted one."""
    out = tmp_path / "e.parquet"
    _stop_at(monkeypatch, out)
    assert main([*ARGS, "--checkpoint-interval", "0", "--out", str(out)]) == 130
    monkeypatch.undo()
    part = sorted(checkpoint_dir(out).glob("part-*.jsonl"))[-1]
    part.write_bytes(part.read_bytes()[:100])
    capsys.readouterr()
    assert main([*ARGS, "--checkpoint-interval", "0", "--out", str(out), "--resume"]) == 0
    assert f"{part.name} in {checkpoint_dir(out)} was torn" in capsys.readouterr().err
    _same(out, whole)


def test_force_starts_over(tmp_path, whole):
    """--force replaces finished outputs; --force with --resume is refused."""
    out = tmp_path / "e.parquet"
    assert main([*ARGS, "--out", str(out)]) == 0
    assert main([*ARGS, "--out", str(out)]) == 2
    assert main([*ARGS, "--out", str(out), "--force", "--resume"]) == 2
    assert main([*ARGS, "--out", str(out), "--force"]) == 0
    _same(out, whole)


def test_an_output_written_during_the_run_is_not_replaced(tmp_path, monkeypatch, whole, capsys):
    """A sections file that another process writes while the members run is kept: exit 2
    naming it, this run's table beside it, and the checkpoint kept, from which --resume
    (once that file is moved away) writes the same outputs as an uninterrupted run."""
    from chaoscam.sweep import _engine

    out = tmp_path / "e.parquet"
    sections = out.with_name("e.sections.parquet")
    run_plan = _engine.run_plan

    def meanwhile(*args, **kwargs):
        sections.write_text("theirs")
        return run_plan(*args, **kwargs)

    monkeypatch.setattr(_engine, "run_plan", meanwhile)
    assert main([*ARGS, "--out", str(out)]) == 2
    assert "another process wrote it while this run worked" in capsys.readouterr().err
    assert sections.read_text() == "theirs"
    assert len(pd.read_parquet(tmp_path / f"e.sections.{os.getpid()}.parquet")) > 0
    assert checkpoint_dir(out).is_dir()
    monkeypatch.setattr(_engine, "run_plan", run_plan)
    sections.unlink()
    assert main([*ARGS, "--out", str(out), "--resume"]) == 0
    _same(out, whole)
