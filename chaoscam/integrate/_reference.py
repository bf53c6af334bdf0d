"""An independent reference path on ``scipy.integrate.solve_ivp`` with events.

Slow (pure numpy right-hand side, adaptive DOP853 at tight tolerances) and meant for short
runs: the tests use it to cross-check the compiled kernel, which shares none of its code. It
uses the numpy model functions of :mod:`chaoscam.model` and the same impact rule as the
kernel (shared/MODEL.md): a closing faster than ``v_min`` gets the restitution jump (4), a
slower one enters the compliant contact.

Piecewise integration: in *flight* a terminal event watches the gap closing (direction -1);
in *contact* a terminal event watches it opening (direction +1). Each switch restarts the
solver, so no step straddles an impact.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import pandas as pd
from scipy.integrate import solve_ivp

from ..model import (
    LineLengthStream,
    Params,
    angular_acceleration,
    gap,
    gap_rate,
    lever_arm,
    normal_cam_speed,
)
from ._layout import IMPACT_NAMES

__all__ = ["simulate_reference", "ReferenceResult"]


@dataclass(frozen=True)
class ReferenceResult:
    """Impacts, stroboscopic section and final state of a reference run."""

    impacts: pd.DataFrame
    section: pd.DataFrame
    final_state: tuple[float, float]
    n_pieces: int


def simulate_reference(
    p: Params,
    duration: float,
    *,
    seed: int = 0,
    index: int = 0,
    rtol: float = 1e-12,
    atol: float = 1e-14,
    max_pieces: int = 200_000,
) -> ReferenceResult:
    """Integrate the model with ``solve_ivp`` (DOP853) and located impacts.

    Parameters
    ----------
    p : Params
        The model; ``p.dt`` is not used.
    duration : float
        End time [s].
    seed, index : int
        Realization of the line-length process (as in :func:`chaoscam.simulate`).
    rtol, atol : float
        solve_ivp tolerances. The default rtol = 1e-12 is the loosest at which the reference is
        itself converged for the tests' use: on the default model's first three impacts rtol
        1e-12 and 1e-13 agree to 1e-8 s, while 1e-11 is 2.3e-7 s off the third one (measured on
        an AMD EPYC; how far depends on the processor's last bits, which is how 1e-11 passed on
        some machines and failed on others).
    max_pieces : int
        Guard on the number of restarts (chattering); a RuntimeError past it.
    """
    stream = LineLengthStream(p, seed, index)
    lam = float(stream.draw(1)[0])
    from ..model import contact_angle, contact_angle_rate

    th = contact_angle(p, 0.0) if p.theta_f0 is None else p.theta_f0
    om = contact_angle_rate(p, 0.0) if p.omega_f0 is None else p.omega_f0
    y = np.array([float(th), float(om)])
    t = 0.0
    T = p.cam_period
    next_resample = p.resample_dt if p.resample == "interval" else math.inf
    in_contact = gap(p, 0.0, y[0]) <= 0.0
    impacts, section = [], []
    k_next = 0
    pieces = 0
    while t < duration:
        pieces += 1
        if pieces > max_pieces:
            raise RuntimeError(f"reference path: more than {max_pieces} restarts before t = {t}")
        t_stop = min(duration, next_resample)
        lam_now = lam

        def rhs(tt, yy, lam_now=lam_now):
            return [yy[1], float(angular_acceleration(p, tt, yy[0], yy[1], lam_now))]

        def event(tt, yy):
            return float(gap(p, tt, yy[0]))

        event.terminal = True
        event.direction = 1.0 if in_contact else -1.0
        sol = solve_ivp(
            rhs,
            (t, t_stop),
            y,
            method="DOP853",
            rtol=rtol,
            atol=atol,
            events=event,
            dense_output=True,
        )
        t_new = float(sol.t[-1])
        while k_next * T <= t_new:
            if k_next * T >= t:
                s = sol.sol(k_next * T)
                section.append((k_next, k_next * T, s[0], s[1], lam_now))
            k_next += 1
        y = sol.y[:, -1].copy()
        t = t_new
        if sol.status == 1:  # a gap event
            if in_contact:
                in_contact = False
                continue
            rate = float(gap_rate(p, t, y[0], y[1]))
            if -rate > p.v_min:
                l1 = float(lever_arm(p, t, y[0]))
                cdn = float(normal_cam_speed(p, t, y[0]))
                # below v_chatter: the plastic closure that ends a complete chattering
                chatter_end = -rate < p.v_chatter
                xi = 0.0 if chatter_end else p.xi
                om_after = -xi * y[1] + (1.0 + xi) * cdn / l1
                kind = 2 if chatter_end else (1 if -rate < p.v_micro else 0)
                if p.resample == "impact" or (p.resample == "contact" and kind == 0):
                    lam = float(stream.draw(1)[0])
                impacts.append((t, y[0], y[1], om_after, rate, l1, lam, kind))
                y[1] = om_after
                in_contact = chatter_end
            else:
                in_contact = True
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
