"""The model-level rules (chaoscam.verdict.RULES, chaoscam/verdict/_rules.py): one test per rule,
each showing the verdict the rule gives and, with the rule taken out of RULES, the verdict it
overturns (so the test fails when the rule is removed or stops doing what it checks).

On real runs the section reaches the rules quasiperiodic or thinly chaotic nowhere measured
(the labelled sets, and a 13 x 11 (omega, xi) grid at sigma = 0 and 1 mm, 10 s recorded,
extended to 60 s): the map contracts area, so it has no torus (docs/findings.md), and
classify_section already refuses a chaotic label with fewer than two chaotic votes. Those two
rules are tested on constructed sections and verdicts; the others on configurations of the
labelled set and of the tests ported with them.
"""

import numpy as np
import pytest

from chaoscam import Numerics, Params, classify, simulate
from chaoscam.verdict import RULES, _rules, judge_points


def _without(monkeypatch, name):
    """RULES with the rule ``name`` taken out, for the rest of the test."""
    rules = _rules.RULES
    assert name in [r.name for r in rules]
    monkeypatch.setattr(_rules, "RULES", tuple(r for r in rules if r.name != name))


def _verdict(changes, *, seed=0, index=0, extend_to=None):
    """The verdict on a 20 s run (10 s recorded) of ``Params(**changes)``, not extended
    unless asked."""
    run = simulate(
        Params(**changes), duration=20.0, transient=10.0, seed=seed, index=index, series=False,
        tangent=True,
    )  # fmt: skip
    (v,) = classify(run, extend_to=extend_to)
    return v


def _votes(v):
    return {e.name: e.vote for e in v.evidence}


def test_the_rules_apply_in_this_order():
    """Each rule of RULES has its test below, in the order the rules apply, and says what it
    checks."""
    assert [r.name for r in RULES] == [
        "common_noise_twins",
        "torus_needs_zero_exponent",
        "random_period_needs_contraction",
        "banded_chaos",
        "periodic_orbit",
    ]
    assert all(r.checks and callable(r.apply) for r in RULES)


# --- common_noise_twins ----------------------------------------------------------------------


def test_common_noise_twins_decide_a_random_line_length(monkeypatch):
    """xi = 0.525, sigma = 2 mm (extended to 40 s recorded): 8 narrow bands and a positive
    tangent exponent, but twins sharing the draws contract: periodic 8 with its noise width
    (the random set's truth). Twins that separate (a stand-in outcome, on sigma = 1.5 mm at
    l_lambda = 8 mm, whose 8 bands are undecided on the short run) make it 8-band chaos. The
    deterministic model runs no twins. Without the rule: the first is chaotic, the second
    undetermined."""
    from chaoscam.verdict._twins import TwinTest

    sticking = dict(xi=0.525, l_lambda_sigma=0.002)
    bands = dict(l_lambda=0.008, l_lambda_sigma=0.0015)
    v = _verdict(sticking, extend_to=40.0)
    assert (v.label, v.period, _votes(v)["twins"]) == ("periodic", 8, "not_chaotic")
    assert v.settings["noisy"]["band_width"] > 0 and _votes(v)["exponent"] == "chaotic"
    assert "twins" not in _votes(_verdict(dict(xi=0.525)))
    apart = TwinTest("separated", (50.0, 20.0), (60.0, 30.0), (None, None), 0.1, 30.0, "stand-in")
    with monkeypatch.context() as m:
        m.setattr(_rules, "twin_test", lambda *a, **k: apart)
        chaos = _verdict(bands, seed=1, index=1)
    assert (chaos.label, _votes(chaos)["twins"], _votes(chaos)["banded_chaos"]) == (
        "chaotic", "chaotic", "chaotic",
    )  # fmt: skip
    _without(monkeypatch, "common_noise_twins")
    assert _verdict(sticking, extend_to=40.0).label == "chaotic"
    assert _verdict(bands, seed=1, index=1).label == "undetermined"


# --- torus_needs_zero_exponent ---------------------------------------------------------------


def _circle(n=400):
    """A rotation by the golden mean on an ellipse: a section the section tests call a torus,
    and the rotation's Jacobian."""
    alpha = (np.sqrt(5.0) - 1.0) / 2.0
    phase = 2.0 * np.pi * alpha * np.arange(n)
    points = np.column_stack([0.05 * np.cos(phase), 0.5 * np.sin(phase)])
    c, s = np.cos(2.0 * np.pi * alpha), np.sin(2.0 * np.pi * alpha)
    return points, np.repeat(np.array([[c, -s], [s, c]])[None], n, axis=0)


def test_a_torus_needs_a_zero_exponent(monkeypatch):
    """Quasiperiodic section votes stand only when the tangent exponent confirms lambda_1 =
    0 within its interval (the rotation's exact Jacobians: lambda_1 = 0 +- 1e-17); with the
    same section and Jacobians scaled by exp(0.5 z) (lambda_1 = 0 +- 0.12 1/s, no decision)
    the verdict is undetermined and says to run longer. Without the rule: quasiperiodic."""
    points, rotation = _circle()
    z = np.random.default_rng(0).standard_normal(len(points))
    noisy = np.exp(0.5 * (z - z.mean()))[:, None, None] * rotation
    p, num = Params(), Numerics()
    exact = judge_points(points, rotation, p, num, {})
    assert exact.label == "quasiperiodic" and _votes(exact)["exponent"] == "not_chaotic"
    v = judge_points(points, noisy, p, num, {})
    assert _votes(v)["section_rotation"] == "quasiperiodic" and _votes(v)["exponent"] is None
    assert v.label == "undetermined"
    assert any("does not confirm lambda_1 = 0" in r and "run longer" in r for r in v.reasons)
    _without(monkeypatch, "torus_needs_zero_exponent")
    assert judge_points(points, noisy, p, num, {}).label == "quasiperiodic"


# --- random_period_needs_contraction ---------------------------------------------------------


def test_a_random_line_length_needs_a_contracting_exponent_for_a_period(monkeypatch):
    """sigma = 1.5 mm at l_lambda = 8 mm (seed 1, realization 1): 8 bands within the band
    tolerance but lambda_1 < 0 not confirmed, and no orbit to certify (the line length is
    random): undetermined, run longer (a longer run is chaotic). xi = 0.2, sigma = 2 mm (the
    labelled set's periodic 1) has lambda_1 < 0 beyond its interval: periodic. Without the
    rule the 8 bands would be called periodic 8. (The rule is the fallback when the twins are
    inconclusive: they are taken out here, as they would settle the bands.)"""
    _without(monkeypatch, "common_noise_twins")
    bands = dict(l_lambda=0.008, l_lambda_sigma=0.0015)
    v = _verdict(bands, seed=1, index=1)
    assert v.label == "undetermined" and _votes(v)["section_period"] == "periodic"
    assert any("the line length is random" in r and "run longer" in r for r in v.reasons)
    settled = _verdict(dict(xi=0.2, l_lambda_sigma=0.002))
    assert (settled.label, settled.period, _votes(settled)["exponent"]) == (
        "periodic", 1, "not_chaotic",
    )  # fmt: skip
    _without(monkeypatch, "random_period_needs_contraction")
    without = _verdict(bands, seed=1, index=1)
    assert (without.label, without.period) == ("periodic", 8)


# --- banded_chaos ----------------------------------------------------------------------------


@pytest.mark.parametrize(
    ("changes", "seed"),
    [(dict(l_lambda=0.008, l_lambda_sigma=0.004), 7), (dict(l_lambda=0.015), 0)],
    ids=["Fig. 8, random", "l_lambda=15mm, deterministic"],
)
def test_narrow_bands_with_a_positive_exponent_are_banded_chaos(monkeypatch, changes, seed):
    """Fig. 8's run (random line length: no orbit to look for; extended to 40 s recorded) and
    the labelled set's l_lambda = 15 mm (chaotic; no attracting period-n orbit in its bands):
    a positive exponent beyond its interval on narrow bands is n-band chaos, with the
    banded_chaos evidence. Without the rule (and the twins, which reach Fig. 8's n-band chaos
    by themselves): undetermined on the same windows (Fig. 8's section tests decide it only on
    a longer one)."""
    v = _verdict(changes, seed=seed, extend_to=40.0)
    # the stretching: the tangent's (extended run), or the twins' (Fig. 8, on the short run)
    assert v.label == "chaotic" and "chaotic" in (_votes(v)["exponent"], _votes(v).get("twins"))
    band = next(e for e in v.evidence if e.name == "banded_chaos")
    assert band.vote == "chaotic" and band.value >= 2
    orbit = next(e for e in v.evidence if e.name == "periodic_orbit")
    assert orbit.vote != "periodic"
    _without(monkeypatch, "banded_chaos")
    _without(monkeypatch, "common_noise_twins")
    assert _verdict(changes, seed=seed, extend_to=40.0).label == "undetermined"


# --- periodic_orbit --------------------------------------------------------------------------


def test_a_periodic_section_of_the_deterministic_model_needs_its_certificate(monkeypatch):
    """e = 0.02 m: the period-1 section is certified by Newton shooting (evidence
    periodic_orbit, certified). (omega, xi) = (26, 0.3), seed 1: 7 bands within the band
    tolerance, but the period-7 orbit there is unstable on the grid and on refined steps:
    undetermined, run longer (the extended run is chaotic). Without the rule: periodic 1
    with no orbit evidence, and periodic 7."""
    certified = _verdict(dict(e=0.02))
    assert (certified.label, certified.period) == ("periodic", 1)
    orbit = next(e for e in certified.evidence if e.name == "periodic_orbit")
    assert orbit.vote == "periodic" and orbit.detail.startswith("certified")
    unstable = _verdict(dict(omega=26.0, xi=0.3), seed=1)
    assert unstable.label == "undetermined"
    assert any("the orbit found is unstable" in r for r in unstable.reasons)
    _without(monkeypatch, "periodic_orbit")
    bare = _verdict(dict(e=0.02))
    assert (bare.label, bare.period) == ("periodic", 1) and "periodic_orbit" not in _votes(bare)
    assert _verdict(dict(omega=26.0, xi=0.3), seed=1).label == "periodic"
