"""Cam-sized data: 20 s at 1 ms, forcing 28.7 rad/s, ~90 section points (bouncing ball).

The bouncing ball is an impact oscillator like the cam follower; its dimensionless time
is mapped onto the cam's forcing, ω t = τ with ω = 28.7 rad/s, so a run has the length,
sampling and section size of a default cam simulation.
"""

import math

import numpy as np
import pytest

from chaoscam.analysis import classify_signal, spectrum_from_jacobians
from chaoscam.testsystems import ball_impact_map, bouncing_ball

OMEGA = 28.7
PERIOD = 2 * math.pi / OMEGA
E = 0.5


def cam_sized(gamma):
    """θ-like signal (ball height) at 1 ms for 20 s, and its stroboscopic section."""
    run = bouncing_ball(gamma, E, 6000, t0=0.3, v0=math.pi)
    tau0 = 2 * math.pi * math.ceil(run.times[len(run.times) - 1000] / (2 * math.pi))
    tau = tau0 + OMEGA * np.arange(0.0, 20.0, 1e-3)
    x = run.positions(tau)
    strobe = tau0 + 2 * math.pi * np.arange(90)
    h = 1e-7
    section = np.column_stack(
        [run.positions(strobe), (run.positions(strobe + h) - run.positions(strobe)) / h]
    )
    return run, x, section


def _impact_jacobian(state, gamma, h=1e-7):
    """The impact map's Jacobian at ``state`` by central differences (smooth off grazing)."""
    cols = [
        ball_impact_map(state + d, gamma, E) - ball_impact_map(state - d, gamma, E)
        for d in np.eye(2) * h
    ]
    return np.column_stack(cols) / (2 * h)


@pytest.mark.parametrize("gamma, period", [(1.2, 1), (1.6, 2), (2.0, 8)])
def test_periodic_regimes(gamma, period):
    """Period-1 and period-2 bouncing, and a sticking period-8 motion, are found from 20 s."""
    _, x, section = cam_sized(gamma)
    v = classify_signal(x, 1e-3, PERIOD, section=section)
    assert (v.label, v.period) == ("periodic", period), v.reasons


def test_chaotic_regime():
    """At Γ = 1.75 (no sticking, impact-map QR exponent λ₁ > 0.1) 20 s of signal are chaotic."""
    run, x, section = cam_sized(1.75)
    assert run.n_stick == 0
    k = len(run.times) - 1000
    states = np.column_stack([run.times[k : k + 600], run.velocities[k : k + 600]])
    lyap = spectrum_from_jacobians(np.array([_impact_jacobian(s, 1.75) for s in states]), 1.0)
    assert lyap.exponent > 0.1
    v = classify_signal(x, 1e-3, PERIOD, section=section)
    assert v.label == "chaotic", v.reasons
