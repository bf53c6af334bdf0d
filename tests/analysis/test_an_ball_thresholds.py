"""Bouncing ball: the period-one window found by the classifier and by stability analysis."""

import math

import numpy as np
import pytest

from chaoscam.analysis import classify_section
from chaoscam.testsystems import ball_period_one_theory, bouncing_ball, period_one_thresholds

# A textbook system (9-10 s for the window's runs): with -m slow. The classifier's verdicts
# on the model itself are tested by default (tests/test_labelled_set.py).
pytestmark = pytest.mark.slow

E = 0.5


def impact_points(run, keep=200):
    """Impact section (cos φ, sin φ, v) of the last `keep` impacts (the phase embedded)."""
    sec = run.impact_section(len(run.times) - keep)
    return np.column_stack([np.cos(sec[:, 0]), np.sin(sec[:, 0]), sec[:, 1]])


def period_one_attracts(gamma, e=E, launches=8):
    """True when some launch settles on one impact per table period (classifier: period 1)."""
    for phase in np.linspace(0.0, 2 * math.pi, launches, endpoint=False):
        run = bouncing_ball(gamma, e, 2500, t0=phase, v0=math.pi)
        if run.status != "ok" or len(run.times) < 2500:
            continue
        verdict = classify_section(impact_points(run), zero_one=False)
        if verdict.label == "periodic" and verdict.period == 1:
            # one impact per table period, not one per n periods
            if np.allclose(np.diff(run.times[-20:]), 2 * math.pi, atol=1e-6):
                return True
    return False


def bisect_edge(inside, outside, rel_tol=1e-3):
    """Bisect between a Γ where period one attracts and one where it does not."""
    while abs(inside - outside) > rel_tol * inside:
        mid = 0.5 * (inside + outside)
        if period_one_attracts(mid):
            inside = mid
        else:
            outside = mid
    return 0.5 * (inside + outside)


@pytest.fixture(scope="module")
def window():
    """The period-one window located by a coarse classifier sweep and bisection."""
    grid = np.round(np.arange(0.8, 2.0, 0.05), 10)
    flags = [period_one_attracts(g) for g in grid]
    idx = np.nonzero(flags)[0]
    assert idx.size, "the classifier found no period-one motion on the grid"
    lo_in, hi_in = grid[idx[0]], grid[idx[-1]]
    assert all(flags[idx[0] : idx[-1] + 1]), "the period-one window is not an interval"
    lo = bisect_edge(lo_in, grid[idx[0] - 1])
    hi = bisect_edge(hi_in, grid[idx[-1] + 1])
    return lo, hi


def test_classifier_finds_existence_threshold(window):
    """Period one first attracts at Γ = π(1 - e)/(1 + e) (within 1 %)."""
    g1, _ = ball_period_one_theory(E)
    assert abs(window[0] / g1 - 1) < 0.01


def test_classifier_finds_period_doubling(window):
    """Period one stops attracting at the period-doubling Γ of the closed form (within 1 %)."""
    _, g2 = ball_period_one_theory(E)
    assert abs(window[1] / g2 - 1) < 0.01


def test_classifier_sees_period_two_after_doubling(window):
    """Just after the doubling the classifier reports period 2 on the impact section."""
    run = bouncing_ball(1.03 * window[1], E, 3000, t0=0.0, v0=math.pi)
    verdict = classify_section(impact_points(run))
    assert verdict.label == "periodic" and verdict.period == 2


def test_stability_computation_from_the_classifier_window(window):
    """Continuation from the window's middle gives both thresholds within 1 % of theory."""
    g1, g2 = ball_period_one_theory(E)
    num1, num2 = period_one_thresholds(E, gamma_start=0.5 * (window[0] + window[1]))
    assert abs(num1 / g1 - 1) < 0.01 and abs(num2 / g2 - 1) < 0.01
