"""Saltation matrices (the tangent's jump at an impact): the generic formula on the bouncing
ball, and the model's kernel form (chaoscam/kernel/_tangent.py)."""

from __future__ import annotations

import math

import numpy as np
import pytest

from chaoscam import Numerics, Params
from chaoscam.analysis import saltation_matrix
from chaoscam.kernel import kernel_constants
from chaoscam.kernel._tangent import saltation
from chaoscam.model import contact_angle, gap, lever_arm, normal_cam_speed
from chaoscam.testsystems import ball_period_one_theory, period_one_orbit


@pytest.mark.parametrize(("gamma", "e", "n"), [(1.2, 0.5, 1), (2.0, 0.3, 1), (5.0, 0.6, 2)])
def test_bouncing_ball_floquet_multipliers_are_analytic(gamma, e, n):
    """Flight flow x saltation x flight flow over one period-one cycle of the ball on a table
    s = Gamma sin t (units g / omega^2) has the analytic multipliers: the roots of
    mu^2 - (1 + e^2 - (1 + e)^2 Gamma sin(phi)) mu + e^2, with Gamma cos(phi) =
    n pi (1 - e)/(1 + e) (Tufillaro et al. 1992, ch. 4; our derivation: det = e^2)."""
    c, doubling = ball_period_one_theory(e, n)
    assert c <= gamma
    period = 2.0 * math.pi * n
    u = n * math.pi * (1.0 - e) / (1.0 + e)
    phi = math.acos(u / gamma)  # the stable branch: sin(phi) > 0
    a = gamma * math.sin(phi)
    # state (x, v); flight x' = v, v' = -1; impact at h = x - Gamma sin t = 0 at t = phi
    v_before = period / 2.0 - period  # launched at pi n, falls for one period
    v_after = (1.0 + e) * u - e * v_before
    s = saltation_matrix(
        g_x=[[1.0, 0.0], [0.0, -e]],
        g_t=[0.0, -(1.0 + e) * gamma * math.sin(phi)],
        f_minus=[v_before, -1.0],
        f_plus=[v_after, -1.0],
        h_x=[1.0, 0.0],
        h_t=-gamma * math.cos(phi),
    )
    flight = np.array([[1.0, period], [0.0, 1.0]])  # from just after to just before the impact
    mult = np.linalg.eigvals(s @ flight)
    trace = 1.0 + e * e - (1.0 + e) ** 2 * a
    theory = np.roots([1.0, -trace, e * e])
    assert np.sort_complex(mult) == pytest.approx(np.sort_complex(theory), rel=1e-12)
    assert np.linalg.det(s) == pytest.approx(e * e, rel=1e-12)
    assert (np.abs(mult).max() < 1.0) == (gamma < doubling)
    # and the exact impact map's finite-difference Jacobian at the orbit Newton finds
    _, jac, ok = period_one_orbit(gamma, e, n, guess=(phi, n * math.pi))
    assert ok
    assert np.sort_complex(np.linalg.eigvals(jac)) == pytest.approx(
        np.sort_complex(theory), rel=1e-5, abs=1e-6
    )


@pytest.mark.parametrize("xi", [0.42, 0.0])
def test_kernel_saltation_equals_the_generic_formula(xi):
    """The cam kernel's written-out saltation matrix equals Müller's formula fed with the
    model's own derivatives (central differences of the numpy model functions), for a
    restitution jump and for the plastic closure of a chattering end (xi = 0)."""
    p = Params(xi=0.42)
    c = kernel_constants(p, Numerics())
    t = 0.031
    th = float(contact_angle(p, t))
    l1 = float(lever_arm(p, t, th))
    cdn = float(normal_cam_speed(p, t, th))
    om = cdn / l1 - 1.7  # approaching at ~0.9 m/s
    g_free = -0.5 * p.m * p.g * p.l / p.inertia * math.cos(th)

    def q(tt, tth):
        return float(normal_cam_speed(p, tt, tth)) / float(lever_arm(p, tt, tth))

    eps = 1e-7
    q_th = (q(t, th + eps) - q(t, th - eps)) / (2 * eps)
    q_t = (q(t + eps, th) - q(t - eps, th)) / (2 * eps)
    h_th = (float(gap(p, t, th + eps)) - float(gap(p, t, th - eps))) / (2 * eps)
    h_t = (float(gap(p, t + eps, th)) - float(gap(p, t - eps, th))) / (2 * eps)
    om_after = -xi * om + (1.0 + xi) * cdn / l1
    ref = saltation_matrix(
        g_x=[[1.0, 0.0], [(1.0 + xi) * q_th, -xi]],
        g_t=[0.0, (1.0 + xi) * q_t],
        f_minus=[om, g_free],
        f_plus=[om_after, g_free],
        h_x=[h_th, 0.0],
        h_t=h_t,
    )
    s11, s21, s22 = saltation(t, th, om, om_after, l1, cdn, xi, c)
    ours = np.array([[s11, 0.0], [s21, s22]])
    assert ours == pytest.approx(ref, rel=1e-6, abs=1e-9)
