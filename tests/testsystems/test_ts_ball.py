"""Tests of the exact bouncing-ball simulator and its period-one orbit."""

import math

import numpy as np

from chaoscam.testsystems import (
    ball_impact_map,
    ball_period_one_theory,
    bouncing_ball,
    period_one_orbit,
    period_one_thresholds,
)


def test_impacts_happen_on_the_table_with_the_restitution_law():
    """At every impact the ball meets the table and v+ - u = -e (v- - u)."""
    gamma, e = 1.7, 0.5
    run = bouncing_ball(gamma, e, 300)
    t, v = run.times, run.velocities
    tl, vl = run.leave_times[:-1], run.leave_velocities[:-1]
    tau = t[1:] - tl
    height = gamma * np.sin(tl) + vl * tau - 0.5 * tau**2
    assert np.allclose(height, gamma * np.sin(t[1:]), atol=1e-9)
    v_in = vl - tau
    u = gamma * np.cos(t[1:])
    assert np.allclose(v[1:] - u, -e * (v_in - u), atol=1e-9)


def test_ball_never_below_the_table():
    """Sampled between impacts, the ball's height never drops below the table's."""
    run = bouncing_ball(1.8, 0.5, 400)
    t = np.linspace(run.times[0], run.times[-1], 20_000)
    assert np.all(run.positions(t) - 1.8 * np.sin(t) >= -1e-9)


def test_sticking_below_gamma_one():
    """With Γ < 1 the ball comes to rest on the table and the run says so."""
    run = bouncing_ball(0.9, 0.5, 1000)
    assert run.status.startswith("stuck")


def test_period_one_orbit_matches_closed_form():
    """Newton on the exact map finds v = π n and cos φ = nπ(1 - e) / ((1 + e) Γ)."""
    gamma, e = 1.3, 0.5
    x, jac, ok = period_one_orbit(gamma, e, guess=(0.5, 3.0))
    assert ok
    assert math.isclose(x[1], math.pi, rel_tol=1e-9)
    assert math.isclose(math.cos(x[0]), math.pi * (1 - e) / ((1 + e) * gamma), rel_tol=1e-8)
    assert math.isclose(np.linalg.det(jac), e * e, rel_tol=1e-5)  # det DP = e² on the orbit


def test_impact_map_is_consistent_with_simulation():
    """One step of ball_impact_map reproduces the next impact of a simulated run."""
    run = bouncing_ball(1.4, 0.6, 20)
    k = 5
    nxt = ball_impact_map(np.array([run.times[k], run.velocities[k]]), 1.4, 0.6)
    assert np.allclose(nxt, [run.times[k + 1], run.velocities[k + 1]], atol=1e-10)


def test_stability_thresholds_match_theory():
    """Continuation of the numerical orbit gives both thresholds within 1 % of theory."""
    for e, n in ((0.5, 1), (0.3, 1), (0.5, 2)):
        g1, g2 = ball_period_one_theory(e, n)
        num1, num2 = period_one_thresholds(e, n, gamma_start=0.5 * (g1 + g2))
        assert abs(num1 / g1 - 1) < 0.01
        assert abs(num2 / g2 - 1) < 0.01
