"""Compiled fixed-step RK4 with located impacts: the reference integrator (paper sec. 3).

One call of :func:`run_chunk` advances one trajectory on the grid ``t_n = n dt`` until the end
step or until an output buffer needs emptying; the Python driver (``chaoscam.simulate``) then
empties the buffers and calls again. The kernel never raises: it returns a status code
(:class:`chaoscam.integrate.Status`).

Within one grid step the interval is cut into *segments* at the scheduled times that fall
inside it (stroboscopic section times ``k T``, line-length resampling times ``j dt_l``) and at
located impacts. Each segment is one RK4 substep, so the section points are exact RK4 states,
not interpolations, and the grid itself never shifts.

Impacts (paper (4)–(5), shared/MODEL.md): when the gap ``delta`` is positive at a segment's
start and non-positive at its end, the crossing time is found by the Illinois variant of
regula falsi on ``tau -> delta(RK4 substep of length tau)`` down to ``event_tol``; the state is
taken at the bracket end where ``delta <= 0``. If the approach speed ``-d(delta)/dt`` exceeds
``v_min`` the restitution jump ``theta'+ = -xi theta'- + (1 + xi) (dC/dt . n) / l_1`` is applied
and recorded; slower closings are left to the compliant force. Limits: two crossings within one
segment (a graze shorter than a step) are not seen.

All numbers come from the constants vector built by ``chaoscam.integrate.kernel_constants``;
the names ``C_*`` below index it.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

# --- indices into the constants vector (see _constants.py) -------------------------------
C_OMEGA = 0  # cam speed [rad/s]
C_THETA_C0 = 1  # cam phase at t = 0 [rad]
C_E = 2  # eccentricity [m]
C_XO = 3  # pivot x [m]
C_YO = 4  # pivot y [m]
C_RSUM = 5  # R + r [m]
C_RCAM = 6  # cam radius R [m]
C_RROD = 7  # rod radius r, in the slip speed [m]
C_GRAV = 8  # m g l / 2 [N m]
C_INV_J = 9  # 1 / J [1/(kg m^2)]
C_HERTZ = 10  # (pi/4) E: K_n = C_HERTZ * l_lambda for the Hertz model [Pa]
C_K_FIXED = 11  # K_n of the fractal model; 0 selects the Hertz model [N/m]
C_DAMP_SIGN = 12  # +1 Hunt–Crossley, -1 the paper's literal signs
C_BETA = 13  # impact damping factor [s/m]
C_MU_ARM = 14  # mu_f times the friction arm [m]
C_VEPS = 15  # sign regularisation speed [m/s]; 0 = exact sign
C_VMIN = 16  # least approach speed of an applied impact [m/s]
C_XI = 17  # coefficient of restitution
C_ROD_L = 18  # rod length l [m]
C_DT = 19  # grid step [s]
C_EVENT_TOL = 20  # impact-time tolerance [s]
C_PERIOD = 21  # section interval 2 pi / omega [s]
C_T_RECORD = 22  # outputs are kept from this time on (transient) [s]
C_RESAMPLE_DT = 23  # interval between line-length draws [s]; 0 = draw at each impact
C_MAX_EVENTS = 24  # impacts handled in one step before chattering hand-over
C_STRIDE = 25  # series sample every C_STRIDE steps; 0 = no series
C_FLIGHT_MERGE = 26  # most grid steps taken as one RK4 step where the gap provably stays open
C_METHOD = 27  # METHOD_RK4 (this module) or METHOD_ADAPTIVE (_adaptive.py)
C_RTOL = 28  # adaptive: relative tolerance of the step error
C_ATOL = 29  # adaptive: absolute tolerance [rad and rad/s]
C_H_MAX = 30  # adaptive: largest step [s]
N_CONSTANTS = 31

METHOD_RK4 = 0
METHOD_ADAPTIVE = 1

# --- indices into the integer counters ---------------------------------------------------
I_STEP = 0  # grid step n of the current time n dt
I_N_SERIES = 1  # rows filled in the series buffer
I_N_SECTION = 2  # rows filled in the section buffer
I_N_IMPACT = 3  # rows filled in the impact buffer
I_LAM_POS = 4  # index of the line length in use in the draws buffer
I_SECTION_K = 5  # next section index k (time k T)
I_RESAMPLE_J = 6  # next resampling index j (time j dt_l)
I_CONTACT_STEPS = 7  # recorded steps ending in contact
I_COUNTED_STEPS = 8  # recorded steps
I_CHATTER = 9  # steps where the chattering guard handed over to the compliant contact
I_SLOW_CLOSINGS = 10  # closings slower than v_min (no jump applied)
I_SAFE_STEP = 11  # the gap provably stays open until grid step I_SAFE_STEP (0 = not known)
I_SERIES_J = 12  # adaptive: index j of the next series sample (time j * stride * dt)
N_COUNTERS = 13

# --- the state vector y ----------------------------------------------------------------------
Y_THETA = 0  # theta_f [rad]
Y_OMEGA = 1  # theta_f' [rad/s]
Y_TIME = 2  # t [s] (the fixed-step kernel keeps it equal to cnt[I_STEP] * dt)
Y_STEP = 3  # adaptive: the step size to try next [s]; 0 = not known yet
Y_RECORDED = 4  # adaptive: time integrated after the transient [s]
Y_CONTACT = 5  # adaptive: of which in contact (gap <= 0) [s]
Y_EVENTS = 6  # adaptive: events so far in the grid interval Y_WINDOW (chattering guard)
Y_WINDOW = 7  # adaptive: that grid interval's index n, [n dt, (n + 1) dt)
Y_SIZE = 8

# --- status codes (mirrors chaoscam.integrate.Status) ------------------------------------
OK = 0
NEED_BUFFER = 1
LEFT_REACH = 2
NON_FINITE = 3
PENETRATION = 4

SECTION_NAMES = ("k", "t", "theta_f", "omega_f", "l_lambda")
IMPACT_NAMES = (
    "t", "theta_f", "omega_before", "omega_after", "gap_rate_before", "lever_arm", "l_lambda",
)
SERIES_COLS = 4  # t, theta_f, omega_f, l_lambda
SECTION_COLS = len(SECTION_NAMES)
IMPACT_COLS = len(IMPACT_NAMES)


@njit(cache=True)
def stiffness(lam, c):
    """K_n for line length ``lam``: Hertz (18) unless a fixed (fractal) value is set."""
    return c[C_K_FIXED] if c[C_K_FIXED] > 0.0 else c[C_HERTZ] * lam


@njit(cache=True)
def geometry(t, th, c):
    """Gap delta, lever arm l_1 and normal cam speed dC/dt . n at time t and angle th."""
    thc = c[C_OMEGA] * t + c[C_THETA_C0]
    return geometry_trig(math.cos(thc), math.sin(thc), math.cos(th), math.sin(th), c)


@njit(cache=True)
def geometry_trig(cc, sc, ct, st, c):
    """:func:`geometry` given cos/sin of the cam angle (cc, sc) and of theta_f (ct, st)."""
    dx = c[C_XO] - c[C_E] * cc
    dy = c[C_YO] - c[C_E] * sc
    delta = -dx * st + dy * ct - c[C_RSUM]
    l1 = -(dx * ct + dy * st)
    ew = c[C_E] * c[C_OMEGA]
    cdn = ew * sc * st + ew * cc * ct
    return delta, l1, cdn


@njit(cache=True)
def acceleration(t, th, om, K, c):
    """theta_f'' from (1)–(3): gravity, Hunt–Crossley normal force, friction torque."""
    thc = c[C_OMEGA] * t + c[C_THETA_C0]
    return acceleration_trig(math.cos(thc), math.sin(thc), math.cos(th), math.sin(th), om, K, c)


@njit(cache=True)
def acceleration_trig(cc, sc, ct, st, om, K, c):
    """:func:`acceleration` given cos/sin of the cam angle (cc, sc) and of theta_f (ct, st).

    The one home of equations (1)–(3); callers that know the trigonometric values (the
    adaptive kernel rotates them from a step's start) skip four transcendental calls.
    """
    cx = c[C_E] * cc
    cy = c[C_E] * sc
    dx = c[C_XO] - cx
    dy = c[C_YO] - cy
    delta = -dx * st + dy * ct - c[C_RSUM]
    torque = -c[C_GRAV] * ct
    if delta < 0.0:
        l1 = -(dx * ct + dy * st)
        ew = c[C_E] * c[C_OMEGA]
        cdn = ew * sc * st + ew * cc * ct
        pen = -delta
        pen_rate = cdn - l1 * om
        force = K * pen * (1.0 + c[C_DAMP_SIGN] * c[C_BETA] * pen_rate)
        if force > 0.0:
            # slip of the rod surface over the cam at B_c = C - R n
            bx = cx + c[C_RCAM] * st
            by = cy - c[C_RCAM] * ct
            v_r = c[C_RROD] * om - c[C_OMEGA] * (bx * st - by * ct)
            if c[C_VEPS] > 0.0:
                x = v_r / c[C_VEPS]
                # tanh(x) rounds to +-1 in float64 for |x| > 19.1: skip the call there.
                sgn = math.tanh(x) if abs(x) < 20.0 else (1.0 if x > 0.0 else -1.0)
            else:
                sgn = (v_r > 0.0) - (v_r < 0.0)
            torque += force * l1 - c[C_MU_ARM] * force * sgn
    return torque * c[C_INV_J]


@njit(cache=True)
def rk4(t, th, om, h, K, c):
    """One classical fourth-order Runge–Kutta step of length h for (theta_f, theta_f')."""
    a1 = acceleration(t, th, om, K, c)
    th2 = th + 0.5 * h * om
    om2 = om + 0.5 * h * a1
    a2 = acceleration(t + 0.5 * h, th2, om2, K, c)
    th3 = th + 0.5 * h * om2
    om3 = om + 0.5 * h * a2
    a3 = acceleration(t + 0.5 * h, th3, om3, K, c)
    th4 = th + h * om3
    om4 = om + h * a3
    a4 = acceleration(t + h, th4, om4, K, c)
    return (
        th + h / 6.0 * (om + 2.0 * om2 + 2.0 * om3 + om4),
        om + h / 6.0 * (a1 + 2.0 * a2 + 2.0 * a3 + a4),
    )


@njit(cache=True)
def rk4_flight(th, om, h, c):
    """RK4 step of the free pendulum J theta'' = -(m g l/2) cos theta (no contact force).

    Exactly the step :func:`rk4` takes whenever the gap stays positive over the step, at a
    quarter of the cost; :func:`closing_bound` decides when that is guaranteed.
    """
    k = -c[C_GRAV] * c[C_INV_J]
    a1 = k * math.cos(th)
    om2 = om + 0.5 * h * a1
    a2 = k * math.cos(th + 0.5 * h * om)
    om3 = om + 0.5 * h * a2
    a3 = k * math.cos(th + 0.5 * h * om2)
    om4 = om + h * a3
    a4 = k * math.cos(th + h * om3)
    return (
        th + h / 6.0 * (om + 2.0 * om2 + 2.0 * om3 + om4),
        om + h / 6.0 * (a1 + 2.0 * a2 + 2.0 * a3 + a4),
    )


@njit(cache=True)
def gap_accel_bound(om, c):
    """A bound on |delta''| in flight while |theta'| stays below |om| + 1 rad/s [m/s^2].

    For ``delta = (O - C).n - (R + r)``:
    ``|delta''| <= e w^2 + 2 e w |theta'| + rho_max (|theta''| + theta'^2)`` with
    ``rho_max = |O| + e`` and ``|theta''| <= m g l / (2 J)`` in flight.
    """
    w = abs(om) + 1.0
    ew = c[C_E] * c[C_OMEGA]
    rho = math.hypot(c[C_XO], c[C_YO]) + c[C_E]
    return ew * c[C_OMEGA] + 2.0 * ew * w + rho * (c[C_GRAV] * c[C_INV_J] + w * w)


@njit(cache=True)
def closing_bound(l1, cdn, om, h, c):
    """An upper bound on how much the gap can shrink within a time h <= J / (m g l / 2) [m].

    ``|delta(t + s) - delta(t)| <= s |delta'| + s^2/2 max|delta''|``, doubled for safety.
    Over such an h gravity changes theta' by at most 1 rad/s, as :func:`gap_accel_bound`
    assumes.
    """
    return 2.0 * (h * abs(l1 * om - cdn) + 0.5 * h * h * gap_accel_bound(om, c))


@njit(cache=True)
def safe_horizon(g, l1, cdn, om, c):
    """The time over which a positive gap g certainly stays positive [s].

    The largest H with ``closing_bound(H) <= g``, capped at J / (m g l / 2).
    """
    acc = gap_accel_bound(om, c)
    v = abs(l1 * om - cdn)
    horizon = 0.5 * g / (v + math.sqrt(v * v + acc * g))
    return min(horizon, 1.0 / (c[C_GRAV] * c[C_INV_J]))


@njit(cache=True, inline="always")
def illinois_point(a, fa, b, fb):
    """The next point of regula falsi in the bracket [a, b], where fa > 0 >= fb: the secant's
    root, or the midpoint when rounding puts that outside the bracket."""
    m = b - fb * (b - a) / (fb - fa)
    if not (a < m < b):
        m = 0.5 * (a + b)
    return m


@njit(cache=True, inline="always")
def illinois_update(a, fa, b, fb, m, fm, side):
    """The bracket after f(m) = fm, for Illinois regula falsi (Dowell & Jarratt 1971).

    The end that stays twice in a row has its value halved, which keeps the method
    superlinear where plain regula falsi stalls. ``side`` remembers the end replaced last.
    """
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
    return a, fa, b, fb, side


@njit(cache=True)
def locate_crossing(t, th, om, h, g_start, g_end, K, c):
    """The substep length tau in (0, h] at which the gap delta changes sign.

    Illinois regula falsi on ``tau -> delta(RK4 substep of length tau)``, with a bisection
    whenever an iteration fails to halve the bracket, until the bracket is narrower than the
    event tolerance. Returns the bracket's right end, past the crossing: delta <= 0 there for
    a closing, delta >= 0 for an opening.
    """
    s = 1.0 if g_start > 0.0 else -1.0  # work on s * delta, positive at the start
    a, fa, b, fb = 0.0, s * g_start, h, s * g_end
    side = 0
    for _ in range(400):
        width = b - a
        if width <= c[C_EVENT_TOL]:
            break
        m = illinois_point(a, fa, b, fb)
        thm, _ = rk4(t, th, om, m, K, c)
        fm, _, _ = geometry(t + m, thm, c)
        a, fa, b, fb, side = illinois_update(a, fa, b, fb, m, fm * s, side)
        if b - a > 0.5 * width:
            m = 0.5 * (a + b)
            thm, _ = rk4(t, th, om, m, K, c)
            fm, _, _ = geometry(t + m, thm, c)
            a, fa, b, fb, _ = illinois_update(a, fa, b, fb, m, fm * s, 0)
    return b


@njit(cache=True, inline="always")
def next_scheduled(t_limit, cnt, c):
    """The first scheduled time up to ``t_limit``: (time, is_section, is_resample).

    Scheduled times are the stroboscopic sections ``k T`` and, with interval resampling,
    the line-length draws ``j dt_l``; a step or segment must end exactly there.
    """
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
def at_scheduled(t, th, om, is_section, is_resample, K, lam, cnt, section, c):
    """Record the section point and/or draw the next line length at a scheduled time t.

    Returns the stiffness in use afterwards.
    """
    if is_section:
        if t >= c[C_T_RECORD]:
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
        K = stiffness(lam[cnt[I_LAM_POS]], c)
    return K


@njit(cache=True, inline="always")
def impact(t, th, om, l1, cdn, K, lam, cnt, impacts, c):
    """The impact law (4)–(5) at a located closing at (t, th) with lever arm l1 and dC/dt.n.

    When the approach speed -(l1 theta' - dC/dt.n) exceeds v_min the angular velocity jumps,
    ``theta'+ = -xi theta'- + (1 + xi) (dC/dt.n) / l1``, a new line length is drawn (impact
    resampling) and the jump is recorded (after the transient); a slower closing is left to
    the compliant force and counted. Returns (theta' after, stiffness in use).
    """
    rate = l1 * om - cdn
    if -rate > c[C_VMIN]:
        om_after = -c[C_XI] * om + (1.0 + c[C_XI]) * cdn / l1
        if c[C_RESAMPLE_DT] <= 0.0:
            cnt[I_LAM_POS] += 1
            K = stiffness(lam[cnt[I_LAM_POS]], c)
        if t >= c[C_T_RECORD]:
            i = cnt[I_N_IMPACT]
            impacts[i, 0] = t
            impacts[i, 1] = th
            impacts[i, 2] = om
            impacts[i, 3] = om_after
            impacts[i, 4] = rate
            impacts[i, 5] = l1
            impacts[i, 6] = lam[cnt[I_LAM_POS]]
            cnt[I_N_IMPACT] += 1
        return om_after, K
    cnt[I_SLOW_CLOSINGS] += 1
    return om, K


@njit(cache=True)
def leave(y, cnt, th, om, t, safe_n, code):
    """Store the state and the flight horizon before returning ``code`` to the driver."""
    y[Y_THETA] = th
    y[Y_OMEGA] = om
    y[Y_TIME] = t
    cnt[I_SAFE_STEP] = safe_n
    return code


@njit(cache=True)
def run_chunk(y, cnt, c, n_stop, lam, series, section, impacts):
    """Advance one trajectory from step ``cnt[I_STEP]`` towards ``n_stop``.

    Parameters
    ----------
    y : float64[Y_SIZE]
        (theta_f [rad], theta_f' [rad/s], t [s], ...) at ``t = cnt[I_STEP] * dt``; updated in
        place (slots ``Y_*``; this kernel reads the first two and writes the time).
    cnt : int64[N_COUNTERS]
        Counters (indices ``I_*``); updated in place.
    c : float64[N_CONSTANTS]
        Constants (indices ``C_*``).
    n_stop : int
        Grid step at which the run ends.
    lam : float64[:]
        Line-length draws; ``lam[cnt[I_LAM_POS]]`` is the one in use.
    series, section, impacts : float64[:, 4], [:, 5], [:, 7]
        Output buffers, filled from the row counts in ``cnt``.

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
    th = y[0]
    om = y[1]
    K = stiffness(lam[cnt[I_LAM_POS]], c)
    sections_per_step = np.int64(h / c[C_PERIOD]) + 2
    draws_per_step = max_events + 1
    if not resample_on_impact:
        draws_per_step += np.int64(h / c[C_RESAMPLE_DT]) + 2

    g, l1, cdn = geometry(cnt[I_STEP] * h, th, c)  # gap, lever arm, dC/dt.n here
    # Until grid step safe_n the gap certainly stays open (no geometry needed). Kept in the
    # counters, so that a run resumed after a buffer hand-back is bit-identical to one that
    # was not interrupted. Whoever changes the state y from outside must reset it to 0.
    safe_n = cnt[I_SAFE_STEP]
    stale = False  # g, l1, cdn belong to an earlier point (only while the gap is safe)
    while cnt[I_STEP] < n_stop:
        # Room for one more step's worth of outputs and draws, else hand back to Python.
        if (
            cnt[I_N_SERIES] + samples_per_block > series.shape[0]
            or cnt[I_N_SECTION] + sections_per_step > section.shape[0]
            or cnt[I_N_IMPACT] + max_events > impacts.shape[0]
            or cnt[I_LAM_POS] + draws_per_step >= lam.shape[0]
        ):
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
            if m >= 2 and (n + m) * h >= c[C_T_RECORD] > t:
                m = 0  # do not merge across the start of the recording
        if m >= 2:
            th0 = th
            om0 = om
            th, om = rk4_flight(th0, om0, m * h, c)
            stale = True
            cnt[I_STEP] = n + m
            if not (math.isfinite(th) and math.isfinite(om)):
                return leave(y, cnt, th, om, cnt[I_STEP] * h, safe_n, NON_FINITE)
            if (n + m) * h >= c[C_T_RECORD]:
                cnt[I_COUNTED_STEPS] += m
                # Series samples inside the block come from a substep off its start, so that
                # sampling never changes the trajectory.
                j = n + stride - n % stride if stride > 0 else n + m + 1
                while j <= n + m:
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
                th, om = rk4_flight(th, om, hs, c)  # far from the cam: pure flight
                t = seg_end
                stale = True
            elif hs > 0.0:
                if stale:
                    g, l1, cdn = geometry(t, th, c)
                    stale = False
                if g > 0.0 and g > closing_bound(l1, cdn, om, hs, c):
                    th_new, om_new = rk4_flight(th, om, hs, c)  # no contact possible
                else:
                    th_new, om_new = rk4(t, th, om, hs, K, c)
                g_new, l1, cdn = geometry(seg_end, th_new, c)
                closing = g > 0.0 and g_new <= 0.0
                if (closing or (g < 0.0 and g_new > 0.0)) and events >= max_events:
                    cnt[I_CHATTER] += 1  # chattering: the rest of the step is left as it is
                elif closing or (g < 0.0 and g_new > 0.0):
                    # The gap changes sign inside the segment: go to the crossing, so that no
                    # RK4 step straddles the kink of the force at delta = 0, then resume.
                    tau = locate_crossing(t, th, om, hs, g, g_new, K, c)
                    th, om = rk4(t, th, om, tau, K, c)
                    t = t + tau
                    events += 1
                    g, l1, cdn = geometry(t, th, c)
                    if not closing:
                        continue
                    if not (0.0 < l1 < c[C_ROD_L]):
                        return leave(y, cnt, th, om, t, safe_n, LEFT_REACH)
                    om, K = impact(t, th, om, l1, cdn, K, lam, cnt, impacts, c)
                    continue
                th = th_new
                om = om_new
                t = seg_end
                g = g_new
                if g > 0.0:
                    safe_n = np.int64(math.floor((t + safe_horizon(g, l1, cdn, om, c)) / h))
            K = at_scheduled(t, th, om, is_section, is_resample, K, lam, cnt, section, c)

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
    return leave(y, cnt, th, om, cnt[I_STEP] * h, safe_n, OK)
