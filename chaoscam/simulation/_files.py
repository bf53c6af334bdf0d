"""The one reader of trajectory files (``Solution.to_parquet``, ``chaoscam simulate --out``) for
every command: :func:`load_trajectory` rebuilds one, checking its metadata and columns;
:func:`read_trajectory` also refuses one too short to classify."""

from __future__ import annotations

import json
import math
from io import StringIO
from pathlib import Path

import numpy as np
import pandas as pd

from ..kernel import Status
from ..model import Params
from ..numerics import Numerics
from ._solution import (
    IMPACT_COLUMNS,
    IMPACT_KINDS,
    MEMBER_COLUMNS,
    SECTION_COLUMNS,
    SERIES_COLUMNS,
    Solution,
)

MIN_POINTS = 16
"""Fewest section points or samples a verdict is asked from; fewer is "too little data"."""


class TrajectoryFileError(ValueError):
    """A trajectory file is missing, unreadable, not chaoscam's, or holds too little data."""


SIMULATE_LONGER = "simulate longer, or keep more of the run after the transient"


def check_enough(n: int, what: str, where: str | Path, hint: str = SIMULATE_LONGER) -> None:
    """Refuse ``n`` < :data:`MIN_POINTS` rows of ``what`` in ``where`` (``hint``: what to do)."""
    if n < MIN_POINTS:
        raise TrajectoryFileError(
            f"{where}: too little data: {n} {what}, at least {MIN_POINTS} are needed for a "
            f"verdict ({hint})"
        )


def read_trajectory(path: str | Path, *, need_data: bool = True):
    """A one-member :class:`chaoscam.Solution` from ``path``, else :class:`TrajectoryFileError`
    (with ``need_data``, also for fewer than :data:`MIN_POINTS` section points and samples)."""
    path = Path(path)
    try:
        traj = load_trajectory(path)
    except (OSError, ValueError, KeyError, TypeError) as err:
        raise TrajectoryFileError(str(err).strip("'\"") or repr(err)) from None
    if need_data:
        n_series = 0 if traj.series is None else len(traj.series)
        check_enough(max(len(traj.section), n_series), "section points and samples", path)
    return traj


def _check_finite(path: Path, status: Status, tables) -> None:
    """Refuse NaN or infinite times or states of a normally ended run (chaoscam writes none)."""
    if status is not Status.OK:
        return  # a run that diverged may end on a non-finite state
    for name, table in tables:
        for col in ("t", "theta_f", "omega_f"):
            bad = int((~np.isfinite(table[col].to_numpy(dtype=float))).sum())
            if bad:
                raise ValueError(
                    f"{path}: damaged: {bad} NaN or infinite value(s) in {col} of {name} "
                    "(a run chaoscam wrote has none); not classified"
                )


def load_trajectory(path) -> Solution:
    """Rebuild a one-member :class:`Solution` from a trajectory file (``Solution.to_parquet``):
    the table holds the series (or the section, for a run without one); the metadata keys
    ``chaoscam.trajectory`` (params, numerics, settings, status, stats), ``chaoscam.section``
    and ``chaoscam.impacts`` (JSON, pandas "split", floats exact) the rest. Not stored: a
    ``tangent=True`` run's Jacobians and a resumable run's copy.

    Raises
    ------
    FileNotFoundError
        No such file.
    ValueError
        Not a Parquet file, or not one written by chaoscam (the message names the file).
    """
    import pyarrow as pa

    from ..io import DamagedFileError, read_table

    path = Path(path)
    if path.is_dir():
        raise ValueError(f"{path}: is a folder; give a trajectory file (.parquet)")
    if not path.is_file():
        raise FileNotFoundError(f"{path}: no such file")
    try:
        table = read_table(path)
    except DamagedFileError as err:
        raise ValueError(str(err)) from None
    except (pa.ArrowException, OSError) as err:
        raise ValueError(f"{path}: not a Parquet file ({err})") from err
    meta = table.schema.metadata or {}
    missing = [key for key in (b"chaoscam.trajectory", b"chaoscam.section", b"chaoscam.impacts")
               if key not in meta]  # fmt: skip
    if missing:
        raise ValueError(
            f"{path}: not a chaoscam trajectory file (metadata "
            f"{', '.join(m.decode() for m in missing)} missing; write one with "
            "`chaoscam simulate --out FILE.parquet` or Solution.to_parquet)"
        )
    try:
        prov = json.loads(meta[b"chaoscam.trajectory"])
        params = Params(**prov["params"])
        numerics = Numerics(**prov["numerics"])
        status = Status[prov["status"]]
        section, impacts = (
            pd.read_json(StringIO(meta[key].decode()), orient="split", precise_float=True)
            for key in (b"chaoscam.section", b"chaoscam.impacts")
        )
        settings = dict(prov["settings"])
        stats = dict(prov.get("stats", {}))
    except (KeyError, TypeError, ValueError) as err:
        raise ValueError(f"{path}: unreadable chaoscam metadata ({err!r})") from err
    frame = table.to_pandas()
    cols = tuple(frame.columns)
    if cols == SERIES_COLUMNS:
        series = frame
    elif cols == SECTION_COLUMNS:
        series = None
    else:
        raise ValueError(f"{path}: unexpected columns {list(cols)} for a chaoscam trajectory")
    for name, table_ in (("the table", frame), ("the section metadata", section)):
        for col in table_.columns:
            if not pd.api.types.is_numeric_dtype(table_[col]):
                raise ValueError(
                    f"{path}: column {col!r} of {name} holds {table_[col].dtype} values, not "
                    "numbers; not a file chaoscam wrote (or it was edited)"
                )
    lacking = [c for c in SECTION_COLUMNS if c not in section.columns]
    if lacking:
        raise ValueError(
            f"{path}: the section metadata lacks column(s) {', '.join(lacking)}; not a file "
            "chaoscam wrote (or it was edited)"
        )
    section = section[list(SECTION_COLUMNS)]
    _check_finite(path, status, (("the table", frame), ("the section metadata", section)))
    if len(section):  # JSON does not keep dtypes: 0.0 alone reads back as an integer
        section = section.astype({c: np.int64 if c == "k" else np.float64 for c in section})
    if len(impacts) and set(impacts.columns) == set(IMPACT_COLUMNS):  # as simulate gives them
        floats = {c: np.float64 for c in impacts.columns if c != "kind"}
        impacts = impacts.astype(floats)
        impacts["kind"] = pd.Categorical(impacts["kind"], categories=list(IMPACT_KINDS))
    return _solution(params, numerics, settings, status, stats, frame, series, section, impacts)


def _solution(params, numerics, settings, status, stats, frame, series, section, impacts):
    """The one-member Solution of a file's tables, stopped at the table's last row."""
    last = frame.iloc[-1] if len(frame) else None
    end = ((float(last["t"]), float(last["theta_f"]), float(last["omega_f"])) if last is not None
           else (math.nan, math.nan, math.nan))  # fmt: skip
    row = (
        0, int(settings.pop("index", 0)), status.name, int(stats.get("n_impacts", 0)),
        float(stats.get("contact_fraction", math.nan)), int(stats.get("slow_closings", 0)),
        int(stats.get("chatter_handovers", 0)), *end,
    )  # fmt: skip
    settings.setdefault("impacts", True)
    return Solution(
        models=(params,), numerics=numerics, settings=settings,
        members=pd.DataFrame([row], columns=list(MEMBER_COLUMNS)),
        sections=section.assign(member=0)[["member", *SECTION_COLUMNS]],
        impacts=impacts.assign(member=0)[["member", *impacts.columns]] if len(impacts.columns)
        else None,
        series=None if series is None else series.assign(member=0)[["member", *SERIES_COLUMNS]],
    )  # fmt: skip
