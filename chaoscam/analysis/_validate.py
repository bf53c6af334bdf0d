"""Input checks shared by the analysis functions."""

from __future__ import annotations

import math
import numbers
import re
from typing import Any

import numpy as np

MIN_SERIES = 16  # fewer samples than this cannot show an oscillation: too little data


def _checked(arr: np.ndarray, name: str, min_size: int, what: str) -> np.ndarray:
    if arr.shape[0] < min_size:
        raise ValueError(
            f"too little data: {name} has {arr.shape[0]} {what}, at least {min_size} are needed"
        )
    if not np.all(np.isfinite(arr)):
        raise ValueError(
            f"{name} contains NaN or infinite values; remove or interpolate them first"
        )
    return arr


def as_series(x, name: str = "x", min_size: int = 1) -> np.ndarray:
    """`x` as a 1-D float array; ValueError on NaN, inf or fewer than `min_size` samples."""
    arr = np.asarray(x, dtype=float)
    if arr.ndim != 1:
        arr = np.squeeze(arr)
        if arr.ndim != 1:
            raise ValueError(f"{name} must be one-dimensional, got shape {np.shape(x)}")
    return _checked(arr, name, min_size, "samples")


def as_points(points, name: str = "points", min_size: int = 1) -> np.ndarray:
    """Points as an (N, d) float array ((N,) -> (N, 1)); ValueError as for `as_series`."""
    arr = np.asarray(points, dtype=float)
    if arr.ndim == 1:
        arr = arr[:, None]
    if arr.ndim != 2:
        raise ValueError(f"{name} must have shape (N,) or (N, d), got {np.shape(points)}")
    return _checked(arr, name, min_size, "points")


def check_settings(fn: str, **settings: tuple[Any, str]) -> None:
    """ValueError naming ``fn`` for a ``name=(value, rule)`` outside its rule: ``"number"`` (NaN,
    ±inf too), ``"real"`` (finite), ``"real>0"``, ``"real>=0"``, ``"int>=N"``; ``?`` lets None."""
    for name, (value, rule) in settings.items():
        if value is None and rule.endswith("?"):
            continue
        base = rule.rstrip("?")
        if base == "number":
            if isinstance(value, numbers.Real) and not isinstance(value, bool):
                continue
            none = " or None" if rule.endswith("?") else ""
            raise ValueError(f"{fn}: {name} = {value!r} must be a number{none}")
        kind, op, low = re.fullmatch(r"(int|real)(>=|>)?([0-9.]+)?", base).groups()
        number = numbers.Integral if kind == "int" else numbers.Real
        ok = isinstance(value, number) and not isinstance(value, bool)
        if ok:
            v = float(value)
            ok = math.isfinite(v) and (
                op is None or v > float(low) or (op == ">=" and v == float(low))
            )
        if not ok:
            what = "an integer" if kind == "int" else "a finite number"
            bound = f" {op} {low}" if op else ""
            none = " or None" if rule.endswith("?") else ""
            got = "" if isinstance(value, number) else f" (got {type(value).__name__})"
            raise ValueError(f"{fn}: {name} = {value!r} must be {what}{bound}{none}{got}")


def check_atol(fn: str, atol: Any, d: int) -> None:
    """ValueError unless ``atol`` is None, one finite number >= 0, or ``d`` of them."""
    if atol is None:
        return
    items = atol if isinstance(atol, list | tuple | np.ndarray) else [atol]
    numeric = all(isinstance(v, numbers.Real) and not isinstance(v, bool) for v in items)
    a = np.asarray(atol, dtype=float) if numeric else None  # not "1e-3" or True, which it reads
    ok = a is not None and (a.ndim == 0 or a.shape == (d,))
    if not (ok and np.isfinite(a).all() and (a >= 0).all()):
        raise ValueError(
            f"{fn}: atol = {atol!r} must be a finite number >= 0, or {d} of them (one per "
            "coordinate), or None"
        )
