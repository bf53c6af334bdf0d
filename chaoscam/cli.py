"""The ``chaoscam`` command: a thin layer over the API.

Each subcommand lives with the layer it drives; this module only wires them. A command module
exposes ``register(subparsers)``, which adds its parsers and sets ``func`` on them; ``func``
takes the parsed arguments and returns an exit code. Bad input exits with code 2 and a message
naming the field.
"""

from __future__ import annotations

import argparse
import importlib
import sys

from .model import ParameterError, Params

__all__ = ["main", "parse_assignments", "UsageError"]

# Modules that add subcommands, in the order they are listed by --help.
_COMMAND_MODULES = (
    "chaoscam._cli_simulate",
    "chaoscam._cli_ensemble",
    "chaoscam._cli_classify",
    "chaoscam.sweep._cli",
    "chaoscam.report._cli",
)


class UsageError(Exception):
    """Bad command-line input: printed as ``chaoscam: error: ...`` with exit code 2."""


def parse_assignments(items: list[str] | None, base: Params | None = None) -> Params:
    """Params from ``--set NAME=VALUE`` items."""
    pairs: dict[str, str] = {}
    for item in items or []:
        name, sep, value = item.partition("=")
        if not sep or not name.strip():
            raise UsageError(f"--set expects NAME=VALUE, got {item!r}")
        pairs[name.strip()] = value
    return Params.from_strings(pairs, base=base)


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(
        prog="chaoscam",
        description="Stochastic dynamics of a cam-follower oblique impact system.",
    )
    from ._version import __version__

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


def _on_sigterm(signum, frame) -> None:
    """SIGTERM is handled like Ctrl-C (finished work saved, a resume hint), exit 143."""
    _SIGTERM["seen"] = True
    raise KeyboardInterrupt


def main(argv: list[str] | None = None) -> int:
    """Run the ``chaoscam`` command; returns the exit code.

    0 success, 1 a run that could not do what was asked (its cause printed), 2 bad input
    (a message naming the field or path, never a traceback), 130 Ctrl-C and 143 SIGTERM
    (both after saving finished work and saying how to resume).
    """
    import signal
    import threading

    previous = None
    _SIGTERM["seen"] = False
    if threading.current_thread() is threading.main_thread():
        previous = signal.signal(signal.SIGTERM, _on_sigterm)
    try:
        code = _dispatch(argv)
    except KeyboardInterrupt:
        print("chaoscam: " + ("terminated" if _SIGTERM["seen"] else "interrupted"),
              file=sys.stderr)
        code = 130
    finally:
        if previous is not None:
            signal.signal(signal.SIGTERM, previous)
    return 143 if code == 130 and _SIGTERM["seen"] else code


def _dispatch(argv: list[str] | None) -> int:
    from ._outputs import OutputError

    parser = build_parser()
    args = parser.parse_args(argv)
    if not getattr(args, "func", None):
        parser.print_help()
        return 2
    try:
        code = int(args.func(args) or 0)
    except (ParameterError, UsageError, OutputError, FileExistsError) as err:
        print(f"chaoscam: error: {err}", file=sys.stderr)
        return 2
    except OSError as err:  # a file the command reads or writes: never a traceback
        print(f"chaoscam: error: {err}", file=sys.stderr)
        return 2
    except MemoryError:
        print("chaoscam: error: out of memory; ask for a smaller run", file=sys.stderr)
        return 1
    return code


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
