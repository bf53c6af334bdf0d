"""Compiled fixed-step RK4 with located impacts: the reference integrator (paper sec. 3).

One call of :func:`run_chunk` advances one trajectory on the grid ``t_n = n dt`` until the end
step or until an output buffer needs emptying; the Python driver then empties the buffers and
calls again. The kernel never raises: it returns a status code
(:class:`chaoscam.integrate.Status`).

Within one grid step the interval is cut into *segments* at the scheduled times that fall
inside it (stroboscopic section times ``k T``, line-length resampling times ``j dt_l``) and at
located impacts. Each segment is one RK4 substep, so the section points are exact RK4 states,
not interpolations, and the grid itself never shifts.

Impacts (paper (4)–(5), MODEL.md): when the gap ``delta`` is positive at a segment's start and
non-positive at its end, the crossing time is found by the Illinois variant of regula falsi on
``tau -> delta(RK4 substep of length tau)`` down to ``event_tol``; the state is taken at the
bracket end where ``delta <= 0``. There the restitution law applies (:func:`._steps.impact`): a jump
``theta'+ = -xi theta'- + (1 + xi) (dC/dt . n) / l_1``, or, when the approach is slower than
``v_chatter``, the plastic closure that ends a complete chattering sequence. Two crossings
within one segment (a micro-flight or a graze shorter than a step) are found where the gap
rate turns inside it (:func:`._events.graze_point`).

The gap is resolved to ~1e-16 m at any time (the last bounces of a chattering sequence rise
~3e-14 m): the cam angle is reduced exactly (:func:`._physics.cam_angle`) and every substep's
length is rounded so that its end is the double the kernel stamps it with
(:func:`._physics.on_clock`), so the state and the clock never part by a rounding of ``t``.

With ``c[C_TANGENT]`` set, the tangent matrix is integrated with the state (:mod:`._tangent`)
from shortly before the recording starts (:func:`._steps.tangent_on`) and carried through each
located event by the flow's saltation matrix (:func:`._steps.impact`); at each section time the
Jacobian of the stroboscopic map over the last period is written beside the section point
and the tangent restarts from the identity. The state is the same with and without it.

The model's equations live in :mod:`._physics`, the array layout in :mod:`.layout`, the
location of events inside a step in :mod:`._events`.

Compiled without numba's reference counting. Every function of the kernels' modules that
numba compiles on its own (not inlined into its caller) says ``_nrt=False`` (numba's option
for a function that needs no runtime; none allocates an array). With the runtime on, such a
function took a reference to its array arguments on entry and let it go on return, and
:func:`run_chunk` did the same around the code it inlines (``NRT_incref`` / ``NRT_decref``,
atomic operations): 8 % of a regime map's samples. Without it a run is the same bits and the
kernels' time shorter (``benchmarks/PROFILE.md``). ``tests/integrate/test_no_refcount.py``
keeps it so.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

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
    tangent_on,
)
from ._tangent import rk4_flight_tangent, rk4_tangent_trig
from .layout import (
    C_CALL_STEPS,
    C_DT,
    C_FLIGHT_MERGE,
    C_MAX_EVENTS,
    C_PERIOD,
    C_RCAM,
    C_RESAMPLE_DT,
    C_ROD_L,
    C_STRIDE,
    C_T_RECORD,
    C_V_CHATTER,
    I_CHATTER,
    I_CONTACT_STEPS,
    I_COUNTED_STEPS,
    I_GRAZES,
    I_LAM_POS,
    I_N_IMPACT,
    I_N_SECTION,
    I_N_SERIES,
    I_RESAMPLE_J,
    I_SAFE_STEP,
    I_SECTION_K,
    I_STEP,
    I_SURFACE,
    LEFT_REACH,
    NEED_BUFFER,
    NON_FINITE,
    OK,
    PENETRATION,
    Y_J11,
    Y_J12,
    Y_J21,
    Y_J22,
    Y_OMEGA,
    Y_THETA,
    Y_TIME,
)


@njit(cache=True, inline="always")
def step_rk4(t, th, om, h, K, c, y, commit, first, rest, trig):
    """One RK4 substep of the state; with the tangent on (:func:`._steps.tangent_on`: not in
    the transient), of the tangent too, the Jacobian at its first stage taken on side
    ``first`` of the contact surface, at the others on side ``rest``
    (:data:`._physics.JAC_NATURAL` and others; :func:`._tangent.rk4_tangent_trig`).
    ``trig`` is the trigonometry at the substep's start, ``(cc, sc, ct, st)`` from
    :func:`._physics.geometry_at`.

    Returns ``(th, om, v11, v21, v12, v22, div)``, the last five being the tangent after the
    step (written into ``y`` when ``commit``; the state is always returned, never stored),
    and the cam angle's ``(cos, sin)`` at ``t + h``.
    """
    cc, sc, ct, st = trig
    if tangent_on(t, c):
        v11, v21, v12, v22 = y[Y_J11], y[Y_J21], y[Y_J12], y[Y_J22]
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
        r = rk4_flight_tangent(th, om, h, c, y[Y_J11], y[Y_J21], y[Y_J12], y[Y_J22])
        if commit:
            commit_tangent(y, r[2], r[3], r[4], r[5], 0.0)
        return r[0], r[1], r[2], r[3], r[4], r[5], 0.0
    th1, om1 = rk4_flight(th, om, h, c)
    return th1, om1, 0.0, 0.0, 0.0, 0.0, 0.0


@njit(cache=True, _nrt=False)
def leave(y, cnt, th, om, t, safe_n, code):
    """Store the state and the flight horizon before returning ``code`` to the driver."""
    y[Y_THETA] = th
    y[Y_OMEGA] = om
    y[Y_TIME] = t
    cnt[I_SAFE_STEP] = safe_n
    return code


@njit(cache=True, _nrt=False)
def run_chunk(y, cnt, c, n_stop, lam, series, section, impacts):
    """Advance one trajectory from step ``cnt[I_STEP]`` towards ``n_stop``.

    Parameters
    ----------
    y : float64[Y_SIZE]
        (theta_f [rad], theta_f' [rad/s], t [s], ..., tangent) at ``t = cnt[I_STEP] * dt``;
        updated in place (slots ``Y_*``).
    cnt : int64[N_COUNTERS]
        Counters (indices ``I_*``); updated in place.
    c : float64[N_CONSTANTS]
        Constants (indices ``C_*``).
    n_stop : int
        Grid step at which the run ends.
    lam : float64[:]
        Line-length draws; ``lam[cnt[I_LAM_POS]]`` is the one in use.
    series, section, impacts : float64[:, SERIES_COLS], [:, SECTION_COLS], [:, IMPACT_COLS]
        Output buffers, filled from the row counts in ``cnt``. ``impacts`` of no rows: the
        impacts are counted in ``cnt[I_N_IMPACT]``, not recorded, and never ask for room.

    Returns
    -------
    int
        A status code; ``NEED_BUFFER`` asks the driver to empty buffers or add draws.
    """
    h = c[C_DT]
    stride = np.int64(c[C_STRIDE])
    merge = np.int64(c[C_FLIGHT_MERGE])
    samples_per_block = merge // stride + 1 if stride > 0 else 0
    max_events = np.int64(c[C_MAX_EVENTS])
    resample_on_impact = c[C_RESAMPLE_DT] <= 0.0
    th = y[Y_THETA]
    om = y[Y_OMEGA]
    K = stiffness(lam[cnt[I_LAM_POS]], c)
    sections_per_step = np.int64(h / c[C_PERIOD]) + 2
    draws_per_step = max_events + 1
    if not resample_on_impact:
        draws_per_step += np.int64(h / c[C_RESAMPLE_DT]) + 2

    # gap, lever arm, dC/dt.n here, and the trigonometry they came from (a step from here
    # takes its first stage from it: :func:`._physics.rk4_trig`)
    g, l1, cdn, cc0, sc0, ct0, st0 = geometry_at(cnt[I_STEP] * h, th, c)
    # Until grid step safe_n the gap certainly stays open (no geometry needed). Kept in the
    # counters, so that a run resumed after a buffer hand-back is bit-identical to one that
    # was not interrupted. Whoever changes the state y from outside must reset it to 0.
    safe_n = cnt[I_SAFE_STEP]
    stale = False  # g, l1, cdn, trig belong to an earlier point (only while the gap is safe)
    # The surface flags, kept in the counters across a buffer hand-back (an event may end a
    # grid step exactly) so that a resumed run is bit-identical to one not interrupted.
    jumped = (cnt[I_SURFACE] & 1) != 0  # a rebound was just applied: the opening is flight's
    settled = (cnt[I_SURFACE] & 2) != 0  # a plastic closure: the point stays in contact
    budget = np.int64(c[C_CALL_STEPS])  # steps before a hand-back (Ctrl-C is seen between)
    taken = np.int64(0)
    while cnt[I_STEP] < n_stop:
        # Room for one more step's worth of outputs and draws, else hand back to Python.
        taken += 1
        if (
            (budget > 0 and taken > budget)
            or cnt[I_N_SERIES] + samples_per_block > series.shape[0]
            or cnt[I_N_SECTION] + sections_per_step > section.shape[0]
            or 0 < impacts.shape[0] < cnt[I_N_IMPACT] + max_events  # (no rows: counted only)
            or cnt[I_LAM_POS] + draws_per_step >= lam.shape[0]
        ):
            cnt[I_SURFACE] = (1 if jumped else 0) + (2 if settled else 0)
            return leave(y, cnt, th, om, cnt[I_STEP] * h, safe_n, NEED_BUFFER)

        n = cnt[I_STEP]
        t = n * h
        # Proven flight over several grid steps: one RK4 step of the free pendulum across
        # them, ending on the grid and before any scheduled time or series sample.
        m = min(safe_n - n, merge, n_stop - n)
        if m >= 2:
            m = min(m, np.int64((cnt[I_SECTION_K] * c[C_PERIOD] - t) / h))
            if not resample_on_impact:
                m = min(m, np.int64((cnt[I_RESAMPLE_J] * c[C_RESAMPLE_DT] - t) / h))
            # A block may straddle the start of the recording: the motion does not depend on
            # the transient (only what is kept does), so a run is the same bits whatever it.
        if m >= 2:
            th0 = th
            om0 = om
            # the block's length as the difference of its stamped ends (see on_clock)
            th, om, _, _, _, _, _ = step_flight(t, th0, om0, (n + m) * h - t, c, y, True)
            stale = True
            cnt[I_STEP] = n + m
            if not (math.isfinite(th) and math.isfinite(om)):
                return leave(y, cnt, th, om, cnt[I_STEP] * h, safe_n, NON_FINITE)
            if (n + m) * h >= c[C_T_RECORD]:
                first = n + 1  # the block's first grid step ending in the recording
                while first * h < c[C_T_RECORD]:
                    first += 1
                cnt[I_COUNTED_STEPS] += n + m + 1 - first
                # Series samples inside the block come from a substep off its start, so that
                # sampling never changes the trajectory.
                j = n + stride - n % stride if stride > 0 else n + m + 1
                while j <= n + m:
                    if j >= first:
                        if j == n + m:
                            th_j, om_j = th, om
                        else:
                            th_j, om_j = rk4_flight(th0, om0, (j - n) * h, c)
                        i = cnt[I_N_SERIES]
                        series[i, 0] = j * h
                        series[i, 1] = th_j
                        series[i, 2] = om_j
                        series[i, 3] = lam[cnt[I_LAM_POS]]
                        cnt[I_N_SERIES] += 1
                    j += stride
            continue
        t_end = (n + 1) * h
        events = 0
        while t < t_end:
            # The segment ends at the step's end or at the next scheduled time inside it.
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
                # The side the segment starts on. A located crossing leaves the point on the
                # surface to rounding (slow closings give delta = 0.0 exactly: 1e-6 m/s over
                # the 1e-12 s event tolerance is 1e-18 m, below delta's ~1e-16 m resolution).
                # There the side is the motion's: contact just after a plastic closure (its
                # gap rate is 0 to rounding, and taking the rounding's sign starts a
                # ping-pong of zero-length events that only the chattering guard ends), else
                # flight when moving out (after a rebound, or a located opening).
                on_surface = g == 0.0 or (jumped and g <= 0.0)
                gs = g
                if on_surface:
                    gs = ON_SURFACE if not settled and (jumped or rate0 > 0.0) else -ON_SURFACE
                # On the surface the first stage sits at delta ~ 0 on the wrong side of the
                # Jacobian's jump (~K l_1^2 / J): take it on the side the segment starts on.
                trial_side = JAC_NATURAL
                if on_surface:
                    trial_side = JAC_FLIGHT if gs > 0.0 else JAC_CONTACT
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
                        # A micro-flight from the surface: the gap is rounding noise near the
                        # start, so the bracket starts at the flight's top.
                        tau_lo = graze_point(t, th, om, hs, rate0, rate1, K, c, trig0)
                        g_lo, _, _, _ = gap_after(t, th, om, tau_lo, K, c, trig0)
                        crossing = g_lo > 0.0
                        closing = crossing
                elif not crossing and events < max_events and trial_full:
                    # No sign change between the ends, but the gap rate turns (closing to
                    # opening in flight, the reverse in contact): the gap may have crossed
                    # zero and come back inside the segment. Micro-flights of a chattering
                    # sequence last ~2 xi v / |delta''| (0.1 us at v = 1e-6 m/s), far below
                    # dt; unlocated, the step integrates through one without its jump and the
                    # tangent misses a saltation matrix of size ~|delta''| / v.
                    if (rate0 < 0.0 < rate1) if gs > 0.0 else (rate1 < 0.0 < rate0):
                        tau_hi = graze_point(t, th, om, hs, rate0, rate1, K, c, trig0)
                        g_hi, _, _, _ = gap_after(t, th, om, tau_hi, K, c, trig0)
                        closing = gs > 0.0 and g_hi <= 0.0
                        crossing = closing or (gs < 0.0 and g_hi > 0.0)
                        if crossing:
                            cnt[I_GRAZES] += 1
                if crossing and events >= max_events:
                    cnt[I_CHATTER] += 1  # chattering: the rest of the step is left as it is
                elif crossing:
                    # The gap changes sign inside the segment: go to the crossing, so that no
                    # RK4 step straddles the kink of the force at delta = 0, then resume.
                    # A closing ends a free flight: its substep is the free pendulum's (no
                    # Hertz force from a last stage that overshoots into the cam by up to
                    # v event_tol), provided the free pendulum crosses in the bracket too (a
                    # step far too coarse for the contact may close where free flight does
                    # not). A micro-flight from the surface keeps the full equations: its
                    # bracket starts at a top found on them, and its overshoot is < 1e-15 m.
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
                        # The flow's tangent takes every stage on the side the substep comes
                        # from (flight before a closing and just after a jump, else contact).
                        side = JAC_FLIGHT if closing or jumped else JAC_CONTACT
                        r, _ = step_rk4(t, th, om, tau, K, c, y, True, side, side, trig0)
                        th, om = r[0], r[1]
                    jumped = False
                    settled = False
                    t = t + tau
                    events += 1
                    g, l1, cdn, cc0, sc0, ct0, st0 = geometry_at(t, th, c)
                    om_before = om
                    plastic = cdn - l1 * om < c[C_V_CHATTER]  # a chattering end, if applied
                    if closing:
                        if not (0.0 < l1 < c[C_ROD_L]):
                            return leave(y, cnt, th, om, t, safe_n, LEFT_REACH)
                        om, K = impact(t, th, om, l1, cdn, K, lam, cnt, impacts, y, c)
                        # after a rebound the point still lies on the surface, moving out
                        jumped = om != om_before and not plastic and l1 * om - cdn > 0.0
                        settled = om != om_before and plastic
                    continue
                if tangent_on(t, c):
                    commit_tangent(y, trial[2], trial[3], trial[4], trial[5], trial[6])
                jumped = False
                settled = False
                th = th_new
                om = om_new
                t = seg_end
                g = g_new
                cc0, sc0, ct0, st0 = cam1[0], cam1[1], ct1, st1
                if g > 0.0:
                    safe_n = np.int64(math.floor((t + safe_horizon(g, l1, cdn, om, c)) / h))
            K = at_scheduled(t, th, om, is_section, is_resample, K, lam, cnt, section, y, c)

        # End of the grid step: checks and outputs. Here g and l1 belong to (t_end, th).
        cnt[I_STEP] = n + 1
        if not (math.isfinite(th) and math.isfinite(om)):
            return leave(y, cnt, th, om, cnt[I_STEP] * h, safe_n, NON_FINITE)
        if g <= 0.0:
            if not (0.0 < l1 < c[C_ROD_L]):
                return leave(y, cnt, th, om, cnt[I_STEP] * h, safe_n, LEFT_REACH)
            if -g > c[C_RCAM]:
                return leave(y, cnt, th, om, cnt[I_STEP] * h, safe_n, PENETRATION)
        if t_end >= c[C_T_RECORD]:
            cnt[I_COUNTED_STEPS] += 1
            if g <= 0.0:
                cnt[I_CONTACT_STEPS] += 1
            if stride > 0 and (n + 1) % stride == 0:
                i = cnt[I_N_SERIES]
                series[i, 0] = t_end
                series[i, 1] = th
                series[i, 2] = om
                series[i, 3] = lam[cnt[I_LAM_POS]]
                cnt[I_N_SERIES] += 1
    # The flags too, for a run continued later from here (``_ensemble.extend_ensemble``).
    cnt[I_SURFACE] = (1 if jumped else 0) + (2 if settled else 0)
    return leave(y, cnt, th, om, cnt[I_STEP] * h, safe_n, OK)
