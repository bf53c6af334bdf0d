"""Tests of the exponent evidence: a largest exponent judged by its confidence interval."""

import math
from types import SimpleNamespace

import pytest

from chaoscam.analysis import Thresholds, as_exponent, exponent_evidence


def test_positive_interval_votes_chaotic():
    """λ = 0.4 ± 0.01 per iterate (3σ interval far above 0.01) votes chaotic."""
    assert exponent_evidence(0.4, 0.01).vote == "chaotic"


@pytest.mark.parametrize("lam", [0.0, -0.3])
def test_zero_or_negative_interval_votes_not_chaotic(lam):
    """λ = 0 ± 0.001 and λ = -0.3 ± 0.01 both vote not chaotic."""
    assert exponent_evidence(lam, 0.001 if lam == 0 else 0.01).vote == "not_chaotic"


def test_minus_infinity_is_decisively_not_chaotic():
    """λ = -inf (a zero Floquet multiplier) votes not chaotic even without a stderr."""
    e = exponent_evidence(-math.inf, math.nan)
    assert e.vote == "not_chaotic" and "Floquet" in e.detail


def test_straddling_interval_abstains_and_says_how_much_longer():
    """λ = 0.05 ± 0.02 over 100 intervals: the interval contains 0.01: abstain, run 2.25x
    longer (225 intervals); a factor of 10 and more is rounded up to a whole one, and a
    factor near 1 is not (it read "~2x longer (46 -> 52 intervals)")."""
    e = exponent_evidence(0.05, 0.02, 100)
    assert e.vote is None
    assert "~2.25x longer" in e.detail and "225 intervals" in e.detail
    e = exponent_evidence(0.02, 0.02, 46)  # (3 x 0.02 / 0.01)^2 = 36
    assert "~36x longer" in e.detail and "(46 -> 1656 intervals)" in e.detail
    e = exponent_evidence(0.05, 0.01417, 46)  # (3 x 0.01417 / 0.04)^2 = 1.13
    assert "~1.13x longer" in e.detail and "(46 -> 52 intervals)" in e.detail


def test_missing_stderr_or_nan_abstains():
    """No stderr, or a NaN exponent, abstains with a reason."""
    assert exponent_evidence(0.4, None).vote is None
    assert exponent_evidence(math.nan, 0.1).vote is None


def test_thresholds_move_the_decision():
    """With exponent_zero = 0.5 the same λ = 0.4 ± 0.01 is no longer chaotic."""
    assert exponent_evidence(0.4, 0.01, thresholds=Thresholds(exponent_zero=0.5)).vote == (
        "not_chaotic"
    )


def test_as_exponent_accepts_tuples_objects_and_scales():
    """(λ, σ), (λ, σ, n) and objects with .exponent/.stderr give the same numbers, scaled."""
    assert as_exponent((0.2, 0.01)) == (0.2, 0.01, None)
    assert as_exponent((0.2, 0.01, 50)) == (0.2, 0.01, 50)
    obj = SimpleNamespace(exponent=2.0, stderr=0.1, n_intervals=400)
    lam, se, n = as_exponent(obj, time_per_iterate=0.5)
    assert (lam, se, n) == (1.0, 0.05, 400)
    lam, se, n = as_exponent(0.3)
    assert lam == 0.3 and math.isnan(se) and n is None
