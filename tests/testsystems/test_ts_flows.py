"""Tests of the continuous-time test systems and the torus signal."""

import math

import numpy as np
import pytest

from chaoscam.testsystems import (
    flow_reference,
    flow_trajectory,
    lorenz,
    rossler,
    torus_section,
    torus_signal,
    ueda,
)


@pytest.mark.parametrize(
    "system, y0",
    [(lorenz(), [1.0, 1.0, 20.0]), (rossler(), [1.0, 1.0, 0.0]), (ueda(), [2.5, 0.0, 0.0])],
)
def test_rk4_agrees_with_dop853_reference(system, y0):
    """Fixed-step RK4 agrees with scipy's DOP853 at tight tolerance over a short horizon."""
    t, states = flow_trajectory(system, y0, dt=0.001, n_samples=201, sample_every=10)
    ref = flow_reference(system, y0, t)
    assert np.max(np.abs(states - ref)) < 1e-8 * (1 + np.max(np.abs(ref)))


def test_rk4_is_fourth_order():
    """Halving the RK4 step divides the Rössler error at t = 5 by 16 (order 4)."""
    y0 = [1.0, 1.0, 0.0]
    ref = flow_reference(rossler(), y0, np.array([0.0, 5.0]))[-1]
    errs = []
    for dt in (0.04, 0.02):
        _, s = flow_trajectory(rossler(), y0, dt=dt, n_samples=2, sample_every=round(5 / dt))
        errs.append(np.linalg.norm(s[-1] - ref))
    assert 15 < errs[0] / errs[1] < 17


def test_ueda_carries_time_as_last_component():
    """The Ueda state's last component advances exactly with time (t' = 1)."""
    t, s = flow_trajectory(ueda(), [2.5, 0.0, 0.0], dt=2 * math.pi / 400, n_samples=401)
    np.testing.assert_allclose(s[:, 2], t, rtol=0, atol=1e-12)
    assert math.isclose(t[-1], 2 * math.pi, rel_tol=1e-12)


def test_torus_section_matches_signal_and_derivative():
    """The section holds x(t_k) and the analytic x'(t_k) of the torus signal."""
    sec = torus_section(20)
    t = np.arange(20.0)
    h = 1e-6
    assert np.allclose(sec[:, 0], torus_signal(t), atol=1e-14)
    fd = (torus_signal(t + h) - torus_signal(t - h)) / (2 * h)
    assert np.allclose(sec[:, 1], fd, atol=1e-6)
