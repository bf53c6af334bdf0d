"""Tests of the evidence builders: the 0–1 test votes only where its validity rule holds."""

import numpy as np

from chaoscam.analysis import Thresholds, zero_one_evidence
from chaoscam.testsystems import logistic_orbit


def test_zero_one_votes_when_both_halves_agree():
    """Logistic r = 4 (1000 points) votes chaotic, period 3 (r = 3.83) not chaotic."""
    assert zero_one_evidence("z", logistic_orbit(4.0, 1000), "x", 0).vote == "chaotic"
    assert zero_one_evidence("z", logistic_orbit(3.83, 1000), "x", 0).vote == "not_chaotic"


def test_zero_one_abstains_below_the_minimum_length():
    """199 chaotic points (< zero_one_min_points = 200) abstain and say to run longer."""
    e = zero_one_evidence("z", logistic_orbit(4.0, 199), "x", 0)
    assert e.vote is None and "longer" in e.detail


def test_zero_one_abstains_when_k_changes_with_length():
    """Periodic then chaotic: K(first half) ≈ 0, K(whole) ≈ 1, so K is not used."""
    x = np.concatenate([logistic_orbit(3.2, 600), logistic_orbit(4.0, 400)])
    e = zero_one_evidence("z", x, "x", 0)
    assert e.vote is None and e.value > 0.8 and "not converged" in e.detail


def test_zero_one_minimum_length_is_a_threshold():
    """With zero_one_min_points = 1000 the same 1000-point chaotic orbit still votes, 999 not."""
    thr = Thresholds(zero_one_min_points=1000)
    assert zero_one_evidence("z", logistic_orbit(4.0, 1000), "x", 0, thr).vote == "chaotic"
    assert zero_one_evidence("z", logistic_orbit(4.0, 999), "x", 0, thr).vote is None
