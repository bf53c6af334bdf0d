"""The "why the paper differs" findings follow from the sweeps, not from text written in advance."""

import pandas as pd

from chaoscam.model import Params
from chaoscam.paper._findings import step_finding
from chaoscam.paper._sensitivity import (
    PAPER_K_N,
    XI_WINDOW,
    restitution_finding,
    stiffness_finding,
    xi_values,
)


def _verdicts(rows):
    return pd.DataFrame(rows, columns=["value", "label", "period"]).sort_values("value")


def test_xi_sweep_samples_table_1_and_its_neighbourhood():
    """Both grids hold Table 1's ξ and ξ ± 0.025, ± 0.05 exactly, once each, in order."""
    xi0 = Params().xi
    for quick in (True, False):
        v = xi_values(quick)
        assert v == sorted(set(v))
        for d in (-2, -1, 0, 1, 2):
            assert any(abs(x - (xi0 + d * XI_WINDOW / 2)) < 1e-12 for x in v)
        assert min(v) == 0.1 and max(v) == 0.7


def test_restitution_is_called_more_sensitive_only_when_it_is():
    """Several regimes near ξ0 against one stiffness label: 'more sensitive'; one regime near
    ξ0: the sentence says the sweep does not single the restitution out."""
    rich = _verdicts(
        [(0.1, "periodic", 1), (0.4, "periodic", 5), (0.42, "chaotic", None),
         (0.45, "periodic", 6), (0.7, "left_reach", None)]
    )  # fmt: skip
    text = restitution_finding(rich, 0.42, ["chaotic"])
    assert "takes 3 regimes (period 5, chaotic, period 6), against 1 across" in text
    assert "more sensitive to the restitution" in text
    assert "(3 values sampled)" in text

    flat = _verdicts([(0.1, "periodic", 1), (0.4, "chaotic", None), (0.45, "chaotic", None)])
    text = restitution_finding(flat, 0.42, ["chaotic"])
    assert "more sensitive" not in text
    assert "takes 1 regime (chaotic)" in text
    assert "does not single the restitution out" in text


def test_restitution_equal_to_a_rich_stiffness_range_is_not_called_more_sensitive():
    """Two regimes near ξ0 and two across the stiffness range: no claim either way."""
    v = _verdicts([(0.4, "periodic", 5), (0.42, "chaotic", None)])
    text = restitution_finding(v, 0.42, ["chaotic", "period 3"])
    assert "more sensitive" not in text
    assert "no more than the 2 across the paper's Hertz range (chaotic, period 3)" in text


def test_full_sweeps_check_the_step_and_quick_ones_do_not(tmp_path, monkeypatch):
    """The full report's sensitivity sweeps re-run their verdicts at dt/2; the quick one
    keeps its time; the rest of the classifier is the report's (the sensitivity stage's
    verdict keywords, caught at the call, before any run)."""
    from chaoscam.paper import _paper, _sensitivity
    from chaoscam.paper._stage import FULL_EXTEND_TO, QUICK_EXTEND_TO, judging

    seen = {}
    monkeypatch.setattr(
        _sensitivity, "sensitivity", lambda quick, outdir, workers=None, judge=None: judge
    )
    for quick in (True, False):
        seen[quick] = _paper.sensitivity_stage(quick, tmp_path, workers=1)
        assert seen[quick]["check_step"] is (not quick)
        assert seen[quick]["extend_to"] == judging(quick)["extend_to"]
    assert (seen[True]["extend_to"], seen[False]["extend_to"]) == (QUICK_EXTEND_TO, FULL_EXTEND_TO)


def test_step_finding_counts_checked_verdicts_and_names_the_changed():
    """Checked = a step_check value (1 held, 0 changed); undetermined and escaped runs have
    none and are not counted; no column or no value: no sentence."""
    rows = pd.DataFrame({"value": [0.1, 0.2, 0.3, 0.4], "ev_step_check": [1.0, 0.0, None, 1.0]})
    text = step_finding(rows, lambda r: f"ξ = {r.value:g}")
    assert "2 of 3 verdicts hold; 1 changes there and is undetermined (ξ = 0.2)." in text
    rows.loc[0, "ev_step_check"] = 0.0
    assert "1 of 3 verdicts hold; 2 change there and are undetermined (ξ = 0.1, ξ = 0.2)." in (
        step_finding(rows, lambda r: f"ξ = {r.value:g}")
    )
    assert step_finding(rows.assign(ev_step_check=1.0), str).endswith("4 of 4 verdicts hold.")
    assert step_finding(rows.iloc[:1].assign(ev_step_check=1.0), str).endswith(
        "1 of 1 verdict holds."
    )
    assert step_finding(rows.drop(columns="ev_step_check"), str) == ""
    assert step_finding(rows.assign(ev_step_check=None), str) == ""


def test_undetermined_is_no_regime_on_either_side():
    """Undetermined runs near ξ0 are counted as such, not as a regime; an undetermined tag
    across the Hertz range does not make it richer."""
    v = _verdicts(
        [(0.4, "periodic", 5), (0.41, "undetermined", None), (0.42, "chaotic", None)]
    )  # fmt: skip
    text = restitution_finding(v, 0.42, ["chaotic", "undetermined"])
    assert "(3 values sampled, 1 undetermined) the motion takes 2 regimes" in text
    assert "against 1 across the paper's Hertz range (chaotic)" in text


def test_banded_chaos_is_named_by_its_bands():
    """A chaotic run on 8 narrow bands reads "8-band chaos" in the sentences."""
    v = _verdicts([(0.4, "periodic", 8), (0.42, "chaotic", None)]).assign(
        ev_banded_chaos=[None, 8.0]
    )
    assert "period 8 (0.4) → 8-band chaos (0.42)" in restitution_finding(v, 0.42, [])


def _stiff(rows):
    frame = pd.DataFrame(rows, columns=["K_n", "label", "period", "ev_banded_chaos"])
    return frame.assign(value=frame["K_n"]).sort_values("K_n")


def test_stiffness_finding_judges_the_hertz_range_from_both_sweeps():
    """One regime across the range: the stiffness cannot explain the difference; period 8 and
    8-band chaos: the same motion, the label only; another regime: the stiffness matters.
    Y_f runs outside the range do not count; the paper's regimes are looked for."""
    lo, hi = PAPER_K_N
    yf = _stiff([(10.0, "periodic", 3, None), (hi / 2, "chaotic", None, 8.0)])
    one = _stiff([(lo, "chaotic", None, 8.0), (hi, "undetermined", None, None)])
    text, tags = stiffness_finding(yf, one)
    assert "(2 values) and by 1 of the Y_f values" in text
    assert "one regime there, so the paper's stiffness model cannot explain" in text
    assert "neither the paper's period 2 nor a quasiperiodic motion appears there" in text
    assert tags == ["8-band chaos", "8-band chaos", "undetermined"]

    family = _stiff([(lo, "periodic", 8, None), (hi, "chaotic", None, 8.0)])
    text, _ = stiffness_finding(yf, family)
    assert "moves between period 8 and 8-band chaos, the same motion on 8 narrow bands" in text

    other = _stiff([(lo, "periodic", 2, None), (hi, "chaotic", None, None)])
    text, _ = stiffness_finding(yf, other)
    assert "the response changes inside that range, so the stiffness model matters" in text
    assert "the paper's period 2 appears there" in text


def test_the_open_choices_sentence_is_computed_from_the_sweeps():
    """J, pivot and friction-arm sweeps and the literal damping: regimes counted together
    against the Hertz range (undetermined on neither side), the paper's period 2 looked for,
    and the choices not swept named with the values the runs used (from Params())."""
    from chaoscam.paper._findings import choices_finding

    p = Params()
    inertia = _verdicts(
        [(0.02, "periodic", 1), (0.044, "chaotic", None), (0.08, "undetermined", None)]
    )
    pivot = _verdicts([(0.085, "periodic", 2), (0.105, "periodic", 5)])
    arm = _verdicts([(0.0, "periodic", 5), (0.02, "periodic", 3)])
    damping = _verdicts([(0.42, "chaotic", None)]).assign(ev_banded_chaos=[8.0])
    text = choices_finding(inertia, pivot, arm, damping, ["8-band chaos", "undetermined"])
    assert "J from 0.02 to 0.08 kg m²" in text and f"(the solid rod's {p.inertia:.3g})" in text
    assert "period 1 (0.02) → chaotic (0.044) → undetermined (0.08)" in text
    assert f"arm from 0 to 0.02 m (default r = {p.arm:g}): period 5 (0) → period 3 (0.02)" in text
    assert "the paper's literal damping signs: 8-band chaos." in text
    assert (
        "Together 6 regimes (period 1, chaotic, period 2, period 5, period 3, 8-band chaos), "
        "against 1" in text
    )
    assert "move the motion more than the paper's stiffness does" in text
    assert "the paper's period 2 appears among them" in text
    assert f"v_chatter = {p.v_chatter:g} m/s" in text and f"resample = {p.resample}" in text

    none = pivot.iloc[:0]
    one = choices_finding(inertia.iloc[[1]], none, none, none, ["chaotic"])
    assert "no more than the paper's stiffness does" in one
