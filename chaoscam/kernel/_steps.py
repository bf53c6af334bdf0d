"""What both integrators (:mod:`._rk4`, :mod:`._adaptive`) do the same, inlined into them: the
output schedule (sections ``k T``, line-length draws ``j dt_l``), the impact law at a located
closing, the tangent's bookkeeping."""

from __future__ import annotations

import numpy as np
from numba import njit

from ._physics import stiffness
from ._tangent import saltation
from .layout import (
    C_PERIOD,
    C_RESAMPLE_DT,
    C_RESAMPLE_EVERY,
    C_T_RECORD,
    C_TANGENT,
    C_V_CHATTER,
    C_V_MICRO,
    C_VMIN,
    C_XI,
    I_LAM_POS,
    I_N_IMPACT,
    I_N_SECTION,
    I_RESAMPLE_J,
    I_SECTION_K,
    I_SLOW_CLOSINGS,
    IMPACT_CHATTER_END,
    IMPACT_MACRO,
    IMPACT_MICRO,
    SECTION_NAMES,
    SECTION_TANGENT_NAMES,
    Y_DIV,
    Y_J11,
    Y_J12,
    Y_J21,
    Y_J22,
)

__all__ = [
    "at_scheduled", "commit_tangent", "impact", "next_scheduled", "reset_tangent", "tangent_on",
]  # fmt: skip

TANGENT_LEAD = 2.0
"""Periods [T] before the recording from which the tangent is integrated (:func:`tangent_on`):
the first Jacobian read spans the period before the first recorded section, and a second period
keeps that section's predecessor inside the span whatever the rounding of ``t_record - T``."""


@njit(cache=True, inline="always")
def tangent_on(t, c):
    """Whether the tangent is carried over a segment (or impact) starting at ``t``: with
    ``c[C_TANGENT]`` set, from ``TANGENT_LEAD`` periods before the recording. Jacobians are
    written at recorded sections only, each over the period since the last restart (no segment
    crosses a section time), so skipping the transient changes no recorded bit (a whole run's
    tangent costs 0.15 plain runs on the RK4 path, 3 on the adaptive one). The state never
    depends on the tangent."""
    return c[C_TANGENT] > 0.0 and t >= c[C_T_RECORD] - TANGENT_LEAD * c[C_PERIOD]


@njit(cache=True, inline="always")
def next_scheduled(t_limit, cnt, c):
    """The first scheduled time up to ``t_limit``, (time, is_section, is_resample): sections
    ``k T`` and, with interval resampling, draws ``j dt_l``, where a step must end exactly."""
    t_next = t_limit
    is_section = False
    is_resample = False
    t_sec = cnt[I_SECTION_K] * c[C_PERIOD]
    if t_sec <= t_next:
        t_next = t_sec
        is_section = True
    if c[C_RESAMPLE_DT] > 0.0:
        t_res = cnt[I_RESAMPLE_J] * c[C_RESAMPLE_DT]
        if t_res < t_next:
            t_next = t_res
            is_section = False
            is_resample = True
        elif t_res == t_next:
            is_resample = True
    return t_next, is_section, is_resample


@njit(cache=True, inline="always")
def at_scheduled(t, th, om, is_section, is_resample, K, lam, cnt, section, y, c):
    """Record the section point and/or draw the next line length at a scheduled time t; at a
    section the tangent (the map's Jacobian over the period ending here) is written beside the
    point and restarted from the identity. Returns the stiffness in use afterwards."""
    if is_section:
        if t >= c[C_T_RECORD]:
            i = cnt[I_N_SECTION]
            section[i, 0] = cnt[I_SECTION_K]
            section[i, 1] = t
            section[i, 2] = th
            section[i, 3] = om
            section[i, 4] = lam[cnt[I_LAM_POS]]
            start = len(SECTION_NAMES)
            for j in range(len(SECTION_TANGENT_NAMES)):  # Y_J11 .. Y_DIV, in this order
                section[i, start + j] = y[Y_J11 + j] if c[C_TANGENT] > 0.0 else np.nan
            cnt[I_N_SECTION] += 1
        reset_tangent(y)
        cnt[I_SECTION_K] += 1
    if is_resample:
        cnt[I_LAM_POS] += 1
        cnt[I_RESAMPLE_J] += 1
        K = stiffness(lam[cnt[I_LAM_POS]], c)
    return K


@njit(cache=True, inline="always")
def reset_tangent(y):
    """The tangent matrix back to the identity and the divergence integral to 0."""
    y[Y_J11] = 1.0
    y[Y_J21] = 0.0
    y[Y_J12] = 0.0
    y[Y_J22] = 1.0
    y[Y_DIV] = 0.0


@njit(cache=True, inline="always")
def impact(t, th, om, l1, cdn, K, lam, cnt, impacts, y, c):
    """The impact law (4)–(5) at a located closing at (t, th) with lever arm l1 and dC/dt.n.

    With approach speed ``v = -(l1 theta' - dC/dt.n)`` > ``v_min`` (0 by default) the angular
    velocity jumps, ``theta'+ = -xi theta'- + (1 + xi) (dC/dt.n) / l1`` (gap rate times -xi).
    Slower than ``v_chatter`` the closing ends a complete chattering sequence (bounces whose
    speeds fall by ``xi`` each, Nordmark & Piiroinen 2009, Nonlinear Dyn. 58) and is replaced
    by its accumulation point, the plastic closure ``theta'+ = (dC/dt.n) / l1``. With the
    tangent on, a jump multiplies it by its saltation matrix (:func:`._tangent.saltation`).
    Each jump after the transient is a row of ``impacts`` with its kind (macro, micro below
    ``v_micro``, chatter end), or only counted for a buffer of no rows. A macro impact draws a
    new line length under ``resample="contact"``, every jump under ``"impact"``. Closings
    slower than ``v_min`` are counted and left to the compliant force. Returns (theta' after,
    stiffness in use).
    """
    rate = l1 * om - cdn
    if not (-rate > c[C_VMIN]):
        cnt[I_SLOW_CLOSINGS] += 1
        return om, K
    if -rate < c[C_V_CHATTER]:
        xi = 0.0
        kind = IMPACT_CHATTER_END
    else:
        xi = c[C_XI]
        kind = IMPACT_MICRO if -rate < c[C_V_MICRO] else IMPACT_MACRO
    om_after = -xi * om + (1.0 + xi) * cdn / l1
    if tangent_on(t, c):
        s11, s21, s22 = saltation(t, th, om, om_after, l1, cdn, xi, c)
        v11, v21, v12, v22 = y[Y_J11], y[Y_J21], y[Y_J12], y[Y_J22]
        y[Y_J11] = s11 * v11
        y[Y_J12] = s11 * v12
        y[Y_J21] = s21 * v11 + s22 * v21
        y[Y_J22] = s21 * v12 + s22 * v22
    if c[C_RESAMPLE_DT] <= 0.0 and (kind == IMPACT_MACRO or c[C_RESAMPLE_EVERY] > 0.0):
        cnt[I_LAM_POS] += 1
        K = stiffness(lam[cnt[I_LAM_POS]], c)
    if t >= c[C_T_RECORD]:
        i = cnt[I_N_IMPACT]
        if impacts.shape[0] > 0:  # a buffer of no rows: the impacts are only counted
            impacts[i, 0] = t
            impacts[i, 1] = th
            impacts[i, 2] = om
            impacts[i, 3] = om_after
            impacts[i, 4] = rate
            impacts[i, 5] = l1
            impacts[i, 6] = lam[cnt[I_LAM_POS]]
            impacts[i, 7] = kind
        cnt[I_N_IMPACT] += 1
    return om_after, K


@njit(cache=True, inline="always")
def commit_tangent(y, v11, v21, v12, v22, div):
    """Store an accepted step's tangent matrix and add its divergence integral."""
    y[Y_J11] = v11
    y[Y_J21] = v21
    y[Y_J12] = v12
    y[Y_J22] = v22
    y[Y_DIV] += div
