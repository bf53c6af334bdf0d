"""Tests of the thresholds table: validated, recorded once in every verdict, and in effect."""

import dataclasses
import math

import numpy as np
import pytest

from chaoscam.analysis import Thresholds, classify_section, classify_signal
from chaoscam.testsystems import logistic_orbit


def test_thresholds_are_frozen_and_validated():
    """The table is immutable; negative, NaN or inconsistent entries raise ValueError."""
    thr = Thresholds()
    with pytest.raises(dataclasses.FrozenInstanceError):
        thr.period_rtol = 1.0
    for bad in (dict(period_rtol=-1.0), dict(noise_floor=math.nan), dict(zero_one_regular=0.9)):
        with pytest.raises(ValueError):
            Thresholds(**bad)


def test_both_classifiers_record_the_table_they_used():
    """settings["thresholds"] of either classifier equals the table passed."""
    thr = Thresholds(expansion_chaotic=0.2)
    v = classify_section(logistic_orbit(4.0, 300), thresholds=thr)
    assert v.settings["thresholds"] == thr.to_dict()
    x = np.cos(2 * math.pi * np.arange(2000) * 0.01)
    w = classify_signal(x, 0.01, 1.0, thresholds=thr)
    assert w.settings["thresholds"] == thr.to_dict()


def test_rtol_keyword_overrides_the_table_and_is_recorded():
    """classify_section(rtol=...) replaces period_rtol in the recorded table."""
    v = classify_section(logistic_orbit(3.5, 100), rtol=2e-3)
    assert v.settings["thresholds"]["period_rtol"] == 2e-3 == v.settings["rtol"]


def test_a_threshold_changes_the_decision():
    """Period 2 with bands 1e-3 of the extent: periodic by default, not with period_rtol 1e-4."""
    rng = np.random.default_rng(3)
    pts = np.tile([0.0, 1.0], 50) + 1e-3 * rng.uniform(size=100)
    assert classify_section(pts).period == 2
    v = classify_section(pts, thresholds=Thresholds(period_rtol=1e-4))
    assert v.label != "periodic"


@pytest.mark.parametrize("rtol", [-1.0, "x", float("nan")])
def test_a_bad_rtol_keyword_is_named_as_given(rtol):
    """rtol (the keyword) in the message, not Thresholds.period_rtol (the table's entry)."""
    with pytest.raises(ValueError, match=r"^rtol must be a finite number >= 0"):
        classify_section(np.random.default_rng(0).normal(size=(200, 2)), rtol=rtol)
