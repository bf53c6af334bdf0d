"""The analyses/ scripts: one per paper figure, each writing its data and figure."""

import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]


def test_there_is_one_script_per_paper_figure():
    """analyses/ holds fig3.py ... fig10.py."""
    assert sorted(p.name for p in (ROOT / "analyses").glob("fig*.py")) == sorted(
        f"fig{n}.py" for n in range(3, 11)
    )


def _script(name, *args):
    return subprocess.run(
        [sys.executable, str(ROOT / "analyses" / name), *args],
        capture_output=True,
        text=True,
    )


def test_a_script_replaces_existing_files_only_with_force(tmp_path):
    """A script writes a PNG and a data file into OUTDIR and prints the comparison; a second
    run into the same folder is refused (exit 2, one line naming a file, the files kept: the
    committed reports/paper-data would otherwise be overwritten by a quick run); with
    --force it replaces them."""
    first = _script("fig5.py", "--quick", str(tmp_path))
    assert first.returncode == 0 and "Fig. 5" in first.stdout
    data = list(tmp_path.glob("*.csv")) + list(tmp_path.glob("*.parquet"))
    assert list(tmp_path.glob("*.png")) and data
    before = {p.name: p.stat().st_mtime_ns for p in tmp_path.iterdir()}
    again = _script("fig5.py", "--quick", str(tmp_path))
    assert again.returncode == 2 and "Traceback" not in again.stderr
    assert "--force" in again.stderr and "already holds fig5" in again.stderr
    assert {p.name: p.stat().st_mtime_ns for p in tmp_path.iterdir()} == before
    forced = _script("fig5.py", "--quick", "--force", str(tmp_path))
    assert forced.returncode == 0
    assert all(p.stat().st_mtime_ns != before[p.name] for p in tmp_path.iterdir())


def test_a_script_explains_itself_and_refuses_what_it_does_not_know(tmp_path):
    """--help prints the usage and creates nothing (it used to make a folder named
    '--help'); an unknown option and an OUTDIR that is a file: exit 2 without a traceback."""
    helped = subprocess.run(
        [sys.executable, str(ROOT / "analyses" / "sensitivity.py"), "--help"],
        capture_output=True,
        text=True,
        cwd=tmp_path,
    )
    assert helped.returncode == 0 and "--force" in helped.stdout and "OUTDIR" in helped.stdout
    assert list(tmp_path.iterdir()) == []
    workers = _script("fig4.py", "--workers", "0", str(tmp_path / "w"))
    assert workers.returncode == 2 and "workers = 0 must be in [1, " in workers.stderr
    assert "Traceback" not in workers.stderr and not (tmp_path / "w").exists()
    wrong = _script("fig4.py", "--quik", str(tmp_path))
    assert wrong.returncode == 2 and "--quik" in wrong.stderr and "Traceback" not in wrong.stderr
    (tmp_path / "file").write_text("x")
    onto_file = _script("fig3.py", "--quick", str(tmp_path / "file"))
    assert onto_file.returncode == 2 and "is a file" in onto_file.stderr
    assert list(tmp_path.iterdir()) == [tmp_path / "file"]


def test_labelled_set_refuses_to_overwrite_the_truth_before_measuring(tmp_path):
    """analyses/labelled_set.py checks OUT.json before hours of measurement: an existing
    file (by default the tests' truth) is refused without --force, at once, and kept."""
    out = tmp_path / "truth.json"
    out.write_text("{}")
    run = _script("labelled_set.py", str(out))
    assert run.returncode == 2 and "--force" in run.stderr and "Traceback" not in run.stderr
    assert out.read_text() == "{}"


def test_a_script_into_a_folder_in_use_is_refused(tmp_path):
    """While another process writes into OUTDIR (chaoscam paper into its paper-data, or
    another script), a script there is refused at once, naming the holder."""
    from tests.test_outputs import _hold_lock

    outdir = tmp_path / "paper-data"
    outdir.mkdir()
    holder = _hold_lock(outdir)
    try:
        busy = _script("fig3.py", "--quick", "--force", str(outdir))
    finally:
        holder.kill()
        holder.wait()
    assert busy.returncode == 2 and "Traceback" not in busy.stderr
    assert f"in use by another chaoscam process (pid {holder.pid})" in busy.stderr
    assert list(outdir.iterdir()) == []


def test_a_script_into_the_current_folder_runs(tmp_path):
    """OUTDIR '.' (the current folder): its lock goes beside it, as chaoscam paper's does
    (the lock refused a path without a name)."""
    done = subprocess.run(
        [sys.executable, str(ROOT / "analyses" / "fig3.py"), "--quick", "."],
        capture_output=True,
        text=True,
        cwd=tmp_path,
    )
    assert done.returncode == 0, done.stderr
    assert (tmp_path / "fig3.csv").exists()
    assert not list(tmp_path.parent.glob(f".{tmp_path.name}.lock"))  # released


@pytest.mark.slow
def test_a_script_stopped_by_sigterm_says_so_and_resumes(tmp_path):
    """SIGTERM during the sensitivity sweeps (~20 s quick): exit 143 with one line saying what
    is kept and --resume (it exited silently); --resume then finishes, with no checkpoint
    left."""
    import signal
    import time

    proc = subprocess.Popen(
        [sys.executable, str(ROOT / "analyses" / "sensitivity.py"), "--quick", str(tmp_path)],
        stderr=subprocess.PIPE,
        stdout=subprocess.PIPE,
        text=True,
    )
    time.sleep(8.0)  # imports done, a sweep under way
    proc.send_signal(signal.SIGTERM)
    _, err = proc.communicate(timeout=120)
    assert proc.returncode == 143, err
    assert err.strip().endswith("run the same command with --resume to continue")
    assert "terminated; the finished sweeps are kept" in err and "Traceback" not in err
    done = _script("sensitivity.py", "--quick", "--resume", str(tmp_path))
    assert done.returncode == 0, done.stderr
    assert not list(tmp_path.glob("*.ckpt"))
