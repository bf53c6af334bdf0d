"""The parameter set: Table 1 of the paper plus every decision of shared/MODEL.md, the single
home of physics choices (a kernel receives its numbers from here: ``kernel_constants``).

Reference: "Effect of Surface Morphology on Dynamic Characteristics of Cam-Follower Oblique
Impact System", Table 1 (SI units throughout).
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass, field, fields
from typing import Any

from .._util import check_fields, parse_field, strict_init
from .._util import meta as _meta
from ._stiffness import composite_modulus, fractal_stiffness, hertz_line_stiffness

__all__ = ["FIELD_DOCS", "Params", "field_names", "params_arg", "parse_value"]

STIFFNESS_MODELS = ("hertz", "fractal")
DAMPING_FORMS = ("hunt_crossley", "paper_literal")
RESAMPLE_MODES = ("contact", "impact", "interval")
_MODULUS = "Pa", 1e2, 1e13, "a soft gel (1e2 Pa) to above diamond (1.2e12 Pa)"


def _in(doc: str, unit: str, low: float, high: float, why: str) -> dict:
    """The metadata of a field in [low, high], with ``why`` that range."""
    return _meta(doc, unit, (low, high, True, True), why=why)


def _length(doc: str, low: float = 1e-6) -> dict:
    return _in(doc, "m", low, 10.0, f"a machine part: {'1 um' if low else '0'} to 10 m")


def _speed(doc: str) -> dict:
    return _in(doc, "m/s", 0.0, 10.0, "above a cam follower's every speed (~0.01-5 m/s)")


@strict_init
@dataclass(frozen=True, slots=True)
class Params:
    """Frozen, validated parameters of the cam-follower oblique impact model.

    Every field is overridable by keyword (``Params(omega=30.0)``), by :meth:`replace`, or on
    the command line as ``--set NAME=VALUE``; the field names are the CLI names. Defaults are
    Table 1 of the paper; fields marked *decision* are ours where the paper is silent or
    inconsistent (docs/model.md), each with its reason in ``FIELD_DOCS``.

    Derived quantities (``J``, ``y_O``, the composite modulus, the stiffness) are computed by
    properties so that a value left as ``None`` always means "the documented default rule".
    The integrator and its settings are not here: see :class:`chaoscam.Numerics`.
    """

    _WHAT = "parameter"

    # --- Table 1 -------------------------------------------------------------------------
    l: float = field(default=0.6, metadata=_length("follower (rod) length"))
    r: float = field(default=0.005, metadata=_length("follower radius"))
    m: float = field(default=0.3676, metadata=_in("follower mass", "kg", 1e-6, 1e3, "1 mg to 1 t"))
    R: float = field(default=0.09, metadata=_length("cam radius"))
    e: float = field(default=0.04, metadata=_length("cam eccentricity", 0.0))
    nu_f: float = field(
        default=0.3, metadata=_meta("Poisson's ratio of the follower", "-", (0.0, 0.5, True, False))
    )
    nu_c: float = field(
        default=0.3, metadata=_meta("Poisson's ratio of the cam", "-", (0.0, 0.5, True, False))
    )
    Y_f: float = field(default=2.07e11, metadata=_in("Young's modulus of the follower", *_MODULUS))
    Y_c: float = field(default=2.07e11, metadata=_in("Young's modulus of the cam", *_MODULUS))
    g: float = field(default=9.81, metadata=_in("gravity", "m/s^2", 0.0, 100.0, "none to ~10 g"))
    mu_f: float = field(default=0.3, metadata=_in(
        "friction coefficient", "-", 0.0, 10.0, "dry contacts stay below ~1.5"))  # fmt: skip
    beta: float = field(default=3.25, metadata=_in("impact damping factor", "s/m", 0.0, 1e4,
        "Hunt-Crossley's 3 (1 - e) / (2 v) for impact speeds down to 1e-4 m/s"))  # fmt: skip
    xi: float = field(default=0.42, metadata=_meta(
        "coefficient of restitution, eq. (4)", "-", (0.0, 1.0, True, True)))  # fmt: skip
    omega: float = field(default=28.7, metadata=_meta(
        "cam speed (practical bound: 1e4 rad/s, ~95,000 rpm)", "rad/s",
        (0.0, 1e4, False, True)))  # fmt: skip
    l_lambda: float = field(default=0.008, metadata=_length(
        "contact line length l_lambda, the mean mu when random, eq. (18)"))  # fmt: skip
    D: float = field(default=1.45, metadata=_meta(
        "fractal dimension, eq. (15)", "-", (1.0, 2.0, False, False)))  # fmt: skip
    G: float = field(default=1e-10, metadata=_in(
        "fractal roughness, eq. (15)", "m", 1e-15, 1e-3, "below an atom to 1 mm"))  # fmt: skip
    k: float = field(default=2.8, metadata=_in("hardness/yield-strength ratio", "-", 0.1, 10.0,
        "Tabor's ~2.8 for metals, a decade either side"))  # fmt: skip
    phi: float = field(default=0.01, metadata=_in("yield-strength/modulus ratio", "-", 1e-5, 1.0,
        "a yield strength below the modulus"))  # fmt: skip
    A_r: float = field(default=1e-5, metadata=_in(
        "real contact area", "m^2", 1e-12, 1.0, "1 um^2 to 1 m^2"))  # fmt: skip

    # --- Decisions: geometry and inertia -------------------------------------------------
    J: float | None = field(default=None, metadata=_meta(
        "follower moment of inertia about the pivot; None = m (l^2/3 + r^2/4), a solid rod "
        "about a transverse axis through its end (decision)", "kg m^2", (1e-15, 1e5, True, True),
        why="a 1-mg, 0.1-mm part to a 1-t, 10-m rod"))  # fmt: skip
    x_O: float = field(default=-0.5, metadata=_meta(
        "pivot x, cam rotation centre at the origin (decision; practical bound 100 m)", "m",
        (-100.0, 100.0, True, True)))  # fmt: skip
    y_O: float | None = field(default=None, metadata=_meta(
        "pivot y; None = R + r, so the rod is horizontal when touching the cam with the cam "
        "centre on the x axis (decision; practical bound 100 m)", "m",
        (-100.0, 100.0, True, True)))  # fmt: skip
    theta_c0: float = field(default=0.0, metadata=_meta(
        "cam phase at t = 0 (decision); restarts carry the accumulated phase omega t, so the "
        "practical bound is wide: 1e9 rad (sin keeps ~1e-7 rad there)", "rad",
        (-1e9, 1e9, True, True)))  # fmt: skip
    theta_f0: float | None = field(default=None, metadata=_meta(
        "initial follower angle; None = theta_fc(0), in contact (decision, paper sec. 2)", "rad",
        (-2 * math.pi, 2 * math.pi, True, True)))  # fmt: skip
    omega_f0: float | None = field(default=None, metadata=_meta(
        "initial follower angular velocity; None = d(theta_fc)/dt at t = 0 (decision)", "rad/s",
        (-1e4, 1e4, True, True)))  # fmt: skip

    # --- Decisions: contact force, friction, impacts -------------------------------------
    stiffness: str = field(default="hertz", metadata=_meta(
        "contact stiffness model: 'hertz' line contact (18) or 'fractal' joint (15)/(17)", "-",
        None, STIFFNESS_MODELS))  # fmt: skip
    damping: str = field(default="hunt_crossley", metadata=_meta(
        "contact damping: 'hunt_crossley' F = K p (1 + beta dp/dt) (default), or "
        "'paper_literal' F = -K d - beta K d dd/dt, whose damping feeds energy in on "
        "restitution; kept for reproduction only (decision). Both are clamped at F >= 0: a "
        "contact pushes, never pulls", "-", None, DAMPING_FORMS))  # fmt: skip
    friction_arm: float | None = field(default=None, metadata=_length(
        "arm of the friction force about the pivot; None = r, the rod radius (decision: (1) "
        "writes a force where a torque belongs)", 0.0))  # fmt: skip
    v_eps: float = field(default=1e-4, metadata=_speed(
        "slip-speed scale of the regularised sign, sgn(v) ~ tanh(v / v_eps); 0 = exact sign. "
        "Decision: keeps the right-hand side smooth for RK4; slips are 1.4-3.8 m/s in contact "
        "at the defaults, far from 0"))  # fmt: skip
    v_min: float = field(default=0.0, metadata=_speed(
        "least approach speed -d(delta)/dt for which the restitution jump (4) is applied; "
        "slower closings are left to the compliant force. Default 0: the law applies at every "
        "closing (MODEL.md: a positive v_min lets slow closings rebound almost elastically, the "
        "sticking phase rattles and the flight amplifies it into bands that grow with v_min; "
        "the model is the limit v_min -> 0)"))  # fmt: skip
    v_chatter: float = field(default=1e-6, metadata=_speed(
        "approach speed below which a closing is taken as the end of a complete chattering "
        "sequence and replaced by its accumulation point, a plastic closure (gap rate 0; "
        "Nordmark & Piiroinen 2009). Bounces slower than this last < 2 xi v / ((1 - xi) "
        "|delta''|) ~ 1e-7 s in all; 0 = simulate every bounce (Zeno: the count then depends "
        "on dt). Measured convergence: docs/verdicts.md"))  # fmt: skip
    v_micro: float = field(default=1e-2, metadata=_speed(
        "approach speed below which an applied impact is micro (in a chattering sequence), "
        "not macro (the fast impacts after a flight, ~0.05-1 m/s): a label, and under "
        "resample = 'contact' the start of a new contact's line"))  # fmt: skip

    # --- Decisions: random contact-line length (section 2.5) -----------------------------
    l_lambda_sigma: float = field(default=0.0, metadata=_length(
        "standard deviation sigma of the contact-line length; 0 = deterministic", 0.0))  # fmt: skip
    l_min: float = field(default=1e-4, metadata=_length(
        "lower truncation of the line-length normal, which must stay positive "
        "(decision)"))  # fmt: skip
    resample: str = field(default="contact", metadata=_meta(
        "when a new line length is drawn: at each macro impact ('contact', default: each "
        "contact has its own line), at every applied jump ('impact': micro-impacts too, whose "
        "count changes with dt, and the draws with it; docs/model.md), or every resample_dt "
        "('interval', the paper's Fig. 3)", "-", None, RESAMPLE_MODES))  # fmt: skip
    resample_dt: float = field(default=0.01, metadata=_meta(
        "interval between draws when resample = 'interval'", "s", (1e-12, 1e4, True, True),
        why="from a time's rounding at 1000 s to 1e4 s"))  # fmt: skip

    # ------------------------------------------------------------------------------------
    def __post_init__(self) -> None:
        check_fields(self)
        if self.stiffness == "fractal":  # a ParameterError naming D or G where (15)/(17) fail
            self.stiffness_at(0.0)

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
        return composite_modulus(self.nu_f, self.Y_f, self.nu_c, self.Y_c)

    def stiffness_at(self, l_lambda: float) -> float:
        """Contact stiffness K_n [N/m] for a contact-line length ``l_lambda`` [m]."""
        if self.stiffness == "hertz":
            return hertz_line_stiffness(self.E, l_lambda)
        return fractal_stiffness(self.E, self.D, self.G, self.k, self.phi, self.A_r)

    @property
    def cam_period(self) -> float:
        """Forcing period 2 pi / omega [s]: the stroboscopic section's interval."""
        return 2.0 * math.pi / self.omega

    # --- conveniences --------------------------------------------------------------------
    def replace(self, **changes: Any) -> Params:
        """A copy with ``changes`` applied and validated."""
        return dataclasses.replace(self, **changes)

    def to_dict(self) -> dict[str, Any]:
        """The fields as given (``None`` kept), for provenance records."""
        return {f.name: getattr(self, f.name) for f in fields(self)}

    @classmethod
    def from_strings(cls, assignments: dict[str, str], base: Params | None = None) -> Params:
        """Build from a dict ``{NAME: "VALUE"}``, as ``--set NAME=VALUE`` gives them."""
        base = cls() if base is None else base
        return base.replace(**{k: parse_value(k, v) for k, v in assignments.items()})


def field_names() -> tuple[str, ...]:
    """The fields of :class:`Params`, in order (the ``--set`` names)."""
    return tuple(f.name for f in fields(Params))


FIELD_DOCS: dict[str, dict] = {f.name: dict(f.metadata) for f in fields(Params)}


def parse_value(name: str, text: str) -> Any:
    """Convert the string ``text`` to the type of field ``name``."""
    return parse_field(Params, name, text)


def params_arg(params: Any, name: str = "params") -> Params:
    """An API function's ``params`` argument (or another argument ``name`` holding a model,
    a sweep's ``base``): a :class:`Params`, or None for the defaults."""
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
