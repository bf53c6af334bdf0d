"""``chaoscam ensemble``: a torn part is computed again, and a run killed between its
output files is finished by --resume (the outputs are one commit)."""

import os

import pandas as pd
import pytest

from chaoscam.cli import main

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
    "--chunk",
    "2",
    "--quiet",
    "--keep-impacts",
]
NAMES = ("", ".sections", ".impacts")


@pytest.fixture(scope="module")
def whole(tmp_path_factory):
    out = tmp_path_factory.mktemp("ens") / "whole.parquet"
    assert main([*ARGS, "--out", str(out)]) == 0
    return {n: pd.read_parquet(out.with_name(f"whole{n}.parquet")) for n in NAMES}


def _same(out, whole):
    for n in NAMES:
        pd.testing.assert_frame_equal(pd.read_parquet(out.with_name(f"e{n}.parquet")), whole[n])
    assert not out.with_suffix(".parts").exists()


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


@pytest.mark.parametrize("stop", ["sections", "impacts", "members", "parts removal"])
def test_killed_between_output_files_resumes(tmp_path, monkeypatch, whole, stop, capsys):
    """A stop before any of the renames of the final commit (or before the parts are
    removed): --resume finishes, and the outputs equal those of an uninterrupted run."""
    out = tmp_path / "e.parquet"
    target = {
        "sections": out.with_name("e.sections.parquet"),
        "impacts": out.with_name("e.impacts.parquet"),
        "members": out,
        "parts removal": tmp_path / f".tmp-{os.getpid()}-removed-e.parts",
    }[stop]
    _stop_at(monkeypatch, target)
    assert main([*ARGS, "--out", str(out)]) == 130
    monkeypatch.undo()
    assert main([*ARGS, "--out", str(out), "--resume"]) == 0, capsys.readouterr().err
    _same(out, whole)


def test_torn_part_is_computed_again(tmp_path, monkeypatch, whole, capsys):
    """A part cut short after its .done marker was written is found (size and checksum in
    the marker), computed again with a notice, and the result is the uninterrupted one."""
    out = tmp_path / "e.parquet"
    _stop_at(monkeypatch, out.with_name("e.sections.parquet"))
    assert main([*ARGS, "--out", str(out)]) == 130
    monkeypatch.undo()
    part = out.with_suffix(".parts") / "000000000002.sections.parquet"
    part.write_bytes(part.read_bytes()[:100])
    assert main([*ARGS, "--out", str(out), "--resume"]) == 0
    assert "part 2" in capsys.readouterr().err
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
    naming it, no output placed, and the parts kept, from which --resume (once it is moved
    away) writes the same outputs as an uninterrupted run."""
    import chaoscam.integrate

    out = tmp_path / "e.parquet"
    sections = out.with_name("e.sections.parquet")
    run = chaoscam.integrate.simulate_ensemble

    def meanwhile(*args, **kwargs):
        sections.write_text("theirs")
        return run(*args, **kwargs)

    monkeypatch.setattr(chaoscam.integrate, "simulate_ensemble", meanwhile)
    assert main([*ARGS, "--out", str(out)]) == 2
    assert "appeared while this run was working" in capsys.readouterr().err
    assert sections.read_text() == "theirs" and not out.exists()
    assert out.with_suffix(".parts").is_dir()
    monkeypatch.setattr(chaoscam.integrate, "simulate_ensemble", run)
    sections.unlink()
    assert main([*ARGS, "--out", str(out), "--resume"]) == 0
    _same(out, whole)
