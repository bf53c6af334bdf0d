"""Sweep axes (``START:STOP:NUM``; any numeric Params or Numerics field), grid validation
and the realization-index scheme."""

from __future__ import annotations

import math
from collections import Counter
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from .._util import ParameterError, whole
from ..model import FIELD_DOCS, LineLengthStream, Params, field_names
from ..numerics import Numerics

_DOCS = {**FIELD_DOCS, **{f: dict(m) for f, m in Numerics.field_docs().items()}}
"""The sweepable fields' metadata: the model's and the numerics'."""


class SweepError(ValueError):
    """A sweep cannot start or continue as asked; the message says what to change."""


MAX_AXIS_POINTS = 100_000
"""Most values on one axis (each is at least one simulation)."""

MAX_GRID_POINTS = 1_000_000
"""Most points of a grid (cells of a regime map, values of a bifurcation diagram)."""


def parse_range(text: str, what: str = "range") -> tuple[float, float, int]:
    """``START:STOP:NUM`` (NUM points, both ends included) as (start, stop, num); a
    :class:`SweepError` for anything else (NUM < 1, STOP < START, one point with two ends)."""
    parts = text.split(":")
    if len(parts) != 3:
        raise SweepError(f"{what} {text!r}: expected START:STOP:NUM (NUM points, ends included)")
    try:
        start, stop = float(parts[0]), float(parts[1])
    except ValueError:
        raise SweepError(f"{what} {text!r}: START and STOP must be numbers") from None
    try:
        num = int(parts[2])
    except ValueError:
        raise SweepError(f"{what} {text!r}: NUM must be a whole number") from None
    if not (math.isfinite(start) and math.isfinite(stop)):
        raise SweepError(f"{what} {text!r}: START and STOP must be finite")
    if not math.isfinite(stop - start):  # before numpy's linspace, which would warn
        raise SweepError(f"{what} {text!r}: STOP - START overflows a float; narrow the range")
    if num < 1:
        raise SweepError(f"{what} {text!r}: NUM = {num} must be >= 1")
    if num > MAX_AXIS_POINTS:
        raise SweepError(
            f"{what} {text!r}: NUM = {num} is more than {MAX_AXIS_POINTS} values on one axis; "
            "sweep a coarser grid first"
        )
    if stop < start:
        raise SweepError(f"{what} {text!r}: STOP = {stop:g} is below START = {start:g}")
    if num == 1 and stop != start:
        raise SweepError(f"{what} {text!r}: one point (NUM = 1) needs STOP = START")
    if num > 1 and stop == start:
        raise SweepError(f"{what} {text!r}: {num} points need STOP > START")
    return start, stop, num


@dataclass(frozen=True)
class Axis:
    """One swept field: ``name``, a numeric field of :class:`~chaoscam.Params` or
    :class:`~chaoscam.Numerics` (e.g. ``l_lambda``, ``dt``), and its ``values`` in sweep
    order, in the field's SI unit; each value once."""

    name: str
    values: tuple[float, ...]

    def __post_init__(self) -> None:
        if not isinstance(self.name, str):
            raise SweepError(f"axis name {self.name!r}: must be a Params field's name (a str)")
        if self.name not in _DOCS:
            from .._util import unknown_message

            raise ParameterError(unknown_message(self.name, tuple(_DOCS), "field"))
        if _DOCS[self.name]["choices"] is not None:
            raise SweepError(f"{self.name} is not numeric and cannot be swept")
        if isinstance(self.values, str | bytes) or not hasattr(self.values, "__iter__"):
            raise SweepError(
                f"axis {self.name}: values must be a sequence of numbers or "
                f"'START:STOP:NUM', got {type(self.values).__name__} {self.values!r}"
            )
        try:
            vals = tuple(float(v) for v in self.values)
        except (TypeError, ValueError):
            raise SweepError(f"axis {self.name}: values must be numbers") from None
        if any(isinstance(v, bool) for v in self.values):  # Params refuses a bool too
            raise SweepError(f"axis {self.name}: values must be numbers, not True/False")
        if len(vals) > MAX_AXIS_POINTS:
            raise SweepError(f"axis {self.name}: more than {MAX_AXIS_POINTS} values")
        if not vals:
            raise SweepError(f"axis {self.name}: no values")
        if not all(math.isfinite(v) for v in vals):
            raise SweepError(f"axis {self.name}: values must be finite")
        if len(set(vals)) < len(vals):  # the same runs again, under other indices
            twice = sorted(v for v, n in Counter(vals).items() if n > 1)
            raise SweepError(
                f"axis {self.name}: the value {twice[0]!r} appears more than once; give each "
                "value once"
            )
        object.__setattr__(self, "values", vals)

    @classmethod
    def linspace(cls, name: str, start: float, stop: float, num: int) -> Axis:
        """``num`` evenly spaced values from ``start`` to ``stop``, both included."""
        start, stop = (v.item() if type(v).__module__ == "numpy" else v for v in (start, stop))
        parse_range(f"{start!r}:{stop!r}:{num}", what=name)
        try:
            with np.errstate(over="raise"):  # ends near the largest float: no silent inf
                values = np.linspace(start, stop, num)
        except FloatingPointError:
            raise SweepError(
                f"{name} range {start!r}:{stop!r}:{num}: its points overflow a float; narrow "
                "the range"
            ) from None
        return cls(name, tuple(values.tolist()))

    @classmethod
    def parse(cls, text: str, name: str | None = None) -> Axis:
        """From ``NAME=START:STOP:NUM`` or ``NAME=V1,V2,...`` (exact values, e.g. the paper's
        ``l_lambda=0.008,0.015,0.023``); without ``NAME=`` when ``name`` is given."""
        if name is None:
            given = text
            name, sep, text = text.partition("=")
            if not sep or not name.strip():
                raise SweepError(f"axis {given!r}: expected NAME=START:STOP:NUM or NAME=V1,V2,...")
            name = name.strip()
        if ":" not in text:
            try:
                values = tuple(float(v) for v in text.split(","))
            except ValueError:
                raise SweepError(
                    f"{name} values {text!r}: expected START:STOP:NUM or numbers V1,V2,..."
                ) from None
            return cls(name, values)
        start, stop, num = parse_range(text, what=f"{name} range")
        return cls.linspace(name, start, stop, num)

    def __len__(self) -> int:
        return len(self.values)

    def to_dict(self) -> dict:
        return {"name": self.name, "values": list(self.values)}


def realization_index(cell: int, index: int) -> int:
    """The :func:`chaoscam.simulate` index of realization ``index`` of grid cell ``cell``: the
    Cantor pairing ``(c + i)(c + i + 1)/2 + i``, a bijection onto the non-negative integers, so
    each (cell, realization) has its own stream whatever the workers, grid or cell sizes."""
    try:
        c, i = whole("cell", cell, low=0), whole("index", index, low=0)
    except ParameterError as err:
        raise SweepError(str(err)) from None
    s = c + i
    return s * (s + 1) // 2 + i


def cell_params(base: Params, num: Numerics, changes: dict[str, float]) -> tuple[Params, Numerics]:
    """``base`` and ``num`` with ``changes`` applied to their owners, validated as a run is."""
    model = {k: v for k, v in changes.items() if k in field_names()}
    steps = {k: v for k, v in changes.items() if k not in model}
    p = base.replace(**model) if model else base
    LineLengthStream(p, 0, 0)  # raises ParameterError when the truncation keeps no mass
    return p, (num.replace(**steps) if steps else num)


def validate_grid(base: Params, num: Numerics, axes: Sequence[Axis], *, points=True) -> None:
    """Raise before any work if the axes repeat a parameter, the grid is too large or (with
    ``points``, a second pass after the budget check) a point gives invalid parameters."""
    names = [a.name for a in axes]
    if len(set(names)) != len(names):
        raise SweepError(f"the axes repeat a parameter: {names}")
    size = math.prod(len(a) for a in axes)
    if size > MAX_GRID_POINTS:
        raise SweepError(
            f"the grid has {size} points, more than {MAX_GRID_POINTS}; sweep a coarser grid"
        )
    if not points:
        return
    grids = np.meshgrid(*[np.asarray(a.values) for a in axes], indexing="ij")
    for point in zip(*[g.ravel().tolist() for g in grids], strict=True):
        changes = dict(zip(names, point, strict=True))
        try:
            cell_params(base, num, changes)
        except ParameterError as err:
            where = ", ".join(f"{k} = {v!r}" for k, v in changes.items())
            raise ParameterError(f"at {where}: {err}") from None
