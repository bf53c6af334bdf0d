"""Options every run-making subcommand shares: the model overrides and the run's times.

One declaration each, so that ``--set``, ``--duration``, ``--transient`` and ``--seed`` mean
the same on ``simulate``, ``ensemble``, ``bifurcation`` and ``regime-map``.
"""

from __future__ import annotations

import argparse
from pathlib import Path

__all__ = ["add_run_options", "path_arg"]


def path_arg(text: str) -> Path:
    """The argparse type of every file argument: ``Path(text)``, but an empty text is refused
    (``Path("")`` is the current folder, and ``--out ''`` read as "--out .: the file must
    end in .parquet")."""
    if not text.strip():
        raise argparse.ArgumentTypeError("an empty path: give a file name")
    return Path(text)


def add_run_options(p, *, transient: float | None) -> None:
    """``--set``, ``--duration``, ``--transient`` and ``--seed`` on parser ``p``.

    ``transient`` is the default discarded start [s]; None means half the duration (the
    sweeps and ensembles), 0.0 the whole run (``simulate``).
    """
    p.add_argument(
        "--set",
        action="append",
        metavar="NAME=VALUE",
        default=[],
        help="override a model parameter (repeatable), e.g. --set omega=30",
    )
    p.add_argument("--duration", type=float, default=20.0, help="simulated time [s] (default 20)")
    p.add_argument(
        "--transient",
        type=float,
        default=transient,
        help="discarded start [s] (default: "
        + ("half the duration)" if transient is None else f"{transient:g})"),
    )
    p.add_argument("--seed", type=int, default=0, help="master seed of the line-length process")
