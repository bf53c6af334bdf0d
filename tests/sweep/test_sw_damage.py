"""Damaged checkpoints: a torn last part is dropped and recomputed, a damaged middle part or
a record that does not fit is refused with what to do; never a raw decoding traceback."""

import pytest

from chaoscam.sweep import Axis, SweepError, bifurcation, checkpoint_dir, regime_map
from chaoscam.sweep._store import DamagedPart, decode_part, encode_part

from ._helpers import InterruptOnce, SpreadClassifier, frames_equal, one_run_per_batch

GRID = dict(realizations=3, seed=3, duration=1.0, transient=0.5, workers=1)
X, Y = Axis.parse("l_lambda=0.006:0.010:3"), Axis.parse("l_lambda_sigma=0:0.002:2")


@pytest.fixture(scope="module")
def reference():
    return regime_map(X, Y, classify=SpreadClassifier(), **GRID)


def _dead_pid() -> str:
    """The pid of a process that has finished."""
    import subprocess
    import sys

    code = "import os; print(os.getpid())"
    run = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    return run.stdout.strip()


def _interrupted(tmp_path, monkeypatch, victim=11):
    """A regime map stopped by Ctrl-C after several one-record parts."""
    one_run_per_batch(monkeypatch)
    out = tmp_path / "m.parquet"
    stop = InterruptOnce(str(tmp_path / "marker"), victim)
    with pytest.raises(KeyboardInterrupt):
        regime_map(X, Y, classify=stop, out=out, flush_interval=0.0, **GRID)
    parts = sorted(checkpoint_dir(out).glob("part-*.jsonl"))
    assert len(parts) >= 3
    return out, parts, stop


def test_part_round_trip_and_damage():
    """A part decodes to its records; a cut, a flipped byte or garbage are DamagedPart."""
    records = [{"cell": 1, "x": 0.1}, {"cell": 2, "x": float("inf")}]
    data = encode_part(records)
    assert decode_part(data) == records
    assert decode_part(data.split(b"#chaoscam-part")[0]) == records  # no trailer: legacy
    for bad in (data[:-10], data[:5] + b"9" + data[6:], b"\xff\xfe" + data, data[:12]):
        with pytest.raises(DamagedPart):
            decode_part(bad)


@pytest.mark.parametrize("damage", ["truncated", "garbage"])
def test_torn_last_part_is_recomputed(tmp_path, monkeypatch, reference, damage, capsys):
    """A torn last part (cut short, or garbage bytes) is dropped with a one-line notice and
    --resume ends with the uninterrupted table."""
    out, parts, stop = _interrupted(tmp_path, monkeypatch)
    data = parts[-1].read_bytes()
    parts[-1].write_bytes(data[: len(data) // 2] if damage == "truncated" else b"\xff\x00" * 9)
    res = regime_map(X, Y, classify=stop, out=out, resume=True, **GRID)
    notice = [ln for ln in capsys.readouterr().err.splitlines() if "torn" in ln]
    assert len(notice) == 1 and parts[-1].name in notice[0]
    frames_equal(res.realizations, reference.realizations)


def test_damaged_middle_part_is_refused(tmp_path, monkeypatch):
    """A damaged part before the last one: refused, the message says which file to delete."""
    out, parts, stop = _interrupted(tmp_path, monkeypatch)
    parts[0].write_bytes(parts[0].read_bytes()[:-7])
    with pytest.raises(SweepError, match=f"{parts[0].name} is damaged.*delete that file"):
        regime_map(X, Y, classify=stop, out=out, resume=True, **GRID)


def test_record_that_does_not_fit_is_refused(tmp_path, monkeypatch):
    """A well-formed record for a cell the grid does not have: a message, not IndexError."""
    out, parts, stop = _interrupted(tmp_path, monkeypatch)
    record = decode_part(parts[-1].read_bytes())[0]
    parts[-1].write_bytes(encode_part([dict(record, cell=999)]))
    with pytest.raises(SweepError, match="does not fit this run"):
        regime_map(X, Y, classify=stop, out=out, resume=True, **GRID)


def test_bifurcation_torn_last_part(tmp_path, monkeypatch, capsys):
    """The same for a bifurcation diagram: torn last part dropped, same points as a run
    that was never interrupted."""
    kw = dict(duration=1.0, transient=0.5, workers=1)
    values = "0.006:0.010:4"
    ref = bifurcation("l_lambda", values, classify=SpreadClassifier(), **kw)
    one_run_per_batch(monkeypatch)
    out = tmp_path / "b.parquet"
    stop = InterruptOnce(str(tmp_path / "marker"), 3)
    with pytest.raises(KeyboardInterrupt):
        bifurcation("l_lambda", values, classify=stop, out=out, flush_interval=0.0, **kw)
    parts = sorted(checkpoint_dir(out).glob("part-*.jsonl"))
    parts[-1].write_bytes(parts[-1].read_bytes()[:-3])
    res = bifurcation("l_lambda", values, classify=stop, out=out, resume=True, **kw)
    assert "torn" in capsys.readouterr().err
    frames_equal(res.points, ref.points)


def test_what_a_killed_deletion_left_is_removed_by_the_next_run(tmp_path, reference):
    """A SIGKILL while a finished run deleted its checkpoint (renamed away, then removed)
    leaves ``.tmp-PID-removed-NAME``: the next run over that output removes it, also when it
    only finds the output finished; a folder of a process that still runs stays."""
    import os

    out = tmp_path / "m.parquet"
    regime_map(X, Y, classify=SpreadClassifier(), out=out, **GRID)
    dead = _dead_pid()
    name = checkpoint_dir(out).name
    killed = tmp_path / f".tmp-{dead}-removed-{name}"
    created = tmp_path / f".tmp-{dead}-{name}"  # killed while creating its checkpoint
    mine = tmp_path / f".tmp-{os.getpid()}-removed-{name}"
    for folder in (killed, created, mine):
        (folder / "part-000001.jsonl").parent.mkdir()
        (folder / "part-000001.jsonl").write_text("{}\n")
    again = regime_map(X, Y, classify=SpreadClassifier(), out=out, resume=True, **GRID)
    frames_equal(again.cells, reference.cells)
    assert not killed.exists() and not created.exists()
    assert mine.exists()  # this process still runs


def test_an_interrupted_force_run_over_another_output_resumes(tmp_path, monkeypatch, reference):
    """--force over an output of another configuration, stopped by Ctrl-C, then --resume:
    the checkpoint is this configuration's, so the resume finishes it and replaces the
    output (what --force asked); without that checkpoint the foreign output is refused."""
    out = tmp_path / "m.parquet"
    regime_map(X, Y, classify=SpreadClassifier(), out=out, **{**GRID, "seed": 4})
    one_run_per_batch(monkeypatch)
    stop = InterruptOnce(str(tmp_path / "marker"), 11)
    with pytest.raises(KeyboardInterrupt):
        regime_map(X, Y, classify=stop, out=out, force=True, flush_interval=0.0, **GRID)
    assert checkpoint_dir(out).is_dir()
    res = regime_map(X, Y, classify=stop, out=out, resume=True, **GRID)
    frames_equal(res.realizations, reference.realizations)
    frames_equal(regime_map(X, Y, classify=stop, out=out, resume=True, **GRID).cells, res.cells)
    assert not checkpoint_dir(out).exists()
    with pytest.raises(SweepError, match="different configuration.*--force"):
        regime_map(X, Y, classify=stop, out=out, resume=True, **{**GRID, "seed": 4})


def test_a_file_made_at_the_output_after_the_interruption_is_not_overwritten(tmp_path, monkeypatch):
    """Ctrl-C, then another command writes the free output names, then --resume: refused,
    the files kept (the resume replaced them silently: it took any foreign output beside
    its checkpoint for one a --force run had been asked to replace)."""
    import pandas as pd

    from chaoscam.sweep._common import companion

    out, _, stop = _interrupted(tmp_path, monkeypatch)
    made = {p: p.write_bytes(b"someone else's") for p in (out, companion(out, "cells"))}
    for path in made:
        with pytest.raises(FileExistsError, match="not there.*when the interrupted run"):
            regime_map(X, Y, classify=stop, out=out, resume=True, **GRID)
        assert path.read_bytes() == b"someone else's"
        path.unlink()
    res = regime_map(X, Y, classify=stop, out=out, resume=True, **GRID)  # now it finishes
    assert isinstance(res.cells, pd.DataFrame) and not checkpoint_dir(out).exists()


def test_what_a_run_killed_while_writing_its_tables_left_is_removed(tmp_path, reference):
    """A SIGKILL while the tables were written leaves ``.tmp-PID-NAME`` files beside them:
    the next run over that output removes those of processes that no longer run."""
    import os

    out = tmp_path / "m.parquet"
    dead = _dead_pid()
    killed = [tmp_path / f".tmp-{dead}-{name}" for name in ("m.parquet", "m.cells.parquet")]
    mine = tmp_path / f".tmp-{os.getpid()}-m.parquet.other"
    for path in (*killed, mine):
        path.write_bytes(b"PAR1 half a table")
    res = regime_map(X, Y, classify=SpreadClassifier(), out=out, **GRID)
    frames_equal(res.cells, reference.cells)
    assert not any(p.exists() for p in killed)
    assert mine.exists()  # not a leftover of this output


def test_ctrl_c_while_the_tables_are_written_says_how_to_resume(tmp_path, reference):
    """A Ctrl-C after the last run, while the tables are written: the records are all in
    the checkpoint, the interruption says so (not a bare KeyboardInterrupt), and --resume
    writes the tables."""
    from unittest import mock

    from chaoscam.sweep import SweepInterrupted
    from chaoscam.sweep._regime import RegimeMap

    out = tmp_path / "m.parquet"
    with mock.patch.object(RegimeMap, "_write", side_effect=KeyboardInterrupt):
        with pytest.raises(SweepInterrupted) as stopped:
            regime_map(X, Y, classify=SpreadClassifier(), out=out, **GRID)
    total = len(reference.realizations)
    assert f"{total} of {total} runs are saved" in stopped.value.message
    assert "--resume" in stopped.value.message and not out.exists()
    res = regime_map(X, Y, classify=SpreadClassifier(), out=out, resume=True, **GRID)
    frames_equal(res.realizations, reference.realizations)


def test_a_file_where_the_checkpoint_folder_goes(tmp_path):
    """A file at FILE.ckpt: refused before any work, saying it is a file (it said it held
    the checkpoint of an interrupted run); force=True replaces it and leaves nothing behind
    (it ran the whole map, then failed with 'Not a directory' leaving a .tmp-...-removed file)."""
    out = tmp_path / "m.parquet"
    ckpt = checkpoint_dir(out)
    ckpt.write_text("not mine")
    kw = dict(GRID, classify=SpreadClassifier(), out=out)
    with pytest.raises(FileExistsError, match="is a file where this run keeps its checkpoint"):
        regime_map(X, Y, **kw)
    assert ckpt.read_text() == "not mine" and not out.exists()
    regime_map(X, Y, force=True, **kw)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["m.cells.parquet", "m.parquet"]


def test_a_companion_without_its_main_table_is_named_a_leftover(tmp_path):
    """FILE.cells.parquet without FILE.parquet (and no checkpoint): refused as a leftover,
    with or without resume, naming --force (without resume it advised --resume, which then
    called it another configuration's); force=True replaces it."""
    out = tmp_path / "m.parquet"
    kw = dict(GRID, classify=SpreadClassifier(), out=out)
    regime_map(X, Y, **kw)
    out.unlink()
    for resume in (False, True):
        with pytest.raises(FileExistsError, match="exists without m.parquet, a leftover.*--force"):
            regime_map(X, Y, resume=resume, **kw)
    regime_map(X, Y, force=True, **kw)
    assert out.exists()


def test_a_damaged_finished_output_is_named_on_resume(tmp_path):
    """--resume over a finished run whose companion was cut short raised pyarrow's
    traceback, and one whose main table was cut short was called "another configuration":
    each now names the damage and says to pass --force."""
    from chaoscam.sweep._common import companion

    out = tmp_path / "m.parquet"
    kw = dict(classify=SpreadClassifier(), out=out, **GRID)
    regime_map(X, Y, **kw)
    cells = companion(out, "cells")
    cells.write_bytes(cells.read_bytes()[:300])
    with pytest.raises(SweepError, match="companion cannot be read back.*--force"):
        regime_map(X, Y, resume=True, **kw)
    out.write_bytes(out.read_bytes()[:300])
    with pytest.raises(SweepError, match="not a readable chaoscam sweep.*--force"):
        regime_map(X, Y, resume=True, **kw)
    regime_map(X, Y, force=True, **kw)  # computed again
    assert regime_map(X, Y, resume=True, **kw).cells.shape[0] == 6


def test_a_full_disk_at_the_end_says_what_is_kept_and_resumes(tmp_path, monkeypatch, reference):
    """ENOSPC while the tables are written: the message names the output, the checkpoint
    that keeps every finished run and --resume (it printed only "[Errno 28] ... No space
    left on device"); after the cause is gone the resume writes the tables."""
    import errno

    from chaoscam.sweep._regime import RegimeMap

    out = tmp_path / "m.parquet"

    def full(self, path, replace=False):
        raise OSError(errno.ENOSPC, "No space left on device")

    monkeypatch.setattr(RegimeMap, "_write", full)
    with pytest.raises(OSError, match="No space left on device while saving the results of") as e:
        regime_map(X, Y, classify=SpreadClassifier(), out=out, **GRID)
    assert e.value.errno == errno.ENOSPC
    assert f"kept in {checkpoint_dir(out)}" in str(e.value) and "--resume" in str(e.value)
    monkeypatch.undo()
    res = regime_map(X, Y, classify=SpreadClassifier(), out=out, resume=True, **GRID)
    frames_equal(res.realizations, reference.realizations)


def test_an_error_that_is_not_the_disk_is_not_reworded(tmp_path, monkeypatch):
    """A lost connection (an OSError) during the runs was reported as a save failure ("fix
    the cause (free space)"), its type lost; only a disk that takes no more is reworded."""
    from chaoscam.sweep import _engine

    def lost(*args, **kwargs):
        raise ConnectionError("scheduler closed the connection")

    monkeypatch.setattr(_engine, "run_plan", lost)
    with pytest.raises(ConnectionError, match="^scheduler closed the connection$"):
        regime_map(X, Y, classify=SpreadClassifier(), out=tmp_path / "m.parquet", **GRID)
