"""The integrator and its settings, apart from the model (:class:`chaoscam.Params`).

A run is ``solve(params, numerics)``: ``Params`` says what is simulated (Table 1 of the paper
and the model decisions), :class:`Numerics` how (the paper's fixed-step RK4, the reference,
or the adaptive DOP853 path, with their steps and tolerances). A result must not change when
the step is halved (shared/MODEL.md); :meth:`Numerics.refined` is that check's partner.
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass, field
from typing import Any

from ._util import check_fields, meta, parse_field, strict_init

__all__ = ["INTEGRATORS", "Numerics"]

INTEGRATORS = ("rk4", "adaptive")
_ROUNDING = "at least 1e-12 s: a shorter step is lost in the rounding of t ~ 1e3 s"


@strict_init
@dataclass(frozen=True, slots=True)
class Numerics:
    """Frozen, validated settings of the integrator.

    Every field is overridable by keyword (``Numerics(dt=1e-6)``), by :meth:`replace`, or on
    the command line as ``--set NAME=VALUE`` (the names are unique across ``Params`` and
    ``Numerics``). ``chaoscam params`` lists each field with its unit, default and range.
    """

    _WHAT = "numerics setting"

    integrator: str = field(default="rk4", metadata=meta(
        "'rk4': the paper's fixed-step RK4 on the grid n dt with located impacts, the "
        "reference; 'adaptive': DOP853 with error control (rtol, atol), long steps in "
        "flight, events located on the step's interpolant. At equal accuracy (20-s "
        "sections of periodic responses to 1e-6 rad) the adaptive path is 5.5-10x cheaper "
        "than plain fixed-step RK4 and about as fast as the default merged RK4 "
        "(benchmarks/bench_work_precision.py)", "-", None, INTEGRATORS))  # fmt: skip
    dt: float = field(default=2e-6, metadata=meta(
        "RK4 step; resolves the Hertz contact oscillation (period ~9e-5 s) with ~45 steps; "
        "on the adaptive path, the step cap near the cam", "s", (1e-12, 1.0, True, True),
        why=_ROUNDING))  # fmt: skip
    event_tol: float = field(default=1e-12, metadata=meta(
        "located impact time's tolerance, at most 1e-9 s", "s", (1e-15, 1e-9, True, True),
        why="a bisection resolves no finer than a time's rounding"))  # fmt: skip
    max_events_per_step: int = field(default=8, metadata=meta(
        "chattering guard: impacts handled inside one step before the rest of the step is "
        "left to the compliant contact (at most 1024: buffers are sized by it)", "-",
        (1, 1024, True, True)))  # fmt: skip
    flight_merge: int = field(default=16, metadata=meta(
        "most grid steps taken as one RK4 step where a bound on the gap's curvature proves "
        "no contact can occur (free pendulum); 1 = plain RK4. Equal to plain RK4 within "
        "5e-9 s / 1e-8 rad (tests); at most 1024 (buffers)", "-",
        (1, 1024, True, True)))  # fmt: skip
    rtol: float = field(default=1e-12, metadata=meta(
        "adaptive integrator: relative tolerance of the local error of (theta_f, theta_f'); "
        "1e-12: periodic sections within 1e-6 rad of converged RK4 (tests)", "-",
        (1e-15, 1e-2, True, True),
        why="no step meets a tolerance below double precision"))  # fmt: skip
    atol: float = field(default=1e-13, metadata=meta(
        "adaptive integrator: absolute tolerance of the local error, for theta_f [rad] and "
        "theta_f' [rad/s]", "rad, rad/s", (1e-18, 1.0, True, True),
        why="down to double precision's spacing near 0.01 rad"))  # fmt: skip
    h_max: float = field(default=0.005, metadata=meta(
        "adaptive integrator: largest step (flight), at most 1 s", "s",
        (1e-12, 1.0, True, True), why=_ROUNDING))  # fmt: skip

    def __post_init__(self) -> None:
        check_fields(self)

    def refined(self) -> Numerics:
        """The same integrator about twice as fine: the step-halving check's partner.

        Fixed-step RK4: ``dt / 2``. Adaptive: ``rtol`` and ``atol`` / 32, the error reduction
        of a fifth-order method whose steps halve (its near-cam step cap ``dt`` is halved too).
        """
        if self.integrator == "adaptive":
            return self.replace(dt=self.dt / 2, rtol=self.rtol / 32, atol=self.atol / 32)
        return self.replace(dt=self.dt / 2)

    def describe_step(self) -> str:
        """The resolution in words, e.g. ``dt = 2e-06 s``."""
        if self.integrator == "adaptive":
            return f"adaptive, rtol = {self.rtol:g}"
        return f"dt = {self.dt:g} s"

    def replace(self, **changes: Any) -> Numerics:
        """A copy with ``changes`` applied and validated."""
        return dataclasses.replace(self, **changes)

    def to_dict(self) -> dict[str, Any]:
        """The fields, for provenance records."""
        return {f.name: getattr(self, f.name) for f in dataclasses.fields(self)}

    @classmethod
    def field_names(cls) -> tuple[str, ...]:
        return tuple(f.name for f in dataclasses.fields(cls))

    @classmethod
    def field_docs(cls) -> dict[str, dict]:
        """Each field's metadata: doc, unit, range, choices."""
        return {f.name: dict(f.metadata) for f in dataclasses.fields(cls)}

    @classmethod
    def parse(cls, name: str, text: str) -> Any:
        """``text`` as the type of field ``name`` (``--set NAME=VALUE``)."""
        return parse_field(cls, name, text)
