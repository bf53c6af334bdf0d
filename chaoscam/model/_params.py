"""The parameter set: Table 1 of the paper plus every decision of shared/MODEL.md.

This module is the single home of physics choices. A kernel never holds a constant of its
own; it receives the numbers assembled here (see :meth:`Params.kernel_constants`).

Reference: "Effect of Surface Morphology on Dynamic Characteristics of Cam-Follower Oblique
Impact System", Table 1 (SI units throughout).
"""

from __future__ import annotations

import dataclasses
import functools
import math
from dataclasses import dataclass, field, fields
from typing import Any

from ._fieldcheck import ParameterError, validate_field

__all__ = ["Params", "ParameterError", "FIELD_DOCS"]


STIFFNESS_MODELS = ("hertz", "fractal")
DAMPING_FORMS = ("hunt_crossley", "paper_literal")
RESAMPLE_MODES = ("contact", "impact", "interval")
INTEGRATORS = ("rk4", "adaptive")

# (lower, upper, lower_inclusive, upper_inclusive); None = unbounded.
_POS = (0.0, None, False, None)
_NONNEG = (0.0, None, True, None)
_TO_1 = (0.0, 1.0, False, True)


def _meta(doc: str, unit: str, rng: tuple | None = _POS, choices: tuple | None = None) -> dict:
    return {"doc": doc, "unit": unit, "range": rng, "choices": choices}


@dataclass(frozen=True, slots=True)
class Params:
    """Frozen, validated parameters of the cam-follower oblique impact model.

    Every field is overridable by keyword (``Params(omega=30.0)``), by :meth:`replace`, or on
    the command line as ``--set NAME=VALUE``; the field names are the CLI names. Defaults are
    Table 1 of the paper; fields marked *decision* are ours where the paper is silent or
    inconsistent (shared/MODEL.md), each with its reason in ``FIELD_DOCS``.

    Derived quantities (``J``, ``y_O``, the composite modulus, the stiffness) are computed by
    properties so that a value left as ``None`` always means "the documented default rule".
    """

    # --- Table 1 -------------------------------------------------------------------------
    l: float = field(
        default=0.6, metadata=_meta("follower (rod) length", "m", (0.0, 100.0, False, True))
    )
    r: float = field(default=0.005, metadata=_meta("follower radius", "m"))
    m: float = field(default=0.3676, metadata=_meta("follower mass", "kg"))
    R: float = field(default=0.09, metadata=_meta("cam radius", "m"))
    e: float = field(default=0.04, metadata=_meta("cam eccentricity", "m", _NONNEG))
    nu_f: float = field(
        default=0.3, metadata=_meta("Poisson's ratio of the follower", "-", (0.0, 0.5, True, False))
    )
    nu_c: float = field(
        default=0.3, metadata=_meta("Poisson's ratio of the cam", "-", (0.0, 0.5, True, False))
    )
    Y_f: float = field(default=2.07e11, metadata=_meta("Young's modulus of the follower", "Pa"))
    Y_c: float = field(default=2.07e11, metadata=_meta("Young's modulus of the cam", "Pa"))
    g: float = field(default=9.81, metadata=_meta("gravity", "m/s^2", _NONNEG))
    mu_f: float = field(default=0.3, metadata=_meta("friction coefficient", "-", _NONNEG))
    beta: float = field(default=3.25, metadata=_meta("impact damping factor", "s/m", _NONNEG))
    xi: float = field(
        default=0.42,
        metadata=_meta("coefficient of restitution, eq. (4)", "-", (0.0, 1.0, True, True)),
    )
    omega: float = field(
        default=28.7,
        metadata=_meta(
            "cam speed (practical bound: 1e4 rad/s, ~95,000 rpm)", "rad/s", (0.0, 1e4, False, True)
        ),
    )
    l_lambda: float = field(
        default=0.008,
        metadata=_meta("contact line length l_lambda, the mean mu when random, eq. (18)", "m"),
    )
    D: float = field(
        default=1.45,
        metadata=_meta("fractal dimension, eq. (15)", "-", (1.0, 2.0, False, False)),
    )
    G: float = field(default=1e-10, metadata=_meta("fractal roughness, eq. (15)", "m"))
    k: float = field(default=2.8, metadata=_meta("hardness/yield-strength ratio", "-"))
    phi: float = field(default=0.01, metadata=_meta("yield-strength/modulus ratio", "-"))
    A_r: float = field(default=1e-5, metadata=_meta("real contact area", "m^2"))

    # --- Decisions: geometry and inertia -------------------------------------------------
    J: float | None = field(
        default=None,
        metadata=_meta(
            "follower moment of inertia about the pivot; None = m (l^2/3 + r^2/4), a solid "
            "rod about a transverse axis through its end (decision)",
            "kg m^2",
        ),
    )
    x_O: float = field(
        default=-0.5,
        metadata=_meta(
            "pivot x, cam rotation centre at the origin (decision; practical bound 100 m)",
            "m",
            (-100.0, 100.0, True, True),
        ),
    )
    y_O: float | None = field(
        default=None,
        metadata=_meta(
            "pivot y; None = R + r, so the rod is horizontal when touching the cam with the "
            "cam centre on the x axis (decision; practical bound 100 m)",
            "m",
            (-100.0, 100.0, True, True),
        ),
    )
    theta_c0: float = field(
        default=0.0,
        metadata=_meta(
            "cam phase at t = 0 (decision); restarts carry the accumulated phase omega t, so "
            "the practical bound is wide: 1e9 rad (sin keeps ~1e-7 rad there)",
            "rad",
            (-1e9, 1e9, True, True),
        ),
    )
    theta_f0: float | None = field(
        default=None,
        metadata=_meta(
            "initial follower angle; None = theta_fc(0), in contact (decision, paper sec. 2)",
            "rad",
            (-2 * math.pi, 2 * math.pi, True, True),
        ),
    )
    omega_f0: float | None = field(
        default=None,
        metadata=_meta(
            "initial follower angular velocity; None = d(theta_fc)/dt at t = 0 (decision)",
            "rad/s",
            (-1e4, 1e4, True, True),
        ),
    )

    # --- Decisions: contact force, friction, impacts -------------------------------------
    stiffness: str = field(
        default="hertz",
        metadata=_meta(
            "contact stiffness model: 'hertz' line contact (18) or 'fractal' joint (15)/(17)",
            "-",
            None,
            STIFFNESS_MODELS,
        ),
    )
    damping: str = field(
        default="hunt_crossley",
        metadata=_meta(
            "contact damping: 'hunt_crossley' F = K p (1 + beta dp/dt) (default), or "
            "'paper_literal' F = -K d - beta K d dd/dt, whose damping feeds energy in on "
            "restitution; kept for reproduction only (decision). Both are clamped at "
            "F >= 0: a contact pushes, never pulls",
            "-",
            None,
            DAMPING_FORMS,
        ),
    )
    friction_arm: float | None = field(
        default=None,
        metadata=_meta(
            "arm of the friction force about the pivot; None = r, the rod radius "
            "(decision: (1) writes a force where a torque belongs)",
            "m",
            _NONNEG,
        ),
    )
    v_eps: float = field(
        default=1e-4,
        metadata=_meta(
            "slip-speed scale of the regularised sign, sgn(v) ~ tanh(v / v_eps); 0 = exact "
            "sign. Decision: keeps the right-hand side smooth for RK4; slips are 1.4-3.8 m/s "
            "in contact at the defaults, far from 0",
            "m/s",
            _NONNEG,
        ),
    )
    v_min: float = field(
        default=0.0,
        metadata=_meta(
            "least approach speed -d(delta)/dt for which the restitution jump (4) is applied; "
            "slower closings are left to the compliant force. Default 0: the law applies at "
            "every closing (MODEL.md: a positive v_min lets slow closings rebound almost "
            "elastically, the sticking phase rattles and the flight amplifies it into bands "
            "that grow with v_min; the model is the limit v_min -> 0)",
            "m/s",
            _NONNEG,
        ),
    )
    v_chatter: float = field(
        default=1e-6,
        metadata=_meta(
            "approach speed below which a closing is taken as the end of a complete "
            "chattering sequence and replaced by its accumulation point, a plastic closure "
            "(gap rate 0; Nordmark & Piiroinen 2009). Bounces slower than this last "
            "< 2 xi v / ((1 - xi) |delta''|) ~ 1e-7 s in all; 0 = simulate every bounce "
            "(Zeno: the count then depends on dt). Measured convergence: docs/verdicts.md",
            "m/s",
            _NONNEG,
        ),
    )
    v_micro: float = field(
        default=1e-2,
        metadata=_meta(
            "approach speed below which an applied impact is micro (in a chattering "
            "sequence), not macro (the fast impacts after a flight, ~0.05-1 m/s): a label, "
            "and under resample = 'contact' the start of a new contact's line",
            "m/s",
            _NONNEG,
        ),
    )

    # --- Decisions: random contact-line length (section 2.5) -----------------------------
    l_lambda_sigma: float = field(
        default=0.0,
        metadata=_meta(
            "standard deviation sigma of the contact-line length; 0 = deterministic", "m", _NONNEG
        ),
    )
    l_min: float = field(
        default=1e-4,
        metadata=_meta(
            "lower truncation of the line-length normal, which must stay positive (decision)",
            "m",
        ),
    )
    resample: str = field(
        default="contact",
        metadata=_meta(
            "when a new line length is drawn: at each macro impact ('contact', default: each "
            "contact has its own line), at every applied jump ('impact': micro-impacts too, "
            "whose count changes with dt, and the draws with it; docs/model.md), or every "
            "resample_dt ('interval', the paper's Fig. 3)",
            "-",
            None,
            RESAMPLE_MODES,
        ),
    )
    resample_dt: float = field(
        default=0.01,
        metadata=_meta("interval between draws when resample = 'interval'", "s"),
    )

    # --- Numerics ------------------------------------------------------------------------
    integrator: str = field(
        default="rk4",
        metadata=_meta(
            "'rk4' (default): the paper's fixed-step RK4 on the grid n dt, the reference; "
            "'adaptive': DOP853 with error control (rtol, atol), long steps in flight, events "
            "located on the step's interpolant and re-stepped. At equal accuracy (20-s sections "
            "of periodic responses to 1e-6 rad) the adaptive path is 5.5-10x cheaper than "
            "plain fixed-step RK4 and 1.1-1.2x cheaper than the default merged RK4 "
            "(bench_work_precision.py); at the default settings both take about the same time "
            "and the adaptive path is the more accurate. RK4 stays the default as "
            "the paper's method and the one the published results were validated with",
            "-",
            None,
            INTEGRATORS,
        ),
    )
    dt: float = field(
        default=2e-6,
        metadata=_meta(
            "RK4 step; resolves the Hertz contact oscillation (period ~9e-5 s) with ~45 steps",
            "s",
        ),
    )
    event_tol: float = field(
        default=1e-12,
        metadata=_meta(
            "located impact time's tolerance, at most 1e-9 s (1e-8 merged micro-impacts)",
            "s",
            (0.0, 1e-9, False, True),
        ),
    )
    max_events_per_step: int = field(
        default=8,
        metadata=_meta(
            "chattering guard: impacts handled inside one step before the rest of the step is "
            "left to the compliant contact (at most 1024: buffers are sized by it)",
            "-",
            (1, 1024, True, True),
        ),
    )

    flight_merge: int = field(
        default=16,
        metadata=_meta(
            "most grid steps taken as one RK4 step where a bound on the gap's curvature proves "
            "no contact can occur (free pendulum); 1 = plain RK4. Default 16: 6x faster, equal "
            "to plain RK4 within 5e-9 s / 1e-8 rad (tests). At most 1024 (buffers)",
            "-",
            (1, 1024, True, True),
        ),
    )
    rtol: float = field(
        default=1e-12,
        metadata=_meta(
            "adaptive integrator: relative tolerance of the local error of (theta_f, theta_f'); "
            "1e-12: periodic sections within 1e-6 rad of converged RK4 (tests)",
            "-",
            (0.0, 1e-2, False, True),
        ),
    )
    atol: float = field(
        default=1e-13,
        metadata=_meta(
            "adaptive integrator: absolute tolerance of the local error, for theta_f [rad] and "
            "theta_f' [rad/s]",
            "rad, rad/s",
        ),
    )
    h_max: float = field(
        default=0.005,
        metadata=_meta("adaptive integrator: largest step (flight), at most 1 s", "s", _TO_1),
    )

    # ------------------------------------------------------------------------------------
    def __post_init__(self) -> None:
        for f in fields(self):
            value = getattr(self, f.name)
            if type(value).__module__ == "numpy" and getattr(value, "size", 0) == 1:
                value = value.item()  # numpy scalars: stored as Python numbers
            validate_field(f, value)
            kind = {"int": int, "float": float, "float | None": float}.get(f.type)  # 30 -> 30.0
            if kind and value is not None and type(value) is not kind:  # equal Params, records
                value = kind(value)
            object.__setattr__(self, f.name, value)
        if self.stiffness == "fractal":  # a ParameterError naming D or G where (15)/(17) fail
            from ._stiffness import fractal_stiffness

            fractal_stiffness(self.E, self.D, self.G, self.k, self.phi, self.A_r)

    # --- derived quantities --------------------------------------------------------------
    @property
    def inertia(self) -> float:
        """Moment of inertia J about the pivot [kg m^2]."""
        return self.m * (self.l**2 / 3.0 + self.r**2 / 4.0) if self.J is None else self.J

    @property
    def pivot(self) -> tuple[float, float]:
        """Pivot O = (x_O, y_O) [m], the cam rotation centre O' at the origin."""
        return (self.x_O, self.R + self.r if self.y_O is None else self.y_O)

    @property
    def arm(self) -> float:
        """Friction arm about the pivot [m]."""
        return self.r if self.friction_arm is None else self.friction_arm

    @property
    def E(self) -> float:
        """Composite modulus, eq. (7) [Pa]."""
        from ._stiffness import composite_modulus

        return composite_modulus(self.nu_f, self.Y_f, self.nu_c, self.Y_c)

    def stiffness_at(self, l_lambda: float) -> float:
        """Contact stiffness K_n [N/m] for a contact-line length ``l_lambda`` [m]."""
        from ._stiffness import fractal_stiffness, hertz_line_stiffness

        if self.stiffness == "hertz":
            return hertz_line_stiffness(self.E, l_lambda)
        return fractal_stiffness(self.E, self.D, self.G, self.k, self.phi, self.A_r)

    @property
    def cam_period(self) -> float:
        """Forcing period 2 pi / omega [s]: the stroboscopic section's interval."""
        return 2.0 * math.pi / self.omega

    def refined(self) -> Params:
        """The same model integrated about twice as finely: the convergence check's partner.

        Fixed-step RK4: ``dt / 2``. Adaptive: ``rtol`` and ``atol`` / 32, the error reduction
        of a fifth-order method whose steps halve (its near-cam step cap ``dt`` is halved
        too). "A result must not change when the step is halved" (shared/MODEL.md).
        """
        if self.integrator == "adaptive":
            return self.replace(dt=self.dt / 2, rtol=self.rtol / 32, atol=self.atol / 32)
        return self.replace(dt=self.dt / 2)

    def describe_step(self) -> str:
        """The integrator's resolution in words, e.g. ``dt = 2e-06 s``."""
        if self.integrator == "adaptive":
            return f"adaptive, rtol = {self.rtol:g}"
        return f"dt = {self.dt:g} s"

    # --- conveniences --------------------------------------------------------------------
    def replace(self, **changes: Any) -> Params:
        """A copy with ``changes`` applied and validated."""
        unknown = set(changes) - set(field_names())
        if unknown:
            raise ParameterError(_unknown_message(sorted(unknown)[0]))
        return dataclasses.replace(self, **changes)

    def to_dict(self) -> dict[str, Any]:
        """The fields as given (``None`` kept), for provenance records."""
        return {f.name: getattr(self, f.name) for f in fields(self)}

    @classmethod
    def from_strings(cls, assignments: dict[str, str], base: Params | None = None) -> Params:
        """Build from a dict ``{NAME: "VALUE"}``, as ``--set NAME=VALUE`` gives them."""
        base = cls() if base is None else base
        return base.replace(**{k: parse_value(k, v) for k, v in assignments.items()})


_dataclass_init = Params.__init__


@functools.wraps(_dataclass_init)
def _checked_init(self, *args: Any, **kwargs: Any) -> None:
    """The dataclass's __init__, an unknown keyword refused as by .replace."""
    unknown = set(kwargs) - set(field_names())
    if unknown:
        raise ParameterError(_unknown_message(sorted(unknown)[0]))
    _dataclass_init(self, *args, **kwargs)


Params.__init__ = _checked_init  # type: ignore[method-assign]


def field_names() -> tuple[str, ...]:
    return tuple(f.name for f in fields(Params))


FIELD_DOCS: dict[str, dict] = {f.name: dict(f.metadata) for f in fields(Params)}


def _unknown_message(name: str) -> str:
    from ._names import unknown_message

    return unknown_message(name, field_names())


def parse_value(name: str, text: str) -> Any:
    """Convert the string ``text`` to the type of field ``name``."""
    if name not in FIELD_DOCS:
        raise ParameterError(_unknown_message(name))
    f = next(f for f in fields(Params) if f.name == name)
    if text.strip().lower() == "none":
        if f.default is not None:
            raise ParameterError(f"{name} cannot be None")
        return None
    if FIELD_DOCS[name]["choices"] is not None:
        return text.strip()
    kind = "an integer" if f.type == "int" else "a number"
    if "_" in text:  # Python reads "1_0" as 10: a typo, not a number
        raise ParameterError(f"{name} = {text!r} must be {kind} (no '_' in it)")
    try:
        return int(text) if f.type == "int" else float(text)
    except ValueError:
        raise ParameterError(f"{name} = {text!r} must be {kind}") from None
