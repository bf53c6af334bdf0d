"""Geometry of the cam and the follower rod (shared/MODEL.md, "Geometry"; paper eqs. (5), (6)).

Plain numpy functions of time and the follower state (scalars or arrays); the compiled kernels
carry their own scalar copy, checked against these in the tests.

Frame: cam rotation centre O' at the origin, pivot O = (x_O, y_O), cam phase
``theta_c = omega t + theta_c0``, cam centre ``C = e (cos theta_c, sin theta_c)``. Rod axis
direction ``u = (cos theta_f, sin theta_f)``, upward normal ``n = (-sin theta_f, cos theta_f)``.
"""

from __future__ import annotations

import math
import numbers

import numpy as np

from .._util import ParameterError
from ._params import Params

__all__ = ["cam_angle", "cam_centre", "gap", "lever_arm", "gap_rate", "normal_cam_speed",
           "contact_angle", "contact_angle_rate", "slip_speed", "contact_period"]  # fmt: skip

# 2 pi as a sum of two doubles (the tail is 2 pi - float(2 pi), to 1e-32)
_TWO_PI = 2.0 * math.pi
_TWO_PI_TAIL = 2.4492935982947064e-16


def _two_product(a, b):
    """(p, e) with p = fl(a b) and a b = p + e exactly (Veltkamp's split, Dekker's product)."""
    split = 134217729.0  # 2^27 + 1
    ca = split * a
    a_hi = ca - (ca - a)
    a_lo = a - a_hi
    cb = split * b
    b_hi = cb - (cb - b)
    b_lo = b - b_hi
    p = a * b
    return p, ((a_hi * b_hi - p) + a_hi * b_lo + a_lo * b_hi) + a_lo * b_lo


def cam_angle(p: Params, t):
    """The cam angle ``theta_c = omega t + theta_c0`` reduced to [-pi, pi], to ~1e-16 rad [rad].

    ``omega t`` rounded to a double is off by up to 1e-12 rad at t = 300 s (4e-14 m of cam
    at e = 0.04 m), the height of the last bounces of a chattering sequence; so the product
    is kept exactly as a sum of two doubles and 2 pi taken off in double-double arithmetic
    (for any |theta_c| below 1e15 rad). The kernels use Cody & Waite's reduction instead; the
    tests compare the two.
    """
    t = np.asarray(t, dtype=float)
    prod, err = _two_product(float(p.omega), t)
    s = prod + p.theta_c0
    b = s - prod
    err = err + ((prod - (s - b)) + (p.theta_c0 - b))  # prod + theta_c0 = s + that, exactly
    k = np.rint(s / _TWO_PI)
    kp, ke = _two_product(k, _TWO_PI)  # k 2 pi = kp + ke + k tail
    return ((s - kp) - ke) - k * _TWO_PI_TAIL + err


def cam_centre(p: Params, t):
    """Cam centre C(t) and its velocity dC/dt, each as an (x, y) pair of arrays [m, m/s]."""
    th = cam_angle(p, t)
    c, s = np.cos(th), np.sin(th)
    return (p.e * c, p.e * s), (-p.e * p.omega * s, p.e * p.omega * c)


def gap(p: Params, t, theta_f):
    """Signed gap delta = (O - C).n - (R + r) [m]; > 0 separated, <= 0 in contact."""
    (cx, cy), _ = cam_centre(p, t)
    xo, yo = p.pivot
    return (xo - cx) * -np.sin(theta_f) + (yo - cy) * np.cos(theta_f) - (p.R + p.r)


def lever_arm(p: Params, t, theta_f):
    """Lever arm l_1 = (C - O).u [m], the distance from the pivot to the contact point."""
    (cx, cy), _ = cam_centre(p, t)
    xo, yo = p.pivot
    return (cx - xo) * np.cos(theta_f) + (cy - yo) * np.sin(theta_f)


def normal_cam_speed(p: Params, t, theta_f):
    """Cam-centre velocity along the rod normal, dC/dt . n [m/s] (paper (5): v_Bc . n)."""
    _, (vx, vy) = cam_centre(p, t)
    return -vx * np.sin(theta_f) + vy * np.cos(theta_f)


def gap_rate(p: Params, t, theta_f, omega_f):
    """Gap rate d(delta)/dt = l_1 dtheta_f/dt - dC/dt . n [m/s]."""
    return lever_arm(p, t, theta_f) * omega_f - normal_cam_speed(p, t, theta_f)


def contact_angle(p: Params, t):
    """Persistent-contact angle theta_fc(t) [rad], the root of delta = 0 (closed form).

    With ``O - C = rho (cos phi, sin phi)``: ``theta_fc = phi - pi + arcsin((R + r)/rho)``.
    """
    (cx, cy), _ = cam_centre(p, t)
    xo, yo = p.pivot
    dx, dy = xo - cx, yo - cy
    rho = np.hypot(dx, dy)
    return np.arctan2(dy, dx) - np.pi + np.arcsin((p.R + p.r) / rho)


def contact_angle_rate(p: Params, t):
    """d(theta_fc)/dt = (dC/dt . n) / l_1 at theta_f = theta_fc [rad/s]."""
    th = contact_angle(p, t)
    return normal_cam_speed(p, t, th) / lever_arm(p, t, th)


def slip_speed(p: Params, t, theta_f, omega_f):
    """Slip speed v_r = r dtheta_f/dt - (omega z x B_c).u [m/s] at B_c = C + R n, the cam's
    surface point facing the rod (MODEL.md)."""
    (cx, cy), _ = cam_centre(p, t)
    nx, ny = -np.sin(theta_f), np.cos(theta_f)
    bx, by = cx + p.R * nx, cy + p.R * ny
    return p.r * omega_f - p.omega * (-by * np.cos(theta_f) + bx * np.sin(theta_f))


def contact_period(p: Params, l_lambda: float | None = None) -> float:
    """Period of the linearised contact oscillation, 2 pi sqrt(J / (K_n l_1^2)) [s], at the
    initial contact's lever arm: the RK4 step should resolve it with ~20 or more steps, and the
    adaptive path's cost grows as its inverse square."""
    if not isinstance(p, Params):
        raise TypeError(f"p must be a chaoscam Params, got {type(p).__name__}")
    if l_lambda is None:
        lam = p.l_lambda
    else:
        lam = float(l_lambda) if isinstance(l_lambda, numbers.Real) else math.nan
        if isinstance(l_lambda, bool) or not (math.isfinite(lam) and lam > 0):
            raise ParameterError(f"l_lambda = {l_lambda!r} m must be a finite number > 0")
    l1 = float(lever_arm(p, 0.0, contact_angle(p, 0.0)))
    return 2.0 * math.pi * math.sqrt(p.inertia / (p.stiffness_at(lam) * l1 * l1))
