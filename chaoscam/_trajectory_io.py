"""The one reader of trajectory files for every command (``classify``, ``report``).

A trajectory file is what ``chaoscam simulate --out FILE.parquet`` (``Trajectory.to_parquet``)
writes. :func:`read_trajectory` rebuilds it through :func:`chaoscam.classify.load_trajectory`
(which checks the metadata and columns) and refuses a file that holds too little data to
classify, so both commands accept and refuse the same files with the same messages.
"""

from __future__ import annotations

from pathlib import Path

__all__ = ["TrajectoryFileError", "read_trajectory", "check_enough", "MIN_POINTS"]

MIN_POINTS = 16
"""Fewest section points or samples a verdict is asked from; fewer is "too little data"."""


class TrajectoryFileError(ValueError):
    """A trajectory file is missing, unreadable, not chaoscam's, or holds too little data."""


def check_enough(n: int, what: str, where: str | Path) -> None:
    """Refuse ``n`` < :data:`MIN_POINTS` rows of ``what`` in ``where``: too little data."""
    if n < MIN_POINTS:
        raise TrajectoryFileError(
            f"{where}: too little data: {n} {what}, at least {MIN_POINTS} are needed for a "
            "verdict (simulate longer, or keep more of the run after the transient)"
        )


def read_trajectory(path: str | Path, *, need_data: bool = True):
    """A :class:`chaoscam.Trajectory` from ``path``; :class:`TrajectoryFileError` if not.

    With ``need_data``, a file with fewer than :data:`MIN_POINTS` section points and series
    samples is refused ("too little data").
    """
    from .classify import load_trajectory

    path = Path(path)
    try:
        traj = load_trajectory(path)
    except (OSError, ValueError, KeyError, TypeError) as err:
        raise TrajectoryFileError(str(err).strip("'\"") or repr(err)) from None
    if need_data:
        n_series = 0 if traj.series is None else len(traj.series)
        n = max(len(traj.section), n_series)
        check_enough(n, "section points and samples", path)
    return traj
