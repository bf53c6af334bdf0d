"""Checking one parameter value against its field's declared type, range and choices.

The declarations live with the fields (:mod:`._params`); this is how they are enforced, so
that every refusal names the field and the allowed range.
"""

from __future__ import annotations

import dataclasses
import math
from typing import Any

__all__ = ["ParameterError", "describe_range", "validate_field"]


class ParameterError(ValueError):
    """A parameter is missing, of the wrong type or outside its allowed range.

    The message always names the field and the allowed range.
    """


def describe_range(rng: tuple) -> str:
    lo, hi, lo_inc, hi_inc = rng
    left = "(-inf" if lo is None else ("[" if lo_inc else "(") + repr(lo)
    right = "inf)" if hi is None else repr(hi) + ("]" if hi_inc else ")")
    return f"{left}, {right}"


def validate_field(f: dataclasses.Field, value: Any) -> None:
    meta = f.metadata
    name = f.name
    if value is None:
        if f.default is None:
            return
        raise ParameterError(f"{name} must be given (None is not allowed)")
    if meta["choices"] is not None:
        if value not in meta["choices"]:
            raise ParameterError(
                f"{name} = {value!r} is not one of {', '.join(map(repr, meta['choices']))}"
            )
        return
    if isinstance(value, bool) or not isinstance(value, int | float):
        raise ParameterError(f"{name} = {value!r} must be a number [{meta['unit']}]")
    if f.type == "int" and not float(value).is_integer():
        raise ParameterError(f"{name} = {value!r} must be an integer")
    if not math.isfinite(value):
        raise ParameterError(f"{name} = {value!r} must be finite [{meta['unit']}]")
    rng = meta["range"]
    if rng is None:
        return
    lo, hi, lo_inc, hi_inc = rng
    bad_lo = lo is not None and (value < lo or (value == lo and not lo_inc))
    bad_hi = hi is not None and (value > hi or (value == hi and not hi_inc))
    if bad_lo or bad_hi:
        raise ParameterError(
            f"{name} = {value!r} [{meta['unit']}] is outside the allowed range "
            f"{describe_range(rng)}: {meta['doc']}"
        )
