"""Pieces shared by the sweep plans: run settings, the judge, outputs, tables, the budget."""

from __future__ import annotations

import math
import numbers
from collections import Counter
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd

from .._util import real, warn, whole
from ..io import check_output, lock_all, read_frame
from ..simulation import check_window
from ._grid import Axis, SweepError
from ._runs import Judge
from ._store import (
    CheckpointStore,
    MemoryStore,
    checkpoint_dir,
    discard_checkpoint,
    guard_outputs,
    read_sweep_metadata,
    remove_leftovers,
    write_parquet,
)

__all__ = [
    "TwoTables",
    "as_axis",
    "check_fate",
    "check_sweep_budget",
    "companion",
    "evidence_columns",
    "make_judge",
    "open_store",
    "read_tables",
    "run_settings",
    "show_progress",
    "write_tables",
]


def run_settings(duration: float, transient: float | None, seed: int) -> tuple[float, float]:
    """Validated (duration, transient) [s]; transient None = half the duration."""
    if transient is None and isinstance(duration, numbers.Real) and not isinstance(duration, bool):
        transient = 0.5 * float(duration)  # checked with the duration just below
    duration, transient = check_window(duration, transient)
    whole("seed", seed)
    return float(duration), float(transient)


def show_progress(progress) -> bool:
    """Whether to show a progress bar: as asked, or (None) when stderr is a terminal."""
    import sys

    if progress is None:
        return bool(getattr(sys.stderr, "isatty", lambda: False)())
    return bool(progress)


def check_fate(fate: float | None, duration: float) -> float | None:
    """The ``fate`` horizon validated: None, or a finite number of seconds > duration."""
    if fate is None:
        return None
    if isinstance(fate, bool) or not (
        isinstance(fate, numbers.Real) and math.isfinite(fate) and fate > duration
    ):
        raise SweepError(
            f"fate = {fate!r} s: the time to which runs labelled chaotic, quasiperiodic or "
            f"undetermined are continued must be a finite number > duration = {duration:g} s"
        )
    return float(fate)


def make_judge(classify, lyapunov: bool, check_step: bool, extend_to, labels=True) -> Judge:
    """The sweep's :class:`~._runs.Judge`: the package's verdict (``classify`` None) or a
    classifier of one's own, with the Lyapunov and step-check adapters."""
    if classify is not None and not callable(classify):
        raise SweepError(f"classify = {classify!r} must be callable (or None: the default)")
    if classify is not None and check_step:
        raise SweepError("check_step (--check-step) applies to the package's verdict only")
    if extend_to is not None:
        extend_to = real("extend_to", extend_to, low=0.0, unit="s")
    return Judge(classify, bool(lyapunov), bool(check_step), extend_to, labels)


def as_axis(axis: Axis | str | tuple) -> Axis:
    """An Axis from an Axis, ``"NAME=START:STOP:NUM"`` or ``(name, values)``."""
    if isinstance(axis, Axis):
        return axis
    if isinstance(axis, str):
        return Axis.parse(axis)
    try:
        name, values = axis
    except (TypeError, ValueError):
        raise SweepError(
            f"an axis must be an Axis, 'NAME=START:STOP:NUM' or (name, values), got {axis!r}"
        ) from None
    return Axis(name, values)


def companion(out: Path, what: str) -> Path:
    """``FILE.parquet`` -> ``FILE.<what>.parquet``."""
    stem = out.name[: -len(".parquet")] if out.name.endswith(".parquet") else out.name
    return out.with_name(f"{stem}.{what}.parquet")


def check_pair(path: str | Path, second: str, replace: bool) -> None:
    """Refuse, before writing, a sweep's ``FILE.parquet`` or ``FILE.<second>.parquet`` that
    exists (unless ``replace``), a folder, or a missing folder, naming the file."""
    path = Path(path)
    for name in (path, companion(path, second)):
        check_output(name, flag="path", force=replace, force_hint="pass replace=True")


class TwoTables:
    """``to_parquet`` of a sweep's result: its main table to ``FILE.parquet`` and the second
    to ``FILE.<second>.parquet`` (names in ``_tables``), with the configuration."""

    _tables: tuple[str, str]

    def to_parquet(self, path: str | Path, *, replace: bool = False) -> None:
        """Both tables, each atomically; an existing file is refused unless ``replace=True``."""
        check_pair(path, self._tables[1], replace)
        self._write(path, replace=replace)

    def _write(self, path: str | Path, *, replace: bool) -> None:
        """Both tables (``replace=False``: a file that appeared meanwhile is kept)."""
        main, second = self._tables
        frames = getattr(self, main), getattr(self, second)
        write_tables(path, frames[0], second, frames[1], self.config, replace=replace)


def write_tables(
    path: str | Path,
    main: pd.DataFrame,
    second: str,
    other: pd.DataFrame,
    config: dict[str, Any],
    *,
    replace: bool = True,
) -> None:
    """A sweep's two tables: ``main`` to ``FILE.parquet``, ``other`` to
    ``FILE.<second>.parquet``, each written atomically with the configuration (``replace=
    False``: never over an existing file)."""
    path = Path(path)
    write_parquet(main, path, config, replace=replace)
    write_parquet(other, companion(path, second), config, replace=replace)


_KIND_NAMES = {
    "bifurcation": "bifurcation diagram",
    "regime_map": "regime map",
    "ensemble": "ensemble",
}


def read_tables(
    path: str | Path, second: str, kind: str
) -> tuple[pd.DataFrame, pd.DataFrame, dict]:
    """(main table, ``second`` table, configuration) of a sweep of ``kind`` written by
    :func:`write_tables`. The main file may be named by its companion too.

    Raises FileNotFoundError for a missing table and :class:`SweepError` for a file that is
    not such a sweep (another kind, another chaoscam output, not Parquet), naming it."""
    path = Path(path)
    tail = f".{second}.parquet"
    if path.name.endswith(tail):  # the companion named: read its main file
        path = path.with_name(path.name[: -len(tail)] + ".parquet")
    what, other = _KIND_NAMES[kind], companion(path, second)
    if path.is_dir():
        raise SweepError(f"{path} is a directory; give the {what}'s .parquet file")
    if not path.is_file():
        raise FileNotFoundError(f"{path}: no such file")
    meta = read_sweep_metadata(path)
    if meta is None:
        raise SweepError(f"{path}: not a chaoscam {what} (no sweep record in its metadata)")
    config = meta.get("config", {})
    found = config.get("kind", kind)  # files without a kind predate it
    if found != kind:
        raise SweepError(
            f"{path}: a {_KIND_NAMES.get(found, found)}, not a {what}"
            + (f"; read it with chaoscam.sweep.read_{found}" if found in _KIND_NAMES else "")
        )
    if not other.is_file():
        raise FileNotFoundError(f"{other}: no such file; a {what} is {path.name} and {other.name}")
    return read_frame(path), read_frame(other), config


def lock_outputs(out: Path | None, second: str):
    """An OS lock on a sweep's output (and so on its checkpoint) and on its companion
    (FILE.<second>.parquet) for the whole run; a second process on either is refused. No
    output: nothing to lock."""
    import contextlib

    return contextlib.nullcontext() if out is None else lock_all([out, companion(out, second)])


def open_store(
    out: Path | None,
    second: str,
    config: dict,
    resume: bool,
    flush_interval: float,
    force: bool = False,
) -> tuple[Any, bool]:
    """The record store of a run and whether a finished output can be reused as is.

    Call it holding :func:`lock_outputs`. ``force`` starts over: an existing output is
    replaced at the end and an existing checkpoint is discarded.
    """
    flush_interval = real("flush_interval", flush_interval, low=0.0, unit="s")
    if out is None:
        return MemoryStore(), False
    out = Path(out)
    if out.suffix != ".parquet":
        raise SweepError(f"--out {out}: the output must be a .parquet file")
    for path in (out, companion(out, second)):
        check_output(path, force=True)  # the folder and the path; existence is below
    ckpt = checkpoint_dir(out)
    # Of a run killed while it created or deleted its checkpoint, or wrote its outputs.
    for path in (ckpt, out, companion(out, second)):
        remove_leftovers(path)
    if force and not resume:
        discard_checkpoint(ckpt)
    elif guard_outputs([out, companion(out, second)], config, resume):
        return None, True
    replaces = (out, companion(out, second)) if force else ()
    store = CheckpointStore(
        ckpt, config, resume=resume, flush_interval=flush_interval, replaces=replaces
    )
    return store, False


RECORD_BYTES = 4096
"""Memory of one finished record held by the driver (verdict, evidence, warnings) [bytes]."""


def check_sweep_budget(
    base,
    num,
    *,
    runs: int,
    duration: float,
    transient: float,
    judge: Judge,
    workers,
    keeps_sections: bool,
    what: str,
    reduce: str,
    fate: float | None = None,
) -> None:
    """Refuse a sweep that cannot fit in memory, warn about one that takes hours.

    ``runs`` realizations of ``base`` (the step check runs each twice, a ``fate`` horizon at
    most ``fate / duration`` times more), one batch per worker in memory at a time, their
    records (and, with ``keeps_sections``, their section points) all kept by the driver. A
    warning when the extensions of undetermined runs, which the estimate does not count,
    could take more than an hour and more than 10 times the estimate (runs that record far
    less than the cap).
    """
    from ..simulation import WARN_SECONDS, JobEstimate, check_budget, estimate, human_seconds
    from ._backends import default_workers

    n = default_workers() if workers is None else max(1, int(workers))
    one = estimate(base, num, duration=duration, transient=transient, series=judge.series)
    if fate is not None:
        longer = estimate(base, num, duration=fate, transient=duration)
        one = JobEstimate((max(one.bytes, longer.bytes), one.seconds))
        reduce = f"{reduce}, or the fate horizon"
    kept = estimate(base, num, duration=duration, transient=transient) if keeps_sections else None
    memory = one.bytes * n + runs * (RECORD_BYTES + (kept.bytes / 3 if kept else 0.0))
    factor = 1 + judge.check_step + (fate / duration if fate else 0.0)  # fate: a bound
    seconds = one.seconds * runs * factor / n
    check_budget(
        JobEstimate((memory, seconds)),
        what=what,
        reduce=reduce,
        run=dict(params=base, num=num, duration=duration, what="each run of the base model"),
    )
    recorded, extend_to = duration - transient, judge.extend_to
    if judge.custom is None and extend_to is not None and recorded < extend_to:
        more = one.seconds * runs / n * (extend_to - recorded) / duration
        if more > max(WARN_SECONDS, 10 * seconds):
            warn(
                f"{what} records {recorded:g} s per run; an undetermined run is extended up "
                f"to {extend_to:g} s recorded, which the time estimate does not count: if "
                f"most are, about {human_seconds(more)} more. Record more per run (duration "
                "- transient) for fewer extensions"
            )


def unique_sorted(records, key_fields: tuple[str, str]) -> list[dict]:
    """Records sorted by their key, one per key (a duplicate must equal the first)."""
    seen: dict[tuple, dict] = {}
    for r in records:
        k = tuple(r[f] for f in key_fields)
        if k in seen:
            if seen[k] != r and not _nan_equal(seen[k], r):
                where = dict(zip(key_fields, k, strict=True))
                raise SweepError(f"two different records for {where}")
            continue
        seen[k] = r
    return [seen[k] for k in sorted(seen)]


def _nan_equal(a: Any, b: Any) -> bool:
    if isinstance(a, dict) and isinstance(b, dict):
        return a.keys() == b.keys() and all(_nan_equal(a[k], b[k]) for k in a)
    if isinstance(a, list) and isinstance(b, list):
        return len(a) == len(b) and all(_nan_equal(x, y) for x, y in zip(a, b, strict=True))
    if isinstance(a, float) and isinstance(b, float) and math.isnan(a) and math.isnan(b):
        return True
    return a == b


def evidence_columns(records: list[dict]) -> pd.DataFrame:
    """``ev_<name>`` columns (float, NaN when absent), names sorted, one row per record."""
    names = sorted({n for r in records for n in r["evidence"]})
    return pd.DataFrame(
        {
            f"ev_{n}": np.array([r["evidence"].get(n, math.nan) for r in records], dtype=float)
            for n in names
        },
        index=pd.RangeIndex(len(records)),
    )


def period_column(records: list[dict]) -> pd.Series:
    return pd.array([r["period"] for r in records], dtype="Int64")


def reemit_warnings(records: list[dict]) -> None:
    """Warn once per distinct message the runs raised (they are also in each row); called
    by :func:`._batch.run_sweep`, the warning points at the sweep's caller."""
    counts: Counter = Counter()
    for r in records:
        for msg in filter(None, r["warnings"].split(" | ")):
            counts[msg] += 1
    for msg, n in counts.items():
        warn(f"{n} of {len(records)} runs: {msg}")
