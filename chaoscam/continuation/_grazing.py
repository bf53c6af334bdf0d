"""Grazing along a branch: the test function ψ of an orbit's flights (:func:`flight_margin`),
zero where a flight just touches the cam (gap 0 at gap rate 0), and its location where the
branch ends at one (:func:`locate_grazing`).

ψ [m] is the signed margin of the flight closest to grazing: a flight's least gap δ_min > 0
where the gap has a minimum in flight (no impact), and the virtual penetration
``-v² / (2 a)`` of an impact whose approach decelerates (gap rate v < 0 rising at a > 0: the
unimpeded flight would have had its minimum at ``-v² / (2 a)`` past the cam). Both go to 0
linearly in the parameter at a grazing, from either side, so ψ changes sign there (Nordmark
1991, J. Sound Vib. 145, 279; di Bernardo et al. 2008, *Piecewise-smooth Dynamical Systems*,
sec. 2.5 and ch. 6, the grazing of a periodic orbit). An impact whose gap rate falls as it
closes (a ≤ 0: the follower driven onto the cam, as in chattering's bounces) has no virtual
minimum and no margin.
"""

from __future__ import annotations

import math

import numpy as np

from ..kernel import layout as k
from ..model import Params, gap, gap_rate

__all__ = ["GRAZE_SAMPLES", "flight_margin"]

GRAZE_SAMPLES = 256
"""Series samples per cam period the flight's least gap is found from: each flight minimum is
the minimum of the cubic Hermite interpolant of the gap and its rate between the two samples
around it (error ~ h⁴ max|δ⁽⁴⁾| / 384, below 1e-12 m at h = T / 256 on the default cam)."""

_RATE = k.IMPACT_NAMES.index("gap_rate_before")


def flight_margin(p: Params, series: np.ndarray, impacts: np.ndarray) -> tuple[float, float]:
    """(ψ [m], its time [s]) over the run whose series rows are (t, θ_f, θ̇_f, ...) and
    whose impact rows are the kernel's; (NaN, NaN) where no flight has a minimum and no
    impact a decelerating approach."""
    t, th, om = series[:, 0], series[:, 1], series[:, 2]
    g, r = gap(p, t, th), gap_rate(p, t, th, om)
    jumps = impacts[impacts[:, -1] != k.IMPACT_CHATTER_END]
    crossed = np.zeros(len(t), dtype=bool)  # the interval [t_i, t_i+1] holds an impact
    crossed[np.clip(np.searchsorted(t, impacts[:, 0]) - 1, 0, len(t) - 1)] = True
    found = [(_hermite_min(t[i], t[i + 1], g[i], g[i + 1], r[i], r[i + 1]), t[i])
             for i in np.flatnonzero((r[:-1] < 0) & (r[1:] >= 0) & (g[:-1] > 0)
                                     & (g[1:] > 0) & ~crossed[:-1])]  # fmt: skip
    for ti, v in zip(jumps[:, 0], jumps[:, _RATE], strict=True):
        i = int(np.searchsorted(t, ti)) - 1  # the last sample before the impact
        if i < 0 or g[i] <= 0 or np.any((impacts[:, 0] > t[i]) & (impacts[:, 0] < ti)):
            continue  # the sample before it is not in its flight
        a = (v - r[i]) / (ti - t[i]) if ti > t[i] else math.nan
        if v < 0 and a > 0:
            found.append((-v * v / (2.0 * a), ti))
    if not found:
        return math.nan, math.nan
    return min(found, key=lambda f: abs(f[0]))


def _hermite_min(t0, t1, g0, g1, r0, r1) -> float:
    """The least value on [t0, t1] of the cubic with values g0, g1 and slopes r0 < 0 ≤ r1."""
    h = t1 - t0
    d0, d1 = r0 * h, r1 * h
    a3, a2 = 2.0 * (g0 - g1) + d0 + d1, 3.0 * (g1 - g0) - 2.0 * d0 - d1
    roots = np.roots([3.0 * a3, 2.0 * a2, d0]) if abs(a3) > 0 else np.array([-d0 / (2 * a2)])
    s = [float(x.real) for x in np.atleast_1d(roots) if abs(x.imag) < 1e-12 and 0 <= x.real <= 1]
    values = [g0, g1, *(((a3 * x + a2) * x + d0) * x + g0 for x in s)]
    return float(min(values))
