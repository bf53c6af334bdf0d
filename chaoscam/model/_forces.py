"""Contact force, friction torque and the equation of motion (paper eqs. (1)–(3)), in plain
numpy; the compiled kernel has its own scalar copy, checked against this one in the tests."""

from __future__ import annotations

import numpy as np

from ._geometry import gap, gap_rate, lever_arm, slip_speed
from ._params import Params

__all__ = ["normal_force", "friction_torque", "angular_acceleration", "regularised_sign"]


def regularised_sign(v, v_eps: float):
    """sgn(v), or tanh(v / v_eps) when ``v_eps > 0`` [-]."""
    return np.tanh(np.asarray(v) / v_eps) if v_eps > 0 else np.sign(v)


def normal_force(p: Params, t, theta_f, omega_f, l_lambda):
    """Normal contact force F_n >= 0 [N], eq. (3) in Hunt–Crossley form (decision).

    ``F_n = K_n p (1 + beta dp/dt)`` with penetration ``p = -delta >= 0`` (zero when
    separated), clamped at 0 (no adhesion). With ``damping='paper_literal'`` the paper's
    signs are kept: ``F_n = K_n p (1 - beta dp/dt)``.
    """
    d = np.asarray(gap(p, t, theta_f), dtype=float)
    pen = np.maximum(-d, 0.0)
    pen_rate = -gap_rate(p, t, theta_f, omega_f)
    sign = 1.0 if p.damping == "hunt_crossley" else -1.0
    K = stiffness_array(p, l_lambda)
    f = K * pen * (1.0 + sign * p.beta * pen_rate)
    return np.where(d < 0.0, np.maximum(f, 0.0), 0.0)


def stiffness_array(p: Params, l_lambda):
    """K_n for each line length (constant for the fractal model) [N/m]."""
    lam = np.asarray(l_lambda, dtype=float)
    return np.broadcast_to(p.stiffness_at(lam), lam.shape)


def friction_torque(p: Params, t, theta_f, omega_f, F_n):
    """Friction torque T_f = -mu_f a F_n sgn(v_r) [N m] (decision: arm a = r, sign opposes slip)."""
    v = slip_speed(p, t, theta_f, omega_f)
    return -p.mu_f * p.arm * F_n * regularised_sign(v, p.v_eps)


def angular_acceleration(p: Params, t, theta_f, omega_f, l_lambda):
    """d^2 theta_f / dt^2 from eqs. (1)–(2): J theta'' + (m g l/2) cos theta = F_n l_1 + T_f."""
    F = normal_force(p, t, theta_f, omega_f, l_lambda)
    torque = F * lever_arm(p, t, theta_f) + friction_torque(p, t, theta_f, omega_f, F)
    return (torque - 0.5 * p.m * p.g * p.l * np.cos(theta_f)) / p.inertia
