"""Tests of the verdict and of how votes combine."""

import json

import pytest

from chaoscam.analysis import Evidence, Verdict, combine


def ev(name, vote, value=0.0):
    return Evidence(name, value, vote, "test")


def test_agreeing_votes_give_the_label():
    """Votes that all admit 'chaotic', one naming it, give 'chaotic'."""
    v = combine([ev("a", "chaotic"), ev("b", "not_periodic"), ev("c", None)])
    assert v.label == "chaotic" and v.period is None and v.reasons == ()


def test_disagreement_is_undetermined_with_reasons():
    """A periodic and a chaotic vote give 'undetermined' and name both votes."""
    v = combine([ev("spectrum", "periodic"), ev("zero_one", "chaotic")])
    assert v.label == "undetermined"
    assert "spectrum: periodic" in v.reasons[0] and "zero_one: chaotic" in v.reasons[0]


def test_exclusions_alone_do_not_make_a_label():
    """'not_chaotic' and 'not_periodic' leave only quasiperiodic, yet without direct support."""
    v = combine([ev("a", "not_chaotic"), ev("b", "not_periodic")])
    assert v.label == "undetermined" and "directly" in v.reasons[0]


def test_no_votes_is_undetermined():
    """When every method abstains the verdict is undetermined."""
    assert combine([ev("a", None)]).label == "undetermined"


def test_period_from_section_and_consistent_spectrum():
    """A spectral period dividing the section's is consistent; the section's is kept."""
    v = combine(
        [ev("section_period", "periodic", 4), ev("spectrum", "periodic")],
        periods={"section_period": 4, "spectrum": 2},
    )
    assert v.label == "periodic" and v.period == 4


def test_inconsistent_periods_are_undetermined():
    """A spectral period that does not divide the section's makes the verdict undetermined."""
    v = combine(
        [ev("section_period", "periodic", 4), ev("spectrum", "periodic")],
        periods={"section_period": 4, "spectrum": 3},
    )
    assert v.label == "undetermined"


def test_to_dict_is_json_serialisable():
    """to_dict has keys label, period, evidence, reasons and survives json.dumps (NaN: null)."""
    v = combine(
        [ev("a", "periodic", float("nan")), ev("b", "periodic", 3)], periods={"section_a": 3}
    )
    d = v.to_dict()
    assert set(d) == {"label", "period", "evidence", "reasons"}
    back = json.loads(json.dumps(d, allow_nan=False))
    assert back["period"] == 3 and back["evidence"][0]["value"] is None


def test_unknown_labels_and_votes_are_rejected():
    """Labels and votes outside the documented sets raise ValueError."""
    with pytest.raises(ValueError):
        Evidence("a", 0.0, "chaos", "")
    with pytest.raises(ValueError):
        Verdict("maybe", None, ())


def test_verdict_is_frozen():
    """A verdict cannot be modified after it is made."""
    v = combine([ev("a", "chaotic")])
    with pytest.raises(AttributeError):
        v.label = "periodic"


def test_used_names_the_evidence_that_voted():
    """Verdict.used lists the evidence with a vote, in order, and leaves out abstentions."""
    v = combine([ev("a", "periodic", 2), ev("b", None), ev("c", "not_chaotic")], {"section_a": 2})
    assert v.used == ("a", "c")
