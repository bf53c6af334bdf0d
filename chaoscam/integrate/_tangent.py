"""Tangent (variational) dynamics of the cam-follower through its impacts.

The linearised flow ``V' = A(t) V`` with ``A = [[0, 1], [d theta''/d theta,
d theta''/d theta']]`` is integrated with the state by the *same* RK4 stages
(:func:`rk4_tangent_trig`), so between events V is the exact derivative of the RK4 steps and
the state is bit-identical to :func:`._physics.rk4`'s. At a restitution jump (4)–(5) V is
multiplied by the flow's saltation matrix at the located event (:func:`saltation`; Müller
1995, Chaos Solitons Fractals 5(9); Leine & Nijmeijer 2004, *Dynamics and Bifurcations of
Non-smooth Mechanical Systems*, sec. 3.5; Dankowicz & Nordmark 2000, Physica D 136), not a
derivative of the event search; where chattering ends in sticking the default grid's V
overstates the growth while the grid's motion does not (README, "Tangent dynamics checked
independently"). Cause (found 2026-11-27, measured on the ξ = 0.45 period 6): the RK4
substep that follows a located event inside a chatter cycle (after a micro-impact's rebound,
or an opening) takes the full equations from the surface, and one of its stages dips about
1e-12 m into the cam (the stage extrapolation doubles the rod's acceleration term), where the
Hertz force is negligible in the state but not in its derivative; V uses the flight side at
every stage and the flow's saltation, so it misses the grid map's dependence on the event
time (sensitivity l1/v, 2e5 s/rad at a 2.5e-6 m/s closing). Each chatter cycle's V is then
1-30 % too large (a factor ~3 over the period); the stage's dip shrinks as h^2, hence the
convergence with dt. The contact steps, the saltation and the sticking projection are exact
there. A fix (flight substeps from the surface, or the event-time term in V) is not made yet.
Contact onset and separation need no saltation matrix:
the contact force vanishes at delta = 0, so the vector field is continuous there (its Jacobian
is not, which is why no RK4 step straddles delta = 0).

The same RK4 quadrature gives the integral of the divergence ``tr A = d theta''/d theta'``,
so that Liouville's formula ``ln |det V| = int tr A dt + sum ln |det S|`` can be checked.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from ._layout import C_E, C_GRAV, C_INV_J, C_OMEGA, C_XO, C_YO, SECTION_NAMES
from ._physics import acceleration_jacobian, acceleration_jacobian_trig, cam_angle, cam_trig


@njit(cache=True, inline="always")
def _column(x, y, h, p1, q1, p2, q2, p3, q3, p4, q4):
    """One column (x, y) of V through the RK4 stages of ``x' = y, y' = p_i x + q_i y``."""
    x2, y2 = x + 0.5 * h * y, y + 0.5 * h * (p1 * x + q1 * y)
    x3, y3 = x + 0.5 * h * y2, y + 0.5 * h * (p2 * x2 + q2 * y2)
    x4, y4 = x + h * y3, y + h * (p3 * x3 + q3 * y3)
    return (
        x + h / 6.0 * (y + 2.0 * y2 + 2.0 * y3 + y4),
        y
        + h
        / 6.0
        * (
            p1 * x
            + q1 * y
            + 2.0 * (p2 * x2 + q2 * y2)
            + 2.0 * (p3 * x3 + q3 * y3)
            + p4 * x4
            + q4 * y4
        ),
    )


@njit(cache=True)
def rk4_tangent_trig(t, th, om, h, K, c, v11, v21, v12, v22, side, cc, sc, ct, st):
    """One RK4 step of the state and of its tangent matrix V (columns (v11, v21), (v12, v22)).

    Returns ``(th, om, v11, v21, v12, v22, div, cc4, sc4)`` with ``div`` the step's RK4
    quadrature of the divergence. The state is computed exactly as :func:`._physics.rk4`
    does; ``side`` says on which side of the contact surface the Jacobian is taken
    (:data:`._physics.JAC_NATURAL` unless the substep ends at a located crossing). As
    :func:`._physics.rk4_trig`, it takes the trigonometry at its start (cam angle at t: cc,
    sc; theta_f: ct, st) and hands on the cam angle's cos/sin at ``t + h`` (cc4, sc4).
    """
    a1, p1, q1 = acceleration_jacobian_trig(cc, sc, ct, st, om, K, c, side)
    cm, sm = cam_trig(t + 0.5 * h, c)
    th2 = th + 0.5 * h * om
    om2 = om + 0.5 * h * a1
    a2, p2, q2 = acceleration_jacobian_trig(cm, sm, math.cos(th2), math.sin(th2), om2, K, c, side)
    th3 = th + 0.5 * h * om2
    om3 = om + 0.5 * h * a2
    a3, p3, q3 = acceleration_jacobian_trig(cm, sm, math.cos(th3), math.sin(th3), om3, K, c, side)
    c4, s4 = cam_trig(t + h, c)
    th4 = th + h * om3
    om4 = om + h * a3
    a4, p4, q4 = acceleration_jacobian_trig(c4, s4, math.cos(th4), math.sin(th4), om4, K, c, side)
    # The same stages for each column (x, y) of V: x' = y, y' = p x + q y.
    n11, n21 = _column(v11, v21, h, p1, q1, p2, q2, p3, q3, p4, q4)
    n12, n22 = _column(v12, v22, h, p1, q1, p2, q2, p3, q3, p4, q4)
    div = h / 6.0 * (q1 + 2.0 * q2 + 2.0 * q3 + q4)
    return (
        th + h / 6.0 * (om + 2.0 * om2 + 2.0 * om3 + om4),
        om + h / 6.0 * (a1 + 2.0 * a2 + 2.0 * a3 + a4),
        n11,
        n21,
        n12,
        n22,
        div,
        c4,
        s4,
    )


@njit(cache=True)
def rk4_flight_tangent(th, om, h, c, v11, v21, v12, v22):
    """:func:`._physics.rk4_flight` (the free pendulum) with its tangent matrix.

    In flight ``A = [[0, 1], [(m g l / 2J) sin theta, 0]]``: the divergence is zero. Returns
    ``(th, om, v11, v21, v12, v22)``.
    """
    k = -c[C_GRAV] * c[C_INV_J]
    a1 = k * math.cos(th)
    om2 = om + 0.5 * h * a1
    th2 = th + 0.5 * h * om
    a2 = k * math.cos(th2)
    om3 = om + 0.5 * h * a2
    th3 = th + 0.5 * h * om2
    a3 = k * math.cos(th3)
    om4 = om + h * a3
    th4 = th + h * om3
    a4 = k * math.cos(th4)
    p1 = -k * math.sin(th)
    p2 = -k * math.sin(th2)
    p3 = -k * math.sin(th3)
    p4 = -k * math.sin(th4)
    # the columns of V through the same stages; no damping in flight (q = 0)
    n11, n21 = _column(v11, v21, h, p1, 0.0, p2, 0.0, p3, 0.0, p4, 0.0)
    n12, n22 = _column(v12, v22, h, p1, 0.0, p2, 0.0, p3, 0.0, p4, 0.0)
    return (
        th + h / 6.0 * (om + 2.0 * om2 + 2.0 * om3 + om4),
        om + h / 6.0 * (a1 + 2.0 * a2 + 2.0 * a3 + a4),
        n11,
        n21,
        n12,
        n22,
    )


@njit(cache=True)
def saltation(t, th, om_before, om_after, l1, cdn, xi, c):
    """The saltation matrix S of a restitution jump at a located closing (t, th).

    For the event surface ``h(t, x) = delta(t, theta) = 0`` and the jump
    ``g(t, x) = (theta, -xi theta' + (1 + xi) q)``, ``q = (dC/dt.n) / l_1``:

    ``S = g_x + (f+ - g_x f- - g_t) h_x^T / (h_t + h_x f-)`` (Müller 1995, eq. 16),

    with ``h_x = (l_1, 0)``, ``h_t + h_x f- = l_1 theta'- - dC/dt.n`` (the gap rate before) and
    ``f+- = (theta'+-, theta''_flight)``: the contact force vanishes on the surface, so both
    sides share the free pendulum's acceleration. ``xi`` = 0 gives the plastic closure that
    ends a complete chattering (a singular S). Whatever the geometry,
    ``det S = -xi (h_t + h_x f+)/(h_t + h_x f-) = xi^2``.

    Returns ``(s11, s21, s22)``; ``s12`` is 0.
    """
    w = c[C_OMEGA]
    thc = cam_angle(t, c)
    cc, sc = math.cos(thc), math.sin(thc)
    ct, st = math.cos(th), math.sin(th)
    ew = c[C_E] * w
    dx = c[C_XO] - c[C_E] * cc
    dy = c[C_YO] - c[C_E] * sc
    l1_th = dx * st - dy * ct
    cdn_th = ew * (sc * ct - cc * st)
    l1_t = ew * (cc * st - sc * ct)
    cdn_t = w * l1_t
    q_th = (cdn_th * l1 - cdn * l1_th) / (l1 * l1)
    q_t = (cdn_t * l1 - cdn * l1_t) / (l1 * l1)
    a_free = -c[C_GRAV] * c[C_INV_J] * ct
    rate = l1 * om_before - cdn
    g_th = (1.0 + xi) * q_th
    w1 = om_after - om_before
    w2 = a_free - (g_th * om_before - xi * a_free) - (1.0 + xi) * q_t
    return 1.0 + w1 * l1 / rate, g_th + w2 * l1 / rate, -xi


@njit(cache=True)
def rk4_tangent_along(t, h, th0, om0, thm, omm, th1, om1, K, c, v11, v21, v12, v22, side):
    """One RK4 step of the tangent matrix alone along a known state: its start (th0, om0), its
    midpoint (thm, omm) and its end (th1, om1), e.g. from an adaptive step and its
    interpolant. Returns ``(v11, v21, v12, v22, div)``.

    The adaptive path integrates the state with DOP853 (:mod:`._adaptive`); its tangent is
    this classical RK4 of ``V' = A(t) V`` over a substep, with A at its start, midpoint
    (twice) and end. Accurate to O((h |A|)^5) per substep: the adaptive path cuts each step
    into substeps with ``h |A| <= TANGENT_STEP_RATE`` (:func:`._adaptive.advance_tangent`).
    """
    _, p1, q1 = acceleration_jacobian(t, th0, om0, K, c, side)
    _, p2, q2 = acceleration_jacobian(t + 0.5 * h, thm, omm, K, c, side)
    _, p4, q4 = acceleration_jacobian(t + h, th1, om1, K, c, side)
    n11, n21 = _column(v11, v21, h, p1, q1, p2, q2, p2, q2, p4, q4)
    n12, n22 = _column(v12, v22, h, p1, q1, p2, q2, p2, q2, p4, q4)
    return n11, n21, n12, n22, h / 6.0 * (q1 + 4.0 * q2 + q4)


def section_jacobians(rows: np.ndarray) -> np.ndarray:
    """The (n, 2, 2) Jacobians stored beside section points in kernel section rows.

    Columns ``j11, j21, j12, j22`` (``_layout.SECTION_TANGENT_NAMES``) follow the section's
    own columns: column-major, so ``J = [[j11, j12], [j21, j22]]``.
    """
    start = len(SECTION_NAMES)
    return rows[:, start : start + 4].reshape(-1, 2, 2).transpose(0, 2, 1).copy()
