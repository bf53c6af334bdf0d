"""The compiled kernel against the numpy model, and its event location."""

import math

import numpy as np
import pytest
from scipy.optimize import brentq

from chaoscam import Numerics, Params
from chaoscam.kernel import _physics as k
from chaoscam.kernel import kernel_constants
from chaoscam.kernel import layout as L
from chaoscam.kernel._events import locate_crossing
from chaoscam.model import angular_acceleration, gap, lever_arm, normal_cam_speed

NUM = Numerics()


@pytest.mark.parametrize(
    "params",
    [Params(), Params(damping="paper_literal"), Params(v_eps=0.0), Params(stiffness="fractal")],
    ids=["default", "literal", "exact-sign", "fractal"],
)
def test_kernel_acceleration_matches_numpy_model(params):
    """The kernel's scalar right-hand side equals the numpy model's, in flight and in contact."""
    c = kernel_constants(params, NUM)
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
    c = kernel_constants(p, NUM)
    for t, th in [(0.0, 0.0), (0.1, 0.05), (0.37, -0.1), (1.3, 0.2)]:
        d, l1, cdn = k.geometry(t, th, c)
        assert d == pytest.approx(float(gap(p, t, th)), abs=1e-15)
        assert l1 == pytest.approx(float(lever_arm(p, t, th)), rel=1e-14)
        assert cdn == pytest.approx(float(normal_cam_speed(p, t, th)), rel=1e-13, abs=1e-15)


def test_located_crossing_is_within_1e_10_s_of_the_root():
    """locate_crossing finds the zero of delta along an RK4 substep to better than 1e-10 s."""
    p = Params()
    c = kernel_constants(p, NUM)
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
    tau = locate_crossing(t0, th0, om0, 0.0, g0, h, g1, K, c, False, trig)
    assert abs(tau - root) <= 1e-10
    assert along(tau) <= 0.0


def _textbook_rk4(t, th, om, h, K, c, side=None, rest=None, signs=None):
    """Classical RK4 written out in Python with the kernel's own right-hand side, each stage
    evaluated at its own time and angle with cos/sin called directly (with ``side``, the
    Jacobian's stages too: the first on ``side``, the others on ``rest``, by default ``side``
    too). ``signs`` (12 of +-1) moves stages 2-4's cos/sin of the cam angle and of theta_f by
    two units of 2^-52 each, a rounding as large as :func:`._physics.rotate`'s."""
    from chaoscam.kernel._physics import acceleration_jacobian_trig
    from chaoscam.kernel._tangent import _column

    def f(ts, ths, oms, stage):
        thc = k.cam_angle(ts, c)
        trig = [math.cos(thc), math.sin(thc), math.cos(ths), math.sin(ths)]
        if signs is not None and stage > 0:
            trig = [
                x + 2.0 * 2.0**-52 * e
                for x, e in zip(trig, signs[4 * stage - 4 : 4 * stage], strict=True)
            ]
        if side is None:
            return k.acceleration_trig(*trig, oms, K, c), 0.0, 0.0
        later = side if rest is None else rest
        return acceleration_jacobian_trig(*trig, oms, K, c, side if stage == 0 else later)

    a1, p1, q1 = f(t, th, om, 0)
    th2, om2 = th + 0.5 * h * om, om + 0.5 * h * a1
    a2, p2, q2 = f(t + 0.5 * h, th2, om2, 1)
    th3, om3 = th + 0.5 * h * om2, om + 0.5 * h * a2
    a3, p3, q3 = f(t + 0.5 * h, th3, om3, 2)
    th4, om4 = th + h * om3, om + h * a3
    a4, p4, q4 = f(t + h, th4, om4, 3)
    state = (
        th + h / 6.0 * (om + 2.0 * om2 + 2.0 * om3 + om4),
        om + h / 6.0 * (a1 + 2.0 * a2 + 2.0 * a3 + a4),
    )
    cols = _column.py_func(1.0, 0.0, h, p1, q1, p2, q2, p3, q3, p4, q4)
    cols += _column.py_func(0.0, 1.0, h, p1, q1, p2, q2, p3, q3, p4, q4)
    return np.array(state), np.array(cols), h / 6.0 * (q1 + 2.0 * q2 + 2.0 * q3 + q4)


def test_rotated_cos_and_sin_are_within_two_units_of_the_direct_calls():
    """_physics.rotate (the addition theorem with Taylor polynomials) gives cos/sin of a + b
    within 2 units of 2^-52 of math.cos/math.sin for |b| < ROTATE_MAX, and the direct calls
    beyond."""
    from chaoscam.kernel._physics import ROTATE_MAX, rotate

    rng = np.random.default_rng(0)
    worst = 0.0
    for _ in range(20_000):
        a = float(rng.uniform(-4.0, 4.0))
        b = float(rng.uniform(-ROTATE_MAX, ROTATE_MAX)) * float(rng.choice([1.0, 1e-3, 1e-6]))
        cr, sr = rotate(a, math.cos(a), math.sin(a), b)
        worst = max(worst, abs(cr - math.cos(a + b)), abs(sr - math.sin(a + b)))
    assert worst <= 2.0 * 2.0**-52
    a, b = 0.3, 2.0 * ROTATE_MAX
    assert rotate(a, math.cos(a), math.sin(a), b) == (math.cos(a + b), math.sin(a + b))


@pytest.mark.parametrize("side", [k.JAC_NATURAL, k.JAC_FLIGHT, k.JAC_CONTACT])
def test_steps_with_rotated_stages_are_the_textbook_steps_to_rounding(side):
    """rk4_trig / rk4_tangent_trig (stage 1 from the start's geometry, stages 2-4's cos/sin
    rotated from it, stage 4's cam handed on) equal RK4 evaluated stage by stage with the
    kernel's right-hand side and direct cos/sin, to within what rounding those cos/sin by two
    units moves the textbook step (the largest move over 8 random roundings), in flight and in
    contact. The tangent step's state is rk4_trig's, bit for bit, and gap_after is the
    geometry at rk4_trig's end."""
    from chaoscam.kernel._events import gap_after
    from chaoscam.kernel._tangent import rk4_tangent_trig

    p = Params()
    c = kernel_constants(p, NUM)
    K = k.stiffness(p.l_lambda, c)
    rng = np.random.default_rng(1)
    in_contact = 0
    for _ in range(100):
        t = float(rng.uniform(0, 30))
        th = gap_root(p, t) + float(rng.uniform(-2e-6, 2e-6))  # both sides of the surface
        om = float(rng.uniform(-3, 3))
        h = float(rng.choice([2e-6, 1e-5, 3.7e-7]))
        g, l1, cdn, *trig = k.geometry_at(t, th, c)
        assert (g, l1, cdn) == k.geometry(t, th, c)
        in_contact += g < 0.0
        plain = k.rk4_trig(t, th, om, h, K, c, *trig)
        for rest in (side, k.JAC_NATURAL, None):  # the flow's tangent, the grid map's, none
            jac = (side, rest) if rest is not None else ()
            x, cols, div = _textbook_rk4(t, th, om, h, K, c, *jac)
            moves = [
                _textbook_rk4(t, th, om, h, K, c, *jac, signs=rng.choice([-1, 1], 12))
                for _ in range(8)
            ]
            env_x = np.max([np.abs(m[0] - x) for m in moves], axis=0)
            env_cols = np.max([np.abs(m[1] - cols) for m in moves], axis=0)
            env_div = max(abs(m[2] - div) for m in moves)
            ulps = 2.0 * np.spacing(np.abs(x))
            assert np.all(np.abs(np.array(plain[:2]) - x) <= env_x + ulps)
            if rest is None:
                continue
            r = rk4_tangent_trig(t, th, om, h, K, c, 1.0, 0.0, 0.0, 1.0, side, rest, *trig)
            assert r[:2] == plain[:2]
            assert np.all(
                np.abs(np.array(r[2:6]) - cols) <= env_cols + 2.0 * np.spacing(np.abs(cols))
            )
            assert abs(r[6] - div) <= env_div + 2.0 * np.spacing(abs(div))
        assert r[7:] == k.cam_trig(t + h, c) == plain[2:]
        assert gap_after(t, th, om, h, K, c, tuple(trig)) == (
            *k.geometry(t + h, plain[0], c),
            plain[1],
        )
    assert 20 < in_contact < 80


def test_the_free_pendulums_step_is_the_same_with_and_without_its_tangent():
    """rk4_flight and rk4_flight_tangent rotate the same stages: the same state to the bit,
    and within rounding of the textbook free-pendulum step with direct cosines."""
    from chaoscam.kernel._tangent import rk4_flight_tangent

    c = kernel_constants(Params(), NUM)
    g = -c[L.C_GRAV] * c[L.C_INV_J]
    rng = np.random.default_rng(2)
    for _ in range(200):
        th, om = float(rng.uniform(-1.5, 1.5)), float(rng.uniform(-20, 20))
        h = float(rng.choice([2e-6, 3.2e-5, 1e-3]))
        x = k.rk4_flight(th, om, h, c)
        assert rk4_flight_tangent(th, om, h, c, 1.0, 0.0, 0.0, 1.0)[:2] == x
        a1 = g * math.cos(th)
        a2 = g * math.cos(th + 0.5 * h * om)
        a3 = g * math.cos(th + 0.5 * h * (om + 0.5 * h * a1))
        a4 = g * math.cos(th + h * (om + 0.5 * h * a2))
        om1 = om + h / 6.0 * (a1 + 2.0 * a2 + 2.0 * a3 + a4)
        # each stage's cosine within 2 units: |g| h 2^-51 on theta_f' at most
        assert abs(x[1] - om1) <= abs(g) * h * 2.0**-51 + 4.0 * math.ulp(om1)


@pytest.mark.parametrize("integrator", ["rk4", "adaptive"])
@pytest.mark.parametrize("transient", [2.0, 3.3])
def test_the_transient_changes_what_is_kept_not_the_motion(integrator, transient):
    """A run with a transient keeps the rows of the same run without one from that time on,
    to the bit. A merged flight block used to stop at the start of the recording, so the
    transient moved the grid's rounding: the default run with transient = 2 s differed from
    its transient-0 run by 5.6e-17 rad at once, and at omega = 42.5, xi = 0.4 the follower
    left the cam's reach at 229 s with a 10 s transient and at 505 s with 100 s."""
    from chaoscam import simulate

    kw = dict(duration=6.0, output_dt=1e-3, integrator=integrator)
    whole, part = simulate(transient=0.0, **kw), simulate(transient=transient, **kw)
    for name in ("section", "impacts", "series"):
        a, b = getattr(whole, name), getattr(part, name)
        kept = a[a["t"] >= transient].reset_index(drop=True)
        assert len(b) > 5 and kept.equals(b.reset_index(drop=True)), name


def test_a_status_prints_as_its_name():
    """print(run.status) says OK or LEFT_REACH, not the integer the kernel returned."""
    from chaoscam.kernel import Status

    assert str(Status.OK) == "OK" and f"{Status.LEFT_REACH}" == "LEFT_REACH"
    assert int(Status.LEFT_REACH) == 2
