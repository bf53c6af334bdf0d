"""The classifier against the labelled set of model configurations, run as a user would.

The truth of each configuration was settled by analyses/labelled_set.py from measurements
the classifier never sees (300 s runs at dt and dt/2, band structure, tangent exponent,
Newton shooting, a direct 1e-8 rad perturbation test); unsettled configurations are not in
the set. Here each one is simulated for 120 s (60 s transient) and classified through the
command line, and the label and period must match. Configurations whose settling runs were
slow (sticking with long chattering phases) run only with -m slow.

``holdout_set.json`` holds a second set settled by the same script (``--holdout``) after the
classifier was built, on configurations it had never seen and that were not used to tune it;
it is tested the same way.
"""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from ._settled import classified_through_the_cli

DATA = Path(__file__).parent / "data"
TABLE = json.loads((DATA / "labelled_set.json").read_text())
SETTLED = {k: v for k, v in TABLE.items() if v["label"] != "unsettled"}
HOLDOUT = {
    f"holdout:{k}": v
    for k, v in json.loads((DATA / "holdout_set.json").read_text()).items()
    if v["label"] != "unsettled"
}
SLOW_SETTLING_S = 40.0  # settling wall time above which a case is marked slow


def _cases():
    for name, row in {**SETTLED, **HOLDOUT}.items():
        marks = [pytest.mark.slow] if row["wall_time_s"] > SLOW_SETTLING_S else []
        yield pytest.param(name, row, id=name, marks=marks)


def test_the_set_is_large_and_varied():
    """At least 12 settled configurations, with several periods, chaos, and sticking."""
    labels = [r["label"] for r in SETTLED.values()]
    periods = {r["period"] for r in SETTLED.values() if r["label"] == "periodic"}
    assert len(SETTLED) >= 12
    assert "chaotic" in labels and len(periods) >= 3


@pytest.mark.parametrize(("name", "row"), list(_cases()))
def test_classifier_agrees_with_the_settled_label(name, row, tmp_path, capsys):
    """120 s run through `chaoscam simulate` and `chaoscam classify`: the settled label."""
    verdict = classified_through_the_cli(row["params"], tmp_path, capsys)
    assert (verdict["label"], verdict["period"]) == (row["label"], row["period"]), (
        f"{name}: settled {row['label']} {row['period']} ({row['why']}); "
        f"classifier {verdict['label']} {verdict['period']}: {verdict['reasons']}"
    )


def test_the_holdout_set_is_new_and_varied():
    """The held-out configurations are not in the labelled set, and span periodic and chaos."""
    names = {k.removeprefix("holdout:") for k in HOLDOUT}
    assert not names & set(TABLE)
    assert not {json.dumps(r["params"], sort_keys=True) for r in HOLDOUT.values()} & {
        json.dumps(r["params"], sort_keys=True) for r in TABLE.values()
    }
    assert len(HOLDOUT) >= 10 and {"periodic", "chaotic"} <= {r["label"] for r in HOLDOUT.values()}
