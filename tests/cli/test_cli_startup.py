"""Ctrl-C while the command starts (importing numpy, pandas, numba and the kernels): one
line, exit 130, never a traceback."""

import signal
import subprocess
import sys
import time
import tomllib
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]

# What the console script does, with a mark on stdout just before chaoscam is imported.
CODE = (
    "import sys; print('up', flush=True); from chaoscam.cli import main; "
    "sys.exit(main(sys.argv[1:]))"
)


def _python(*args: str, check: bool = False) -> subprocess.CompletedProcess:
    """A fresh interpreter on ``args`` in the project root, its output captured as text."""
    return subprocess.run(
        [sys.executable, *args], capture_output=True, text=True, cwd=ROOT, check=check
    )


def test_console_script_runs_cli_entry():
    """The installed `chaoscam` command is chaoscam.cli:entry, main (the function tested here)
    and an exit with its code."""
    project = tomllib.loads((ROOT / "pyproject.toml").read_text())["project"]
    assert project["scripts"]["chaoscam"] == "chaoscam.cli:entry"


def test_entry_exits_with_main_code_after_freezing_the_heap():
    """entry() exits with main()'s code, the objects frozen out of the exit's collections."""
    code = (
        "import gc, chaoscam.cli as c\n"
        "c.main = lambda: 3\n"
        "try:\n    c.entry()\n"
        "except SystemExit as e:\n    print(e.code, gc.get_freeze_count() > 0)\n"
    )
    assert _python("-c", code, check=True).stdout.split() == ["3", "True"]


@pytest.mark.parametrize("module", ["chaoscam", "chaoscam.cli"])
def test_python_m_runs_a_command_to_its_end(module, tmp_path):
    """`python -m chaoscam[.cli] simulate` prints its whole summary, writes its file and
    exits 0 through entry(); bad input still exits 2 with one line."""
    out = tmp_path / "impacts.csv"
    run = _python("-m", module, "simulate", "--duration", "0.2", "--impacts", str(out))
    assert run.returncode == 0, run.stderr
    assert "contact fraction" in run.stdout and f"impacts: {out}" in run.stdout
    assert out.read_text().startswith("t,")
    bad = _python("-m", module, "simulate", "--duration", "-1")
    assert bad.returncode == 2 and bad.stderr.startswith("chaoscam: error: duration")


def test_cli_module_loads_nothing_heavy():
    """Importing chaoscam.cli (all the console script does before main catches Ctrl-C) loads
    neither argparse nor numpy, pandas or numba: that unguarded window stays ~a millisecond."""
    code = (
        "import sys, chaoscam.cli; "
        "print(sorted({m.split('.')[0] for m in sys.modules} & "
        "{'argparse', 'numpy', 'pandas', 'numba', 'scipy', 'chaoscam.model'}))"
    )
    assert _python("-c", code, check=True).stdout.strip() == "[]"


def _cli_up(*argv: str) -> subprocess.Popen:
    """The CLI on ``argv`` in a fresh interpreter, returned once it prints its "up" mark (just
    before chaoscam is imported)."""
    proc = subprocess.Popen(
        [sys.executable, "-c", CODE, *argv],
        cwd=ROOT,
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
    )
    assert proc.stdout.readline() == "up\n"
    return proc


@pytest.mark.parametrize("delay", [0.05, 0.1, 0.2, 0.4])
def test_ctrl_c_during_start_up_is_one_line(delay):
    """SIGINT `delay` s after the interpreter is up (while chaoscam imports its layers, or
    just after): exit 130 and the one line "chaoscam: interrupted", no traceback. The run
    is long enough (200 s of model time, about a second) to be going at the latest signal:
    with warm caches a 20 s run ended before 0.4 s, and exited 0."""
    proc = _cli_up("simulate", "--duration", "200")
    try:
        time.sleep(delay)
        proc.send_signal(signal.SIGINT)
        _, err = proc.communicate(timeout=60)
    finally:
        proc.kill()
    assert "Traceback" not in err, err
    assert proc.returncode == 130, err
    assert err.strip() == "chaoscam: interrupted"


def _modules_after(code: str) -> set[str]:
    out = subprocess.run(
        [sys.executable, "-c", code], capture_output=True, text=True, cwd=ROOT, check=True
    ).stdout
    return set(out.split())


def test_import_and_run_leave_numba_threading_layer_to_first_parallel_launch():
    """Importing the simulate path changes no process-wide setting, nor does a single run
    (it launches nothing parallel); the first parallel launch (an ensemble) picks the
    fork-safe layer (unless the user chose one)."""
    code = (
        "import numba, chaoscam; print(numba.config.THREADING_LAYER); "
        "chaoscam.simulate(duration=0.001, series=False); print(numba.config.THREADING_LAYER); "
        "chaoscam.solve(chaoscam.Params(), indices=[0, 1], duration=0.001); "
        "print(numba.config.THREADING_LAYER)"
    )
    out = subprocess.run(
        [sys.executable, "-c", code], capture_output=True, text=True, cwd=ROOT, check=True
    ).stdout.split()
    assert out == ["default", "default", "workqueue"]


def test_ctrl_c_inside_an_import_lock_callback_is_sent_again(monkeypatch):
    """A Ctrl-C that lands in importlib's module-lock weakref callback (where an exception
    is printed as "Exception ignored" and lost: seen once in a clean-clone run) is delivered
    again a moment later; anywhere else it is a KeyboardInterrupt at once."""
    import os
    import types

    from chaoscam import cli

    sent = []
    monkeypatch.setattr(os, "kill", lambda pid, sig: sent.append((pid, sig)))
    in_cb = types.SimpleNamespace(
        f_code=types.SimpleNamespace(co_name="cb", co_filename="<frozen importlib._bootstrap>")
    )
    cli._on_sigint(signal.SIGINT, in_cb)
    deadline = time.monotonic() + 5.0
    while not sent and time.monotonic() < deadline:
        time.sleep(0.01)
    assert sent == [(os.getpid(), signal.SIGINT)]
    with pytest.raises(KeyboardInterrupt):
        cli._on_sigint(signal.SIGINT, sys._getframe())


@pytest.mark.parametrize("signum, code", [(signal.SIGINT, 130), (signal.SIGTERM, 143)])
def test_an_interrupt_lost_on_its_way_still_gives_one_line(monkeypatch, capsys, signum, code):
    """A Ctrl-C (or SIGTERM) whose KeyboardInterrupt a C extension's import turns into an
    ImportError (numpy: 'PyCapsule_Import could not import module "datetime"', then its
    "bad install" message and a traceback, exit 1: 2 of 42 Ctrl-Cs 0.1 s into a loaded
    start-up), or that a guard around an optional import swallows (a clean clone's suite
    once ran a Ctrl-C'd `simulate` to its end, exit 0), still gives the one line and 130
    (143). Without a signal an ImportError propagates and a finished run exits 0."""
    from chaoscam import cli

    handler = {signal.SIGINT: cli._on_sigint, signal.SIGTERM: cli._on_sigterm}[signum]
    word = "interrupted" if signum == signal.SIGINT else "terminated"

    def converted(argv):
        try:
            handler(signum, sys._getframe())
        except KeyboardInterrupt:
            raise ImportError('PyCapsule_Import could not import module "datetime"') from None

    def swallowed(argv):
        try:
            handler(signum, sys._getframe())
        except KeyboardInterrupt:
            pass  # as `except ImportError: pass` around an optional import, once converted
        return 0

    for dispatch in (converted, swallowed):
        monkeypatch.setattr(cli, "_dispatch", dispatch)
        assert cli.main([]) == code
        assert capsys.readouterr().err.strip() == f"chaoscam: {word}"

    def broken(argv):
        raise ImportError("not an interrupt")

    monkeypatch.setattr(cli, "_dispatch", broken)
    with pytest.raises(ImportError, match="not an interrupt"):
        cli.main([])
    monkeypatch.setattr(cli, "_dispatch", lambda argv: 0)
    assert cli.main([]) == 0


def test_sigterm_stops_a_single_run_whose_cam_period_holds_many_steps():
    """SIGTERM reaches a `simulate` inside the compiled kernel: with omega = 1 rad/s and
    dt = 2e-8 s a cam period holds 3e8 steps, and a compiled call that ran to the next
    section ignored the signal for minutes; with the kernel's step budget per call the run
    ends within seconds, exit 143 and one line."""
    proc = _cli_up("simulate", "--duration", "20", "--set", "omega=1", "--set", "dt=2e-8")
    try:
        time.sleep(10.0)  # imported and compiled (or still compiling): inside the run
        assert proc.poll() is None
        sent = time.monotonic()
        proc.send_signal(signal.SIGTERM)
        _, err = proc.communicate(timeout=120)
        waited = time.monotonic() - sent
    finally:
        proc.kill()
    assert proc.returncode == 143, err
    assert "Traceback" not in err and err.strip() == "chaoscam: terminated", err
    assert waited < 10.0, waited
