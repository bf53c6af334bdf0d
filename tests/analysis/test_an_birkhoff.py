"""Tests of the weighted Birkhoff averages: converged digits and the rotation number."""

import math

import numpy as np
import pytest

from chaoscam.analysis import birkhoff_weights, embed_angles, weighted_birkhoff
from chaoscam.testsystems import (
    circle_map_orbit,
    circle_map_rotation_number,
    henon_orbit,
    logistic_orbit,
)

GOLDEN = (math.sqrt(5) - 1) / 2


def rotation(n, rho=GOLDEN):
    """The rotation by `rho` turns, embedded as (cos, sin)."""
    a = 2 * math.pi * rho * np.arange(n)
    return np.column_stack([np.cos(a), np.sin(a)])


def test_weights_are_a_normalised_symmetric_bump():
    """The weights sum to 1, are symmetric, and vanish to machine precision at both ends."""
    w = birkhoff_weights(500)
    assert math.isclose(w.sum(), 1.0, rel_tol=1e-14)
    assert np.allclose(w, w[::-1], rtol=1e-9, atol=0)
    assert w[0] < 1e-100 < w[250]


def test_golden_rotation_converges_to_many_digits_and_gives_its_rotation_number():
    """Rotation by the golden mean, 2001 points: >= 10 digits and ρ correct to 1e-8."""
    res = weighted_birkhoff(rotation(2001))
    assert res.digits >= 10
    assert abs(res.rotation_number - GOLDEN) < 1e-8


def test_rotation_number_keeps_the_orientation():
    """The same rotation run backwards has rotation number 1 - ρ."""
    res = weighted_birkhoff(rotation(2001)[::-1])
    assert abs(res.rotation_number - (1 - GOLDEN)) < 1e-8


def test_circle_map_is_quasiperiodic_to_many_digits():
    """Sine circle map K = 0.5, Ω = golden mean, 1001 points: >= 8 digits, ρ of its lift."""
    res = weighted_birkhoff(embed_angles(circle_map_orbit(1001), [1.0]))
    assert res.digits >= 8
    rho = circle_map_rotation_number(n=200_000)  # itself within 1 / n
    assert abs(res.rotation_number - rho) < 1e-5


@pytest.mark.parametrize(
    "orbit", [logistic_orbit(4.0, 2001), henon_orbit(2001)], ids=["logistic", "henon"]
)
def test_chaotic_orbits_converge_slowly(orbit):
    """Chaotic orbits (logistic r = 4, Hénon) reach fewer than 3 digits with 2001 points."""
    assert weighted_birkhoff(orbit).digits < 3


def test_digits_grow_with_length_only_for_the_torus():
    """From 201 to 2001 points the circle map gains >= 4 digits, Hénon < 1.5."""
    cm = [weighted_birkhoff(embed_angles(circle_map_orbit(n), [1.0])).digits for n in (201, 2001)]
    he = [weighted_birkhoff(henon_orbit(n)).digits for n in (201, 2001)]
    assert cm[1] - cm[0] >= 4 and he[1] - he[0] < 1.5


def test_too_few_points_give_a_message():
    """Fewer than 17 points: digits NaN and a message, not an exception."""
    res = weighted_birkhoff(rotation(10))
    assert math.isnan(res.digits) and "need" in res.message


def test_a_rational_rotation_number_is_not_a_torus_vote():
    """The Birkhoff evidence abstains on a converged rotation number within 1e-8 of p/q
    (q <= N/2): a periodic orbit has one too (the cam model at xi = 0.30, period 30, gave
    0.6000000004 and a torus vote); the golden rotation still votes quasiperiodic."""
    from chaoscam.analysis import Thresholds
    from chaoscam.analysis._evidence import birkhoff_evidence

    thr = Thresholds()
    for rho, vote in (
        (0.6 + 4e-10, None),
        (GOLDEN, "quasiperiodic"),
        (0.6 + 1e-6, "quasiperiodic"),
    ):
        e = birkhoff_evidence("section_birkhoff", rotation(450, rho), thr)
        assert e.vote == vote, (rho, e.detail)
    e = birkhoff_evidence("section_birkhoff", rotation(450, 0.6 + 4e-10), thr)
    assert "= 3/5 to within 1e-08" in e.detail
