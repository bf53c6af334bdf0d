"""An undetermined verdict whose longer run ends early (the motion leaves the cam's reach)
keeps the recorded window's verdict and says that no longer window exists, on both paths
(classify_trajectory, classify_ensemble): it used to keep advising "run ~11x longer", which
cannot be done, and the ensemble tried each round again."""

import pytest

import chaoscam
from chaoscam import Params, classify_ensemble
from chaoscam.integrate import simulate_ensemble

# Chaotic for a while, then leaves the cam's reach after its section point at t = 8.17 s
# (found by a scan of omega x xi; a new-user review found the first such case): 6 s with
# 3 s recorded is undetermined, and the first extension (to 12 s recorded, t = 15 s) stops.
ESCAPING = Params(omega=30, xi=0.6)


def _check(label, reasons, stopped):
    assert label == "undetermined"
    assert "no longer window exists" in reasons and "LEFT_REACH" in reasons
    assert "to decide" not in reasons
    assert stopped["status"] == "LEFT_REACH" and stopped["wanted_s"] == 12.0
    assert stopped["at_s"] == pytest.approx(8.17, abs=0.01)


def test_classify_trajectory_says_no_longer_window_exists():
    tr = chaoscam.simulate(ESCAPING, duration=6, transient=3, series=False, resumable=True)
    v = chaoscam.classify_trajectory(tr)
    _check(v.label, "; ".join(v.reasons), v.settings["extension_stopped"])
    assert "extended" not in v.settings  # the recorded window's verdict: 3 s, not 12


def test_classify_ensemble_says_so_and_does_not_try_again():
    rounds = []

    def progress(n, **kw):
        if kw:
            rounds.append(kw["recorded_s"])

    ens = simulate_ensemble(ESCAPING, [0], duration=6, transient=3, tangent=True, resumable=True)
    members = classify_ensemble(ens, ESCAPING, progress=progress).members
    from chaoscam._ensemble_verdicts import member_verdicts

    (v,) = member_verdicts(ens, ESCAPING)
    _check(
        members["label"].iat[0], members["reasons"].iat[0], v.verdict.settings["extension_stopped"]
    )
    assert rounds == [12.0]  # one round: the stopped member is not extended again
