"""Longer validation runs (excluded by default; run with -m slow)."""

import math

import numpy as np
import pytest

from chaoscam.analysis import classify_section
from chaoscam.testsystems import ball_period_one_theory, bouncing_ball

TWO_PI = 2 * math.pi


@pytest.mark.slow
def test_fine_gamma_sweep_of_the_period_one_window():
    """A 0.25 %-step Γ sweep of the classifier brackets both thresholds within 1 %."""
    e = 0.5
    g1, g2 = ball_period_one_theory(e)
    gammas = np.arange(0.95, 1.65, 0.0025)
    found = []
    for g in gammas:
        ok = False
        for phase in np.linspace(0, TWO_PI, 8, endpoint=False):
            run = bouncing_ball(g, e, 2500, t0=phase, v0=math.pi)
            if run.status != "ok" or len(run.times) < 2500:
                continue
            sec = run.impact_section(2300)
            z = np.column_stack([np.cos(sec[:, 0]), np.sin(sec[:, 0]), sec[:, 1]])
            v = classify_section(z, zero_one=False)
            if v.period == 1 and np.allclose(np.diff(run.times[-20:]), TWO_PI, atol=1e-6):
                ok = True
                break
        found.append(ok)
    found = np.array(found)
    assert found.any()
    lo, hi = gammas[found].min(), gammas[found].max()
    assert np.all(found[(gammas >= lo) & (gammas <= hi)])
    assert abs(lo / g1 - 1) < 0.01 and abs(hi / g2 - 1) < 0.01
