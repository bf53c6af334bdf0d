"""Checks of the plain settings a caller passes (seeds, indices, counts, intervals).

Each raises :class:`~chaoscam.model.ParameterError` naming the setting, what was expected and
what was given; numpy scalars are accepted and returned as Python numbers.
"""

from __future__ import annotations

import math
import numbers
from typing import Any

from .model import ParameterError

__all__ = ["COUNT_MAX", "flag", "whole", "real", "params_arg", "with_overrides"]

COUNT_MAX = 2**63 - 1
"""Largest seed or realization index: the tables store them as 64-bit integers (a seed of
2**64 ran a whole sweep and then failed writing its table, and again on --resume)."""


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
    name: str,
    value: Any,
    *,
    low: float | None = None,
    strict: bool = False,
    unit: str = "",
    high: float | None = None,
) -> float:
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


def of_type(name: str, value: Any, cls: type, made_by: str) -> Any:
    """``value`` when it is a ``cls``; else a TypeError naming ``name``, what it got and
    what makes one (a trajectory passed where a file name goes, or None, gave an
    AttributeError from deep inside)."""
    if not isinstance(value, cls):
        raise TypeError(
            f"{name} must be a chaoscam {cls.__name__} ({made_by}), got {type(value).__name__}"
        )
    return value


def params_arg(params: Any, name: str = "params"):
    """The ``params`` argument of an API function (or another argument ``name`` holding a
    model, a sweep's ``base``): a :class:`Params`, or None for defaults."""
    from .model import Params

    if params is None:
        return Params()
    if isinstance(params, Params):
        return params
    if isinstance(params, dict):
        keywords = ", or pass the fields as keywords, e.g. simulate(omega=30.0)"
        raise TypeError(
            f"{name} must be a chaoscam.Params, got a dict: use Params(**d)"
            + (keywords if name == "params" else "")
        )
    raise TypeError(
        f"{name} must be a chaoscam.Params or None, got {type(params).__name__} {params!r}"
    )


def with_overrides(p, overrides: dict, caller) -> Any:
    """``p.replace(**overrides)`` for an API function's ``**overrides``: a keyword that is
    neither one of ``caller``'s settings nor a model parameter is refused naming both lists
    and what it was probably meant to be (``simulate(duraton=1)`` -> duration)."""
    import inspect

    from .model._names import close_names
    from .model._params import field_names

    unknown = [k for k in overrides if k not in field_names()]
    if unknown:
        own = [
            n
            for n, a in inspect.signature(caller).parameters.items()
            if a.kind is inspect.Parameter.KEYWORD_ONLY
        ]
        close = close_names(unknown[0], own + list(field_names()))
        hint = f" Did you mean {', '.join(close)}?" if close else ""
        raise ParameterError(
            f"{caller.__name__}() got an unknown keyword {unknown[0]!r}: neither one of its "
            f"settings nor a model parameter.{hint} Its settings: {', '.join(own)}; the "
            f"parameters: {', '.join(field_names())}"
        )
    return p.replace(**overrides)
