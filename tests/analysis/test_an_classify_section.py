"""Decisions of classify_section on sections with jitter, tori, chaos and a given exponent."""

import math
from types import SimpleNamespace

import numpy as np
import pytest

from chaoscam.analysis import classify_section, embed_angles
from chaoscam.testsystems import (
    circle_map_orbit,
    henon_orbit,
    logistic_orbit,
    torus_section,
)

RNG = np.random.default_rng(np.random.SeedSequence(7))
GOLDEN = (math.sqrt(5) - 1) / 2


def by_name(v):
    return {e.name: e for e in v.evidence}


def test_jittery_fixed_point_is_period_one_and_the_other_tests_abstain():
    """A fixed point at θ = 0 with 1e-9 jitter is periodic 1; expansion, 0-1, Birkhoff abstain."""
    pts = np.column_stack([np.zeros(300), np.full(300, 0.35)])
    v = classify_section(pts + 1e-9 * RNG.standard_normal((300, 2)))
    assert (v.label, v.period) == ("periodic", 1)
    assert v.used == ("section_period",)
    ev = by_name(v)
    assert all(ev[k].vote is None for k in ("section_expansion", "section_zero_one"))


def test_period_eight_with_small_bands_is_periodic_eight_and_reports_them():
    """Period 8, bands 1e-4 rad on an orbit of 0.3 rad: periodic 8, bands and extent reported."""
    theta = np.linspace(-0.15, 0.15, 8)[[0, 4, 2, 6, 1, 5, 3, 7]]
    cyc = np.column_stack([theta, np.linspace(-1.0, 1.0, 8)])
    pts = np.tile(cyc, (12, 1)) + 1e-4 * (RNG.uniform(size=(96, 2)) - 0.5)
    v = classify_section(pts)
    assert (v.label, v.period) == ("periodic", 8)
    detail = by_name(v)["section_period"].detail
    assert "bands [" in detail and "extent [0.3" in detail


def test_golden_rotation_is_quasiperiodic_with_its_rotation_number():
    """Rotation by the golden mean (cos, sin), 2001 points: quasiperiodic, ρ to 1e-8."""
    a = 2 * math.pi * GOLDEN * np.arange(2001)
    v = classify_section(np.column_stack([np.cos(a), np.sin(a)]))
    assert v.label == "quasiperiodic", v.reasons
    e = by_name(v)["section_birkhoff"]
    assert e.vote == "quasiperiodic" and abs(e.value - GOLDEN) < 1e-8


def test_circle_map_is_quasiperiodic_by_birkhoff():
    """Sine circle map (K = 0.5, golden Ω), 1000 points: the Birkhoff evidence votes quasi."""
    v = classify_section(circle_map_orbit(1000), angle_periods=[1.0])
    assert v.label == "quasiperiodic"
    assert by_name(v)["section_birkhoff"].vote == "quasiperiodic"


@pytest.mark.parametrize(
    "orbit",
    [logistic_orbit(4.0, 1000), henon_orbit(1000), henon_orbit(1000)[:, 0]],
    ids=["logistic", "henon", "henon_x"],
)
def test_chaos_is_chaotic_with_two_votes_and_birkhoff_abstains(orbit):
    """Logistic r = 4, Hénon and its x alone: chaotic from >= 2 votes; Birkhoff does not vote."""
    v = classify_section(orbit)
    assert v.label == "chaotic", v.reasons
    assert sum(e.vote == "chaotic" for e in v.evidence) >= 2
    assert by_name(v)["section_birkhoff"].vote is None


@pytest.mark.parametrize(
    "observe",
    [
        np.cos,
        lambda a: a / (2 * math.pi),
        lambda a: np.cos(a) + np.cos(2 * a + 1) + np.cos(3 * a + 2),
    ],
    ids=["cos", "angle", "three_harmonics"],
)
def test_torus_seen_through_a_scalar_is_quasiperiodic(observe):
    """A golden rotation seen through cos θ, θ itself, or three harmonics (their delay pairs
    cross themselves, 3 delays do not): quasiperiodic, no expansion (|g| < 0.05)."""
    v = classify_section(observe(np.mod(2 * math.pi * GOLDEN * np.arange(2000), 2 * math.pi)))
    assert v.label == "quasiperiodic", v.reasons
    assert abs(by_name(v)["section_expansion"].value) < 0.05


@pytest.mark.parametrize(
    ("x", "period"),
    [(np.cos(2 * math.pi * np.arange(600) / 3), 3), (np.cos(math.pi * np.arange(600) / 2), 4)],
    ids=["cos_3", "cos_4"],
)
def test_periodic_scalar_with_equal_values_is_periodic(x, period):
    """cos(2πk/3) and cos(2πk/4) repeat a value within each period (their states do not):
    periodic 3 and 4, not a torus."""
    v = classify_section(x)
    assert (v.label, v.period) == ("periodic", period), v.reasons


def test_a_single_chaotic_vote_is_not_enough_and_says_what_to_run():
    """150 chaotic points (only the expansion votes): undetermined, run longer or pass λ."""
    v = classify_section(logistic_orbit(4.0, 150))
    assert v.label == "undetermined"
    assert "only section_expansion" in v.reasons[0]
    assert "longer" in v.reasons[-1] and "exponent" in v.reasons[-1]


def test_positive_exponent_decides_a_short_chaotic_section():
    """60 chaotic points with λ = 0.49 ± 0.01 per iterate: chaotic, the exponent used."""
    v = classify_section(logistic_orbit(3.9, 60), exponent=(0.49, 0.01))
    assert v.label == "chaotic" and "exponent" in v.used


def test_exponent_object_in_per_second_units_is_scaled():
    """An object with exponent 2.0 ± 0.05 1/s and a 0.25 s iterate is 0.5 ± 0.0125 per iterate."""
    obj = SimpleNamespace(exponent=2.0, stderr=0.05, n_intervals=300)
    v = classify_section(logistic_orbit(3.9, 60), exponent=obj, exponent_time=0.25)
    assert v.label == "chaotic"
    assert v.settings["exponent"] == dict(exponent=0.5, stderr=0.0125, n_intervals=300)


def test_periodic_section_with_a_clearly_positive_exponent_is_a_conflict():
    """Period 4 (r = 3.5) with λ = 0.3 ± 0.01: undetermined, the disagreement named."""
    v = classify_section(logistic_orbit(3.5, 200), exponent=(0.3, 0.01))
    assert v.label == "undetermined" and "disagrees" in v.reasons[0]


def test_sticking_orbit_exponent_minus_inf_agrees_with_a_period():
    """Period 4 with λ = -inf (zero Floquet multiplier): periodic 4."""
    v = classify_section(logistic_orbit(3.5, 200), exponent=(-math.inf, math.nan))
    assert (v.label, v.period) == ("periodic", 4)


def test_torus_with_zero_exponent_is_quasiperiodic_negative_is_a_conflict():
    """Circle map with λ = 0 ± 0.001 is quasiperiodic; with λ = -0.2 ± 0.01 undetermined."""
    pts = embed_angles(circle_map_orbit(1000), [1.0])
    assert classify_section(pts, exponent=(0.0, 0.001)).label == "quasiperiodic"
    v = classify_section(pts, exponent=(-0.2, 0.01))
    assert v.label == "undetermined" and any("negative" in r for r in v.reasons)


def test_short_torus_section_with_undecided_exponent_says_what_to_run():
    """90 torus points and λ = 0.02 ± 0.01: undetermined; run longer and run the exponent longer."""
    v = classify_section(torus_section(90), exponent=(0.02, 0.01, 100))
    assert v.label == "undetermined"
    assert "run ~3x longer" in v.reasons[-1] and "exponent longer" in v.reasons[-1]
