"""The model's physics as compiled functions: geometry, equations (1)–(3), RK4 steps; numbers
come from the constants vector (``C_*``, :mod:`.layout`)."""

from __future__ import annotations

import math

from numba import njit

from .layout import (
    C_BETA,
    C_DAMP_SIGN,
    C_E,
    C_GRAV,
    C_HERTZ,
    C_INV_J,
    C_K_FIXED,
    C_MU_ARM,
    C_OMEGA,
    C_RCAM,
    C_RROD,
    C_RSUM,
    C_THETA_C0,
    C_VEPS,
    C_XO,
    C_YO,
    DEKKER_SPLIT,
    INV_TWO_PI,
    TWO_PI_1,
    TWO_PI_2,
    TWO_PI_3,
)


@njit(cache=True, _nrt=False)
def stiffness(lam, c):
    """K_n for line length ``lam``: Hertz (18) unless a fixed (fractal) value is set."""
    return c[C_K_FIXED] if c[C_K_FIXED] > 0.0 else c[C_HERTZ] * lam


@njit(cache=True, inline="always")
def cam_angle(t, c):
    """The cam angle ``theta_c = omega t + theta_c0`` reduced to [-pi, pi], to ~1e-16 rad.

    A naive ``omega t`` is off by 2.3e-13 rad at t = 60 s, moving the cam by 1e-14 m: the
    height of a chattering sequence's last bounces (``v^2 / 2|delta''|``). Here ``omega t`` is
    exact as two doubles (Dekker's product), ``theta_c0`` added by Knuth's two-sum and 2 pi
    taken off by Cody & Waite's three-part reduction. Limits: exact for |theta_c| < 4e8 rad
    (beyond, as the naive sum); fused multiply-adds (the GPU) round the error term differently."""
    w = c[C_OMEGA]
    p = w * t
    cw = DEKKER_SPLIT * w
    w_hi = cw - (cw - w)
    w_lo = w - w_hi
    ct = DEKKER_SPLIT * t
    t_hi = ct - (ct - t)
    t_lo = t - t_hi
    e = ((w_hi * t_hi - p) + w_hi * t_lo + w_lo * t_hi) + w_lo * t_lo  # w t = p + e exactly
    s = p + c[C_THETA_C0]
    b = s - p
    e += (p - (s - b)) + (c[C_THETA_C0] - b)  # p + theta_c0 = s + that, exactly
    k = math.floor(s * INV_TWO_PI + 0.5)
    return ((s - k * TWO_PI_1) - k * TWO_PI_2) - k * TWO_PI_3 + e


@njit(cache=True, inline="always")
def on_clock(t, tau):
    """``tau`` rounded so that ``t + tau`` is a double, ``(t + tau) - t``: a substep of this
    length ends at the time it is stamped with, so state and cam angle never part by the
    rounding of ``t + tau`` (3.6e-15 s at t = 60 s: the cam moves 1e-15 m)."""
    return (t + tau) - t


@njit(cache=True, inline="always")
def cam_trig(t, c):
    """(cos, sin) of the cam angle at time t (:func:`cam_angle`)."""
    thc = cam_angle(t, c)
    return math.cos(thc), math.sin(thc)


ROTATE_MAX = 0.01  # [rad] an angle this close to a known one is rotated to (rotate)


@njit(cache=True, inline="always")
def rotate(a, ca, sa, b):
    """(cos(a + b), sin(a + b)) from ca = cos a, sa = sin a: for |b| < ROTATE_MAX by the
    addition theorem with Taylor polynomials of cos b, sin b (truncation < b^8 / 8! < 1e-20),
    else directly. Saves the stages' transcendental calls (40 % of the RK4 kernel's time).
    Within a few ulp of the direct call; a step's end takes direct values, so no drift."""
    if abs(b) >= ROTATE_MAX:
        return math.cos(a + b), math.sin(a + b)
    return _turn(ca, sa, b)


@njit(cache=True, inline="always")
def _turn(ca, sa, b):
    """:func:`rotate`'s addition theorem, for |b| < ROTATE_MAX."""
    b2 = b * b
    cb = 1.0 - b2 * (0.5 - b2 * (1.0 / 24.0 - b2 * (1.0 / 720.0)))
    sb = b * (1.0 - b2 * (1.0 / 6.0 - b2 * (1.0 / 120.0 - b2 * (1.0 / 5040.0))))
    return ca * cb - sa * sb, sa * cb + ca * sb


@njit(cache=True, inline="always")
def cam_trig_near(t, s, cc, sc, c):
    """(cos, sin) of the cam angle at ``t + s`` from (cc, sc) at t: rotated by omega ((t + s)
    - t) below ROTATE_MAX (:func:`rotate`), else :func:`cam_trig` at ``t + s``."""
    b = c[C_OMEGA] * ((t + s) - t)
    if abs(b) >= ROTATE_MAX:
        return cam_trig(t + s, c)
    return _turn(cc, sc, b)


@njit(cache=True, _nrt=False)
def geometry(t, th, c):
    """Gap delta, lever arm l_1 and normal cam speed dC/dt . n at time t and angle th."""
    thc = cam_angle(t, c)
    return geometry_trig(math.cos(thc), math.sin(thc), math.cos(th), math.sin(th), c)


@njit(cache=True, _nrt=False)
def geometry_at(t, th, c):
    """:func:`geometry` and its trigonometry: ``(delta, l_1, dC/dt.n, cc, sc, ct, st)``."""
    cc, sc = cam_trig(t, c)
    ct, st = math.cos(th), math.sin(th)
    delta, l1, cdn = geometry_trig(cc, sc, ct, st, c)
    return delta, l1, cdn, cc, sc, ct, st


@njit(cache=True, _nrt=False)
def geometry_trig(cc, sc, ct, st, c):
    """:func:`geometry` given cos/sin of the cam angle (cc, sc) and of theta_f (ct, st)."""
    dx = c[C_XO] - c[C_E] * cc
    dy = c[C_YO] - c[C_E] * sc
    delta = -dx * st + dy * ct - c[C_RSUM]
    l1 = -(dx * ct + dy * st)
    ew = c[C_E] * c[C_OMEGA]
    cdn = ew * sc * st + ew * cc * ct
    return delta, l1, cdn


@njit(cache=True, _nrt=False)
def acceleration(t, th, om, K, c):
    """theta_f'' from (1)–(3): gravity, Hunt–Crossley normal force, friction torque."""
    thc = cam_angle(t, c)
    return acceleration_trig(math.cos(thc), math.sin(thc), math.cos(th), math.sin(th), om, K, c)


# Which side of delta = 0 the Jacobian is taken on (the state always uses the actual side).
JAC_NATURAL = 0  # the side the point lies on
JAC_FLIGHT = 1  # the free pendulum's, e.g. on a substep that ends at a located closing
JAC_CONTACT = 2  # the contact force's continuation, e.g. on a substep ending at an opening


@njit(cache=True, inline="always")
def _equations(cc, sc, ct, st, om, K, c, jac, side):
    """The one home of equations (1)–(3) and, with ``jac``, of their Jacobian: returns
    ``(theta'', d theta''/d theta, d theta''/d theta')`` (derivatives 0 without ``jac``). With
    ``delta = (O - C).n - (R + r)``, ``l_1 = (C - O).u``, ``dC/dt.n = e w (sin th_c sin th + cos
    th_c cos th)``:

    - ``d delta/d theta = l_1``, ``d l_1/d theta = -(delta + R + r)``,
      ``d(dC/dt.n)/d theta = e w (sin th_c cos th - cos th_c sin th)``;
    - ``F_n = K p (1 + s beta p')`` with ``p = -delta``, ``p' = dC/dt.n - l_1 theta'``
      (s = +1 Hunt–Crossley, -1 the paper's literal signs), clamped at F_n >= 0;
    - friction torque ``-mu_f a F_n sgn(v_r)`` with the slip speed at ``B_c = C + R n``,
      ``v_r = r theta' - w (C_x sin th - C_y cos th - R)``.

    The field is continuous across delta = 0 (no saltation at onset and separation); its
    Jacobian jumps by ~K l_1^2 / J, so a substep ending on the surface takes it on its own side
    (``side``: JAC_FLIGHT before a closing, JAC_CONTACT, the force continued past p = 0, before
    an opening)."""
    cx = c[C_E] * cc
    cy = c[C_E] * sc
    dx = c[C_XO] - cx
    dy = c[C_YO] - cy
    delta = -dx * st + dy * ct - c[C_RSUM]
    torque = -c[C_GRAV] * ct
    d_th = c[C_GRAV] * st if jac else 0.0
    d_om = 0.0
    in_contact = delta < 0.0
    if in_contact or (jac and side == JAC_CONTACT):
        l1 = -(dx * ct + dy * st)
        ew = c[C_E] * c[C_OMEGA]
        cdn = ew * sc * st + ew * cc * ct
        pen = -delta
        pen_rate = cdn - l1 * om
        damp = c[C_DAMP_SIGN] * c[C_BETA]
        shape = 1.0 + damp * pen_rate
        force = K * pen * shape
        pressing = force > 0.0 if in_contact else False
        if side == JAC_CONTACT:
            jac_on = jac and shape > 0.0
        else:
            jac_on = jac and pressing and side == JAC_NATURAL
        if pressing or jac_on:
            # slip of the rod surface over the cam at B_c = C + R n (MODEL.md)
            v_r = c[C_RROD] * om - c[C_OMEGA] * (cx * st - cy * ct - c[C_RCAM])
            dsgn = 0.0
            if c[C_VEPS] > 0.0:
                x = v_r / c[C_VEPS]
                # tanh(x) rounds to +-1 in float64 for |x| > 19.1: skip the call there.
                if abs(x) < 20.0:
                    sgn = math.tanh(x)
                    dsgn = (1.0 - sgn * sgn) / c[C_VEPS]
                else:
                    sgn = 1.0 if x > 0.0 else -1.0
            else:
                sgn = (v_r > 0.0) - (v_r < 0.0)
            if pressing:
                torque += force * l1 - c[C_MU_ARM] * force * sgn
            if jac_on:
                arm = l1 - c[C_MU_ARM] * sgn
                l1_th = -(delta + c[C_RSUM])
                rate_th = ew * (sc * ct - cc * st) - l1_th * om
                f_th = K * (-l1 * shape + pen * damp * rate_th)
                f_om = -K * pen * damp * l1
                vr_th = -c[C_OMEGA] * (cx * ct + cy * st)
                d_th += f_th * arm + force * (l1_th - c[C_MU_ARM] * dsgn * vr_th)
                d_om += f_om * arm - force * c[C_MU_ARM] * dsgn * c[C_RROD]
    inv_j = c[C_INV_J]
    return torque * inv_j, d_th * inv_j, d_om * inv_j


@njit(cache=True, _nrt=False)
def acceleration_trig(cc, sc, ct, st, om, K, c):
    """:func:`acceleration` given cos/sin of the cam angle (cc, sc) and of theta_f (ct, st)."""
    return _equations(cc, sc, ct, st, om, K, c, False, JAC_NATURAL)[0]


@njit(cache=True, _nrt=False)
def acceleration_jacobian_trig(cc, sc, ct, st, om, K, c, side):
    """:func:`acceleration_jacobian` given cos/sin of the cam angle and of theta_f."""
    return _equations(cc, sc, ct, st, om, K, c, True, side)


@njit(cache=True, _nrt=False)
def acceleration_jacobian(t, th, om, K, c, side=JAC_NATURAL):
    """(theta_f'', d theta_f''/d theta_f, d theta_f''/d theta_f') [1/s^2, 1/s] on ``side``."""
    thc = cam_angle(t, c)
    return acceleration_jacobian_trig(
        math.cos(thc), math.sin(thc), math.cos(th), math.sin(th), om, K, c, side
    )


@njit(cache=True, _nrt=False)
def rk4(t, th, om, h, K, c):
    """One classical fourth-order Runge–Kutta step of length h for (theta_f, theta_f')."""
    cc, sc = cam_trig(t, c)
    r = rk4_trig(t, th, om, h, K, c, cc, sc, math.cos(th), math.sin(th))
    return r[0], r[1]


@njit(cache=True, inline="always")
def _accel(cc, sc, ct, st, om, K, c, jac, side):
    """(theta'', d/d theta, d/d theta') of a stage; the derivatives 0 without ``jac``."""
    if jac:
        return acceleration_jacobian_trig(cc, sc, ct, st, om, K, c, side)
    return acceleration_trig(cc, sc, ct, st, om, K, c), 0.0, 0.0


@njit(cache=True, inline="always")
def rk4_stages(t, th, om, h, K, c, cc, sc, ct, st, jac, first, rest):
    """The one home of the RK4 step: ``(th, om, cc4, sc4, (p1, q1, ..., p4, q4))``, with
    ``jac`` each stage's (d theta''/d theta, d theta''/d theta'), the first's taken on side
    ``first`` of the surface, the others' on ``rest`` (:func:`_equations`). The stages' cos/sin
    are rotated from the start's (:func:`rotate`); the end's cam angle is direct."""
    a1, p1, q1 = _accel(cc, sc, ct, st, om, K, c, jac, first)
    cm, sm = cam_trig_near(t, 0.5 * h, cc, sc, c)
    th2 = th + 0.5 * h * om
    om2 = om + 0.5 * h * a1
    ct2, st2 = rotate(th, ct, st, th2 - th)
    a2, p2, q2 = _accel(cm, sm, ct2, st2, om2, K, c, jac, rest)
    th3 = th + 0.5 * h * om2
    om3 = om + 0.5 * h * a2
    ct3, st3 = rotate(th, ct, st, th3 - th)
    a3, p3, q3 = _accel(cm, sm, ct3, st3, om3, K, c, jac, rest)
    c4, s4 = cam_trig(t + h, c)
    th4 = th + h * om3
    om4 = om + h * a3
    ct4, st4 = rotate(th, ct, st, th4 - th)
    a4, p4, q4 = _accel(c4, s4, ct4, st4, om4, K, c, jac, rest)
    th_new = th + h / 6.0 * (om + 2.0 * om2 + 2.0 * om3 + om4)
    om_new = om + h / 6.0 * (a1 + 2.0 * a2 + 2.0 * a3 + a4)
    return th_new, om_new, c4, s4, (p1, q1, p2, q2, p3, q3, p4, q4)


@njit(cache=True, _nrt=False)
def rk4_trig(t, th, om, h, K, c, cc, sc, ct, st):
    """:func:`rk4` given the trigonometry at its start (cc, sc of the cam angle at t; ct, st of
    theta_f), e.g. :func:`geometry_at`'s; returns ``(th, om, cc4, sc4)``, the last two the cam
    angle's cos/sin at ``t + h``. Two transcendental calls a step, not six."""
    r = rk4_stages(t, th, om, h, K, c, cc, sc, ct, st, False, JAC_NATURAL, JAC_NATURAL)
    return r[0], r[1], r[2], r[3]


@njit(cache=True, inline="always")
def flight_stages(th, om, h, c):
    """The RK4 step of the free pendulum: ``(th, om, (p1, p2, p3, p4))``, p_i = d theta''/d
    theta at the stages (the cosines rotated: one sincos a step)."""
    k = -c[C_GRAV] * c[C_INV_J]
    ct, st = math.cos(th), math.sin(th)
    a1 = k * ct
    om2 = om + 0.5 * h * a1
    th2 = th + 0.5 * h * om
    ct2, st2 = rotate(th, ct, st, th2 - th)
    a2 = k * ct2
    om3 = om + 0.5 * h * a2
    th3 = th + 0.5 * h * om2
    ct3, st3 = rotate(th, ct, st, th3 - th)
    a3 = k * ct3
    om4 = om + h * a3
    th4 = th + h * om3
    ct4, st4 = rotate(th, ct, st, th4 - th)
    a4 = k * ct4
    th_new = th + h / 6.0 * (om + 2.0 * om2 + 2.0 * om3 + om4)
    om_new = om + h / 6.0 * (a1 + 2.0 * a2 + 2.0 * a3 + a4)
    return th_new, om_new, (-k * st, -k * st2, -k * st3, -k * st4)


@njit(cache=True, _nrt=False)
def rk4_flight(th, om, h, c):
    """RK4 step of the free pendulum J theta'' = -(m g l/2) cos theta: :func:`rk4`'s step
    where the gap stays positive (:func:`closing_bound`), at a quarter of the cost."""
    r = flight_stages(th, om, h, c)
    return r[0], r[1]


@njit(cache=True, _nrt=False)
def gap_accel_bound(om, c):
    """A bound on |delta''| in flight while |theta'| < |om| + 1 rad/s [m/s^2]: ``|delta''| <=
    e w^2 + 2 e w |theta'| + rho_max (|theta''| + theta'^2)``, ``rho_max = |O| + e``,
    ``|theta''| <= m g l / (2 J)``."""
    w = abs(om) + 1.0
    ew = c[C_E] * c[C_OMEGA]
    rho = math.hypot(c[C_XO], c[C_YO]) + c[C_E]
    return ew * c[C_OMEGA] + 2.0 * ew * w + rho * (c[C_GRAV] * c[C_INV_J] + w * w)


@njit(cache=True, _nrt=False)
def closing_bound(l1, cdn, om, h, c):
    """A bound on how much the gap can shrink within h <= J / (m g l / 2) [m]: ``s |delta'| +
    s^2/2 max|delta''|``, doubled for safety (gravity changes theta' by <= 1 rad/s in h, as
    :func:`gap_accel_bound` assumes)."""
    return 2.0 * (h * abs(l1 * om - cdn) + 0.5 * h * h * gap_accel_bound(om, c))


@njit(cache=True, _nrt=False)
def safe_horizon(g, l1, cdn, om, c):
    """The time [s] over which a positive gap g certainly stays positive: the largest H with
    ``closing_bound(H) <= g``, capped at J / (m g l / 2) (none without gravity)."""
    acc = gap_accel_bound(om, c)
    v = abs(l1 * om - cdn)
    horizon = 0.5 * g / (v + math.sqrt(v * v + acc * g))
    if c[C_GRAV] > 0.0:
        horizon = min(horizon, 1.0 / (c[C_GRAV] * c[C_INV_J]))
    return horizon
