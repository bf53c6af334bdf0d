"""The ``chaoscam`` command: a thin layer over the API.

One module per group of subcommands in this package (``_simulate``, ``_ensemble``,
``_classify``, ``_sweep``, ``_report``), each importing the layer it drives, never the reverse;
this module only wires them. A command module exposes ``register(subparsers)``, which adds
its parsers and sets ``func`` on them; ``func`` takes the parsed arguments and returns an
exit code. Bad input exits with code 2 and a message naming the field.

Importing this module loads nothing but :mod:`sys`: everything else (argparse, numpy, the
kernels, the command modules) is imported inside :func:`main`, where a Ctrl-C is caught, so
a Ctrl-C during start-up ends with one line and exit 130 like one during the work. What runs
before (the interpreter's own start-up and ``import chaoscam``, about a millisecond) is
outside the command's reach.
"""

from __future__ import annotations

import sys

TYPE_CHECKING = False  # typing.TYPE_CHECKING without importing typing (start-up time)
if TYPE_CHECKING:
    import argparse

    from ..model import Params
    from ..numerics import Numerics

__all__ = ["entry", "main", "parse_assignments", "show_warning", "stop_word", "UsageError"]

# Modules that add subcommands, in the order they are listed by --help.
_COMMAND_MODULES = (
    "chaoscam.cli._simulate",
    "chaoscam.cli._ensemble",
    "chaoscam.cli._classify",
    "chaoscam.cli._sweep",
    "chaoscam.cli._report",
    "chaoscam.cli._params",
)


class UsageError(Exception):
    """Bad command-line input: printed as ``chaoscam: error: ...`` with exit code 2."""


def parse_assignments(items: list[str] | None) -> tuple[Params, Numerics]:
    """The model and numerics of ``--set NAME=VALUE`` items (each name a field of one of them)."""
    from .._util import ParameterError, unknown_message
    from ..model import Params, field_names, parse_value
    from ..numerics import Numerics

    pairs: dict[str, str] = {}
    for item in items or []:
        name, sep, value = item.partition("=")
        if not sep or not name.strip():
            raise UsageError(f"--set expects NAME=VALUE, got {item!r}")
        if name.strip() in pairs:
            raise UsageError(
                f"--set {name.strip()} is given twice ({pairs[name.strip()]!r} and {value!r}): "
                "give each parameter once"
            )
        pairs[name.strip()] = value
    steps = Numerics.field_names()
    for name in pairs:
        if name not in field_names() and name not in steps:
            raise ParameterError(unknown_message(name, (*field_names(), *steps)))
    model = {k: parse_value(k, v) for k, v in pairs.items() if k not in steps}
    numerics = {k: Numerics.parse(k, v) for k, v in pairs.items() if k in steps}
    return Params(**model), Numerics(**numerics)


def build_parser() -> argparse.ArgumentParser:
    import argparse
    import importlib

    parser = argparse.ArgumentParser(
        prog="chaoscam",
        description="Stochastic dynamics of a cam-follower oblique impact system.",
    )
    from .._version import __version__

    parser.add_argument("--version", action="version", version=f"chaoscam {__version__}")
    sub = parser.add_subparsers(dest="command", metavar="COMMAND")
    for name in _COMMAND_MODULES:
        try:
            module = importlib.import_module(name)
        except ModuleNotFoundError as err:
            if err.name is None or not (name == err.name or name.startswith(err.name + ".")):
                raise  # a missing dependency inside the module, not a missing module
            continue  # that layer is not installed in this build
        module.register(sub)
    return parser


_SIGTERM = {"seen": False}
_SIGINT = {"seen": False}


def _on_sigterm(signum, frame) -> None:
    """SIGTERM is handled like Ctrl-C (finished work saved, a resume hint), exit 143."""
    _SIGTERM["seen"] = True
    raise KeyboardInterrupt


def _on_sigint(signum, frame) -> None:
    """Ctrl-C: a KeyboardInterrupt, except inside the weakref callback importlib runs when a
    module lock is released during an import (``_get_module_lock.<locals>.cb``). An exception
    raised there cannot propagate: Python prints "Exception ignored ... Traceback" and goes
    on, the Ctrl-C lost. There the signal is sent again a moment later, when the callback has
    returned (rare: once in a clean-clone test run, never in 48 tries at 0.15-0.3 s).

    The signal is recorded too, for :func:`main`: a KeyboardInterrupt raised inside an
    import does not always arrive. Inside a C extension's initialisation it can come back
    as an ImportError (numpy's ``PyCapsule_Import could not import module "datetime"``, then
    its "bad install" message and a traceback: 2 of 42 Ctrl-Cs 0.1 s into a start-up on a
    loaded machine), which a guard around an optional import may swallow (a clean clone's
    suite once ran a Ctrl-C'd ``simulate`` to its end, exit 0). Putting every signal off
    until the import under way ends avoids both, but made a Ctrl-C in start-up take 1.1 s
    (median, 1.4 s at most) instead of 0.04 s."""
    _SIGINT["seen"] = True
    code = getattr(frame, "f_code", None)
    if (
        code is not None
        and code.co_name == "cb"
        and code.co_filename == "<frozen importlib._bootstrap>"
    ):
        import os
        import threading

        threading.Timer(0.01, os.kill, (os.getpid(), signum)).start()
        return
    raise KeyboardInterrupt


def main(argv: list[str] | None = None) -> int:
    """Run the ``chaoscam`` command; returns the exit code.

    0 success, 1 a run that could not do what was asked (its cause printed), 2 bad input
    (a message naming the field or path, never a traceback), 130 Ctrl-C and 143 SIGTERM
    (both after saving finished work and saying how to resume), 141 when the reader of
    stdout left (``| head``: no message, as a shell reports SIGPIPE). A Ctrl-C at any point of
    this function, the imports of start-up included, gives one line and 130, also where
    the interrupt came back as another exception or was swallowed on its way (the run then
    ends where it would have, its output whole; :func:`_on_sigint`). Without a Ctrl-C or
    SIGTERM an exception propagates as it is.
    """
    previous = None
    previous_int = None
    _SIGTERM["seen"] = False
    _SIGINT["seen"] = False
    try:
        import signal
        import threading

        if threading.current_thread() is threading.main_thread():
            previous = signal.signal(signal.SIGTERM, _on_sigterm)
            if signal.getsignal(signal.SIGINT) is signal.default_int_handler:
                previous_int = signal.signal(signal.SIGINT, _on_sigint)
        code = _dispatch(argv)
        if code == 0 and (_SIGINT["seen"] or _SIGTERM["seen"]):
            code = _interrupted()  # the interrupt was swallowed on its way: say so
    except KeyboardInterrupt:
        code = _interrupted()
    except Exception:
        if not (_SIGINT["seen"] or _SIGTERM["seen"]):
            raise
        code = _interrupted()  # the interrupt, turned into another exception on its way
    finally:
        if previous is not None:
            signal.signal(signal.SIGTERM, previous)
        if previous_int is not None:
            signal.signal(signal.SIGINT, previous_int)
    return 143 if code == 130 and _SIGTERM["seen"] else code


def entry() -> None:
    """The ``chaoscam`` process: :func:`main` on ``sys.argv``, then exit with its code.

    The console script, ``python -m chaoscam`` and ``python -m chaoscam.cli`` come here;
    code that runs commands in-process calls :func:`main`. Before exiting, every live object
    is moved to the garbage collector's permanent generation (:func:`gc.freeze`): the
    interpreter's finalization otherwise runs full collections over the objects numba's
    type registries leave (about 0.09 s of a 0.9 s ``chaoscam simulate --duration 20``,
    measured by ``benchmarks/bench_startup.py``). Nothing is lost by it: every output is
    written and closed (atomically renamed into place) before :func:`main` returns, and
    Python promises no finalizer at exit anyway.
    """
    code = main()
    import gc

    gc.freeze()
    sys.exit(code)


def stop_word() -> str:
    """How the run was stopped: "terminated" after a SIGTERM, else "interrupted"."""
    return "terminated" if _SIGTERM["seen"] else "interrupted"


class interrupts_ignored:
    """A context in which a second Ctrl-C is ignored (in the main thread, where handlers
    live): a command that stops says once what it kept, and waits for its threads to stop.
    A class, not ``contextlib``: this module is imported at every start."""

    def __enter__(self) -> None:
        import signal
        import threading

        main_thread = threading.current_thread() is threading.main_thread()
        self._before = signal.signal(signal.SIGINT, signal.SIG_IGN) if main_thread else None

    def __exit__(self, *exc) -> None:
        import signal

        if self._before is not None:
            signal.signal(signal.SIGINT, self._before)


def _interrupted() -> int:
    """Say "interrupted" (or "terminated") once; a second Ctrl-C meanwhile is ignored."""
    with interrupts_ignored():
        print(f"chaoscam: {stop_word()}", file=sys.stderr)
    return 130


def show_warning(message, *args, **kwargs) -> None:
    """A warning as one line on stderr, ``chaoscam: warning: ...``, printed at once."""
    print(f"chaoscam: warning: {message}", file=sys.stderr, flush=True)


NUMBA_LAYERS = ("default", "safe", "threadsafe", "forksafe", "workqueue", "omp", "tbb")
"""The values numba accepts for ``NUMBA_THREADING_LAYER`` (its documentation, 0.68)."""


def check_numba_environment() -> None:
    """Refuse numba settings in the environment that numba itself would reject with a
    traceback mid-run (a set but empty or unknown threading layer, a thread count that is
    not a positive integer): a UsageError naming the variable and what it allows."""
    import os

    layer = os.environ.get("NUMBA_THREADING_LAYER")
    if layer is not None and layer not in NUMBA_LAYERS:
        raise UsageError(
            f"NUMBA_THREADING_LAYER={layer!r} in the environment: must be one of "
            f"{', '.join(NUMBA_LAYERS)} (or unset; chaoscam then uses workqueue)"
        )
    threads = os.environ.get("NUMBA_NUM_THREADS")
    if threads is not None and not (threads.strip().isdigit() and int(threads) >= 1):
        raise UsageError(
            f"NUMBA_NUM_THREADS={threads!r} in the environment: must be a whole number >= 1 "
            "(or unset: one thread per core)"
        )


GRID_FLAGS = ("--values", "--mu", "--sigma")
"""Options whose value may start with a minus sign (``--values -0.5,-0.4``)."""


def _negative_values(argv: list[str]) -> list[str]:
    """``--values -0.5,-0.4`` as ``--values=-0.5,-0.4``: argparse takes a value that starts
    with "-" and is not a single number for an option, and says "expected one argument"."""
    out: list[str] = []
    i = 0
    while i < len(argv):
        token = argv[i]
        following = argv[i + 1] if i + 1 < len(argv) else ""
        if token in GRID_FLAGS and len(following) > 1 and following[0] == "-":
            if following[1].isdigit() or following[1] == ".":
                out.append(f"{token}={following}")
                i += 2
                continue
        out.append(token)
        i += 1
    return out


def _command_parser(parser, args):
    """The subcommand's parser of ``args`` (the top-level one when there is none)."""
    import argparse

    for action in parser._actions:
        if isinstance(action, argparse._SubParsersAction):
            return action.choices.get(getattr(args, "command", None), parser)
    return parser


def _mute_stdout() -> None:
    """Point stdout at /dev/null, so that the interpreter's flush of what is left at exit
    does not fail again on the closed pipe (the Python documentation's recipe for SIGPIPE)."""
    import os

    try:
        devnull = os.open(os.devnull, os.O_WRONLY)
        os.dup2(devnull, sys.stdout.fileno())
    except (OSError, ValueError, AttributeError):  # no real stdout (captured in tests)
        pass


def _dispatch(argv: list[str] | None) -> int:
    import warnings

    from .._util import ParameterError
    from ..io import OutputError

    parser = build_parser()
    args, extra = parser.parse_known_args(
        _negative_values(sys.argv[1:] if argv is None else list(argv))
    )
    if extra:  # with the command's own usage, not the top level's (argparse's default)
        _command_parser(parser, args).error(f"unrecognized arguments: {' '.join(extra)}")
    if not getattr(args, "func", None):
        parser.print_help()
        return 2
    try:
        check_numba_environment()
        with warnings.catch_warnings():
            warnings.showwarning = show_warning  # as they come, not at the end of the run
            code = int(args.func(args) or 0)
    except (ParameterError, UsageError, OutputError, FileExistsError) as err:
        print(f"chaoscam: error: {err}", file=sys.stderr)
        return 2
    except BrokenPipeError:  # the reader of stdout left (`chaoscam classify ... | head`)
        _mute_stdout()
        return 141  # as a shell reports a command stopped by SIGPIPE
    except OSError as err:  # a file the command reads or writes: never a traceback
        print(f"chaoscam: error: {err}", file=sys.stderr)
        return 2
    except MemoryError:
        print("chaoscam: error: out of memory; ask for a smaller run", file=sys.stderr)
        return 1
    return code


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
