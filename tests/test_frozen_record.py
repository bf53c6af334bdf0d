"""A Trajectory's settings and stats are read-only (chaoscam._frozen.FrozenDict): they are
the record of how the run was made, and extend_trajectory re-runs from them; an edited seed
was accepted and the extension simulated another realization as if it were this one."""

import copy
import json
import pickle

import pytest

import chaoscam
from chaoscam import Params


@pytest.fixture(scope="module")
def run():
    return chaoscam.simulate(Params(l_lambda_sigma=0.002), duration=1.0, seed=1, series=False)


@pytest.mark.parametrize(
    "change",
    [
        lambda r: r.settings.__setitem__("seed", 99),
        lambda r: r.settings.update(seed=99),
        lambda r: r.settings.pop("seed"),
        lambda r: r.stats.__setitem__("n_impacts", -1),
        lambda r: r.stats.clear(),
    ],
)
def test_the_record_cannot_be_changed(run, change):
    with pytest.raises(TypeError, match="read-only"):
        change(run)
    assert run.settings["seed"] == 1 and run.stats["n_impacts"] > 0


def test_the_record_reads_like_a_dict(run):
    assert json.loads(json.dumps(run.provenance()))["settings"]["seed"] == 1
    assert {**run.settings, "seed": 2}["seed"] == 2  # a changed copy
    for again in (pickle.loads(pickle.dumps(run)), copy.deepcopy(run)):
        assert again.settings == run.settings and again.stats == run.stats
    longer = chaoscam.extend_trajectory(run, 2.0)
    want = chaoscam.simulate(Params(l_lambda_sigma=0.002), duration=2.0, seed=1, series=False)
    assert longer.section.equals(want.section)


def test_a_verdicts_settings_are_read_only():
    """A Verdict's settings (its thresholds and each method's settings) are its record too;
    they were a plain dict on a frozen dataclass."""
    from chaoscam.analysis import Evidence, combine

    verdict = combine([Evidence("section", 3, "periodic", "3 points")], settings={"n": 5})
    with pytest.raises(TypeError, match="read-only"):
        verdict.settings["n"] = 6
    assert verdict.settings == {"n": 5}
    assert pickle.loads(pickle.dumps(verdict)).settings == {"n": 5}
