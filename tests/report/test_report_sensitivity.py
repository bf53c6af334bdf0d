"""The "why the paper differs" findings follow from the sweeps, not from text written in advance."""

import pandas as pd

from chaoscam.experiments._sensitivity import XI_WINDOW, restitution_finding, xi_values
from chaoscam.model import Params


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
    assert "takes 3 different values (period 5, chaotic, period 6)" in text
    assert "more sensitive to the restitution" in text
    assert "(3 values sampled)" in text

    flat = _verdicts([(0.1, "periodic", 1), (0.4, "chaotic", None), (0.45, "chaotic", None)])
    text = restitution_finding(flat, 0.42, ["chaotic"])
    assert "more sensitive" not in text
    assert "takes 1 value (chaotic)" in text
    assert "does not single the restitution out" in text


def test_restitution_equal_to_a_rich_stiffness_range_is_not_called_more_sensitive():
    """Two regimes near ξ0 and two across the stiffness range: no claim either way."""
    v = _verdicts([(0.4, "periodic", 5), (0.42, "chaotic", None)])
    text = restitution_finding(v, 0.42, ["chaotic", "periodic 3"])
    assert "more sensitive" not in text
    assert "no more than across the paper's stiffness range (2)" in text
