"""The v_min -> 0 limit: chattering handled by the plastic hand-over, measured as it converges."""

from __future__ import annotations

import numpy as np
import pytest

from chaoscam import Params, classify, simulate


def _bands(tr, n=8):
    """Widest spread [rad] of the n sub-sequences of the section's theta_f."""
    th = tr.section["theta_f"].to_numpy()
    return max(np.ptp(th[r::n]) for r in range(n))


@pytest.fixture(scope="module")
def runs():
    kw = dict(duration=120.0, transient=60.0, series=False)
    return {
        "v_min=1e-3": simulate(Params(v_min=1e-3), **kw),
        "v_chatter=1e-5": simulate(Params(v_chatter=1e-5), **kw),
        "v_chatter=1e-6": simulate(Params(), **kw),
        "v_chatter=1e-7": simulate(Params(v_chatter=1e-7), **kw),
    }


def test_bands_converge_as_v_min_goes_to_zero(runs):
    """The withdrawn v_min = 1e-3 smears the default into a cloud; in the limit (v_min = 0)
    the 8 bands are ~100x narrower (within the classifier's band tolerance, 3e-3 of the
    extent; measured 3.1-3.4e-4 rad on 0.315) and agree within 2x whatever v_chatter."""
    limit = [_bands(runs[k]) for k in ("v_chatter=1e-5", "v_chatter=1e-6", "v_chatter=1e-7")]
    assert max(limit) < 3e-3 * np.ptp(runs["v_chatter=1e-6"].section["theta_f"])
    assert max(limit) < 2.0 * min(limit)
    assert _bands(runs["v_min=1e-3"]) > 30.0 * max(limit)


def test_verdict_is_the_same_across_the_hand_over_threshold(runs):
    """The verdict does not depend on v_chatter: chaotic (8 narrow bands, lambda_1 > 0) for
    each, and the chattering ends become rare as v_chatter -> 0 (micro-impacts take over)."""
    labels = {k: classify(runs[k], extend_to=None)[0].label for k in runs}
    assert set(labels.values()) == {"chaotic"}
    ends = [
        runs[k].stats["n_chatter_ends"]
        for k in ("v_chatter=1e-5", "v_chatter=1e-6", "v_chatter=1e-7")
    ]
    assert ends[0] > ends[1] > ends[2]


def test_impact_list_tells_micro_from_macro(runs):
    """Macro-impacts (the fast closings after a flight) are the same few hundred whatever the
    threshold; micro-impacts and chattering ends make up the rest."""
    macro = {runs[k].stats["n_macro_impacts"] for k in runs if k != "v_min=1e-3"}
    assert len(macro) == 1
    tr = runs["v_chatter=1e-6"]
    kinds = tr.impacts["kind"].value_counts()
    assert kinds["micro"] > kinds["macro"] > 0 and kinds["chatter_end"] > 0
