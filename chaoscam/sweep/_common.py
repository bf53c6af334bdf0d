"""Pieces shared by the sweep drivers: run settings, the classifier, outputs, tables."""

from __future__ import annotations

import math
import numbers
from collections import Counter
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd

from .._checks import whole
from .._parquet import read_frame
from .._warn import warn
from ..integrate._driver import check_window
from ._backends import make_backend
from ._checkpoint import (
    CheckpointStore,
    MemoryStore,
    checkpoint_dir,
    discard_checkpoint,
    guard_outputs,
    read_sweep_metadata,
    remove_leftovers,
    write_parquet,
)
from ._grid import Axis, SweepError
from ._tasks import DefaultClassifier, classifier_identity

__all__ = [
    "run_settings",
    "check_fate",
    "resolve_classifier",
    "companion",
    "open_store",
    "evidence_columns",
    "read_tables",
    "write_tables",
]


def run_settings(duration: float, transient: float | None, seed: int) -> tuple[float, float]:
    """Validated (duration, transient) [s]; transient None = half the duration."""
    if transient is None and isinstance(duration, numbers.Real) and not isinstance(duration, bool):
        transient = 0.5 * float(duration)  # checked with the duration just below
    duration, transient = check_window(duration, transient)
    whole("seed", seed)
    return float(duration), float(transient)


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


def resolve_classifier(classify, lyapunov: bool, check_step: bool = False):
    """The classifier to use and its identity; None = the package classifier."""
    if classify is None:
        classify = DefaultClassifier(lyapunov=bool(lyapunov), check_step=bool(check_step))
    elif lyapunov or check_step:
        raise SweepError("lyapunov and check_step apply to the default classifier only")
    return classify, classifier_identity(classify)


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
    from .._outputs import check_output

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


_KIND_NAMES = {"bifurcation": "bifurcation diagram", "regime_map": "regime map"}


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

    from .._outputs import lock_all

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
    from .._checks import real
    from .._outputs import check_output

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
    *,
    runs: int,
    duration: float,
    transient: float,
    series: bool,
    workers,
    keeps_sections: bool,
    what: str,
    reduce: str,
    factor: float = 1.0,
    fate: float | None = None,
    classify=None,
) -> None:
    """Refuse a sweep that cannot fit in memory, warn about one that takes hours.

    ``runs`` realizations of ``base`` (``factor`` times the cost each: the Lyapunov and
    step checks run more), one per worker in memory at a time, their records (and, with
    ``keeps_sections``, their section points) all kept by the driver. With a ``fate``
    horizon a worker may hold a run continued to it (its section from ``duration`` on).
    ``classify`` (the sweep's classifier; its :func:`extension_cap`) adds a warning when the
    extensions of undetermined runs, which the estimate does not count, could take more than
    an hour and more than 10 times the estimate: runs that record far less than the cap (a
    map of 0.5 s runs was estimated at 5.6 h and took ~83 h: nearly every run extended).
    """
    from .._budget import WARN_SECONDS, JobEstimate, check_budget, estimate
    from .._budget import _human_seconds as human_seconds
    from ._backends import default_workers

    n = default_workers() if workers is None else max(1, int(workers))
    one = estimate(base, duration=duration, transient=transient, series=series)
    if fate is not None:
        longer = estimate(base, duration=fate, transient=duration)
        one = JobEstimate((max(one.bytes, longer.bytes), one.seconds))
        reduce = f"{reduce}, or the fate horizon"
    kept = estimate(base, duration=duration, transient=transient) if keeps_sections else None
    memory = one.bytes * n + runs * (RECORD_BYTES + (kept.bytes / 3 if kept else 0.0))
    seconds = one.seconds * runs * factor / n
    check_budget(
        JobEstimate((memory, seconds)),
        what=what,
        reduce=reduce,
        run=dict(params=base, duration=duration, what="each run of the base model"),
    )
    recorded, extend_to = duration - transient, extension_cap(classify)
    if extend_to is not None and recorded < extend_to:
        more = one.seconds * runs / n * (extend_to - recorded) / duration
        if more > max(WARN_SECONDS, 10 * seconds):
            warn(
                f"{what} records {recorded:g} s per run; an undetermined run is extended up "
                f"to {extend_to:g} s recorded, which the time estimate does not count: if "
                f"most are, about {human_seconds(more)} more. Record more per run (duration "
                "- transient) for fewer extensions"
            )


def extension_cap(classify) -> float | None:
    """The recorded time [s] a sweep's classifier extends an undetermined run to, or None
    when it never extends (the tangent verdict alone extends: not with ``tangent=False`` or
    ``lyapunov=True``, nor a classifier of one's own)."""
    extends = getattr(classify, "needs_tangent", False)
    return getattr(classify, "extend_to", None) if extends else None


def backend_for(workers: int | None, scheduler: Any):
    try:
        return make_backend(workers, scheduler)
    except (ValueError, ConnectionError) as err:
        where = "" if scheduler is None or "scheduler" in str(err) else f"scheduler {scheduler!r}: "
        raise SweepError(f"{where}{err}") from None


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
