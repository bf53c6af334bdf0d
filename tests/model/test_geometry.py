"""Geometry: gap, lever arm, persistent-contact angle and its rate."""

import numpy as np
import pytest
from scipy.optimize import brentq

from chaoscam import Params
from chaoscam.model import contact_angle, contact_angle_rate, gap, gap_rate, lever_arm

TIMES = np.linspace(0.0, 0.5, 23)


def test_initial_contact_is_horizontal():
    """With the default pivot the rod touches the cam horizontally at t = 0 (MODEL.md)."""
    p = Params()
    assert contact_angle(p, 0.0) == pytest.approx(0.0, abs=1e-15)
    assert gap(p, 0.0, 0.0) == pytest.approx(0.0, abs=1e-15)
    assert lever_arm(p, 0.0, 0.0) == pytest.approx(0.54)


@pytest.mark.parametrize("t", TIMES)
def test_contact_angle_is_the_root_of_the_gap(t):
    """The closed-form theta_fc equals a numerical root of delta(theta) = 0."""
    p = Params()
    root = brentq(lambda th: gap(p, t, th), -0.6, 0.6, xtol=1e-15)
    assert contact_angle(p, t) == pytest.approx(root, abs=1e-12)


@pytest.mark.parametrize("t", TIMES)
def test_contact_angle_rate_is_its_derivative(t):
    """d(theta_fc)/dt equals a central finite difference of theta_fc."""
    p = Params()
    h = 1e-6
    fd = (contact_angle(p, t + h) - contact_angle(p, t - h)) / (2 * h)
    assert contact_angle_rate(p, t) == pytest.approx(fd, rel=1e-7, abs=1e-9)


def test_gap_rate_is_the_time_derivative_of_the_gap():
    """d(delta)/dt = l_1 theta' - dC/dt.n matches a finite difference along a motion."""
    p = Params()
    rng = np.random.default_rng(1)
    for _ in range(10):
        t, th, om = rng.uniform(0, 0.3), rng.uniform(-0.2, 0.3), rng.uniform(-4, 4)
        h = 1e-7
        fd = (gap(p, t + h, th + om * h) - gap(p, t - h, th - om * h)) / (2 * h)
        assert gap_rate(p, t, th, om) == pytest.approx(fd, rel=1e-6, abs=1e-9)
