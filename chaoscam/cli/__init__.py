"""The ``chaoscam`` command, a thin layer over the API: each command module's ``register``
adds parsers whose ``func(args)`` returns the exit code. Importing this module loads only
:mod:`sys`: the rest is imported inside :func:`main`, where a Ctrl-C is caught."""

from __future__ import annotations

import sys

__all__ = ["entry", "main", "parse_assignments", "show_warning", "stop_word", "UsageError"]


class UsageError(Exception):
    """Bad command-line input: printed as ``chaoscam: error: ...`` with exit code 2."""


def parse_assignments(items: list[str] | None, swept: dict | None = None) -> tuple:
    """(Params, Numerics) of ``--set NAME=VALUE`` items (each name a field of one of them); a
    name in ``swept`` (name: the sweep's option giving its values) is refused."""
    from .._util import ParameterError, unknown_message
    from ..model import Params, field_names, parse_value
    from ..numerics import Numerics

    pairs: dict[str, str] = {}
    for item in items or []:
        name, sep, value = item.partition("=")
        name = name.strip()
        if name in (swept or {}):
            raise UsageError(
                f"--set {item}: {name} is swept by {swept[name]}, which gives its values; "
                "drop the --set"
            )
        if not sep or not name:
            raise UsageError(f"--set expects NAME=VALUE, got {item!r}")
        if name in pairs:
            raise UsageError(
                f"--set {name} is given twice ({pairs[name]!r} and {value!r}): "
                "give each parameter once"
            )
        pairs[name] = value
    steps = Numerics.field_names()
    for name in pairs:
        if name not in field_names() and name not in steps:
            raise ParameterError(unknown_message(name, (*field_names(), *steps)))
    model = {k: parse_value(k, v) for k, v in pairs.items() if k not in steps}
    numerics = {k: Numerics.parse(k, v) for k, v in pairs.items() if k in steps}
    return Params(**model), Numerics(**numerics)


def _build_parser() -> tuple:
    """The command's parser, and its subcommands' (the subparsers action)."""
    import argparse

    from .._version import __version__
    from . import _classify, _continue, _ensemble, _params, _report, _simulate, _sweep

    parser = argparse.ArgumentParser(
        prog="chaoscam",
        description="Stochastic dynamics of a cam-follower oblique impact system.",
    )
    parser.add_argument("--version", action="version", version=f"chaoscam {__version__}")
    sub = parser.add_subparsers(dest="command", metavar="COMMAND")
    for module in (
        _simulate,
        _ensemble,
        _classify,
        _sweep,
        _continue,
        _report,
        _params,
    ):  # --help's order
        module.register(sub)
    return parser, sub


_SIGTERM = {"seen": False}
_SIGINT = {"seen": False}
_LOCK_CALLBACK = ("cb", "<frozen importlib._bootstrap>")  # importlib's module-lock callback


def _on_sigterm(signum, frame) -> None:
    """SIGTERM is handled like Ctrl-C (finished work saved, a resume hint), exit 143."""
    _SIGTERM["seen"] = True
    raise KeyboardInterrupt


def _on_sigint(signum, frame) -> None:
    """Ctrl-C: a KeyboardInterrupt, recorded for :func:`main` (inside an import it may come
    back as an ImportError, or be swallowed). Inside importlib's module-lock weakref callback,
    where an exception is printed and lost, the signal is sent again a moment later. (Putting
    signals off until the import ends made a Ctrl-C in start-up take 1.1 s, not 0.04 s.)"""
    _SIGINT["seen"] = True
    code = getattr(frame, "f_code", None)
    if code is not None and (code.co_name, code.co_filename) == _LOCK_CALLBACK:
        import os
        import threading

        threading.Timer(0.01, os.kill, (os.getpid(), signum)).start()
        return
    raise KeyboardInterrupt


def main(argv: list[str] | None = None) -> int:
    """Run the ``chaoscam`` command; its exit code: 0 success, 1 a run that could not do what
    was asked (its cause printed), 2 bad input (a message naming the field or path), 130 Ctrl-C
    and 143 SIGTERM (one line, after saving finished work; also when the interrupt came back as
    another exception or was swallowed), 141 when the reader of stdout left (as for SIGPIPE)."""
    previous = previous_int = None
    _SIGTERM["seen"] = _SIGINT["seen"] = False
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
    """The ``chaoscam`` process: :func:`main` on ``sys.argv``, then exit with its code, the heap
    frozen first (finalization otherwise collects numba's type registries: 0.09 s of a 0.9 s
    run, ``benchmarks/bench_startup.py``); every output is already written and closed."""
    code = main()
    import gc

    gc.freeze()
    sys.exit(code)


def stop_word() -> str:
    """How the run was stopped: "terminated" after a SIGTERM, else "interrupted"."""
    return "terminated" if _SIGTERM["seen"] else "interrupted"


def _interrupted() -> int:
    """Say "interrupted" (or "terminated") once; a second Ctrl-C meanwhile is ignored."""
    import signal
    import threading

    main_thread = threading.current_thread() is threading.main_thread()
    before = signal.signal(signal.SIGINT, signal.SIG_IGN) if main_thread else None
    print(f"chaoscam: {stop_word()}", file=sys.stderr)
    if before is not None:
        signal.signal(signal.SIGINT, before)
    return 130


def show_warning(message, *args, **kwargs) -> None:
    """A warning as one line on stderr, ``chaoscam: warning: ...``, printed at once."""
    print(f"chaoscam: warning: {message}", file=sys.stderr, flush=True)


NUMBA_LAYERS = ("default", "safe", "threadsafe", "forksafe", "workqueue", "omp", "tbb")
"""The values numba accepts for ``NUMBA_THREADING_LAYER`` (its documentation, 0.68)."""


def check_numba_environment() -> None:
    """Refuse the numba settings in the environment that numba would reject mid-run."""
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


GRID_FLAGS = ("--values", "--mu", "--sigma", "--from", "--to", "--x0")
"""Options whose value may start with a minus sign (``--values -0.5,-0.4``)."""


def _negative_values(argv: list[str]) -> list[str]:
    """``--values -0.5,-0.4`` as ``--values=-0.5,-0.4`` (argparse reads -0.5,-0.4 as an option)."""
    out: list[str] = []
    for token in argv:
        negative = len(token) > 1 and token[0] == "-" and (token[1].isdigit() or token[1] == ".")
        if negative and out and out[-1] in GRID_FLAGS:
            out[-1] += f"={token}"
        else:
            out.append(token)
    return out


def _dispatch(argv: list[str] | None) -> int:
    import warnings

    parser, commands = _build_parser()
    argv = sys.argv[1:] if argv is None else list(argv)
    args, extra = parser.parse_known_args(_negative_values(argv))
    if extra:  # with the command's own usage, not the top level's (argparse's default)
        commands.choices.get(args.command, parser).error(
            "unrecognized arguments: " + " ".join(extra)
        )
    if not getattr(args, "func", None):
        parser.print_help()
        return 2
    try:
        check_numba_environment()
        with warnings.catch_warnings():
            warnings.showwarning = show_warning  # as they come, not at the end of the run
            code = int(args.func(args) or 0)
    except BrokenPipeError:  # the reader of stdout left (`chaoscam classify ... | head`)
        import contextlib
        import os

        # stdout to /dev/null: the flush at exit does not fail again (no real stdout in tests)
        with contextlib.suppress(OSError, ValueError, AttributeError):
            os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())
        return 141  # as a shell reports a command stopped by SIGPIPE
    except (UsageError, OSError, ValueError) as err:  # bad input, or a file read or written
        from .._util import ParameterError
        from ..io import OutputError
        from ..report import InputError
        from ..simulation import TrajectoryFileError
        from ..sweep import SweepError

        refused = (ParameterError, OutputError, InputError, TrajectoryFileError, SweepError)
        if isinstance(err, ValueError) and not isinstance(err, refused):
            raise  # a fault, not bad input: its traceback
        print(f"chaoscam: error: {err}", file=sys.stderr)
        return 2
    except MemoryError:
        print("chaoscam: error: out of memory; ask for a smaller run", file=sys.stderr)
        return 1
    return code
