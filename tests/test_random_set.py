"""The classifier against the random labelled set (sigma > 0), run as a user would.

The truth of each configuration was settled by analyses/random_set.py from measurements the
classifier never sees: twin runs sharing the draws (1e-6 and 1e-8 rad apart, from three points,
100 s) at dt and dt/2, the section's clusters and the tangent exponent at both steps.
Unsettled configurations are not in the set. ``random_holdout.json`` holds a second set settled
by the same script (``--holdout``) after the twin rule was built, on configurations it had never
seen; it is tested the same way. Here each one is simulated for 120 s (60 s
transient) and classified through the command line; the label and period must match.
Configurations whose settling was slow (long sticking phases) run only with -m slow.
"""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from ._settled import classified_through_the_cli

DATA = Path(__file__).parent / "data"
TABLE = json.loads((DATA / "random_set.json").read_text())
SETTLED = {k: v for k, v in TABLE.items() if v["label"] != "unsettled"}
HOLDOUT = {
    f"holdout:{k}": v
    for k, v in json.loads((DATA / "random_holdout.json").read_text()).items()
    if v["label"] != "unsettled"
}
SLOW_SETTLING_S = 60.0


def _cases():
    for name, row in {**SETTLED, **HOLDOUT}.items():
        marks = [pytest.mark.slow] if row["wall_time_s"] > SLOW_SETTLING_S else []
        yield pytest.param(name, row, id=name, marks=marks)


def test_the_set_is_large_and_varied():
    """At least 8 settled random configurations: synchronised and chaotic, with and without
    sticking (a plastic closure in the settling run's twins: an exact zero distance)."""
    labels = [r["label"] for r in SETTLED.values()]
    sticking = [any(t["ratio"] == 0 for t in r["dt"]["sync"]) for r in SETTLED.values()]
    assert len(SETTLED) >= 8 and all(r["params"]["l_lambda_sigma"] > 0 for r in SETTLED.values())
    assert labels.count("chaotic") >= 2 and labels.count("periodic") >= 2
    assert any(sticking) and not all(sticking)


@pytest.mark.parametrize(("name", "row"), list(_cases()))
def test_classifier_agrees_with_the_settled_random_label(name, row, tmp_path, capsys):
    """120 s run through `chaoscam simulate` and `chaoscam classify`: the settled label."""
    verdict = classified_through_the_cli(row["params"], tmp_path, capsys)
    assert (verdict["label"], verdict["period"]) == (row["label"], row["period"]), (
        f"{name}: settled {row['label']} {row['period']} ({row['why']}); "
        f"got {verdict['label']} {verdict['period']}: {verdict['reasons']}"
    )
