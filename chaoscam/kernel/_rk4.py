"""Fixed-step RK4 with located impacts: the reference integrator (paper sec. 3).

On the grid ``t_n = n dt`` a step is cut into *segments*, each one RK4 substep, at the scheduled
times inside it (sections ``k T``, line-length draws ``j dt_l``) and at located impacts, so
section points are RK4 states and the grid never shifts. Impacts (paper (4)–(5), MODEL.md): a
sign change of the gap ``delta`` over a segment is located on ``tau -> delta(RK4 substep of
length tau)`` to ``event_tol`` (:func:`._events.locate_crossing`), the state taken where
``delta <= 0``, the impact law applied (:func:`._steps.impact`); a micro-flight or graze
shorter than a step is found where the gap rate turns (:func:`._events.graze_point`). The gap
is resolved to ~1e-16 m at any time (:func:`._physics.cam_angle`, :func:`._physics.on_clock`).

The tangent (:mod:`._tangent`, with ``c[C_TANGENT]``) never changes the state. Compiled without
numba's reference counting (``_nrt=False``): its atomic increments cost 8 % of a regime map's
samples (``tests/kernel/test_no_refcount.py`` checks).
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from . import layout as k
from ._events import ON_SURFACE, gap_after, graze_point, locate_crossing
from ._physics import (
    JAC_CONTACT,
    JAC_FLIGHT,
    JAC_NATURAL,
    cam_trig,
    closing_bound,
    geometry,
    geometry_at,
    geometry_trig,
    rk4_flight,
    rk4_trig,
    safe_horizon,
    stiffness,
)
from ._steps import (
    at_scheduled,
    commit_tangent,
    impact,
    next_scheduled,
    sample,
    surface_mode,
    tangent_on,
)
from ._tangent import rk4_flight_tangent, rk4_tangent_trig


@njit(cache=True, inline="always")
def step_rk4(t, th, om, h, K, c, y, commit, first, rest, trig):
    """One RK4 substep of the state and (tangent on; sides ``first``, ``rest``) the tangent from
    ``trig`` = (cc, sc, ct, st): ``(th, om, v11, v21, v12, v22, div)``, stored with ``commit``,
    and the cam angle's (cos, sin) at ``t + h``."""
    cc, sc, ct, st = trig
    if tangent_on(t, c):
        v11, v21, v12, v22 = y[k.Y_J11], y[k.Y_J21], y[k.Y_J12], y[k.Y_J22]
        r = rk4_tangent_trig(t, th, om, h, K, c, v11, v21, v12, v22, first, rest, cc, sc, ct, st)
        if commit:
            commit_tangent(y, r[2], r[3], r[4], r[5], r[6])
        return (r[0], r[1], r[2], r[3], r[4], r[5], r[6]), (r[7], r[8])
    r = rk4_trig(t, th, om, h, K, c, cc, sc, ct, st)
    return (r[0], r[1], 0.0, 0.0, 0.0, 0.0, 0.0), (r[2], r[3])


@njit(cache=True, inline="always")
def step_flight(t, th, om, h, c, y, commit):
    """:func:`step_rk4` for the free pendulum (:func:`rk4_flight`); divergence 0."""
    if tangent_on(t, c):
        r = rk4_flight_tangent(th, om, h, c, y[k.Y_J11], y[k.Y_J21], y[k.Y_J12], y[k.Y_J22])
        if commit:
            commit_tangent(y, r[2], r[3], r[4], r[5], 0.0)
        return r[0], r[1], r[2], r[3], r[4], r[5], 0.0
    th1, om1 = rk4_flight(th, om, h, c)
    return th1, om1, 0.0, 0.0, 0.0, 0.0, 0.0


@njit(cache=True, _nrt=False)
def leave(y, cnt, th, om, t, safe_n, code):
    """Store the state and the flight horizon before returning ``code`` to the driver."""
    y[k.Y_THETA] = th
    y[k.Y_OMEGA] = om
    y[k.Y_TIME] = t
    cnt[k.I_SAFE_STEP] = safe_n
    return code


@njit(cache=True, _nrt=False)
def run_chunk(y, cnt, c, n_stop, lam, series, section, impacts):
    """Advance one trajectory from step ``cnt[I_STEP]`` towards grid step ``n_stop``; returns a
    status code, ``NEED_BUFFER`` asking the driver to empty buffers or add draws.

    ``y`` (``Y_*``) and ``cnt`` (``I_*``) are updated in place; ``c``: the constants (``C_*``);
    ``lam``: line-length draws, ``lam[cnt[I_LAM_POS]]`` in use; ``series``, ``section``,
    ``impacts``: buffers filled from ``cnt``'s row counts (``impacts`` of no rows: counted)."""
    h = c[k.C_DT]
    stride = np.int64(c[k.C_STRIDE])
    merge = np.int64(c[k.C_FLIGHT_MERGE])
    samples_per_block = merge // stride + 1 if stride > 0 else 0
    max_events = np.int64(c[k.C_MAX_EVENTS])
    resample_on_impact = c[k.C_RESAMPLE_DT] <= 0.0
    th = y[k.Y_THETA]
    om = y[k.Y_OMEGA]
    K = stiffness(lam[cnt[k.I_LAM_POS]], c)
    sections_per_step = np.int64(h / c[k.C_PERIOD]) + 2
    draws_per_step = max_events + 1
    if not resample_on_impact:
        draws_per_step += np.int64(h / c[k.C_RESAMPLE_DT]) + 2

    g, l1, cdn, cc0, sc0, ct0, st0 = geometry_at(cnt[k.I_STEP] * h, th, c)
    # Until grid step safe_n the gap certainly stays open. It and the surface flags are kept in
    # the counters, so a resumed run is bit-identical; whoever changes y must reset it to 0.
    safe_n = cnt[k.I_SAFE_STEP]
    stale = False  # g, l1, cdn, trig belong to an earlier point (only while the gap is safe)
    surf = cnt[k.I_SURFACE]  # the surface flags (_steps.surface_mode)
    budget = np.int64(c[k.C_CALL_STEPS])  # steps before a hand-back (Ctrl-C is seen between)
    taken = np.int64(0)
    while cnt[k.I_STEP] < n_stop:
        taken += 1
        if (
            (budget > 0 and taken > budget)
            or cnt[k.I_N_SERIES] + samples_per_block > series.shape[0]
            or cnt[k.I_N_SECTION] + sections_per_step > section.shape[0]
            or 0 < impacts.shape[0] < cnt[k.I_N_IMPACT] + max_events  # (no rows: counted only)
            or cnt[k.I_LAM_POS] + draws_per_step >= lam.shape[0]
        ):
            cnt[k.I_SURFACE] = surf
            return leave(y, cnt, th, om, cnt[k.I_STEP] * h, safe_n, k.NEED_BUFFER)

        n = cnt[k.I_STEP]
        t = n * h
        # Proven flight: one free-pendulum RK4 step over grid steps, before anything scheduled.
        m = min(safe_n - n, merge, n_stop - n)
        if m >= 2:
            m = min(m, np.int64((cnt[k.I_SECTION_K] * c[k.C_PERIOD] - t) / h))
            if not resample_on_impact:
                m = min(m, np.int64((cnt[k.I_RESAMPLE_J] * c[k.C_RESAMPLE_DT] - t) / h))
            # (a block may straddle the recording's start: the motion ignores the transient)
        if m >= 2:
            th0 = th
            om0 = om
            th, om, _, _, _, _, _ = step_flight(t, th0, om0, (n + m) * h - t, c, y, True)
            stale = True
            cnt[k.I_STEP] = n + m
            if not (math.isfinite(th) and math.isfinite(om)):
                return leave(y, cnt, th, om, cnt[k.I_STEP] * h, safe_n, k.NON_FINITE)
            if (n + m) * h >= c[k.C_T_RECORD]:
                first = n + 1  # the block's first grid step ending in the recording
                while first * h < c[k.C_T_RECORD]:
                    first += 1
                cnt[k.I_COUNTED_STEPS] += n + m + 1 - first
                # samples inside the block: substeps off its start (the trajectory unchanged)
                j = n + stride - n % stride if stride > 0 else n + m + 1
                while j <= n + m:
                    if j >= first:
                        if j == n + m:
                            th_j, om_j = th, om
                        else:
                            th_j, om_j = rk4_flight(th0, om0, (j - n) * h, c)
                        sample(series, cnt, j * h, th_j, om_j, lam)
                    j += stride
            continue
        t_end = (n + 1) * h
        events = 0
        while t < t_end:
            seg_end, is_section, is_resample = next_scheduled(t_end, cnt, c)
            hs = seg_end - t
            if hs > 0.0 and seg_end <= safe_n * h:
                th, om, _, _, _, _, _ = step_flight(t, th, om, hs, c, y, True)  # pure flight
                t = seg_end
                stale = True
            elif hs > 0.0:
                if stale:
                    g, l1, cdn, cc0, sc0, ct0, st0 = geometry_at(t, th, c)
                    stale = False
                trig0 = (cc0, sc0, ct0, st0)
                rate0 = l1 * om - cdn
                # the start's side, on the surface the motion's; the first stage's Jacobian too
                up, on_surface = surface_mode(g, rate0, surf)
                gs = (ON_SURFACE if up else -ON_SURFACE) if on_surface else g
                trial_side = JAC_NATURAL
                if on_surface:
                    trial_side = JAC_FLIGHT if up else JAC_CONTACT
                trial_full = not (g > 0.0 and g > closing_bound(l1, cdn, om, hs, c))
                if trial_full:
                    trial, cam1 = step_rk4(
                        t, th, om, hs, K, c, y, False, trial_side, trial_side, trig0
                    )
                    if t + hs != seg_end:  # (the cam at t + hs, seg_end - t rounded)
                        cam1 = cam_trig(seg_end, c)
                else:
                    trial = step_flight(t, th, om, hs, c, y, False)  # no contact possible
                    cam1 = cam_trig(seg_end, c)
                th_new, om_new = trial[0], trial[1]
                ct1, st1 = math.cos(th_new), math.sin(th_new)
                g_new, l1, cdn = geometry_trig(cam1[0], cam1[1], ct1, st1, c)
                rate1 = l1 * om_new - cdn
                closing = gs > 0.0 and g_new <= 0.0
                crossing = closing or (gs < 0.0 and g_new > 0.0)
                tau_lo = 0.0  # the crossing lies in (tau_lo, tau_hi], the gap g_lo, g_hi there
                g_lo = gs
                tau_hi = hs
                g_hi = g_new
                if on_surface and crossing:
                    if not closing:
                        crossing = False  # lift-off from the surface: at the segment's start
                    elif rate0 > 0.0 > rate1:
                        # a micro-flight from the surface: the bracket starts at its top
                        tau_lo = graze_point(t, th, om, hs, rate0, rate1, K, c, trig0)
                        g_lo, _, _, _ = gap_after(t, th, om, tau_lo, K, c, trig0)
                        crossing = g_lo > 0.0
                        closing = crossing
                elif not crossing and events < max_events and trial_full:
                    # The gap rate turns: a micro-flight of ~2 xi v / |delta''| (0.1 us at v =
                    # 1e-6 m/s) may lie inside; unlocated, its jump and saltation would be lost.
                    if (rate0 < 0.0 < rate1) if gs > 0.0 else (rate1 < 0.0 < rate0):
                        tau_hi = graze_point(t, th, om, hs, rate0, rate1, K, c, trig0)
                        g_hi, _, _, _ = gap_after(t, th, om, tau_hi, K, c, trig0)
                        closing = gs > 0.0 and g_hi <= 0.0
                        crossing = closing or (gs < 0.0 and g_hi > 0.0)
                        if crossing:
                            cnt[k.I_GRAZES] += 1
                if crossing and events >= max_events:
                    cnt[k.I_CHATTER] += 1  # chattering: the rest of the step is left as it is
                elif crossing:
                    # To the crossing: a closing by the free pendulum where it crosses too (no
                    # Hertz force from a last stage overshooting by v event_tol); a micro-flight
                    # from the surface by the full equations (overshoot < 1e-15 m).
                    free = False
                    if closing and not on_surface:
                        th_f, _ = rk4_flight(th, om, tau_hi, c)
                        g_f, _, _ = geometry(t + tau_hi, th_f, c)
                        free = g_f <= 0.0
                        if free:
                            g_hi = g_f
                    tau = locate_crossing(t, th, om, tau_lo, g_lo, tau_hi, g_hi, K, c, free, trig0)
                    if free:
                        th, om, _, _, _, _, _ = step_flight(t, th, om, tau, c, y, True)
                    else:
                        # every stage's Jacobian on the side the substep comes from
                        side = JAC_FLIGHT if closing else JAC_CONTACT
                        r, _ = step_rk4(t, th, om, tau, K, c, y, True, side, side, trig0)
                        th, om = r[0], r[1]
                    surf = 0
                    t = t + tau
                    events += 1
                    g, l1, cdn, cc0, sc0, ct0, st0 = geometry_at(t, th, c)
                    if closing:
                        if not (0.0 < l1 < c[k.C_ROD_L]):
                            return leave(y, cnt, th, om, t, safe_n, k.LEFT_REACH)
                        om, K, surf = impact(t, th, om, l1, cdn, K, lam, cnt, impacts, y, c)
                    continue
                if tangent_on(t, c):
                    commit_tangent(y, trial[2], trial[3], trial[4], trial[5], trial[6])
                surf = 0
                th = th_new
                om = om_new
                t = seg_end
                g = g_new
                cc0, sc0, ct0, st0 = cam1[0], cam1[1], ct1, st1
                if g > 0.0:
                    safe_n = np.int64(math.floor((t + safe_horizon(g, l1, cdn, om, c)) / h))
            K = at_scheduled(t, th, om, is_section, is_resample, K, lam, cnt, section, y, c)

        # End of the grid step: g and l1 belong to (t_end, th).
        cnt[k.I_STEP] = n + 1
        if not (math.isfinite(th) and math.isfinite(om)):
            return leave(y, cnt, th, om, cnt[k.I_STEP] * h, safe_n, k.NON_FINITE)
        if g <= 0.0:
            if not (0.0 < l1 < c[k.C_ROD_L]):
                return leave(y, cnt, th, om, cnt[k.I_STEP] * h, safe_n, k.LEFT_REACH)
            if -g > c[k.C_RCAM]:
                return leave(y, cnt, th, om, cnt[k.I_STEP] * h, safe_n, k.PENETRATION)
        if t_end >= c[k.C_T_RECORD]:
            cnt[k.I_COUNTED_STEPS] += 1
            if g <= 0.0:
                cnt[k.I_CONTACT_STEPS] += 1
            if stride > 0 and (n + 1) % stride == 0:
                sample(series, cnt, t_end, th, om, lam)
    cnt[k.I_SURFACE] = surf  # the flags too, for a run continued from here (chaoscam.extend)
    return leave(y, cnt, th, om, cnt[k.I_STEP] * h, safe_n, k.OK)
