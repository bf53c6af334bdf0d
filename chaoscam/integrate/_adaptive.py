"""Adaptive, event-driven Dormand–Prince 5(4) with located impacts: the fast path.

The same model and the same call signature as the fixed-step reference
(:func:`chaoscam.integrate._kernel.run_chunk`); :func:`chaoscam.integrate._advance.advance`
picks one by ``Params.integrator``. What differs is how time is cut:

- **Steps** are Dormand–Prince 5(4) steps (Hairer, Nørsett & Wanner, *Solving Ordinary
  Differential Equations I*, 2nd ed., sec. II.5 and II.6) with the usual error control:
  a step is accepted when the embedded error, scaled by ``atol + rtol |y|`` per component,
  has RMS norm <= 1; the next step comes from the PI controller of Hairer's ``dopri5``
  (limited to ``h_max``).
- **In flight** (gap > 0 at the step's start) the step integrates the free pendulum
  ``J theta'' = -(m g l/2) cos theta``, which *is* the motion until the gap closes, so its
  interpolant is exact up to the crossing even when the step ends past it. A step longer
  than the time over which the gap provably stays open (:func:`_kernel.safe_horizon`) is cut
  to ``dt``, the grid step, so that it cannot hold several crossings.
- **In contact** (gap <= 0) the step integrates (1)–(3) with the compliant force; the error
  control resolves the contact oscillation (period ~1e-4 s) only as finely as the tolerance
  asks, instead of ~45 fixed steps a period.
- **Grazes**: a step whose ends show no sign change but whose gap rate turns (from closing
  to opening in flight, the reverse in contact) is searched for the turning point on the
  interpolant; if the gap has changed sign there, the first crossing before it is an event.
  So a graze shorter than a step is seen (the fixed grid misses those shorter than ``dt``);
  two turns inside one step are not looked for.
- **Events**: when the gap changes sign over a step, the crossing is located by Illinois
  regula falsi on the gap along the step's dense output (the 4th-order continuous extension
  of Dormand–Prince, Hairer's ``contd5``) to ``event_tol``; the state there is a
  Dormand–Prince step of that length from the step's start (an integrator state, so the
  interpolant's error does not enter the trajectory), the impact law (4)–(5) is applied
  exactly as in the reference kernel (jump only if the approach speed exceeds ``v_min``),
  and the next step starts there.
- **Scheduled times** (sections ``k T``, line-length resampling ``j dt_l``, the run's end)
  end a step exactly, so section points are integrator states, not interpolations. Series
  samples come from the dense output, so asking for a series never changes the trajectory.

Chattering guard: at most ``max_events_per_step`` events inside one grid interval
``[n dt, (n + 1) dt)``; further sign changes there are stepped over (counted in
``I_CHATTER``). The contact fraction is integrated in time (``Y_RECORDED``, ``Y_CONTACT``).

Like the reference kernel this never raises; it returns a status code.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from . import _kernel as k
from ._kernel import (
    C_ATOL,
    C_DT,
    C_EVENT_TOL,
    C_GRAV,
    C_H_MAX,
    C_INV_J,
    C_MAX_EVENTS,
    C_OMEGA,
    C_PERIOD,
    C_RCAM,
    C_RESAMPLE_DT,
    C_ROD_L,
    C_RTOL,
    C_STRIDE,
    C_T_RECORD,
    C_THETA_C0,
    C_VMIN,
    C_XI,
    I_CHATTER,
    I_LAM_POS,
    I_N_IMPACT,
    I_N_SECTION,
    I_N_SERIES,
    I_RESAMPLE_J,
    I_SECTION_K,
    I_SERIES_J,
    I_SLOW_CLOSINGS,
    I_STEP,
    LEFT_REACH,
    NEED_BUFFER,
    NON_FINITE,
    OK,
    PENETRATION,
    Y_CONTACT,
    Y_ERR_OLD,
    Y_EVENTS,
    Y_OMEGA,
    Y_RECORDED,
    Y_STEP,
    Y_THETA,
    Y_TIME,
    Y_WINDOW,
)

# Dormand–Prince 5(4) tableau (Hairer et al., Table II.5.2), its error weights e = b - b*,
# and the dense-output weights d of the continuous extension (Hairer's contd5).
A21 = 1.0 / 5.0
A31, A32 = 3.0 / 40.0, 9.0 / 40.0
A41, A42, A43 = 44.0 / 45.0, -56.0 / 15.0, 32.0 / 9.0
A51, A52, A53, A54 = 19372.0 / 6561.0, -25360.0 / 2187.0, 64448.0 / 6561.0, -212.0 / 729.0
A61, A62, A63 = 9017.0 / 3168.0, -355.0 / 33.0, 46732.0 / 5247.0
A64, A65 = 49.0 / 176.0, -5103.0 / 18656.0
B1, B3, B4, B5, B6 = 35.0 / 384.0, 500.0 / 1113.0, 125.0 / 192.0, -2187.0 / 6784.0, 11.0 / 84.0
C2, C3, C4, C5 = 1.0 / 5.0, 3.0 / 10.0, 4.0 / 5.0, 8.0 / 9.0
E1, E3, E4 = 71.0 / 57600.0, -71.0 / 16695.0, 71.0 / 1920.0
E5, E6, E7 = -17253.0 / 339200.0, 22.0 / 525.0, -1.0 / 40.0
D1, D3 = -12715105075.0 / 11282082432.0, 87487479700.0 / 32700410799.0
D4, D5 = -10690763975.0 / 1880347072.0, 701980252875.0 / 199316789632.0
D6, D7 = -1453857185.0 / 822651844.0, 69997945.0 / 29380423.0

# Step-size control (Hairer et al. sec. IV.2, the PI controller of their dopri5 code):
# h_new = h * SAFETY / (err^(1/5 - 0.75 BETA) * err_old^-BETA), limited to [SHRINK_MIN,
# GROW_MAX] h; after a rejection h_new = h * max(SHRINK_MIN, SAFETY err^(-1/5 + 0.75 BETA)).
SAFETY = 0.9
BETA = 0.04
GROW_MAX = 10.0
SHRINK_MIN = 0.2
ROTATE_MAX = 0.01  # [rad] stages rotate trigonometric values by less than this (see rotate)
H_FLOOR = 1e-15  # a step this short [s] means the error control cannot be met: NON_FINITE


@njit(cache=True, error_model="numpy")
def accel_trig(tr, om, K, c, flight):
    """theta_f'' at the base ``tr`` (:func:`trig_at`): the free pendulum in flight, else
    the full (1)–(3)."""
    if flight:
        return -c[C_GRAV] * c[C_INV_J] * tr[3]
    return k.acceleration_trig(tr[1], tr[2], tr[3], tr[4], om, K, c)


@njit(cache=True, error_model="numpy")
def rotate(a, ca, sa, b):
    """(cos(a + b), sin(a + b)) from ca = cos a, sa = sin a.

    For |b| < ROTATE_MAX by the addition theorem with Taylor polynomials of cos b and sin b
    (truncation below b^8 / 8! < 1e-16), else directly: the stages of a step sit close to
    its start, so they need no new transcendental calls.
    """
    if abs(b) >= ROTATE_MAX:
        return math.cos(a + b), math.sin(a + b)
    b2 = b * b
    cb = 1.0 - b2 * (0.5 - b2 * (1.0 / 24.0 - b2 * (1.0 / 720.0)))
    sb = b * (1.0 - b2 * (1.0 / 6.0 - b2 * (1.0 / 120.0 - b2 * (1.0 / 5040.0))))
    return ca * cb - sa * sb, sa * cb + ca * sb


@njit(cache=True, error_model="numpy")
def trig_at(t, th, c):
    """(cam angle, its cos, its sin, cos th, sin th) at (t, th): a step's trigonometric base."""
    thc = c[C_OMEGA] * t + c[C_THETA_C0]
    return (thc, math.cos(thc), math.sin(thc), math.cos(th), math.sin(th))


@njit(cache=True, error_model="numpy")
def geometry_near(s_i, th_i, th, tr, c):
    """:func:`_kernel.geometry` at (t + s_i, th_i), rotated from the base ``tr`` at (t, th)."""
    ct, st = rotate(th, tr[3], tr[4], th_i - th)
    cc, sc = rotate(tr[0], tr[1], tr[2], c[C_OMEGA] * s_i)
    return k.geometry_trig(cc, sc, ct, st, c)


@njit(cache=True, error_model="numpy")
def accel_stage(th_i, om_i, s_i, th, tr, K, c, flight):
    """theta_f'' at the stage (t + s_i, th_i, om_i) of a step from (t, th).

    ``tr`` = (cam angle at t, its cos, its sin, cos th, sin th); the stage's trigonometric
    values are rotated from these (:func:`rotate`).
    """
    ct, st = rotate(th, tr[3], tr[4], th_i - th)
    if flight:
        return -c[C_GRAV] * c[C_INV_J] * ct
    cc, sc = rotate(tr[0], tr[1], tr[2], c[C_OMEGA] * s_i)
    return k.acceleration_trig(cc, sc, ct, st, om_i, K, c)


@njit(cache=True, error_model="numpy")
def dopri_step(th, om, a1, h, tr, K, c, flight):
    """One Dormand–Prince step of length h from (th, om), with a1 = theta''(t, th, om).

    ``tr`` = :func:`trig_at` (t, th). Returns the new state, theta'' there (first-same-as-
    last), the scaled RMS error norm, and the dense-output coefficients (r2, r3, r4, r5) for
    theta and for omega.
    """
    w1 = om
    th2 = th + h * A21 * w1
    w2 = om + h * A21 * a1
    a2 = accel_stage(th2, w2, C2 * h, th, tr, K, c, flight)
    th3 = th + h * (A31 * w1 + A32 * w2)
    w3 = om + h * (A31 * a1 + A32 * a2)
    a3 = accel_stage(th3, w3, C3 * h, th, tr, K, c, flight)
    th4 = th + h * (A41 * w1 + A42 * w2 + A43 * w3)
    w4 = om + h * (A41 * a1 + A42 * a2 + A43 * a3)
    a4 = accel_stage(th4, w4, C4 * h, th, tr, K, c, flight)
    th5 = th + h * (A51 * w1 + A52 * w2 + A53 * w3 + A54 * w4)
    w5 = om + h * (A51 * a1 + A52 * a2 + A53 * a3 + A54 * a4)
    a5 = accel_stage(th5, w5, C5 * h, th, tr, K, c, flight)
    th6 = th + h * (A61 * w1 + A62 * w2 + A63 * w3 + A64 * w4 + A65 * w5)
    w6 = om + h * (A61 * a1 + A62 * a2 + A63 * a3 + A64 * a4 + A65 * a5)
    a6 = accel_stage(th6, w6, h, th, tr, K, c, flight)
    th_new = th + h * (B1 * w1 + B3 * w3 + B4 * w4 + B5 * w5 + B6 * w6)
    om_new = om + h * (B1 * a1 + B3 * a3 + B4 * a4 + B5 * a5 + B6 * a6)
    w7 = om_new
    a7 = accel_stage(th_new, om_new, h, th, tr, K, c, flight)

    err_th = h * (E1 * w1 + E3 * w3 + E4 * w4 + E5 * w5 + E6 * w6 + E7 * w7)
    err_om = h * (E1 * a1 + E3 * a3 + E4 * a4 + E5 * a5 + E6 * a6 + E7 * a7)
    sc_th = c[C_ATOL] + c[C_RTOL] * max(abs(th), abs(th_new))
    sc_om = c[C_ATOL] + c[C_RTOL] * max(abs(om), abs(om_new))
    err = math.sqrt(0.5 * ((err_th / sc_th) ** 2 + (err_om / sc_om) ** 2))

    d_th = th_new - th
    b_th = h * w1 - d_th
    r4_th = d_th - h * w7 - b_th
    r5_th = h * (D1 * w1 + D3 * w3 + D4 * w4 + D5 * w5 + D6 * w6 + D7 * w7)
    d_om = om_new - om
    b_om = h * a1 - d_om
    r4_om = d_om - h * a7 - b_om
    r5_om = h * (D1 * a1 + D3 * a3 + D4 * a4 + D5 * a5 + D6 * a6 + D7 * a7)
    return (
        th_new, om_new, a7, err,
        d_th, b_th, r4_th, r5_th,
        d_om, b_om, r4_om, r5_om,
    )  # fmt: skip


@njit(cache=True, error_model="numpy")
def dense(th, d, b, r4, r5, s):
    """The continuous extension at the fraction s of the step (Hairer's contd5)."""
    return th + s * (d + (1.0 - s) * (b + s * (r4 + (1.0 - s) * r5)))


@njit(cache=True, error_model="numpy")
def locate_on_interpolant(h, th, tr, co, g_start, g_end, s_hi, c):
    """The fraction s in (0, s_hi] of the step at which the gap changes sign, on the interpolant.

    Illinois regula falsi (with bisection when a pass fails to halve the bracket) on
    ``s -> delta(t + s h, theta(s))`` until the bracket is narrower than ``event_tol / h``;
    ``tr`` is the step's trigonometric base (:func:`trig_at`).
    Returns the bracket's end past the crossing.
    """
    sgn = 1.0 if g_start > 0.0 else -1.0
    a, fa, b, fb = 0.0, sgn * g_start, s_hi, sgn * g_end
    tol = c[C_EVENT_TOL] / h
    side = 0
    for _ in range(400):
        width = b - a
        if width <= tol:
            break
        m = b - fb * width / (fb - fa)
        if not (a < m < b):
            m = 0.5 * (a + b)
        fm, _, _ = geometry_near(m * h, dense(th, co[0], co[1], co[2], co[3], m), th, tr, c)
        fm *= sgn
        if fm > 0.0:
            a, fa = m, fm
            if side == 1:
                fb *= 0.5
            side = 1
        else:
            b, fb = m, fm
            if side == -1:
                fa *= 0.5
            side = -1
        if b - a > 0.5 * width:
            m = 0.5 * (a + b)
            fm, _, _ = geometry_near(m * h, dense(th, co[0], co[1], co[2], co[3], m), th, tr, c)
            fm *= sgn
            if fm > 0.0:
                a, fa = m, fm
            else:
                b, fb = m, fm
    return b


@njit(cache=True, error_model="numpy")
def turning_point(h, th, om, tr, r, rate0, rate1, c):
    """The fraction s of the step where the gap rate l_1 theta' - dC/dt.n changes sign.

    Illinois regula falsi on the interpolant, to 1e-9 of the step (the turning point only
    needs to be good enough to show on which side of zero the gap's extremum lies).
    """
    sgn = 1.0 if rate1 > 0.0 else -1.0  # work on sgn * rate: negative at 0, positive at 1
    a, fa, b, fb = 0.0, sgn * rate0, 1.0, sgn * rate1
    side = 0
    for _ in range(100):
        if b - a <= 1e-9:
            break
        m = b - fb * (b - a) / (fb - fa)
        if not (a < m < b):
            m = 0.5 * (a + b)
        _, l1, cdn = geometry_near(m * h, dense(th, r[4], r[5], r[6], r[7], m), th, tr, c)
        fm = sgn * (l1 * dense(om, r[8], r[9], r[10], r[11], m) - cdn)
        if fm < 0.0:
            a, fa = m, fm
            if side == 1:
                fb *= 0.5
            side = 1
        else:
            b, fb = m, fm
            if side == -1:
                fa *= 0.5
            side = -1
    return 0.5 * (a + b)


@njit(cache=True, error_model="numpy")
def leave(y, cnt, th, om, t, h, events, window, code, c):
    """Store the state, the time, the next step size and the event count; return ``code``.

    Everything the loop carries from one step to the next is either stored here or
    recomputed from it the same way inside the loop, so a resumed run is bit-identical.
    """
    y[Y_THETA] = th
    y[Y_OMEGA] = om
    y[Y_TIME] = t
    y[Y_STEP] = h
    cnt[I_STEP] = np.int64(math.floor(t / c[C_DT] + 1e-9))
    y[Y_EVENTS] = events
    y[Y_WINDOW] = window
    return code


@njit(cache=True, error_model="numpy")
def run_chunk_adaptive(y, cnt, c, n_stop, lam, series, section, impacts):
    """Advance one trajectory from ``y[Y_TIME]`` to ``n_stop * dt`` with adaptive steps.

    Arguments, buffers and status codes as :func:`chaoscam.integrate._kernel.run_chunk`;
    ``cnt[I_STEP]`` is kept as the last grid step passed, and ``y[Y_STEP]`` carries the step
    size across calls, so a run resumed after a buffer hand-back is bit-identical to one that
    was not interrupted.
    """
    dt = c[C_DT]
    t_stop = n_stop * dt
    stride = np.int64(c[C_STRIDE])
    samples_per_step = np.int64(c[C_H_MAX] / (stride * dt)) + 2 if stride > 0 else 0
    max_events = np.int64(c[C_MAX_EVENTS])
    resample_on_impact = c[C_RESAMPLE_DT] <= 0.0
    t_rec = c[C_T_RECORD]

    t = y[Y_TIME]
    th = y[Y_THETA]
    om = y[Y_OMEGA]
    h = y[Y_STEP] if y[Y_STEP] > 0.0 else min(dt, c[C_H_MAX])
    K = k.stiffness(lam[cnt[I_LAM_POS]], c)
    tr = trig_at(t, th, c)  # trigonometric base of the next step; renewed when (t, th) move
    g, l1, cdn = k.geometry_trig(tr[1], tr[2], tr[3], tr[4], c)
    flight = g > 0.0
    a1 = accel_trig(tr, om, K, c, flight)
    window = np.int64(y[Y_WINDOW])  # grid interval of the chattering guard ...
    events = np.int64(y[Y_EVENTS])  # ... and the events in it so far

    while t < t_stop:
        if (
            cnt[I_N_SERIES] + samples_per_step > series.shape[0]
            or cnt[I_N_SECTION] + 2 > section.shape[0]
            or cnt[I_N_IMPACT] + 2 > impacts.shape[0]
            or cnt[I_LAM_POS] + 3 >= lam.shape[0]
        ):
            return leave(y, cnt, th, om, t, h, events, window, NEED_BUFFER, c)

        # The step ends at the next scheduled time at the latest.
        t_next = t_stop
        is_section = False
        is_resample = False
        t_sec = cnt[I_SECTION_K] * c[C_PERIOD]
        if t_sec <= t_next:
            t_next = t_sec
            is_section = True
        if not resample_on_impact:
            t_res = cnt[I_RESAMPLE_J] * c[C_RESAMPLE_DT]
            if t_res < t_next:
                t_next = t_res
                is_section = False
                is_resample = True
            elif t_res == t_next:
                is_resample = True
        hs = min(h, c[C_H_MAX])
        if flight and hs > dt and hs > k.safe_horizon(g, l1, cdn, om, c):
            # Near the cam a long step could hold several crossings, of which the search
            # might find a later one: steps there are cut to dt (see module doc).
            hs = max(dt, k.safe_horizon(g, l1, cdn, om, c))
        clipped = t + hs >= t_next
        if clipped:
            hs = t_next - t

        r = dopri_step(th, om, a1, hs, tr, K, c, flight)
        th1, om1, err = r[0], r[1], r[3]
        fac = max(err, 1e-300) ** (0.2 - 0.75 * BETA)
        if not (err <= 1.0):
            if not math.isfinite(err) or hs < H_FLOOR:
                return leave(y, cnt, th, om, t, h, events, window, NON_FINITE, c)
            h = hs * max(SHRINK_MIN, SAFETY / fac)
            continue
        fac = fac / max(y[Y_ERR_OLD], 1e-4) ** BETA
        h_next = hs * min(GROW_MAX, max(SHRINK_MIN, SAFETY / fac))
        y[Y_ERR_OLD] = max(err, 1e-4)
        if clipped:
            h_next = max(h_next, h)  # a step cut short by the schedule says nothing about h

        # The step's end, with directly computed trigonometry: what the next step starts from.
        t1 = t_next if clipped else t + hs
        tr1 = trig_at(t1, th1, c)
        g1, l1_1, cdn1 = k.geometry_trig(tr1[1], tr1[2], tr1[3], tr1[4], c)
        s_end = 1.0
        crossing = (g > 0.0 and g1 <= 0.0) or (g <= 0.0 and g1 > 0.0)
        n_window = np.int64(math.floor((t + hs) / dt))
        if n_window != window:
            window = n_window
            events = 0
        if crossing and events >= max_events:
            cnt[I_CHATTER] += 1
            crossing = False
        if crossing:
            s_end = locate_on_interpolant(hs, th, tr, r[4:8], g, g1, 1.0, c)
        elif events < max_events:
            # No sign change between the ends, but the gap rate turns (down to up in flight,
            # up to down in contact): the gap may cross zero and come back inside the step (a
            # graze, or a micro-flight). Find the turning point on the interpolant; if the
            # gap has changed sign there, the first crossing lies before it.
            rate0 = l1 * om - cdn
            rate1 = l1_1 * om1 - cdn1
            if (rate0 < 0.0 < rate1) if flight else (rate1 < 0.0 < rate0):
                s_turn = turning_point(hs, th, om, tr, r, rate0, rate1, c)
                g_turn, _, _ = geometry_near(
                    s_turn * hs, dense(th, r[4], r[5], r[6], r[7], s_turn), th, tr, c
                )
                if (g_turn <= 0.0) if flight else (g_turn > 0.0):
                    crossing = True
                    s_end = locate_on_interpolant(hs, th, tr, r[4:8], g, g_turn, s_turn, c)

        # Series samples in (t, t + s_end hs], from the interpolant.
        t_end = t + s_end * hs if crossing else t1
        if stride > 0:
            j = cnt[I_SERIES_J]
            while (j * stride) * dt <= t_end:
                tj = (j * stride) * dt
                if tj >= t_rec:
                    s = (tj - t) / hs
                    i = cnt[I_N_SERIES]
                    series[i, 0] = tj
                    series[i, 1] = dense(th, r[4], r[5], r[6], r[7], s)
                    series[i, 2] = dense(om, r[8], r[9], r[10], r[11], s)
                    series[i, 3] = lam[cnt[I_LAM_POS]]
                    cnt[I_N_SERIES] += 1
                j += 1
            cnt[I_SERIES_J] = j
        # Time bookkeeping for the contact fraction (the step's mode holds until t_end).
        if t_end > t_rec:
            span = t_end - max(t, t_rec)
            y[Y_RECORDED] += span
            if not flight:
                y[Y_CONTACT] += span

        if crossing:
            # An event inside the step: a step of the located length from the step's start
            # gives the state there (an integrator state, not an interpolation). Should that
            # state not yet be past the crossing (the interpolant is only 4th-order accurate),
            # the length grows by 2, 4, 8, ... event tolerances until it is.
            closing = flight
            reach = c[C_EVENT_TOL] / hs
            for _ in range(60):
                r2 = dopri_step(th, om, a1, s_end * hs, tr, K, c, flight)
                tr2 = trig_at(t + s_end * hs, r2[0], c)
                g2, _, _ = k.geometry_trig(tr2[1], tr2[2], tr2[3], tr2[4], c)
                if (g2 <= 0.0) if closing else (g2 >= 0.0):
                    break
                reach *= 2.0
                s_end = min(1.0, s_end + reach)
            th = r2[0]
            om = r2[1]
            t = t + s_end * hs
            events += 1
            tr = tr2
            g, l1, cdn = k.geometry_trig(tr[1], tr[2], tr[3], tr[4], c)
            if closing:
                if not (0.0 < l1 < c[C_ROD_L]):
                    return leave(y, cnt, th, om, t, h_next, events, window, LEFT_REACH, c)
                rate = l1 * om - cdn
                if -rate > c[C_VMIN]:
                    om_after = -c[C_XI] * om + (1.0 + c[C_XI]) * cdn / l1
                    if resample_on_impact:
                        cnt[I_LAM_POS] += 1
                        K = k.stiffness(lam[cnt[I_LAM_POS]], c)
                    if t >= t_rec:
                        i = cnt[I_N_IMPACT]
                        impacts[i, 0] = t
                        impacts[i, 1] = th
                        impacts[i, 2] = om
                        impacts[i, 3] = om_after
                        impacts[i, 4] = rate
                        impacts[i, 5] = l1
                        impacts[i, 6] = lam[cnt[I_LAM_POS]]
                        cnt[I_N_IMPACT] += 1
                    om = om_after
                else:
                    cnt[I_SLOW_CLOSINGS] += 1
            flight = g > 0.0
            a1 = accel_trig(tr, om, K, c, flight)
            h = min(h_next, hs)  # the event cut the step: do not grow past it
            continue

        # The whole step is accepted. theta'' is evaluated afresh at its end (not taken from
        # the step's last stage, which rotated its trigonometry), as a resumed run does.
        th = th1
        om = om1
        t = t_end
        tr = tr1
        g, l1, cdn = g1, l1_1, cdn1
        flight = g > 0.0
        h = h_next
        a1 = accel_trig(tr, om, K, c, flight)
        if not (math.isfinite(th) and math.isfinite(om)):
            return leave(y, cnt, th, om, t, h, events, window, NON_FINITE, c)
        if g <= 0.0:
            if not (0.0 < l1 < c[C_ROD_L]):
                return leave(y, cnt, th, om, t, h, events, window, LEFT_REACH, c)
            if -g > c[C_RCAM]:
                return leave(y, cnt, th, om, t, h, events, window, PENETRATION, c)
        if clipped:
            if is_section:
                if t >= t_rec:
                    i = cnt[I_N_SECTION]
                    section[i, 0] = cnt[I_SECTION_K]
                    section[i, 1] = t
                    section[i, 2] = th
                    section[i, 3] = om
                    section[i, 4] = lam[cnt[I_LAM_POS]]
                    cnt[I_N_SECTION] += 1
                cnt[I_SECTION_K] += 1
            if is_resample:
                cnt[I_LAM_POS] += 1
                cnt[I_RESAMPLE_J] += 1
                K = k.stiffness(lam[cnt[I_LAM_POS]], c)
                a1 = accel_trig(tr, om, K, c, flight)
    return leave(y, cnt, th, om, t, h, events, window, OK, c)
