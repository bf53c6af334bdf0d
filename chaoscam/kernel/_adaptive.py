"""Adaptive, event-driven Dormand–Prince 8(5,3) with located impacts: the fast path.

The model and call of :func:`._rk4.run_chunk`, time cut differently:

- **Steps**: DOP853 (Hairer, Nørsett & Wanner, *Solving Ordinary Differential Equations I*, 2nd
  ed., sec. II.10; :mod:`._dop853`), eighth order for the barely damped contact oscillation
  (period ~1e-4 s) to ~1e-11 relative. **In flight** the free pendulum ``J theta'' = -(m g l/2)
  cos theta`` (its interpolant exact up to the crossing; steps beyond
  :func:`._physics.safe_horizon` cut to ``dt``); **in contact** (1)–(3).
- **Events**: a gap sign change located by Illinois regula falsi on the step's Hermite
  interpolant to ``event_tol``, the state there a DOP853 step of that length, the impact law
  (4)–(5) as in the reference; a turn of the gap rate (graze, micro-flight) searched first, two
  turns in one step not looked for.
- **Tangent**: RK4 substeps of ``V' = A V`` along each accepted step (:func:`advance_tangent`),
  split at events (saltation). Series samples come from the interpolant: no change of the run.

Chattering guard: at most ``max_events_per_step`` events in one grid interval, later sign
changes there stepped over (``I_CHATTER``). The contact fraction is integrated in time.

Accuracy (``benchmarks/bench_work_precision.py``): 20 s sections of periodic responses are within
1e-6 rad of converged RK4 from rtol 1e-8 (omega = 45 rad/s) or 1e-5 (xi = 0.2). Limit: with v_min
= 0 the impact times cannot be compared to 1e-6 s (each chattering sequence ends on a
discontinuous count of bounces, and differences of 1e-12 s grow 3-6x per impact); with v_min =
1e-3 m/s they agree within 1e-6 s and rad at rtol 3e-14.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from . import _physics as ph
from . import _steps as steps
from . import layout as k
from ._dop853 import ERROR_ORDER, dop853_step, omega_at, theta_at
from ._events import MAX_BRACKET_STEPS, ON_SURFACE, illinois_point, illinois_update
from ._physics import JAC_CONTACT, JAC_FLIGHT, JAC_NATURAL
from ._stages import accel_trig, geometry_near, trig_at
from ._tangent import rk4_tangent_along

# Step-size control (Hairer et al. sec. II.4, their dop853 code): accept when the error norm
# err <= 1; h_new = h * SAFETY * err^(-1/8) within [SHRINK_MIN, GROW_MAX] h and h_max.
SAFETY = 0.9
GROW_MAX = 6.0
SHRINK_MIN = 1.0 / 3.0
EXPONENT = -1.0 / (ERROR_ORDER + 1)
H_FLOOR = 1e-15  # a step this short [s] means the error control cannot be met: NON_FINITE
ERR_FLOOR = 1e-300  # the error estimate's floor in the step-size factor (0 would give inf)
TURN_TOL = 1e-9  # width, as a fraction of the step, to which the gap rate's turn is found
MAX_TURN_STEPS = 100  # passes of that search at most
MAX_EVENT_GROWTH = 60  # doublings of an event step's overshoot (2^60 event tolerances) at most


@njit(cache=True, _nrt=False, error_model="numpy")
def locate_on_interpolant(h, th, tr, co, s_lo, g_lo, s_hi, g_hi, c):
    """The fraction s in (s_lo, s_hi] of the step where the gap (g_lo, g_hi at the ends) changes
    sign on the interpolant ``co``: Illinois regula falsi on ``s -> delta(t + s h, theta(s))``,
    bisecting when a pass fails to halve the bracket, to ``event_tol / h``; ``tr``: ``trig_at``'s
    base. Returns the bracket's end past the crossing."""
    sgn = 1.0 if g_lo > 0.0 else -1.0  # work on sgn * delta, positive at the start
    a, fa, b, fb = s_lo, sgn * g_lo, s_hi, sgn * g_hi
    tol = c[k.C_EVENT_TOL] / h
    side = 0
    for _ in range(MAX_BRACKET_STEPS):
        width = b - a
        if width <= tol:
            break
        m = illinois_point(a, fa, b, fb)
        fm, _, _ = geometry_near(m * h, theta_at(co, m), th, tr, c)
        a, fa, b, fb, side = illinois_update(a, fa, b, fb, m, fm * sgn, side)
        if b - a > 0.5 * width:
            m = 0.5 * (a + b)
            fm, _, _ = geometry_near(m * h, theta_at(co, m), th, tr, c)
            a, fa, b, fb, _ = illinois_update(a, fa, b, fb, m, fm * sgn, 0)
    return b


@njit(cache=True, _nrt=False, error_model="numpy")
def turning_point(h, th, tr, co, rate0, rate1, c):
    """The fraction s of the step where the gap rate l_1 theta' - dC/dt.n changes sign:
    Illinois regula falsi on the interpolant to ``TURN_TOL`` (enough to show on which side of
    zero the gap's extremum lies)."""
    sgn = -1.0 if rate1 > 0.0 else 1.0  # work on sgn * rate: positive at 0, negative at 1
    a, fa, b, fb = 0.0, sgn * rate0, 1.0, sgn * rate1
    side = 0
    for _ in range(MAX_TURN_STEPS):
        if b - a <= TURN_TOL:
            break
        m = illinois_point(a, fa, b, fb)
        _, l1, cdn = geometry_near(m * h, theta_at(co, m), th, tr, c)
        fm = sgn * (l1 * omega_at(co, m) - cdn)
        a, fa, b, fb, side = illinois_update(a, fa, b, fb, m, fm, side)
    return 0.5 * (a + b)


@njit(cache=True, _nrt=False, error_model="numpy")
def advance_tangent(y, c, t, h, th, om, co, s_end, th1, om1, K, side_first, side):
    """Carry the tangent (when on) over the accepted step from (th, om) to (th1, om1), inner
    points from the interpolant ``co``: RK4 substeps of V' = A V with ``h_sub |A| <=
    TANGENT_STEP_RATE`` at start, middle and end (one per DOP853 step would bias the default
    model's lambda_1 to about -22 1/s), the first's Jacobian on ``side_first``, others ``side``."""
    if not steps.tangent_on(t, c):  # off, or in the transient
        return
    _, p0, q0 = ph.acceleration_jacobian(t, th, om, K, c, side_first)
    _, p1, q1 = ph.acceleration_jacobian(
        t + 0.5 * h, theta_at(co, 0.5 * s_end), omega_at(co, 0.5 * s_end), K, c, side
    )
    _, p2, q2 = ph.acceleration_jacobian(t + h, th1, om1, K, c, side)
    rate = max(math.sqrt(max(abs(p0), abs(p1), abs(p2))), max(abs(q0), abs(q1), abs(q2)))
    m = max(1, np.int64(math.ceil(h * rate / k.TANGENT_STEP_RATE)))
    hm = h / m
    thb, omb = th, om
    for i in range(m):
        if i + 1 == m:
            the, ome = th1, om1
        else:
            se = s_end * (i + 1) / m
            the, ome = theta_at(co, se), omega_at(co, se)
        sm = s_end * (i + 0.5) / m
        r = rk4_tangent_along(
            t + i * hm, hm, thb, omb, theta_at(co, sm), omega_at(co, sm), the, ome, K, c,
            y[k.Y_J11], y[k.Y_J21], y[k.Y_J12], y[k.Y_J22], side_first if i == 0 else side,
        )  # fmt: skip
        steps.commit_tangent(y, r[0], r[1], r[2], r[3], r[4])
        thb, omb = the, ome


@njit(cache=True, _nrt=False, error_model="numpy")
def leave(y, cnt, th, om, t, h, events, window, surface, code, c):
    """Store all the loop carries and return ``code``: a resumed run is bit-identical."""
    y[k.Y_THETA] = th
    y[k.Y_OMEGA] = om
    y[k.Y_TIME] = t
    y[k.Y_STEP] = h
    cnt[k.I_STEP] = np.int64(math.floor(t / c[k.C_DT] + 1e-9))
    y[k.Y_EVENTS] = events
    y[k.Y_WINDOW] = window
    cnt[k.I_SURFACE] = surface
    return code


@njit(cache=True, _nrt=False, error_model="numpy")
def run_chunk_adaptive(y, cnt, c, n_stop, lam, series, section, impacts):
    """Advance one trajectory from ``y[Y_TIME]`` to ``n_stop * dt`` with adaptive steps; as
    :func:`._rk4.run_chunk`, ``cnt[I_STEP]`` the last grid step passed, ``y[Y_STEP]`` the next h."""
    dt = c[k.C_DT]
    t_stop = n_stop * dt
    stride = np.int64(c[k.C_STRIDE])
    samples_per_step = np.int64(c[k.C_H_MAX] / (stride * dt)) + 2 if stride > 0 else 0
    max_events = np.int64(c[k.C_MAX_EVENTS])
    t_rec = c[k.C_T_RECORD]

    t = y[k.Y_TIME]
    th = y[k.Y_THETA]
    om = y[k.Y_OMEGA]
    h = y[k.Y_STEP] if y[k.Y_STEP] > 0.0 else min(dt, c[k.C_H_MAX])
    K = ph.stiffness(lam[cnt[k.I_LAM_POS]], c)
    tr = trig_at(t, th, c)  # trigonometric base of the next step; renewed when (t, th) move
    g, l1, cdn = ph.geometry_trig(tr[1], tr[2], tr[3], tr[4], c)
    surf = cnt[k.I_SURFACE]
    flight, on_surface = steps.surface_mode(g, l1 * om - cdn, surf)
    a1 = accel_trig(tr, om, K, c, flight)
    window = np.int64(y[k.Y_WINDOW])  # grid interval of the chattering guard ...
    events = np.int64(y[k.Y_EVENTS])  # ... and the events in it so far

    redo = False  # the step is being taken again in contact mode (see below)
    budget = np.int64(c[k.C_CALL_STEPS])  # steps before a hand-back (Ctrl-C is seen between)
    taken = np.int64(0)
    while t < t_stop:
        taken += 1
        if not redo and (
            (budget > 0 and taken > budget)
            or cnt[k.I_N_SERIES] + samples_per_step > series.shape[0]
            or cnt[k.I_N_SECTION] + 2 > section.shape[0]
            or 0 < impacts.shape[0] < cnt[k.I_N_IMPACT] + 2  # (no rows: counted only)
            or cnt[k.I_LAM_POS] + 3 >= lam.shape[0]
        ):
            return leave(y, cnt, th, om, t, h, events, window, surf, k.NEED_BUFFER, c)

        # The step ends at the next scheduled time at the latest.
        t_next, is_section, is_resample = steps.next_scheduled(t_stop, cnt, c)
        hs = min(h, c[k.C_H_MAX])
        if flight and hs > dt:
            safe = ph.safe_horizon(max(g, 0.0), l1, cdn, om, c)
            if hs > safe:
                hs = max(dt, safe)
        clipped = t + hs >= t_next
        if clipped:
            hs = t_next - t
        else:
            hs = ph.on_clock(t, hs)  # the step ends exactly at the time t1 it is stamped with

        th1, om1, err = dop853_step(th, om, a1, hs, tr, K, c, flight)
        fac = SAFETY * max(err, ERR_FLOOR) ** EXPONENT
        if not (err <= 1.0):
            if not math.isfinite(err) or hs < H_FLOOR:
                return leave(y, cnt, th, om, t, h, events, window, surf, k.NON_FINITE, c)
            h = hs * max(SHRINK_MIN, fac)
            continue
        h_next = hs * min(GROW_MAX, max(SHRINK_MIN, fac))
        if clipped:
            h_next = max(h_next, h)  # a step cut short by the schedule says nothing about h

        # The step's end, with directly computed trigonometry: what the next step starts from.
        t1 = t_next if clipped else t + hs
        tr1 = trig_at(t1, th1, c)
        g1, l1_1, cdn1 = ph.geometry_trig(tr1[1], tr1[2], tr1[3], tr1[4], c)
        a_end = accel_trig(tr1, om1, K, c, flight)  # in the step's mode: the interpolant's
        co = (th, om, a1, th1, om1, a_end, hs)  # data: ends, their rates and accelerations
        s_end = 1.0
        n_window = np.int64(math.floor((t + hs) / dt))
        if n_window != window:
            window = n_window
            events = 0
        rate0 = l1 * om - cdn
        rate1 = l1_1 * om1 - cdn1
        # the gap at the start, signed by the side the step starts on (_steps.surface_mode)
        gs = (ON_SURFACE if flight else -ON_SURFACE) if on_surface else g
        closing = flight and g1 <= 0.0
        crossing = closing or (not flight and g1 > 0.0)
        s_lo, g_lo, s_hi, g_hi = 0.0, gs, 1.0, g1  # the crossing lies in (s_lo, s_hi]
        if on_surface and crossing:
            if not closing:
                crossing = False  # lift-off from the surface: at the step's start
            elif rate0 > 0.0 > rate1:
                # a micro-flight from the surface: the bracket starts at its top
                s_lo = turning_point(hs, th, tr, co, rate0, rate1, c)
                g_lo, _, _ = geometry_near(s_lo * hs, theta_at(co, s_lo), th, tr, c)
                crossing = g_lo > 0.0
                closing = crossing
        elif not crossing and events < max_events:
            # no sign change, but the gap rate turns: a graze or micro-flight may lie inside
            if (rate0 < 0.0 < rate1) if flight else (rate1 < 0.0 < rate0):
                s_hi = turning_point(hs, th, tr, co, rate0, rate1, c)
                g_hi, _, _ = geometry_near(s_hi * hs, theta_at(co, s_hi), th, tr, c)
                closing = flight and g_hi <= 0.0
                crossing = closing or (not flight and g_hi > 0.0)
                if crossing:
                    cnt[k.I_GRAZES] += 1
        if crossing and events >= max_events:
            cnt[k.I_CHATTER] += 1
            crossing = False
        if flight and not crossing and g1 <= 0.0:
            # In the cam without a located closing (a weak rebound, the guard spent): redo it in
            # contact mode, with no hand-back between.
            flight = False
            redo = True
            a1 = accel_trig(tr, om, K, c, flight)
            continue
        redo = False
        if crossing:
            s_end = locate_on_interpolant(hs, th, tr, co, s_lo, g_lo, s_hi, g_hi, c)

        t_end = t + s_end * hs if crossing else t1
        if stride > 0:
            j = cnt[k.I_SERIES_J]
            while (j * stride) * dt <= t_end:
                tj = (j * stride) * dt
                if tj >= t_rec:
                    s = (tj - t) / hs
                    steps.sample(series, cnt, tj, theta_at(co, s), omega_at(co, s), lam)
                j += 1
            cnt[k.I_SERIES_J] = j
        # the contact fraction's time (the step's mode holds to t_end)
        if t_end > t_rec:
            span = t_end - max(t, t_rec)
            y[k.Y_RECORDED] += span
            if not flight:
                y[k.Y_CONTACT] += span

        # the tangent's sides: a step from the surface takes its first Jacobian on its side
        side = JAC_FLIGHT if flight else JAC_NATURAL
        side_first = side
        if on_surface:
            side_first = JAC_FLIGHT if flight else JAC_CONTACT

        if crossing:
            # The state at the event: the located step, grown 2, 4, 8, ... tolerances until past.
            reach = c[k.C_EVENT_TOL] / hs
            for _ in range(MAX_EVENT_GROWTH):
                h_event = ph.on_clock(t, s_end * hs)
                r2 = dop853_step(th, om, a1, h_event, tr, K, c, flight)
                tr2 = trig_at(t + h_event, r2[0], c)
                g2, _, _ = ph.geometry_trig(tr2[1], tr2[2], tr2[3], tr2[4], c)
                if (g2 <= 0.0) if closing else (g2 >= 0.0):
                    break
                reach *= 2.0
                s_end = min(1.0, s_end + reach)
            # the substep ends on the surface: its Jacobian is taken on its own side
            side = JAC_FLIGHT if closing else JAC_CONTACT
            if not on_surface:
                side_first = side
            advance_tangent(y, c, t, h_event, th, om, co, s_end, r2[0], r2[1], K, side_first, side)
            th = r2[0]
            om = r2[1]
            t = t + h_event
            events += 1
            tr = tr2
            g, l1, cdn = ph.geometry_trig(tr[1], tr[2], tr[3], tr[4], c)
            surf = 0
            if closing:
                if not (0.0 < l1 < c[k.C_ROD_L]):
                    return leave(y, cnt, th, om, t, h_next, events, window, surf, k.LEFT_REACH, c)
                om, K, surf = steps.impact(t, th, om, l1, cdn, K, lam, cnt, impacts, y, c)
            flight, on_surface = steps.surface_mode(g, l1 * om - cdn, surf)
            a1 = accel_trig(tr, om, K, c, flight)
            h = min(h_next, hs)  # the event cut the step: do not grow past it
            continue

        # Accepted whole; theta'' at its end (direct trigonometry) is reused if the mode holds.
        step_mode = flight
        advance_tangent(y, c, t, t_end - t, th, om, co, 1.0, th1, om1, K, side_first, side)
        th = th1
        om = om1
        t = t_end
        tr = tr1
        g, l1, cdn = g1, l1_1, cdn1
        surf = 0
        flight, on_surface = steps.surface_mode(g, l1 * om - cdn, surf)
        h = h_next
        a1 = a_end if flight == step_mode else accel_trig(tr, om, K, c, flight)
        if not (math.isfinite(th) and math.isfinite(om)):
            return leave(y, cnt, th, om, t, h, events, window, surf, k.NON_FINITE, c)
        if g <= 0.0:
            if not (0.0 < l1 < c[k.C_ROD_L]):
                return leave(y, cnt, th, om, t, h, events, window, surf, k.LEFT_REACH, c)
            if -g > c[k.C_RCAM]:
                return leave(y, cnt, th, om, t, h, events, window, surf, k.PENETRATION, c)
        if clipped:
            K = steps.at_scheduled(t, th, om, is_section, is_resample, K, lam, cnt, section, y, c)
            if is_resample:
                a1 = accel_trig(tr, om, K, c, flight)
    return leave(y, cnt, th, om, t, h, events, window, surf, k.OK, c)
