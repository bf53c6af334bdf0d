"""The compiled kernel against the numpy model, and its event location."""

import numpy as np
import pytest
from scipy.optimize import brentq

from chaoscam import Params
from chaoscam.integrate import _kernel as k
from chaoscam.integrate import kernel_constants
from chaoscam.model import angular_acceleration, gap, lever_arm, normal_cam_speed


@pytest.mark.parametrize(
    "params",
    [Params(), Params(damping="paper_literal"), Params(v_eps=0.0), Params(stiffness="fractal")],
    ids=["default", "literal", "exact-sign", "fractal"],
)
def test_kernel_acceleration_matches_numpy_model(params):
    """The kernel's scalar right-hand side equals the numpy model's, in flight and in contact."""
    c = kernel_constants(params)
    rng = np.random.default_rng(0)
    for _ in range(200):
        t = rng.uniform(0, 1)
        th = float(rng.uniform(-0.02, 0.02) + gap_root(params, t))  # near contact, both sides
        om = rng.uniform(-3, 3)
        lam = rng.uniform(0.002, 0.015)
        K = k.stiffness(lam, c)
        want = float(angular_acceleration(params, t, th, om, lam))
        assert k.acceleration(t, th, om, K, c) == pytest.approx(want, rel=1e-10, abs=1e-9)


def gap_root(p, t):
    from chaoscam.model import contact_angle

    return float(contact_angle(p, t))


def test_kernel_geometry_matches_numpy_model():
    """gap, lever arm and dC/dt.n of the kernel equal the numpy geometry."""
    p = Params()
    c = kernel_constants(p)
    for t, th in [(0.0, 0.0), (0.1, 0.05), (0.37, -0.1), (1.3, 0.2)]:
        d, l1, cdn = k.geometry(t, th, c)
        assert d == pytest.approx(float(gap(p, t, th)), abs=1e-15)
        assert l1 == pytest.approx(float(lever_arm(p, t, th)), rel=1e-14)
        assert cdn == pytest.approx(float(normal_cam_speed(p, t, th)), rel=1e-13, abs=1e-15)


def test_located_crossing_is_within_1e_10_s_of_the_root():
    """locate_crossing finds the zero of delta along an RK4 substep to better than 1e-10 s."""
    p = Params()
    c = kernel_constants(p)
    K = k.stiffness(p.l_lambda, c)
    t0 = 0.1
    th0 = float(gap_root(p, t0)) + 2e-6  # just above the cam, falling onto it
    om0 = -3.0
    h = 4e-6
    g0 = k.geometry(t0, th0, c)[0]
    g1 = k.geometry(t0 + h, k.rk4(t0, th0, om0, h, K, c)[0], c)[0]
    assert g0 > 0 > g1

    def along(tau):
        return k.geometry(t0 + tau, k.rk4(t0, th0, om0, tau, K, c)[0], c)[0]

    root = brentq(along, 0.0, h, xtol=1e-16, rtol=4 * np.finfo(float).eps)
    trig = k.geometry_at(t0, th0, c)[3:]
    tau = k.locate_crossing(t0, th0, om0, 0.0, g0, h, g1, K, c, False, trig)
    assert abs(tau - root) <= 1e-10
    assert along(tau) <= 0.0
