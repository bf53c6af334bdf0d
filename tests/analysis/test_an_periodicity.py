"""Tests of the section-point evidence: period, rotation order, expansion, dimension."""

import math

import numpy as np
import pytest

from chaoscam.analysis import (
    correlation_dimension,
    embed_angles,
    neighbour_expansion,
    rotation_order,
    section_period,
    stationarity_ratio,
)
from chaoscam.testsystems import circle_map_orbit, logistic_orbit, torus_section

RNG = np.random.default_rng(np.random.SeedSequence(11))


def test_period_of_a_cycle_with_noise_below_tolerance():
    """A period-5 cycle with noise at 1e-5 of its extent is found to have period 5."""
    cycle = RNG.uniform(-1, 1, size=(5, 2))
    pts = np.tile(cycle, (12, 1)) + 1e-5 * RNG.standard_normal((60, 2))
    res = section_period(pts)
    assert res.period == 5 and res.transient == 0


def test_noise_above_tolerance_hides_the_period():
    """The same cycle with noise at 1e-2 of its extent has no period at the default rtol 3e-3."""
    cycle = RNG.uniform(-1, 1, size=(5, 2))
    pts = np.tile(cycle, (12, 1)) + 1e-2 * RNG.standard_normal((60, 2))
    assert section_period(pts).period is None


def test_smallest_period_is_returned():
    """A period-2 cycle is period 2, not 4 or 6."""
    pts = np.tile([[0.0], [1.0]], (20, 1))
    assert section_period(pts).period == 2


def test_fixed_point_is_period_one_even_with_round_off():
    """Points equal up to round-off (no extent to speak of) are a fixed point: period 1."""
    pts = np.array([[0.1, 2.0]]) + 1e-13 * RNG.standard_normal((40, 2))
    res = section_period(pts)
    assert res.period == 1 and res.coincident


def test_converging_transient_is_left_out():
    """A geometric approach to a period-3 cycle is period 3 once the transient is left out."""
    cycle = np.array([[0.0, 1.0], [1.0, 0.0], [0.5, 0.5]])
    k = np.arange(90)
    pts = cycle[k % 3] + 0.1 * (0.5**k)[:, None]
    res = section_period(pts)
    assert res.period == 3 and res.transient > 0


def test_too_few_points_give_a_message():
    """Fewer than 8 points: no period test, and the result says why."""
    res = section_period(np.zeros((5, 2)))
    assert res.period is None and "needs" in res.message


def test_rotation_order_of_a_rotation_and_of_chaos():
    """A circle rotation has R ≈ 1 and ρ = its rotation; a chaotic orbit has R well below."""
    rot = rotation_order(torus_section(500))
    assert rot.consistency > 0.99
    assert math.isclose(
        min(rot.rotation_number, 1 - rot.rotation_number), 1 - (math.sqrt(5) - 1) / 2, abs_tol=0.01
    )
    assert rotation_order(logistic_orbit(3.9, 500)).consistency < 0.7


@pytest.mark.parametrize("observe", [np.cos, lambda a: a], ids=["cos", "angle"])
def test_rotation_order_of_a_scalar_by_value_or_by_delay_pairs(observe):
    """A golden rotation seen through cos θ (ordered by its delay pairs) and through θ in
    [0, 2π) (by value) rotates: R > 0.99 and ρ the golden mean (or 1 - ρ)."""
    golden = (math.sqrt(5) - 1) / 2
    rot = rotation_order(observe(np.mod(2 * math.pi * golden * np.arange(1000), 2 * math.pi)))
    assert rot.consistency > 0.99
    assert math.isclose(min(rot.rotation_number, 1 - rot.rotation_number), 1 - golden, abs_tol=0.01)


def test_embedding_removes_the_wrap_of_angles():
    """One angle written as 0.25, 1.25 and -0.75 turns is one point after embedding."""
    pts = np.array([0.25, 1.25, -0.75] * 10)
    assert section_period(pts).period == 3
    assert section_period(embed_angles(pts, [1.0])).period == 1


def test_expansion_sign():
    """Nearest neighbours separate on a chaotic orbit and keep their distance on a rotation."""
    assert neighbour_expansion(logistic_orbit(4.0, 1000)) > 0.5
    assert abs(neighbour_expansion(torus_section(1000))) < 0.05


def test_correlation_dimension_of_a_curve():
    """Points on a closed curve (quasiperiodic circle map) have D₂ ≈ 1."""
    z = embed_angles(circle_map_orbit(1000), [1.0])
    assert abs(correlation_dimension(z) - 1.0) < 0.1


def test_stationarity_ratio_detects_a_shrinking_transient():
    """A spiral converging to a point has a second-half spread far below the first half's."""
    k = np.arange(200)
    pts = np.column_stack([np.cos(k), np.sin(k)]) * (0.98**k)[:, None]
    assert stationarity_ratio(pts) < 0.5
    assert 0.5 < stationarity_ratio(torus_section(200)) < 2.0


def test_fixed_point_with_integration_jitter_at_zero_angle_is_period_one():
    """A fixed point at θ = 0 with 1e-9 jitter (no extent of its own) is period 1."""
    pts = np.column_stack([np.zeros(90), np.full(90, 0.35)]) + 1e-9 * RNG.standard_normal((90, 2))
    res = section_period(pts)
    assert res.period == 1 and res.coincident


def _period_eight(band, n_rep=12):
    """A period-8 orbit spanning 0.3 rad in θ with bands `band` wide in both coordinates."""
    theta = np.linspace(-0.15, 0.15, 8)[[0, 4, 2, 6, 1, 5, 3, 7]]
    cyc = np.column_stack([theta, np.linspace(-1.0, 1.0, 8)])
    n = 8 * n_rep
    return np.tile(cyc, (n_rep, 1)) + band * (RNG.uniform(size=(n, 2)) - 0.5)


@pytest.mark.parametrize("band", [1e-4, 3e-4])
def test_period_eight_with_bands_far_below_its_extent(band):
    """Period 8 with bands of 1e-4 and 3e-4 rad (<= 1e-3 of the 0.3 rad extent) is period 8."""
    res = section_period(_period_eight(band))
    assert res.period == 8
    assert res.jitter[0] <= band and abs(res.extent[0] - 0.3) < 2 * band


def test_bands_a_sizeable_fraction_of_the_extent_are_not_a_period():
    """Bands 1 % of the extent wide (3e-3 rad on 0.3 rad) are refused: no period."""
    assert section_period(_period_eight(3e-3)).period is None


def test_drift_near_a_resonance_is_not_a_period():
    """A rotation by 1/3 + 1e-5 drifts along its circle: its lag-3 bands are wide, no period."""
    k = np.arange(1000)
    a = 2 * math.pi * (1 / 3 + 1e-5) * k
    assert section_period(np.column_stack([np.cos(a), np.sin(a)])).period is None


def test_overlapping_bands_are_refused():
    """Two bands whose centres lie within one tolerance (atol 1e-3) do not make period 2."""
    pts = np.tile([0.0, 0.9e-3], 30) + 0.9e-3 * RNG.uniform(size=60)
    res = section_period(pts, atol=1e-3, allow_transient=False)
    assert res.period is None


def test_expansion_ignores_pairs_below_the_noise_floor():
    """A fixed point with 1e-9 jitter: growth > 0.1 on the jitter, NaN above a 1e-8 floor."""
    pts = np.array([[0.2, 0.5]]) + 1e-9 * RNG.standard_normal((300, 2))
    assert neighbour_expansion(pts) > 0.1
    assert math.isnan(neighbour_expansion(pts, atol=1e-8))
