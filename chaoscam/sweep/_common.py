"""What the three sweep plans share: checked settings, the judge, the result's two tables."""

from __future__ import annotations

import math
import numbers
from pathlib import Path
from typing import ClassVar

import numpy as np
import pandas as pd

from .._util import flag, freeze_fields, real, whole
from ..io import check_output, read_frame
from ..model import params_arg
from ..simulation import check_window, numerics_arg
from ._grid import Axis, SweepError
from ._runs import SECTION_KEYS, Judge
from ._store import read_sweep_metadata, write_parquet


def settings(base, numerics, duration, transient, seed, fate, resume, force, name="base"):
    """(model, numerics, duration, transient [s], fate [s] or None, resume, force), checked;
    transient None = half the duration; ``fate`` a finite horizon > duration, or None."""
    base, num = params_arg(base, name), numerics_arg(numerics)
    if transient is None and isinstance(duration, numbers.Real) and not isinstance(duration, bool):
        transient = 0.5 * float(duration)  # checked with the duration just below
    duration, transient = check_window(duration, transient, dt=num.dt)  # simulate's rule
    whole("seed", seed)
    if fate is not None:
        if isinstance(fate, bool) or not (
            isinstance(fate, numbers.Real) and math.isfinite(fate) and fate > duration
        ):
            raise SweepError(
                f"fate = {fate!r} s: the time to which runs labelled chaotic, quasiperiodic or "
                f"undetermined are continued must be a finite number > duration = {duration:g} s"
            )
        fate = float(fate)
    return base, num, duration, transient, fate, flag("resume", resume), flag("force", force)


def make_judge(classify, lyapunov, check_step, extend_to, labels=True) -> Judge:
    """The sweep's :class:`~._runs.Judge`, checked: the package's verdict or one's own."""
    lyapunov, check_step = flag("lyapunov", lyapunov), flag("check_step", check_step)
    if classify is not None and not callable(classify):
        raise SweepError(f"classify = {classify!r} must be callable (or None: the default)")
    if classify is not None and check_step:
        raise SweepError("check_step (--check-step) applies to the package's verdict only")
    if extend_to is not None:
        extend_to = real("extend_to", extend_to, low=0.0, unit="s")
    return Judge(classify, lyapunov, check_step, extend_to, labels)


def as_axis(axis: Axis | str | tuple) -> Axis:
    """An Axis from an Axis, ``"NAME=START:STOP:NUM"`` or ``(name, values)``."""
    if isinstance(axis, Axis | str):
        return axis if isinstance(axis, Axis) else Axis.parse(axis)
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


_KIND_NAMES = {"bifurcation": "bifurcation diagram", "regime_map": "regime map",
               "ensemble": "ensemble"}  # fmt: skip


class TwoTables:
    """A sweep's result: its main table in ``FILE.parquet``, the second in
    ``FILE.<second>.parquet`` (names in ``_tables``), each with the configuration."""

    _tables: ClassVar[tuple[str, str]]
    _kind: ClassVar[str]

    def __post_init__(self) -> None:
        freeze_fields(self, "config")

    @classmethod
    def read(cls, path: str | Path):
        """The result written to ``path`` (or named by its companion): FileNotFoundError for
        a missing table, :class:`SweepError` for a file that is not such a sweep."""
        second, kind = cls._tables[1], cls._kind
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
            raise FileNotFoundError(
                f"{other}: no such file; a {what} is {path.name} and {other.name}"
            )
        return cls(read_frame(path), read_frame(other), config)

    def to_parquet(self, path: str | Path, *, replace: bool = False) -> None:
        """Both tables, each atomically; an existing file is refused unless ``replace=True``."""
        path = Path(path)
        for name in (path, companion(path, self._tables[1])):
            check_output(name, flag="path", force=replace, force_hint="pass replace=True")
        self._write(path, replace=replace)

    def _write(self, path: str | Path, *, replace: bool) -> None:
        """Both tables (``replace=False``: a file that appeared meanwhile is kept)."""
        files = (Path(path), companion(Path(path), self._tables[1]))
        for name, file in zip(self._tables, files, strict=True):
            write_parquet(getattr(self, name), file, self.config, replace=replace)


def dataset(frame: pd.DataFrame, dims: list[str], config: dict, **renamed: str):
    """``frame`` as an ``xarray.Dataset`` over its columns ``dims`` (rows missing from their
    grid NaN, text there ""), the columns ``renamed``, the record as JSON in ``attrs``."""
    import json

    try:
        import xarray as xr
    except ImportError:
        raise ImportError(
            "to_xarray needs xarray, an optional extra: pip install 'chaoscam[xarray]' "
            "(xarray with netCDF4 for to_netcdf)"
        ) from None
    ds = xr.Dataset.from_dataframe(frame.set_index(dims)).rename(renamed)
    for name, v in ds.data_vars.items():
        if v.dtype == object:  # text: "" where the grid has no row (NaN, None in the table)
            ds[name] = v.where(v.notnull(), "").astype(str)
    ds.attrs = {"kind": config.get("kind", ""), "config": json.dumps(config)}
    return ds


RUN_COLUMNS = ("status", "label", "period", "n_section", "recorded_s", "n_impacts",
               "contact_fraction", "truncated_mass", "reasons", "warnings")  # fmt: skip
_TEXT = frozenset({"status", "label", "reasons", "warnings"})
_FLOAT = frozenset({"recorded_s", "contact_fraction", "truncated_mass", "value", "theta_f0",
                    "omega_f0"})  # fmt: skip


def _column(records: list[dict], key: str):
    values = [r[key] for r in records]
    if key in _TEXT:
        return values
    if key == "period":
        return pd.array(values, dtype="Int64")
    dtype = bool if key == "continued" else float if key in _FLOAT else np.int64
    return np.array(values, dtype=dtype)


def record_table(records: list[dict], columns, *, fate: bool = True) -> pd.DataFrame:
    """One row per record: ``columns`` (keys, or ``(name, values)``), the fate columns (with
    ``fate``) and an ``ev_<name>`` float column per evidence value (NaN when absent, sorted)."""
    cols = dict(c if isinstance(c, tuple) else (c, _column(records, c)) for c in columns)
    if fate:
        cols["fate"] = [r.get("fate") for r in records]
        cols["left_at"] = [math.nan if r.get("left_at") is None else r["left_at"] for r in records]
        cols["fate_label"] = [r.get("fate_label") for r in records]
        cols["fate_period"] = pd.array([r.get("fate_period") for r in records], dtype="Int64")
    names = sorted({n for r in records for n in r["evidence"]})
    evidence = pd.DataFrame(
        {f"ev_{n}": np.array([r["evidence"].get(n, math.nan) for r in records], dtype=float)
         for n in names},
        index=pd.RangeIndex(len(records)),
    )  # fmt: skip
    return pd.concat([pd.DataFrame(cols), evidence], axis=1)


def section_table(records: list[dict], lead: dict, trail: dict | None = None) -> pd.DataFrame:
    """One row per section point of the records: ``lead``'s columns (one value per record),
    k, t, theta_f, omega_f, l_lambda, then ``trail``'s."""
    rep = np.repeat(np.arange(len(records)), _column(records, "n_section"))
    sec = {
        c: np.concatenate([[]] + [r["section"].get(c, []) for r in records]) for c in SECTION_KEYS
    }
    return pd.DataFrame({
        **{k: v[rep] for k, v in lead.items()},
        "k": sec["k"].astype(np.int64),
        **{c: sec[c].astype(float) for c in SECTION_KEYS[1:]},
        **{k: v[rep] for k, v in (trail or {}).items()},
    })  # fmt: skip
