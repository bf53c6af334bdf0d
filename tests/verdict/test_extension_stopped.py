"""An undetermined verdict whose longer run ends early (the motion leaves the cam's reach)
keeps the recorded window's verdict and says that no longer window exists
(chaoscam.verdict.extension_stopped): it used to keep advising "run ~11x longer", which
cannot be done, and the ensemble tried each round again."""

import pytest

from chaoscam import Params, classify, simulate

# Chaotic for a while, then leaves the cam's reach after its section point at t = 8.17 s
# (found by a scan of omega x xi; a new-user review found the first such case): 6 s with
# 3 s recorded is undetermined, and the first extension (to 12 s recorded, t = 15 s) stops.
ESCAPING = Params(omega=30, xi=0.6)


@pytest.mark.parametrize("resumable", [True, False], ids=["continued", "run again"])
def test_classify_says_no_longer_window_exists_and_does_not_try_again(resumable):
    """The verdict is the recorded window's (3 s, not extended), its reasons say why and
    drop the advice to run longer, settings["extension_stopped"] records the status, where
    it stopped and the time wanted, and only one extension round is run."""
    rounds = []

    def progress(n, **kw):
        if kw:
            rounds.append(kw["recorded_s"])

    tr = simulate(ESCAPING, duration=6, transient=3, series=False, resumable=resumable)
    (v,) = classify(tr, progress=progress)
    reasons = "; ".join(v.reasons)
    assert v.label == "undetermined"
    assert "no longer window exists" in reasons and "LEFT_REACH" in reasons
    assert "to decide" not in reasons
    stopped = v.settings["extension_stopped"]
    assert stopped["status"] == "LEFT_REACH" and stopped["wanted_s"] == 12.0
    assert stopped["at_s"] == pytest.approx(8.17, abs=0.01)
    assert "extended" not in v.settings  # the recorded window's verdict: 3 s, not 12
    assert rounds == [12.0]  # one round: the stopped member is not extended again
