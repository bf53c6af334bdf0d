"""An independent reference path on ``scipy.integrate.solve_ivp`` with events, for the tests'
cross-checks of the compiled kernel: slow (numpy right-hand side, DOP853 at tight tolerances),
sharing no code with it but :mod:`chaoscam.model`'s functions and the kernel's impact rule.

Piecewise, restarted at every closing and opening so that no solver step straddles an impact;
a piece from the surface (|gap| < 1e-14 m) takes its start's side.
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


@dataclass(frozen=True)
class ReferenceResult:
    """Impacts, stroboscopic section and final state of a reference run."""

    impacts: pd.DataFrame
    section: pd.DataFrame
    final_state: tuple[float, float]
    n_pieces: int


FLIGHT, CONTACT = "flight", "contact"
"""The pieces: FLIGHT from a rebound, opening or gap maximum above 0 to the next closing; CONTACT
to the next opening, or back to the first gap maximum above 0 (a micro-flight inside a step)."""

NEAR_STEP = 1.0 / 8.0
"""The solver's longest step near the cam [contact periods]: the error control alone steps over
a contact (a flight's 8.5 ms first step misses a 37 µs micro-flight). In contact a gap maximum
thus shows between step ends; in flight a piece cannot close (:func:`_open_for`) or is one step."""

_ON_SURFACE = {"gap": 1e-14, "rate": 1e-12}
"""|value| [m, m/s] below which a piece starts on the event's surface, where the event takes the
start's side as ±1e-300 (a larger stand-in moves the root search)."""


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
    # maxima only recorded: a restart at each would restart the solver thousands of times
    return [armed("opening", gap_at, 1.0, -1.0),
            armed("maximum", rate_at, -1.0, -1.0, terminal=False)]  # fmt: skip


def _open_for(p: Params, t: float, y: np.ndarray) -> float:
    """A time [s] in which the gap, open at (t, y), provably stays open: with ``|delta''| <= A``
    a gap ``g`` closing at rate ``v`` cannot reach 0 before ``(-v + sqrt(v^2 + 2 A g)) / A``,
    halved for safety; ``A = e w^2 + 2 e w W + rho (m g l / (2 J) + W^2)``, ``rho = |O| + e``,
    ``W = |theta'(t)| + 1 rad/s`` (within ``J / (m g l / 2)``)."""
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
    """The kernel's impact law at a located closing (the jump above ``v_min``, the plastic
    closure below ``v_chatter``); updates ``y``, ``impacts``; (the next phase, line length)."""
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
    p: Params, duration: float, *, seed: int = 0, index: int = 0, rtol: float = 1e-13,
    atol: float = 1e-15, max_pieces: int = 200_000,
) -> ReferenceResult:  # fmt: skip
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
        solve_ivp tolerances; rtol = 1e-13 is the loosest at which the reference is converged
        for the tests (looser results depend on the processor's last bits).
    max_pieces : int
        Guard on the number of restarts (chattering); a RuntimeError past it.

    Returns
    -------
    ReferenceResult
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
        sol = solve_ivp(rhs, (t, t_stop), y, method="DOP853", rtol=rtol, atol=atol, events=events,
                        dense_output=True, max_step=max_step)  # fmt: skip
        t_new, y = float(sol.t[-1]), sol.y[:, -1].copy()
        if phase == CONTACT:  # a maximum above 0: a micro-flight that began inside a step
            above = [(float(te), ye)
                     for te, ye in zip(sol.t_events[1], sol.y_events[1], strict=True)
                     if te > t and gap(p, float(te), ye[0]) > 0.0]  # fmt: skip
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
            fired = [e.name for e, te in zip(events, sol.t_events, strict=True)
                     if len(te) and e.terminal and te[-1] == t]  # fmt: skip
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
        final_state=(float(y[0]), float(y[1])), n_pieces=pieces,
    )  # fmt: skip
