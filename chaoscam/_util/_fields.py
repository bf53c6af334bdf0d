"""Documented, validated fields of a frozen settings dataclass (``Params``, ``Numerics``): each
declares its meaning, unit, allowed range or choices (:func:`meta`), which :func:`check_fields`
enforces and :func:`field_table` lists; :func:`strict_init` refuses an unknown keyword."""

from __future__ import annotations

import dataclasses
import difflib
import functools
import math
from typing import Any

__all__ = [
    "ParameterError", "check_fields", "close_names", "describe_range", "field_table", "meta",
    "parse_field", "strict_init", "unknown_message",
]  # fmt: skip


class ParameterError(ValueError):
    """A parameter or setting is missing, of the wrong type or outside its allowed range (the
    message names the field and the allowed range)."""


def meta(doc: str, unit: str, rng: tuple | None = None, choices: tuple | None = None,
         why: str = "") -> dict:  # fmt: skip
    """A field's metadata: its meaning, unit, allowed range ``(lower, upper, lower_inclusive,
    upper_inclusive)``, finite for a number, and ``why`` that range (or ``choices``, a text's)."""
    return {"doc": doc, "unit": unit, "range": rng, "choices": choices, "why": why}


def describe_range(rng: tuple) -> str:
    """``(lo, hi]``-style text of a range tuple."""
    lo, hi, lo_inc, hi_inc = rng
    lo, hi = (repr(x) if len(repr(x)) <= 10 else f"{x:.7g}" for x in (lo, hi))  # 1e+13
    return f"{'[' if lo_inc else '('}{lo}, {hi}{']' if hi_inc else ')'}"


def _validate(f: dataclasses.Field, value: Any) -> None:
    meta_, name = f.metadata, f.name
    if value is None:
        if f.default is None:
            return
        raise ParameterError(f"{name} must be given (None is not allowed)")
    if meta_["choices"] is not None:
        if value not in meta_["choices"]:
            raise ParameterError(
                f"{name} = {value!r} is not one of {', '.join(map(repr, meta_['choices']))}"
            )
        return
    if isinstance(value, bool) or not isinstance(value, int | float):
        raise ParameterError(f"{name} = {value!r} must be a number [{meta_['unit']}]")
    lo, hi, lo_inc, hi_inc = meta_["range"]  # compared exactly: 10**400 is no overflow
    if value < lo or value > hi or (value == lo and not lo_inc) or (value == hi and not hi_inc):
        shown = repr(value)
        shown = shown if len(shown) <= 24 else f"{shown[:6]}... ({len(shown)} digits)"
        why = f" ({meta_['why']})" if meta_["why"] else ""
        raise ParameterError(
            f"{name} = {shown} [{meta_['unit']}] is outside the allowed range "
            f"{describe_range(meta_['range'])}{why}: {meta_['doc']}"
        )
    if not math.isfinite(value):
        raise ParameterError(f"{name} = {value!r} must be finite [{meta_['unit']}]")
    if f.type == "int" and not float(value).is_integer():
        raise ParameterError(f"{name} = {value!r} must be an integer")


def check_fields(obj: Any) -> None:
    """In a frozen dataclass's ``__post_init__``: validate every field and store numbers as
    the field's Python type (a numpy scalar as a Python number, ``30`` as ``30.0``)."""
    for f in dataclasses.fields(obj):
        value = getattr(obj, f.name)
        if type(value).__module__ == "numpy" and getattr(value, "size", 0) == 1:
            value = value.item()
        kind = {"int": int, "float": float, "float | None": float}.get(f.type)
        _validate(f, value)
        if kind and value is not None and type(value) is not kind:
            value = kind(value)
        object.__setattr__(obj, f.name, value)


def close_names(name: str, names) -> list[str]:
    """Up to three of ``names`` close to ``name``: the same but for case first (OMEGA ->
    omega), then by difflib's similarity."""
    same = [n for n in names if n.lower() == name.lower() and n != name]
    close = difflib.get_close_matches(name, list(names), n=3)
    return list(dict.fromkeys(same + close))[:3]


def unknown_message(name: str, names, what: str = "parameter") -> str:
    """The refusal of an unknown name, with what it was probably meant to be."""
    close = close_names(name, names)
    hint = f" Did you mean {', '.join(close)}?" if close else ""
    return f"unknown {what} {name!r}.{hint} Known: {', '.join(names)}"


def strict_init(cls: type) -> type:
    """Class decorator: the dataclass's ``__init__`` and ``replace`` refuse an unknown keyword
    (with close names), not a TypeError."""
    names = tuple(f.name for f in dataclasses.fields(cls))
    init = cls.__init__

    @functools.wraps(init)
    def checked(self, *args: Any, **kwargs: Any) -> None:
        unknown = sorted(set(kwargs) - set(names))
        if unknown:
            raise ParameterError(unknown_message(unknown[0], names, cls._WHAT))
        init(self, *args, **kwargs)

    cls.__init__ = checked
    return cls


def parse_field(cls: type, name: str, text: str) -> Any:
    """The string ``text`` (as ``--set NAME=VALUE`` gives it) as the type of ``cls``'s
    field ``name``."""
    f = next((f for f in dataclasses.fields(cls) if f.name == name), None)
    if f is None:
        names = [g.name for g in dataclasses.fields(cls)]
        raise ParameterError(unknown_message(name, names, cls._WHAT))
    if text.strip().lower() == "none":
        if f.default is not None:
            raise ParameterError(f"{name} cannot be None")
        return None
    if f.metadata["choices"] is not None:
        return text.strip()
    kind = "an integer" if f.type == "int" else "a number"
    if "_" in text:  # Python reads "1_0" as 10: a typo, not a number
        raise ParameterError(f"{name} = {text!r} must be {kind} (no '_' in it)")
    try:
        return int(text) if f.type == "int" else float(text)
    except ValueError:
        raise ParameterError(f"{name} = {text!r} must be {kind}") from None


def field_table(cls: type) -> list[dict[str, Any]]:
    """One row per field of ``cls``: name, unit, default, range (or choices) and meaning."""
    rows = []
    for f in dataclasses.fields(cls):
        m = f.metadata
        if m["choices"] is not None:
            allowed = ", ".join(map(repr, m["choices"]))
        else:
            allowed = describe_range(m["range"]) + (f" ({m['why']})" if m["why"] else "")
        rows.append({"name": f.name, "unit": m["unit"], "default": f.default, "range": allowed,
                     "doc": m["doc"]})  # fmt: skip
    return rows
