"""Where an event happens inside a fixed step: the substep length ``tau`` at which, through one
RK4 substep from the segment's start, the gap ``delta`` changes sign (:func:`locate_crossing`)
or the gap rate turns (:func:`graze_point`), and the Illinois regula falsi both searches use."""

from __future__ import annotations

import math

from numba import njit

from ._physics import geometry, geometry_trig, on_clock, rk4_flight, rk4_trig
from .layout import C_EVENT_TOL

MAX_BRACKET_STEPS = 400  # passes of a crossing search at most (a guard against a NaN gap)

GRAZE_TOL = 1e-6
"""Width, as a fraction of the step, to which the gap rate's turn is found (an error e in its
time moves the gap's extremum by ~|delta''| e^2 / 2, below 1e-20 m)."""

PROBE_STEP = 0.4
"""How far past its estimate of a crossing, in event tolerances, :func:`locate_crossing` puts
its next trial: below a half, so that two trials either side of one estimate close the bracket."""

MAX_GRAZE_STEPS = 200  # passes of the search for the gap rate's turn at most


@njit(cache=True, _nrt=False)
def gap_after(t, th, om, tau, K, c, trig):
    """``(delta, l_1, dC/dt.n, theta_f')`` after one RK4 substep of length tau from (t, th, om)
    (:func:`._physics.rk4`'s bits); ``trig``: ``(cc, sc, ct, st)`` at the start."""
    cc, sc, ct, st = trig
    th1, om1, c4, s4 = rk4_trig(t, th, om, tau, K, c, cc, sc, ct, st)
    delta, l1, cdn = geometry_trig(c4, s4, math.cos(th1), math.sin(th1), c)
    return delta, l1, cdn, om1


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
    """The bracket after f(m) = fm, for Illinois regula falsi (Dowell & Jarratt 1971): the end
    kept twice in a row has its value halved (superlinear where plain regula falsi stalls).
    ``side`` remembers the end replaced last."""
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


@njit(cache=True, _nrt=False)
def locate_crossing(t, th, om, a, g_start, h, g_end, K, c, flight, trig):
    """The substep length tau in (a, h] at which the gap delta changes sign: a bracketed search
    on ``tau -> delta(RK4 substep of length tau)`` (a > 0: a micro-flight from the surface) to
    the event tolerance ``tol``. The first trial is regula falsi's; each later one the root
    nearest the last trial x of the parabola through the last two with the gap rate at x
    (:func:`model_root`), moved ``PROBE_STEP tol`` towards the bracket's farther end so that the
    next closes it (3.8 substeps a crossing in chattering, against 17.1 for Illinois regula
    falsi); regula falsi for an estimate outside, a bisection after three trials that do not
    halve the bracket. With ``flight`` (a closing from free flight) the substeps are the free
    pendulum's (no Hertz force on an overshoot ``v event_tol``). Returns the bracket's end past
    the crossing (delta <= 0 for a closing, >= 0 for an opening), or a trial where delta is 0.0."""
    tol = c[C_EVENT_TOL]
    s = 1.0 if g_start > 0.0 else -1.0  # work on s * delta, positive at the start
    fa, b, fb = s * g_start, h, s * g_end
    side = 0
    fx, dx, x = 0.0, 0.0, -1.0  # the last trial: s * delta, s * rate there, its length
    fp, xp = fa, a  # the trial before it (at first the bracket's start)
    w1 = w2 = math.inf  # the bracket's width before the last trial, and before the one before
    for _ in range(MAX_BRACKET_STEPS):
        width = b - a
        if width <= tol:
            break
        m = illinois_point(a, fa, b, fb)
        if x >= 0.0 and dx != 0.0:
            r = model_root(x, fx, dx, xp, fp)
            if a < r < b:
                m = r + PROBE_STEP * tol if b - r > r - a else r - PROBE_STEP * tol
        if x >= 0.0:
            xp, fp = x, fx
        x = on_clock(t, m)
        fx, dx = _gap_at(t, th, om, x, K, c, flight, trig, s)
        if fx == 0.0:
            return x  # the gap is 0.0 here to its last bit: the crossing, found exactly
        a, fa, b, fb, side = illinois_update(a, fa, b, fb, x, fx, side)
        if b - a > 0.5 * w2:  # three trials without halving the bracket: bisect
            xp, fp = x, fx
            x = on_clock(t, 0.5 * (a + b))
            fx, dx = _gap_at(t, th, om, x, K, c, flight, trig, s)
            if fx == 0.0:
                return x
            a, fa, b, fb, _ = illinois_update(a, fa, b, fb, x, fx, 0)
            w1 = w2 = math.inf  # the bisection's own halving starts the next count
            continue
        w2, w1 = w1, width
    return b


@njit(cache=True, inline="always")
def model_root(x, fx, dx, xp, fp):
    """The root nearest x of the parabola through (x, fx) with slope dx and through (xp, fp);
    Newton's estimate where it has none (or xp = x)."""
    u = -fx / dx
    if xp != x:
        e = xp - x
        q = (fp - fx - dx * e) / (e * e)  # the curvature's half
        disc = dx * dx - 4.0 * q * fx
        if disc >= 0.0:
            u = -2.0 * fx / (dx + math.copysign(math.sqrt(disc), dx))
    return x + u


@njit(cache=True, _nrt=False)
def _gap_at(t, th, om, m, K, c, flight, trig, s):
    """``s`` times the gap and its rate ``l_1 theta' - dC/dt.n`` after a substep of length m."""
    if flight:
        th1, om1 = rk4_flight(th, om, m, c)
        delta, l1, cdn = geometry(t + m, th1, c)
    else:
        delta, l1, cdn, om1 = gap_after(t, th, om, m, K, c, trig)
    return s * delta, s * (l1 * om1 - cdn)


# stand-in for a gap of exactly 0 at a segment's start (brackets need a sign there)
ON_SURFACE = 1e-300


@njit(cache=True, _nrt=False)
def graze_point(t, th, om, h, rate0, rate1, K, c, trig):
    """The substep length tau in (0, h) at which the gap rate l_1 theta' - dC/dt.n turns (where
    the gap's extremum shows a micro-flight or graze): Illinois regula falsi on ``tau ->
    rate(RK4 substep of length tau)`` to ``GRAZE_TOL`` of the step."""
    s = 1.0 if rate0 > 0.0 else -1.0  # work on s * rate, positive at 0, negative at h
    a, fa, b, fb = 0.0, s * rate0, h, s * rate1
    side = 0
    for _ in range(MAX_GRAZE_STEPS):
        width = b - a
        if width <= GRAZE_TOL * h:
            break
        m = on_clock(t, illinois_point(a, fa, b, fb))
        _, l1, cdn, omm = gap_after(t, th, om, m, K, c, trig)
        a, fa, b, fb, side = illinois_update(a, fa, b, fb, m, s * (l1 * omm - cdn), side)
    return on_clock(t, 0.5 * (a + b))
