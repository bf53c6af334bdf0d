"""One output rule for every command: checked before the work, never overwritten without
--force, written whole, locked against a second writer."""

import os
import subprocess
import sys
import time
from pathlib import Path

import pandas as pd
import pytest

from chaoscam.cli import main
from chaoscam.io import OutputError, OutputLock, atomic_path, check_output

ROOT = Path(__file__).resolve().parents[1]
SLOW = "tests.sweep._helpers:SlowSpreadClassifier"  # 50 ms a run


def _sim(*extra):
    return ["simulate", "--duration", "0.2", *extra]


def _traj(tmp_path):
    path = tmp_path / "run.parquet"
    assert main(_sim("--out", str(path))) == 0
    return path


def _bif(out, *extra):
    return [
        "bifurcation",
        "--param",
        "l_lambda",
        "--values",
        "0.006:0.008:2",
        "--duration",
        "0.5",
        "--workers",
        "1",
        "--quiet",
        "--out",
        str(out),
        *extra,
    ]


def _map(out, *extra):
    return [
        "regime-map",
        "--mu",
        "0.006:0.008:2",
        "--sigma",
        "0:0.001:2",
        "--duration",
        "0.5",
        "--workers",
        "1",
        "--quiet",
        "--classifier",
        "tests.sweep._helpers:SpreadClassifier",
        "--out",
        str(out),
        *extra,
    ]


def _ens(out, *extra):
    return ["ensemble", "--members", "2", "--duration", "0.5", "--quiet", "--out", str(out), *extra]


# Each command and how it names an output: a builder taking the output path.
COMMANDS = {
    "simulate --out": lambda p: _sim("--duration", "2000", "--out", str(p)),
    "simulate --section": lambda p: _sim("--duration", "2000", "--section", str(p)),
    "simulate --impacts": lambda p: _sim("--duration", "2000", "--impacts", str(p)),
    "report --out": lambda p: ["report", "IN", "--out", str(p)],
    "paper --out": lambda p: ["paper", "--figures", "3", "--out", str(p)],
    "bifurcation --out": lambda p: _bif(p),
    "bifurcation --plot": lambda p: _bif(p.with_name("b.parquet"), "--plot", str(p)),
    "regime-map --out": lambda p: _map(p),
    "ensemble --out": lambda p: _ens(p),
    "continue --out": lambda p: ["continue", "--from", "31", "--to", "32", "--out", str(p)],
}
SUFFIX = {
    "simulate --out": ".csv",
    "simulate --section": ".csv",
    "simulate --impacts": ".csv",
    "report --out": ".html",
    "paper --out": ".html",
    "bifurcation --plot": ".png",
}


def _args(tmp_path, command, path):
    args = COMMANDS[command](path)
    if "IN" in args:
        args[args.index("IN")] = str(_traj(tmp_path))
    return args


@pytest.mark.parametrize("case", ["missing folder", "a directory", "exists"])
@pytest.mark.parametrize("command", list(COMMANDS))
def test_bad_output_refused_before_the_work(tmp_path, command, case, capsys):
    """Every command refuses a missing folder, a directory or an existing file with exit 2
    and a message naming the path, before any computation (long runs return at once), and
    leaves an existing file untouched."""
    name = "o" + SUFFIX.get(command, ".parquet")
    path = {
        "missing folder": tmp_path / "nowhere" / name,
        "a directory": tmp_path / "d",
        "exists": tmp_path / name,
    }[case]
    if case == "a directory":
        path = tmp_path / ("d" + SUFFIX.get(command, ".parquet"))
        path.mkdir()
    if case == "exists":
        path.write_text("keep me")
    args = _args(tmp_path, command, path)
    capsys.readouterr()
    t0 = time.perf_counter()
    assert main(args) == 2
    assert time.perf_counter() - t0 < 5.0
    err = capsys.readouterr().err
    assert "error" in err and "Traceback" not in err
    assert str(path.name) in err or str(path.parent) in err, err
    if case == "exists":
        assert path.read_text() == "keep me"


def test_force_replaces_and_writes_whole(tmp_path, capsys):
    """--force replaces an existing output; no temporary file is left beside it."""
    path = tmp_path / "s.csv"
    path.write_text("old")
    assert main(_sim("--section", str(path), "--force")) == 0
    assert pd.read_csv(path).columns[0] == "k"
    assert [p.name for p in tmp_path.iterdir()] == ["s.csv"]


def test_check_output_unwritable_location_and_suffix(tmp_path):
    """A location that takes no files, and a wrong suffix, are refused with the path."""
    with pytest.raises(OutputError, match="cannot write"):
        check_output("/proc/x.csv")
    with pytest.raises(OutputError, match=r"\.html"):
        check_output(tmp_path / "r.txt", suffixes=(".html",))
    assert check_output(None) is None
    # A folder is named as one whatever its suffix; a bare suffix asks for a name before it.
    with pytest.raises(OutputError, match="is a directory"):
        check_output(f"{tmp_path}/", suffixes=(".html",))
    with pytest.raises(OutputError, match=r"after a name \(NAME\.html\)"):
        check_output(tmp_path / ".html", suffixes=(".html",))


def test_atomic_path_keeps_the_old_file_on_failure(tmp_path):
    """A write that fails half-way leaves the old file as it was and no temporary file."""
    path = tmp_path / "a.txt"
    path.write_text("old")
    with pytest.raises(RuntimeError), atomic_path(path) as tmp:
        tmp.write_text("half")
        raise RuntimeError("boom")
    assert path.read_text() == "old"
    assert [p.name for p in tmp_path.iterdir()] == ["a.txt"]


def _hold_lock(path: Path):
    code = (
        "import sys, time; from chaoscam.io import OutputLock; "
        f"OutputLock({str(path)!r}).acquire(); print('held', flush=True); time.sleep(30)"
    )
    proc = subprocess.Popen(
        [sys.executable, "-c", code],
        cwd=ROOT,
        stdout=subprocess.PIPE,
        env=dict(os.environ, PYTHONPATH=str(ROOT)),
        text=True,
    )
    assert proc.stdout.readline().strip() == "held"
    return proc


def test_lock_refuses_a_second_process_and_dies_with_its_holder(tmp_path):
    """A lock held by another process is refused with its pid; once that process is
    killed the lock is free again (no stale lock)."""
    target = tmp_path / "m.parquet"
    proc = _hold_lock(target)
    try:
        with pytest.raises(OutputError, match=f"another chaoscam process .pid {proc.pid}"):
            OutputLock(target).acquire()
    finally:
        proc.kill()
        proc.wait()
    with OutputLock(target):
        pass
    assert not (tmp_path / ".m.parquet.lock").exists()


@pytest.mark.parametrize("command", ["regime-map", "bifurcation", "ensemble"])
def test_locked_output_refused_with_exit_2(tmp_path, command, capsys):
    """A sweep or ensemble whose output is in use by another process is refused (exit 2)
    before any work, and writes nothing."""
    out = tmp_path / "o.parquet"
    build = {"regime-map": _map, "bifurcation": _bif, "ensemble": _ens}[command]
    proc = _hold_lock(out)
    try:
        assert main(build(out)) == 2
    finally:
        proc.kill()
        proc.wait()
    assert "in use by another chaoscam process" in capsys.readouterr().err
    assert sorted(p.name for p in tmp_path.iterdir() if not p.name.startswith(".")) == []


@pytest.mark.parametrize(
    "command, held",
    [
        ("bifurcation", "o.verdicts.parquet"),  # its companion, written by another sweep
        ("regime-map", "o.cells.parquet"),
        ("ensemble", "o.sections.parquet"),
        ("simulate", "o.parquet"),  # a sweep's output
    ],
)
def test_a_companion_in_use_is_refused_too(tmp_path, command, held, capsys):
    """The lock covers a run's companions: a second run naming one (--out X.verdicts.parquet
    while a sweep writes X.parquet) ran to its end and then failed; and `simulate --out`
    took no lock at all."""
    out = tmp_path / "o.parquet"
    build = {"regime-map": _map, "bifurcation": _bif, "ensemble": _ens}.get(command)
    argv = build(out) if build else ["simulate", "--duration", "0.2", "--out", str(out)]
    proc = _hold_lock(tmp_path / held)
    try:
        assert main(argv) == 2
    finally:
        proc.kill()
        proc.wait()
    assert "in use by another chaoscam process" in capsys.readouterr().err
    assert sorted(p.name for p in tmp_path.iterdir() if not p.name.startswith(".")) == []


def test_two_writers_started_together(tmp_path):
    """Two regime maps on one output started together: one is refused (exit 2, a message),
    the other ends normally with every row (3 cells x 4 realizations with sigma > 0, and the
    3 deterministic sigma = 0 cells once each)."""
    out = tmp_path / "m.parquet"
    args = _map(out, "--realizations", "4", "--checkpoint-interval", "0")
    args[args.index("tests.sweep._helpers:SpreadClassifier")] = SLOW
    args[args.index("0.006:0.008:2")] = "0.006:0.010:3"
    code = "import sys; from chaoscam.cli import main; sys.exit(main(sys.argv[1:]))"
    env = dict(os.environ, PYTHONPATH=str(ROOT))
    procs = [
        subprocess.Popen(
            [sys.executable, "-c", code, *args],
            cwd=ROOT,
            env=env,
            stdout=subprocess.PIPE,
            stderr=subprocess.PIPE,
            text=True,
        )
        for _ in range(2)
    ]
    results = [p.communicate(timeout=120) for p in procs]
    codes = sorted(p.returncode for p in procs)
    assert codes == [0, 2], results
    refused = results[[p.returncode for p in procs].index(2)][1]
    assert "in use by another chaoscam process" in refused or "exists" in refused, refused
    assert "Traceback" not in refused
    assert len(pd.read_parquet(out)) == 3 * 4 + 3


def test_atomic_path_without_replace_says_when_the_file_was_there_before(tmp_path):
    """replace=False over a file that existed before the call: kept, and the error allows
    that it was there before (it said only "another process wrote it")."""
    out = tmp_path / "pre.html"
    out.write_text("old")
    said = r"pre.html exists: .* or \(a call with replace=False\) it was there before"
    with pytest.raises(OutputError, match=said):
        with atomic_path(out, replace=False) as tmp:
            tmp.write_text("ours")
    assert out.read_text() == "old"


def test_atomic_path_without_replace_keeps_a_file_that_appeared_meanwhile(tmp_path):
    """replace=False (an output checked absent, no --force): a file another process wrote
    while this one worked is kept as it is, this one's result goes beside it as NAME.PID.SUFFIX,
    and the error names both."""
    from chaoscam.io import conflict_name

    out = tmp_path / "x.csv"
    with pytest.raises(OutputError, match="another process wrote it while this run worked") as err:
        with atomic_path(out, replace=False) as tmp:
            tmp.write_text("ours")
            out.write_text("theirs")  # another process, meanwhile
    assert out.read_text() == "theirs"
    assert conflict_name(out).read_text() == "ours" and str(conflict_name(out)) in str(err.value)
    assert [p.name for p in tmp_path.iterdir() if p.name.startswith(".tmp")] == []
    fresh = tmp_path / "y.csv"
    with atomic_path(fresh, replace=False) as tmp:
        tmp.write_text("ours")
    assert fresh.read_text() == "ours"


def test_a_sweep_does_not_replace_an_output_written_during_its_run(tmp_path, monkeypatch, capsys):
    """A file written at the sweep's --out while it runs (by a command that took no lock on it)
    is not replaced at the end: exit 2, the file kept, the sweep's table beside it, and the
    checkpoint kept: nothing is lost."""
    from chaoscam.sweep import _engine

    out = tmp_path / "b.parquet"
    run_plan = _engine.run_plan

    def meanwhile(*args, **kwargs):
        out.write_text("theirs")
        return run_plan(*args, **kwargs)

    monkeypatch.setattr(_engine, "run_plan", meanwhile)
    assert main(_bif(out)) == 2
    assert "another process wrote it while this run worked" in capsys.readouterr().err
    assert out.read_text() == "theirs"
    assert len(pd.read_parquet(tmp_path / f"b.{os.getpid()}.parquet")) > 0
    assert (tmp_path / "b.parquet.ckpt").is_dir()


@pytest.mark.parametrize(
    "extra, message",
    [
        (["--out", "a.csv", "--section", "a.csv"], "both name"),
        (["--section", "s.csv", "--impacts", "s.csv"], "both name"),
        (["--section", "s.parquet"], "must end in .csv"),
        (["--impacts", "i.parquet"], "must end in .csv"),
    ],
)
def test_simulate_refuses_outputs_that_clash_or_lie_about_their_format(
    tmp_path, monkeypatch, capsys, extra, message
):
    """Two outputs of one simulate naming one file (the second replaced the first), and a
    section or impact list (CSV) named .parquet: exit 2 before any work, nothing written."""
    monkeypatch.chdir(tmp_path)
    assert main(_sim(*extra)) == 2
    assert message in capsys.readouterr().err
    assert list(tmp_path.iterdir()) == []


def test_resume_does_not_replace_an_existing_plot(tmp_path, capsys):
    """--resume continues a sweep's table; a plot exists only after a finished run, so an
    existing --plot file is refused under --resume as without it (exit 2, kept)."""
    plot = tmp_path / "p.png"
    plot.write_text("mine")
    code = main(_bif(tmp_path / "b.parquet", "--plot", str(plot), "--resume"))
    assert code == 2 and "--plot" in capsys.readouterr().err
    assert plot.read_text() == "mine"


def test_a_classifier_that_is_not_callable_is_a_usage_error(tmp_path, capsys):
    """--classifier naming a number (not a function or class): exit 2 with one line that
    names it, no traceback, and no checkpoint left behind."""
    assert main(_bif(tmp_path / "b.parquet", "--classifier", "math:pi")) == 2
    err = capsys.readouterr().err
    assert "--classifier math:pi" in err and "cannot be called" in err and "Traceback" not in err
    assert list(tmp_path.iterdir()) == []
    # A class whose instances cannot be called: said so, not "int is a int".
    assert main(_bif(tmp_path / "b.parquet", "--classifier", "builtins:int")) == 2
    err = capsys.readouterr().err
    assert "int() makes 0 (type int), which cannot be called" in err
    assert list(tmp_path.iterdir()) == []


def test_an_api_sweep_into_a_missing_folder_names_the_folder(tmp_path):
    """bifurcation(out='nodir/x.parquet') says the folder does not exist (it said it could not
    create a lock file)."""
    from chaoscam.sweep import bifurcation

    with pytest.raises(OutputError, match=r"the folder .*nodir does not exist; create it first"):
        bifurcation("l_lambda", [0.008], duration=0.1, out=tmp_path / "nodir" / "x.parquet")


def test_path_messages_say_what_the_path_is(tmp_path, capsys):
    """A file where a folder is expected, a folder where a file is read, and a dangling link
    under --force (replaced like a file): the message describes the actual path."""
    (tmp_path / "f").write_text("a file")
    with pytest.raises(OutputError, match="is a file, not a folder"):
        check_output(tmp_path / "f" / "x.parquet")
    (tmp_path / "d").mkdir()
    assert main(["classify", str(tmp_path / "d")]) == 2
    assert "is a folder" in capsys.readouterr().err
    link = tmp_path / "l.parquet"
    link.symlink_to(tmp_path / "missing" / "z.parquet")
    with pytest.raises(OutputError, match="exists; nothing was overwritten"):
        check_output(link)
    assert check_output(link, force=True) == link
    assert main(["simulate", "--duration", "0.05", "--out", str(link), "--force"]) == 0
    assert not link.is_symlink() and pd.read_parquet(link).shape[0] > 0


def test_a_name_too_long_for_its_companions_is_refused_before_the_work(tmp_path, capsys):
    """A 230-character output ran a whole sweep, wrote its table, then failed on its
    companion's temporary name (over 255 bytes), and again on --resume: now exit 2 first,
    naming the length, for the output or its companion."""
    for stem in ("a" * 244, "a" * 225, "a" * 215):  # its lock's name; itself; its companion
        out = tmp_path / f"{stem}.parquet"
        assert main(_bif(out)) == 2
        assert "bytes; at most" in capsys.readouterr().err
    assert sorted(p.name for p in tmp_path.iterdir() if not p.name.startswith(".")) == []


def test_a_full_disk_names_the_simulation_output(tmp_path, monkeypatch, capsys):
    """simulate --out on a full disk printed "[Errno 28] No space left on device" without
    the file; now the file and that nothing was written there."""
    import errno

    from chaoscam import Solution

    def full(self):
        raise OSError(errno.ENOSPC, "No space left on device")

    monkeypatch.setattr(Solution, "parquet_table", full)
    out = tmp_path / "s.parquet"
    assert main(["simulate", "--duration", "0.2", "--out", str(out)]) == 2
    err = capsys.readouterr().err
    assert f"cannot write {out}: No space left on device; nothing was written" in err
    assert not out.exists()


def test_api_writers_refuse_an_existing_file_and_write_whole(tmp_path, monkeypatch):
    """Solution.to_parquet and RegimeMap.to_parquet never replace a file without
    replace=True, and a write that fails half-way leaves the old file as it was."""
    import chaoscam
    import chaoscam.io._parquet as parquet
    from chaoscam.sweep import Axis, read_regime_map, regime_map

    traj = chaoscam.simulate(duration=0.2)
    path = tmp_path / "t.parquet"
    traj.to_parquet(path)
    before = path.read_bytes()
    with pytest.raises(OutputError, match="exists; nothing was overwritten.*replace=True"):
        traj.to_parquet(path)
    with pytest.raises(OutputError, match="is a directory"):
        traj.to_parquet(tmp_path)

    def half(table, where):
        Path(where).write_bytes(b"PAR1 half")
        raise OSError(28, "No space left on device")

    monkeypatch.setattr(parquet, "write_table", half)
    with pytest.raises(OSError, match="No space"):
        traj.to_parquet(path, replace=True)
    assert path.read_bytes() == before and not list(tmp_path.glob(".tmp-*"))
    monkeypatch.undo()
    m = regime_map(Axis("xi", (0.2,)), Axis("l_lambda_sigma", (0.0,)), realizations=1,
                   duration=0.5, workers=1)  # fmt: skip
    m.to_parquet(tmp_path / "m.parquet")
    with pytest.raises(OutputError, match="m.parquet exists"):
        m.to_parquet(tmp_path / "m.parquet")
    (tmp_path / "n.cells.parquet").write_text("theirs")
    with pytest.raises(OutputError, match="n.cells.parquet exists"):
        m.to_parquet(tmp_path / "n.parquet")
    assert not (tmp_path / "n.parquet").exists()
    m.to_parquet(tmp_path / "m.parquet", replace=True)
    assert read_regime_map(tmp_path / "m.parquet").cells.shape == m.cells.shape


def test_a_second_thread_of_the_process_is_refused_the_lock(tmp_path):
    """The lock is re-entrant in the thread that holds it (a sweep inside the command that
    locked its output) and refused to another thread: two sweeps in one process on one
    output must not both write it."""
    import threading

    target = tmp_path / "out.parquet"
    held, done, seen = threading.Event(), threading.Event(), []

    def holder():
        with OutputLock(target):
            held.set()
            done.wait(10)

    t = threading.Thread(target=holder)
    t.start()
    held.wait(10)
    try:
        with pytest.raises(OutputError, match="in use by another thread of this process"):
            OutputLock(target).acquire()
    finally:
        done.set()
        t.join()
    with OutputLock(target), OutputLock(target):  # re-entrant in one thread
        seen.append(1)
    assert seen == [1]


def test_a_resume_with_another_classifier_is_refused(tmp_path):
    """Two partials of one function, or two lambdas, have different identities: a resume
    with another one does not reuse the first one's labels."""
    import functools

    from chaoscam.sweep import Axis, SweepError, regime_map
    from chaoscam.sweep._runs import classifier_identity

    a = functools.partial(_verdict, extend_to=None)
    b = functools.partial(_verdict, extend_to=40.0)
    assert classifier_identity(a) != classifier_identity(b)
    assert classifier_identity(lambda t: 1) != classifier_identity(lambda t: 2)
    assert classifier_identity(a) == classifier_identity(
        functools.partial(_verdict, extend_to=None)
    )
    kw = dict(realizations=1, seed=3, duration=0.5, workers=1, out=tmp_path / "m.parquet")
    x, y = Axis("xi", (0.2,)), Axis("l_lambda_sigma", (0.0,))
    regime_map(x, y, classify=a, **kw)
    with pytest.raises(SweepError, match="differs in: classifier"):
        regime_map(x, y, classify=b, resume=True, **kw)


def _verdict(run, **options):
    """A classifier of one's own: the package's verdict on the one run."""
    import chaoscam

    (verdict,) = chaoscam.classify(run, **options)
    return verdict


def test_threads_writing_into_one_folder_do_not_collide(tmp_path):
    """The folder probe was named by the process id only: four threads saving runs into one
    folder failed with 'cannot write in the folder (File exists)'."""
    import threading

    import chaoscam

    traj = chaoscam.simulate(duration=0.1, series=False)
    errors = []

    def save(i):
        try:
            for j in range(15):
                traj.to_parquet(tmp_path / f"run{i}-{j}.parquet")
        except Exception as err:  # noqa: BLE001 - collected for the assertion
            errors.append(err)

    threads = [threading.Thread(target=save, args=(i,)) for i in range(4)]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    assert errors == [] and len(list(tmp_path.glob("run*.parquet"))) == 60


def test_classifier_identities_tell_methods_apart_and_ignore_where_code_sits():
    """Bound methods of two instances shared one identity; a lambda's moved down a line or
    compiled under another file name changed it (a resume of the same code was refused);
    a partial's argument with the default repr named an address (new in every process)."""
    import functools

    from chaoscam.sweep._runs import classifier_identity as ident

    class Clf:
        def __init__(self, tol):
            self.tol = tol

        def classify(self, run):
            return _verdict(run)

    assert ident(Clf(0.1).classify) != ident(Clf(0.5).classify)
    assert ident(Clf(0.1).classify) == ident(Clf(0.1).classify)
    one = eval(compile("lambda t: t", "a.py", "eval"))
    moved = eval(compile("\n\n(lambda t:\n t)", "b.py", "eval"))
    assert ident(one) == ident(moved) != ident(eval(compile("lambda t: 2", "a.py", "eval")))
    part = functools.partial(_verdict, helper=Clf(1.0))
    assert " at 0x" not in ident(part)
    assert ident(part) == ident(functools.partial(_verdict, helper=Clf(1.0)))
