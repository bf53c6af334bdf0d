"""Tests of the discrete-time test systems (logistic, Hénon, circle map)."""

import math

import numpy as np

from chaoscam.testsystems import (
    circle_map_orbit,
    circle_map_rotation_number,
    henon_jacobian,
    henon_orbit,
    henon_step,
    logistic_jacobian,
    logistic_orbit,
    logistic_step,
)


def test_logistic_orbit_follows_step():
    """Each iterate of logistic_orbit is logistic_step of the previous one."""
    x = logistic_orbit(3.7, 50, transient=10)
    assert np.allclose(x[1:], logistic_step(x[:-1], 3.7), rtol=0, atol=1e-15)


def test_logistic_orbit_stays_in_unit_interval():
    """For r <= 4 the logistic map maps [0, 1] into itself."""
    x = logistic_orbit(4.0, 10_000)
    assert np.all((x >= 0) & (x <= 1))


def test_logistic_jacobian_matches_finite_difference():
    """The logistic Jacobian equals the central difference of the step."""
    x, h = np.array([0.3]), 1e-6
    fd = (logistic_step(x + h, 3.9) - logistic_step(x - h, 3.9)) / (2 * h)
    assert np.allclose(logistic_jacobian(x, 3.9), fd, rtol=1e-8)


def test_logistic_period_two_matches_closed_form():
    """At r = 3.2 the orbit alternates between the closed-form period-2 points."""
    r = 3.2
    x = logistic_orbit(r, 4)
    disc = math.sqrt((r - 3.0) * (r + 1.0))
    expected = sorted([(r + 1 - disc) / (2 * r), (r + 1 + disc) / (2 * r)])
    assert np.allclose(sorted(x[:2]), expected, atol=1e-12)
    assert abs(x[2] - x[0]) < 1e-12


def test_henon_jacobian_determinant_is_minus_b():
    """det DH = -b everywhere (the Hénon map contracts areas by b)."""
    for p in henon_orbit(20):
        assert math.isclose(np.linalg.det(henon_jacobian(p)), -0.3, rel_tol=1e-12)


def test_henon_orbit_follows_step_and_is_bounded():
    """henon_orbit iterates henon_step and stays on the bounded attractor."""
    p = henon_orbit(2000)
    assert np.allclose(p[1:], np.array([henon_step(q) for q in p[:-1]]), atol=1e-12)
    assert np.max(np.abs(p[:, 0])) < 1.5 and np.max(np.abs(p[:, 1])) < 0.5


def test_circle_map_without_nonlinearity_rotates_by_omega():
    """With K = 0 the circle map is the rigid rotation, rotation number Ω."""
    omega = (math.sqrt(5) - 1) / 2
    rho = circle_map_rotation_number(omega=omega, k=0.0, n=10_000)
    assert math.isclose(rho, omega, abs_tol=1e-12)


def test_circle_map_orbit_is_reduced_mod_one():
    """Angles are returned in [0, 1) and the lift differs from them by integers."""
    x = circle_map_orbit(500)
    lift = circle_map_orbit(500, lift=True)
    assert np.all((x >= 0) & (x < 1))
    assert np.allclose(np.mod(lift, 1.0), x, atol=1e-9)
