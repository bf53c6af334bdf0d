"""Tangent (variational) dynamics of the cam-follower through its impacts.

``V' = A(t) V``, ``A = [[0, 1], [d theta''/d theta, d theta''/d theta']]``, by the *same* RK4
stages as the state (bit-identical to :func:`._physics.rk4`'s); through a located impact V is
multiplied by the saltation matrix (:func:`saltation`; Müller 1995, Chaos Solitons Fractals
5(9); Leine & Nijmeijer 2004, *Dynamics and Bifurcations of Non-smooth Mechanical Systems*, sec.
3.5), onset and separation need none (a continuous field). The quadrature integrates ``tr A``
too, for Liouville's ``ln |det V| = int tr A dt + sum ln |det S|``.

Limits: the flow's tangent, not the derivative of the RK4 grid map. Where chattering ends in
sticking a stage after a located event dips ~1e-12 m into the cam: the tangent then overstates
the growth by up to tens of percent a chatter cycle at dt = 2e-6 s, shrinking as dt^2.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from ._physics import acceleration_jacobian, cam_angle, flight_stages, rk4_stages
from .layout import C_E, C_GRAV, C_INV_J, C_OMEGA, C_XO, C_YO, SECTION_NAMES


@njit(cache=True, inline="always")
def _column(x, y, h, p1, q1, p2, q2, p3, q3, p4, q4):
    """One column (x, y) of V through the RK4 stages of ``x' = y, y' = p_i x + q_i y``."""
    x2, y2 = x + 0.5 * h * y, y + 0.5 * h * (p1 * x + q1 * y)
    x3, y3 = x + 0.5 * h * y2, y + 0.5 * h * (p2 * x2 + q2 * y2)
    x4, y4 = x + h * y3, y + h * (p3 * x3 + q3 * y3)
    return (
        x + h / 6.0 * (y + 2.0 * y2 + 2.0 * y3 + y4),
        y + h / 6.0 * (p1 * x + q1 * y + 2.0 * (p2 * x2 + q2 * y2) + 2.0 * (p3 * x3 + q3 * y3)
                       + p4 * x4 + q4 * y4),
    )  # fmt: skip


@njit(cache=True, _nrt=False)
def rk4_tangent_trig(t, th, om, h, K, c, v11, v21, v12, v22, first, rest, cc, sc, ct, st):
    """One RK4 step of the state and its tangent V (columns (v11, v21), (v12, v22)), Jacobian
    sides ``first``, ``rest`` (:func:`._physics.rk4_stages`): ``(th, om, v11, v21, v12, v22,
    div, cc4, sc4)``, ``div`` the step's quadrature of the divergence."""
    th1, om1, c4, s4, pq = rk4_stages(t, th, om, h, K, c, cc, sc, ct, st, True, first, rest)
    p1, q1, p2, q2, p3, q3, p4, q4 = pq
    n11, n21 = _column(v11, v21, h, p1, q1, p2, q2, p3, q3, p4, q4)
    n12, n22 = _column(v12, v22, h, p1, q1, p2, q2, p3, q3, p4, q4)
    div = h / 6.0 * (q1 + 2.0 * q2 + 2.0 * q3 + q4)
    return th1, om1, n11, n21, n12, n22, div, c4, s4


@njit(cache=True, _nrt=False)
def rk4_flight_tangent(th, om, h, c, v11, v21, v12, v22):
    """:func:`._physics.rk4_flight` with its tangent matrix, ``A = [[0, 1], [(m g l / 2J) sin
    theta, 0]]`` (no divergence): returns ``(th, om, v11, v21, v12, v22)``."""
    th1, om1, (p1, p2, p3, p4) = flight_stages(th, om, h, c)
    n11, n21 = _column(v11, v21, h, p1, 0.0, p2, 0.0, p3, 0.0, p4, 0.0)
    n12, n22 = _column(v12, v22, h, p1, 0.0, p2, 0.0, p3, 0.0, p4, 0.0)
    return th1, om1, n11, n21, n12, n22


@njit(cache=True, _nrt=False)
def saltation(t, th, om_before, om_after, l1, cdn, xi, c):
    """The saltation matrix S of a restitution jump at a located closing (t, th).

    For the surface ``h(t, x) = delta(t, theta) = 0`` and the jump ``g(t, x) = (theta, -xi
    theta' + (1 + xi) q)``, ``q = (dC/dt.n) / l_1`` (Müller 1995, eq. 16):

    ``S = g_x + (f+ - g_x f- - g_t) h_x^T / (h_t + h_x f-)``,

    ``h_x = (l_1, 0)``, ``h_t + h_x f- = l_1 theta'- - dC/dt.n`` (the gap rate before),
    ``f+- = (theta'+-, theta''_flight)`` (the force vanishes on the surface). ``det S = -xi (h_t
    + h_x f+)/(h_t + h_x f-) = xi^2``; ``xi`` = 0 (the plastic closure ending a chattering)
    gives a singular S. Returns ``(s11, s21, s22)``; ``s12`` is 0."""
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
    q_th = (cdn_th * l1 - cdn * l1_th) / (l1 * l1)  # q's derivatives in theta and t
    q_t = (cdn_t * l1 - cdn * l1_t) / (l1 * l1)
    a_free = -c[C_GRAV] * c[C_INV_J] * math.cos(th)
    rate = l1 * om_before - cdn
    g_th = (1.0 + xi) * q_th
    w1 = om_after - om_before
    w2 = a_free - (g_th * om_before - xi * a_free) - (1.0 + xi) * q_t
    return 1.0 + w1 * l1 / rate, g_th + w2 * l1 / rate, -xi


@njit(cache=True, _nrt=False)
def rk4_tangent_along(t, h, th0, om0, thm, omm, th1, om1, K, c, v11, v21, v12, v22, side):
    """One RK4 step of ``V' = A(t) V`` alone along a known state, A at its start (th0, om0),
    midpoint (thm, omm, twice) and end (th1, om1): the adaptive path's tangent, O((h |A|)^5) a
    substep with ``h |A| <= TANGENT_STEP_RATE`` (:func:`._adaptive.advance_tangent`). Returns
    ``(v11, v21, v12, v22, div)``."""
    _, p1, q1 = acceleration_jacobian(t, th0, om0, K, c, side)
    _, p2, q2 = acceleration_jacobian(t + 0.5 * h, thm, omm, K, c, side)
    _, p4, q4 = acceleration_jacobian(t + h, th1, om1, K, c, side)
    n11, n21 = _column(v11, v21, h, p1, q1, p2, q2, p2, q2, p4, q4)
    n12, n22 = _column(v12, v22, h, p1, q1, p2, q2, p2, q2, p4, q4)
    return n11, n21, n12, n22, h / 6.0 * (q1 + 4.0 * q2 + q4)


def section_jacobians(rows: np.ndarray) -> np.ndarray:
    """The (n, 2, 2) Jacobians stored beside section points in kernel section rows: columns
    ``j11, j21, j12, j22`` (``layout.SECTION_TANGENT_NAMES``) after the section's own,
    column-major, so ``J = [[j11, j12], [j21, j22]]``."""
    start = len(SECTION_NAMES)
    return rows[:, start : start + 4].reshape(-1, 2, 2).transpose(0, 2, 1).copy()
