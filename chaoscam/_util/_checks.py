"""Checks of the plain settings a caller passes (seeds, indices, counts, intervals): each raises
:class:`ParameterError` naming the setting, what was expected and what was given; numpy scalars
are accepted and returned as Python numbers."""

from __future__ import annotations

import math
import numbers
from typing import Any

from ._fields import ParameterError

__all__ = ["COUNT_MAX", "flag", "real", "whole"]

COUNT_MAX = 2**63 - 1
"""Largest seed or realization index: the tables store them as 64-bit integers, so a larger one
is refused before any work (not when the table is written)."""


def whole(name: str, value: Any, *, low: int = 0, high: int | None = None) -> int:
    """``value`` as an int in [low, high]; bools, floats (1.5 or 2.0) and text refused. A seed
    or an index (``name`` "seed", "index") is also kept <= :data:`COUNT_MAX`."""
    if high is None and name in ("seed", "index"):
        high = COUNT_MAX
    if isinstance(value, bool) or not isinstance(value, numbers.Integral):
        raise ParameterError(
            f"{name} = {value!r} must be an integer >= {low} (got {type(value).__name__})"
        )
    value = int(value)
    if value < low or (high is not None and value > high):
        top = "" if high is None else f" and <= {high}"
        raise ParameterError(f"{name} = {value} must be an integer >= {low}{top}")
    return value


def flag(name: str, value: Any) -> bool:
    """``value`` as a bool: True or False (numpy's too); "no", 1 or None refused (a string
    is truthy, so "no" would have switched the option on)."""
    if type(value).__module__ == "numpy" and type(value).__name__ in ("bool_", "bool"):
        value = bool(value)
    if not isinstance(value, bool):
        raise ParameterError(f"{name} = {value!r} must be True or False")
    return value


def real(
    name: str, value: Any, *, low: float | None = None, strict: bool = False, unit: str = "",
    high: float | None = None,
) -> float:  # fmt: skip
    """``value`` as a finite float above ``low`` (``strict``: > low, else >= low)."""
    if isinstance(value, bool) or not isinstance(value, numbers.Real):
        raise ParameterError(f"{name} = {value!r} must be a number (got {type(value).__name__})")
    value = float(value)
    unit = f" {unit}" if unit else ""
    if not math.isfinite(value):
        raise ParameterError(f"{name} = {value!r}{unit} must be finite")
    if low is not None and (value < low or (strict and value == low)):
        raise ParameterError(f"{name} = {value!r}{unit} must be {'>' if strict else '>='} {low}")
    if high is not None and value > high:
        raise ParameterError(f"{name} = {value!r}{unit} must be <= {high}")
    return value
