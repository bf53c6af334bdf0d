"""The crossing search (``_events.locate_crossing``) on the model's own gap: where it stops,
and how many substeps it takes to get there."""

import numpy as np
import pytest
from scipy.optimize import brentq

from chaoscam import Numerics, Params
from chaoscam.kernel import _events as ev
from chaoscam.kernel import _physics as k
from chaoscam.kernel import kernel_constants
from chaoscam.kernel import layout as L
from chaoscam.model import contact_angle

T0 = 0.1
STEP = 2e-6


def _bracket(case):
    """(c, K, th0, om0, flight, s) for a crossing inside [T0, T0 + STEP]: s = +1 closing, -1
    opening. The approach speeds span the model's: a macro-impact (~0.7 m/s), a slow closing
    of a chattering sequence (~1e-5 m/s, a gap of 1e-11 m: the gap's last bits matter), and a
    lift-off from inside the cam."""
    p = Params()
    c = kernel_constants(p, Numerics())
    K = k.stiffness(p.l_lambda, c)
    root = float(contact_angle(p, T0))
    rate_c = (float(contact_angle(p, T0 + 1e-7)) - float(contact_angle(p, T0 - 1e-7))) / 2e-7
    l1 = k.geometry(T0, root, c)[1]
    if case in ("macro", "macro-flight"):
        return c, K, root + 4e-7, rate_c - 0.7 / l1, case == "macro-flight", 1.0
    if case == "slow":
        return c, K, root + 1e-11 / l1, rate_c - 1e-5 / l1, False, 1.0
    return c, K, root - 2e-9, rate_c + 0.05 / l1, False, -1.0  # lift-off


def _along(c, K, th0, om0, flight):
    def gap_at(tau):
        if flight:
            return k.geometry(T0 + tau, k.rk4_flight(th0, om0, tau, c)[0], c)[0]
        return k.geometry(T0 + tau, k.rk4(T0, th0, om0, tau, K, c)[0], c)[0]

    return gap_at


CASES = ["macro", "macro-flight", "slow", "lift-off"]


@pytest.mark.parametrize("case", CASES)
def test_crossing_is_found_to_the_event_tolerance(case):
    """The search returns a length past the crossing (s delta <= 0 there) within the event
    tolerance of the root brentq finds on the same substeps, or a point where delta is 0.0 to
    its last bit, for fast and slow closings and an opening."""
    c, K, th0, om0, flight, s = _bracket(case)
    along = _along(c, K, th0, om0, flight)
    g0, g1 = along(0.0), along(STEP)
    assert s * g0 > 0.0 >= s * g1, "the case must bracket a crossing"
    trig = k.geometry_at(T0, th0, c)[3:]
    tau = ev.locate_crossing(T0, th0, om0, 0.0, g0, STEP, g1, K, c, flight, trig)
    root = brentq(along, 0.0, STEP, xtol=1e-18, rtol=4 * np.finfo(float).eps)
    assert 0.0 < tau <= STEP
    assert s * along(tau) <= 0.0
    # the gap's rounding (~1e-17 m) blurs the crossing by that over the approach speed
    blur = 4e-17 / abs((along(root + 1e-9) - along(root - 1e-9)) / 2e-9)
    assert abs(tau - root) <= c[L.C_EVENT_TOL] + blur


@pytest.mark.parametrize("case", CASES)
def test_crossing_search_takes_few_substeps(case, monkeypatch):
    """At most four substeps a crossing (2 to 4 here): regula falsi's first point, then the
    roots of the parabola through the last two trials with the gap rate at the last, each
    trial set just past its estimate so that the next closes the bracket. (Illinois regula
    falsi took 5, 3, 9 and 3 on these four, and 17 a crossing on average over a chattering
    run.)"""
    c, K, th0, om0, flight, s = _bracket(case)
    along = _along(c, K, th0, om0, flight)
    g0, g1 = along(0.0), along(STEP)
    calls = []
    gap_at = ev._gap_at

    def counted(*args):
        calls.append(args[3])
        return gap_at(*args)

    monkeypatch.setattr(ev, "_gap_at", counted)
    trig = k.geometry_at(T0, th0, c)[3:]
    ev.locate_crossing.py_func(T0, th0, om0, 0.0, g0, STEP, g1, K, c, flight, trig)
    assert 1 <= len(calls) <= 4, calls
