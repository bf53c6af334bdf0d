"""An independent reference path on ``scipy.integrate.solve_ivp`` with events.

Slow (pure numpy right-hand side, adaptive DOP853 at tight tolerances) and meant for short
runs: the tests use it to cross-check the compiled kernel, which shares none of its code. It
uses the numpy model functions of :mod:`chaoscam.model` and the same impact rule as the
kernel (shared/MODEL.md): a closing faster than ``v_min`` gets the restitution jump (4), a
slower one enters the compliant contact.

Piecewise integration, restarted at every closing and opening so that no solver step
straddles an impact: in flight a terminal event watches the gap closing (direction -1); in
contact one watches it opening (direction +1), and the gap's maxima are recorded, so that a
micro-flight that begins and ends inside one solver step (the micro-flights of chattering
last 0.1-1 µs) is found from its maximum above 0 and the piece cut back there. A piece that
starts on the surface (|gap| < 1e-14 m: after a rebound, an opening or a plastic closure)
takes the side it starts on: flight after a rebound, so that a closing inside the solver's
first step is seen although the rebound left the gap at -1e-20 m by rounding.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import pandas as pd
from scipy.integrate import solve_ivp

from ..kernel.layout import IMPACT_NAMES
from ..model import (
    LineLengthStream,
    Params,
    angular_acceleration,
    contact_period,
    gap,
    gap_rate,
    lever_arm,
    normal_cam_speed,
)

__all__ = ["simulate_reference", "ReferenceResult"]


@dataclass(frozen=True)
class ReferenceResult:
    """Impacts, stroboscopic section and final state of a reference run."""

    impacts: pd.DataFrame
    section: pd.DataFrame
    final_state: tuple[float, float]
    n_pieces: int


FLIGHT, CONTACT = "flight", "contact"
"""The pieces: FLIGHT from a rebound, an opening or a gap maximum above 0 to the next closing;
CONTACT (the gap about 0 or negative) to the next opening, or back to the first maximum of the
gap above 0, where a micro-flight began and an opening and a closing fell inside one solver
step."""

NEAR_STEP = 1.0 / 8.0
"""The solver's longest step near the cam, as a fraction of the contact oscillation's period.
The error control alone does not keep the solver from stepping over a contact: measured at
t = 0.018 s of the default run, a flight's first step of 8.5 ms stepped over a 37 µs
micro-flight, its closing at 2e-6 m/s and the contact after it (no stage fell inside them),
and a run stopped at another time took other steps and saw them. So in contact no step is
longer than 1/8 of the period, and a change of sign of the gap rate at a maximum is seen
between two step ends; in flight, a piece either provably cannot close (:func:`_open_for`)
or is one step of 1/8 of the period, shorter than any contact, so that a closing in it is
seen at its end."""

_ON_SURFACE = {"gap": 1e-14, "rate": 1e-12}
"""|value| [m, m/s] below which a piece's start is on the event's surface; there the event takes
the side the piece starts on (the value ±1e-300: only its sign counts; a larger stand-in moves
the event's root search, and measured on the v_min = 1e-3 model, later impacts by 5e-8 s)."""


def _events(p: Params, phase: str, t_start: float) -> list:
    """The events of a piece starting at ``t_start`` in ``phase``."""

    def armed(name, fn, direction, side, terminal=True):
        tol = _ON_SURFACE["rate" if name == "maximum" else "gap"]

        def event(tt, yy):
            value = fn(tt, yy)
            return side * 1e-300 if tt == t_start and abs(value) < tol else value

        event.terminal, event.direction, event.name = terminal, direction, name
        return event

    def gap_at(tt, yy):
        return float(gap(p, tt, yy[0]))

    def rate_at(tt, yy):
        return float(gap_rate(p, tt, yy[0], yy[1]))

    if phase == FLIGHT:
        return [armed("closing", gap_at, -1.0, 1.0)]
    # In contact the gap's maxima are only recorded (a restart at each Hertz oscillation's
    # maximum would start the solver thousands of times from its interpolant, measured: the
    # v_min = 1e-3 reference then moved 2.6e-8 s with rtol); the piece is cut back to the first
    # one above 0 afterwards.
    return [
        armed("opening", gap_at, 1.0, -1.0),
        armed("maximum", rate_at, -1.0, -1.0, terminal=False),
    ]


def _open_for(p: Params, t: float, y: np.ndarray) -> float:
    """A time [s] in which the gap, open at (t, y), provably stays open.

    With ``|delta''| <= A`` the gap ``g`` closing at rate ``v`` cannot reach 0 before
    ``(v' + sqrt(v'^2 + 2 A g)) / A`` with ``v' = -v``, halved for safety. A bounds
    ``e w^2 + 2 e w W + rho (m g l / (2 J) + W^2)`` for ``delta = (O - C).n - (R + r)``,
    ``rho = |O| + e``, while ``|theta'| <= W = |theta'(t)| + 1 rad/s``, which gravity
    cannot change by more than 1 rad/s within ``J / (m g l / 2)``.
    """
    g = float(gap(p, t, y[0]))
    if not g > 0.0:
        return 0.0
    v = float(gap_rate(p, t, y[0], y[1]))
    w_cam, e = p.omega, p.e
    w = abs(y[1]) + 1.0
    x_o, y_o = p.pivot
    grav = 0.5 * p.m * p.g * p.l / p.inertia
    acc = e * w_cam * w_cam + 2.0 * e * w_cam * w + (math.hypot(x_o, y_o) + e) * (grav + w * w)
    horizon = 0.5 * (-v + math.sqrt(v * v + 2.0 * acc * g)) / acc
    return min(horizon, 1.0 / grav) if grav > 0.0 else horizon


def _closing(p: Params, t: float, y: np.ndarray, lam: float, stream, impacts: list):
    """The impact law at a located closing, as the kernel's: a closing faster than ``v_min``
    gets the restitution jump (slower than ``v_chatter``: the plastic closure that ends a
    complete chattering), and a new line length when it begins a new contact. Updates ``y``
    and ``impacts``; returns (the next phase, the line length)."""
    rate = float(gap_rate(p, t, y[0], y[1]))
    if not (-rate > p.v_min):
        return CONTACT, lam
    l1 = float(lever_arm(p, t, y[0]))
    cdn = float(normal_cam_speed(p, t, y[0]))
    chatter_end = -rate < p.v_chatter
    xi = 0.0 if chatter_end else p.xi
    om_after = -xi * y[1] + (1.0 + xi) * cdn / l1
    kind = 2 if chatter_end else (1 if -rate < p.v_micro else 0)
    if p.resample == "impact" or (p.resample == "contact" and kind == 0):
        lam = float(stream.draw(1)[0])
    impacts.append((t, y[0], y[1], om_after, rate, l1, lam, kind))
    y[1] = om_after
    return (CONTACT if chatter_end else FLIGHT), lam


def simulate_reference(
    p: Params,
    duration: float,
    *,
    seed: int = 0,
    index: int = 0,
    rtol: float = 1e-13,
    atol: float = 1e-15,
    max_pieces: int = 200_000,
) -> ReferenceResult:
    """Integrate the model with ``solve_ivp`` (DOP853) and located impacts.

    Parameters
    ----------
    p : Params
        The model.
    duration : float
        End time [s].
    seed, index : int
        Realization of the line-length process (as in :func:`chaoscam.simulate`).
    rtol, atol : float
        solve_ivp tolerances. The default rtol = 1e-13 is the loosest at which the reference is
        itself converged for the tests' use. Measured on the v_min = 1e-3 model's first three
        impacts, against RK4 at dt = 2.5e-7 s: rtol 1e-13 within 4.9e-9 s, 3e-14 within
        8.1e-9 s, 1e-12 within 4e-8 s. (Before flights were cut into provably open pieces,
        1e-12 sufficed; 1e-11 was 2.3e-7 s off the third impact on an AMD EPYC and passed on
        other machines: how far depends on the processor's last bits.)
    max_pieces : int
        Guard on the number of restarts (chattering); a RuntimeError past it.
    """
    from .._util import real, whole
    from ..model import contact_angle, contact_angle_rate, params_arg

    p = params_arg(p)
    duration = real("duration", duration, low=0.0, strict=True, unit="s")
    seed, index = whole("seed", seed), whole("index", index)
    # solve_ivp raises rtol below 100 x machine epsilon itself, with a warning.
    rtol = real("rtol", rtol, low=0.0, strict=True)
    atol = real("atol", atol, low=0.0, strict=True)
    max_pieces = whole("max_pieces", max_pieces, low=1)
    stream = LineLengthStream(p, seed, index)
    lam = float(stream.draw(1)[0])
    th = contact_angle(p, 0.0) if p.theta_f0 is None else p.theta_f0
    om = contact_angle_rate(p, 0.0) if p.omega_f0 is None else p.omega_f0
    y = np.array([float(th), float(om)])
    t = 0.0
    T = p.cam_period
    next_resample = p.resample_dt if p.resample == "interval" else math.inf
    phase = CONTACT if gap(p, 0.0, y[0]) <= 0.0 else FLIGHT
    impacts, section = [], []
    k_next = 0
    pieces = 0
    while t < duration:
        pieces += 1
        if pieces > max_pieces:
            raise RuntimeError(f"reference path: more than {max_pieces} restarts before t = {t}")
        t_stop = min(duration, next_resample)
        lam_now = lam
        near = contact_period(p, lam_now) * NEAR_STEP
        max_step = near if phase == CONTACT else math.inf
        if phase == FLIGHT:  # a piece that provably cannot close, or one short step
            open_for = _open_for(p, t, y)
            t_stop = min(t_stop, t + max(open_for, near))
            if open_for < near:
                max_step = near

        def rhs(tt, yy, lam_now=lam_now):
            return [yy[1], float(angular_acceleration(p, tt, yy[0], yy[1], lam_now))]

        events = _events(p, phase, t)
        sol = solve_ivp(
            rhs,
            (t, t_stop),
            y,
            method="DOP853",
            rtol=rtol,
            atol=atol,
            events=events,
            dense_output=True,
            max_step=max_step,
        )
        t_new, y = float(sol.t[-1]), sol.y[:, -1].copy()
        if phase == CONTACT:  # a maximum above 0: a micro-flight that began inside a step
            above = [
                (float(te), ye)
                for te, ye in zip(sol.t_events[1], sol.y_events[1], strict=True)
                if te > t and gap(p, float(te), ye[0]) > 0.0
            ]
            if above:
                t_new, y = above[0][0], above[0][1].copy()
        while k_next * T <= t_new:
            if k_next * T >= t:
                s = sol.sol(k_next * T)
                section.append((k_next, k_next * T, s[0], s[1], lam_now))
            k_next += 1
        cut = t_new < float(sol.t[-1])
        t = t_new
        if cut:  # at a maximum above 0 in contact: in flight
            phase = FLIGHT
        elif sol.status == 1:  # a terminal event ended the piece
            fired = [
                e.name
                for e, te in zip(events, sol.t_events, strict=True)
                if len(te) and e.terminal and te[-1] == t
            ]
            if "closing" in fired:
                phase, lam = _closing(p, t, y, lam, stream, impacts)
            else:  # an opening
                phase = FLIGHT
        elif t >= next_resample:
            lam = float(stream.draw(1)[0])
            next_resample += p.resample_dt
    cols = list(IMPACT_NAMES)  # the kernel's impact columns
    return ReferenceResult(
        impacts=pd.DataFrame(impacts, columns=cols),
        section=pd.DataFrame(section, columns=["k", "t", "theta_f", "omega_f", "l_lambda"]),
        final_state=(float(y[0]), float(y[1])),
        n_pieces=pieces,
    )
