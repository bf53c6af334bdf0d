"""What both integrators (:mod:`._rk4`, :mod:`._adaptive`) do the same, inlined into them: the
output schedule (sections ``k T``, line-length draws ``j dt_l``), the side of a step from the
surface, the impact law at a located closing, the tangent's bookkeeping."""

from __future__ import annotations

import numpy as np
from numba import njit

from . import layout as k
from ._physics import stiffness
from ._tangent import saltation

TANGENT_LEAD = 2.0
"""Periods [T] before the recording from which the tangent is integrated (:func:`tangent_on`):
the first Jacobian read spans the period before the first recorded section, and a second period
keeps that section's predecessor inside the span whatever the rounding of ``t_record - T``."""


@njit(cache=True, inline="always")
def tangent_on(t, c):
    """Whether the tangent is carried over a segment (or impact) starting at ``t``: with
    ``c[C_TANGENT]``, from ``TANGENT_LEAD`` periods before the recording (Jacobians span one
    period, so skipping the transient changes no recorded bit)."""
    return c[k.C_TANGENT] > 0.0 and t >= c[k.C_T_RECORD] - TANGENT_LEAD * c[k.C_PERIOD]


@njit(cache=True, inline="always")
def surface_mode(g, rate, surf):
    """(flight, on_surface): the side of a step from gap ``g`` with gap rate ``rate``.

    On the surface (a located crossing) the side is the motion's: contact after a plastic
    closure (``SURFACE_SETTLED``), else flight when moving out (``SURFACE_JUMPED``, an opening);
    the rounding's sign would make a zero-length event after each rebound."""
    jumped = (surf & k.SURFACE_JUMPED) != 0
    settled = (surf & k.SURFACE_SETTLED) != 0
    if g == 0.0 or (jumped and g <= 0.0):
        return (not settled) and (jumped or rate > 0.0), True
    return g > 0.0, False


@njit(cache=True, inline="always")
def next_scheduled(t_limit, cnt, c):
    """The first scheduled time up to ``t_limit``, (time, is_section, is_resample): sections
    ``k T`` and, with interval resampling, draws ``j dt_l``, where a step must end exactly."""
    t_next = t_limit
    is_section = False
    is_resample = False
    t_sec = cnt[k.I_SECTION_K] * c[k.C_PERIOD]
    if t_sec <= t_next:
        t_next = t_sec
        is_section = True
    if c[k.C_RESAMPLE_DT] > 0.0:
        t_res = cnt[k.I_RESAMPLE_J] * c[k.C_RESAMPLE_DT]
        if t_res < t_next:
            t_next = t_res
            is_section = False
            is_resample = True
        elif t_res == t_next:
            is_resample = True
    return t_next, is_section, is_resample


@njit(cache=True, inline="always")
def at_scheduled(t, th, om, is_section, is_resample, K, lam, cnt, section, y, c):
    """Record the section point (the tangent beside it, then restarted) and/or draw the next line
    length at a scheduled time t; returns the stiffness in use afterwards."""
    if is_section:
        if t >= c[k.C_T_RECORD]:
            i = cnt[k.I_N_SECTION]
            section[i, 0] = cnt[k.I_SECTION_K]
            section[i, 1] = t
            section[i, 2] = th
            section[i, 3] = om
            section[i, 4] = lam[cnt[k.I_LAM_POS]]
            start = len(k.SECTION_NAMES)
            for j in range(len(k.SECTION_TANGENT_NAMES)):  # Y_J11 .. Y_DIV, in this order
                section[i, start + j] = y[k.Y_J11 + j] if c[k.C_TANGENT] > 0.0 else np.nan
            cnt[k.I_N_SECTION] += 1
        reset_tangent(y)
        cnt[k.I_SECTION_K] += 1
    if is_resample:
        cnt[k.I_LAM_POS] += 1
        cnt[k.I_RESAMPLE_J] += 1
        K = stiffness(lam[cnt[k.I_LAM_POS]], c)
    return K


@njit(cache=True, inline="always")
def sample(series, cnt, t, th, om, lam):
    """Append the series row (t, theta_f, theta_f', the line length in use)."""
    i = cnt[k.I_N_SERIES]
    series[i, 0] = t
    series[i, 1] = th
    series[i, 2] = om
    series[i, 3] = lam[cnt[k.I_LAM_POS]]
    cnt[k.I_N_SERIES] += 1


@njit(cache=True, inline="always")
def reset_tangent(y):
    """The tangent matrix back to the identity and the divergence integral to 0."""
    y[k.Y_J11] = 1.0
    y[k.Y_J21] = 0.0
    y[k.Y_J12] = 0.0
    y[k.Y_J22] = 1.0
    y[k.Y_DIV] = 0.0


@njit(cache=True, inline="always")
def impact(t, th, om, l1, cdn, K, lam, cnt, impacts, y, c):
    """The impact law (4)–(5) at a located closing at (t, th) with lever arm l1 and dC/dt.n.

    With approach speed ``v = -(l1 theta' - dC/dt.n)`` > ``v_min`` the angular velocity jumps,
    ``theta'+ = -xi theta'- + (1 + xi) (dC/dt.n) / l1``; below ``v_chatter`` the closing ends a
    complete chattering sequence (speeds falling by ``xi`` a bounce; Nordmark & Piiroinen 2009,
    Nonlinear Dyn. 58), replaced by its accumulation point ``theta'+ = (dC/dt.n) / l1``. A jump
    multiplies the tangent by its saltation matrix, is a row of ``impacts`` after the transient
    (macro, micro below ``v_micro``, chatter end) and draws a line length (macro under
    ``resample="contact"``, any under ``"impact"``); slower than ``v_min``: counted, left to
    the compliant force. Returns (theta' after, stiffness, the surface flags)."""
    rate = l1 * om - cdn
    if not (-rate > c[k.C_VMIN]):
        cnt[k.I_SLOW_CLOSINGS] += 1
        return om, K, 0
    if -rate < c[k.C_V_CHATTER]:
        xi = 0.0
        kind = k.IMPACT_CHATTER_END
    else:
        xi = c[k.C_XI]
        kind = k.IMPACT_MICRO if -rate < c[k.C_V_MICRO] else k.IMPACT_MACRO
    om_after = -xi * om + (1.0 + xi) * cdn / l1
    if tangent_on(t, c):
        s11, s21, s22 = saltation(t, th, om, om_after, l1, cdn, xi, c)
        v11, v21, v12, v22 = y[k.Y_J11], y[k.Y_J21], y[k.Y_J12], y[k.Y_J22]
        y[k.Y_J11] = s11 * v11
        y[k.Y_J12] = s11 * v12
        y[k.Y_J21] = s21 * v11 + s22 * v21
        y[k.Y_J22] = s21 * v12 + s22 * v22
    if c[k.C_RESAMPLE_DT] <= 0.0 and (kind == k.IMPACT_MACRO or c[k.C_RESAMPLE_EVERY] > 0.0):
        cnt[k.I_LAM_POS] += 1
        K = stiffness(lam[cnt[k.I_LAM_POS]], c)
    if t >= c[k.C_T_RECORD]:
        i = cnt[k.I_N_IMPACT]
        if impacts.shape[0] > 0:  # a buffer of no rows: the impacts are only counted
            impacts[i, 0] = t
            impacts[i, 1] = th
            impacts[i, 2] = om
            impacts[i, 3] = om_after
            impacts[i, 4] = rate
            impacts[i, 5] = l1
            impacts[i, 6] = lam[cnt[k.I_LAM_POS]]
            impacts[i, 7] = kind
        cnt[k.I_N_IMPACT] += 1
    surf = 0
    if om_after != om:
        if kind == k.IMPACT_CHATTER_END:
            surf = k.SURFACE_SETTLED
        elif l1 * om_after - cdn > 0.0:
            surf = k.SURFACE_JUMPED
    return om_after, K, surf


@njit(cache=True, inline="always")
def commit_tangent(y, v11, v21, v12, v22, div):
    """Store an accepted step's tangent matrix and add its divergence integral."""
    y[k.Y_J11] = v11
    y[k.Y_J21] = v21
    y[k.Y_J12] = v12
    y[k.Y_J22] = v22
    y[k.Y_DIV] += div
