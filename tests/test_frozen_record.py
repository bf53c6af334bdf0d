"""A Solution's settings are read-only (chaoscam._util.FrozenDict) and its stats cannot be
changed through the dict they are read as: they are the record of how the run was made, and
extend re-runs from them; an edited seed was accepted and the extension simulated another
realization as if it were this one."""

import copy
import json
import pickle

import numpy as np
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
    ],
)
def test_the_record_cannot_be_changed(run, change):
    """Editing the settings in place is refused."""
    with pytest.raises(TypeError, match="read-only"):
        change(run)
    assert run.settings["seed"] == 1 and run.stats["n_impacts"] > 0


@pytest.mark.parametrize(
    "change",
    [lambda s: s.__setitem__("n_impacts", -1), lambda s: s.clear()],
)
def test_the_stats_read_from_the_record_do_not_change_it(run, change):
    """The stats are read from the members table each time: a change to the dict read
    leaves the record (and the next read) as it was."""
    before = dict(run.stats)
    stats = run.stats
    try:
        change(stats)
    except TypeError:  # a read-only dict: as good
        pass
    assert run.stats == before and run.stats["n_impacts"] > 0


def test_the_record_reads_like_a_dict(run):
    """The record serialises, copies, pickles and is what an extension re-runs from."""
    assert json.loads(json.dumps(run.provenance()))["settings"]["seed"] == 1
    assert {**run.settings, "seed": 2}["seed"] == 2  # a changed copy
    for again in (pickle.loads(pickle.dumps(run)), copy.deepcopy(run)):
        assert again.settings == run.settings and again.stats == run.stats
    longer = chaoscam.extend(run, 2.0)
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


@pytest.mark.filterwarnings("ignore:lambda_1.*too few")  # 2 s: enough to hold arrays
def test_a_results_arrays_are_read_only():
    """A result's arrays are read-only views (chaoscam._util.freeze_fields): a Solution's
    Jacobians, the spectrum from them and the 0-1 test's K_c could be changed in place on a
    frozen result, and a later spectrum or report would read the changed numbers."""
    from chaoscam.analysis import section_period, zero_one_test

    run = chaoscam.simulate(duration=2.0, series=False, tangent=True)
    spectrum = chaoscam.lyapunov_spectrum(run)
    zero_one = zero_one_test(np.sin(0.3 * np.arange(400)))
    period = section_period(np.tile([[0.1, 0.2], [0.3, 0.4]], (20, 1)))
    arrays = {
        "jacobians": run.jacobians,
        "divergence": run.divergence,
        "exponents": spectrum.exponents,
        "k_c": zero_one.k_c,
        "tolerance": period.tolerance,
    }
    for name, a in arrays.items():
        with pytest.raises(ValueError, match="read-only"):
            a[0] = 0.0
        assert not a.flags.writeable, name
    with pytest.raises(TypeError, match="read-only"):
        spectrum.settings["n"] = 1
    assert np.isfinite(chaoscam.lyapunov_spectrum(run).exponents).all()  # still readable


def test_nested_records_are_frozen_too():
    """A sweep's config["base"] was a plain dict inside the frozen record: changing it
    changed what replay simulates (found by an API review). Nested dicts are read-only; a
    copy is changeable."""
    from chaoscam.sweep import regime_map

    m = regime_map("xi=0.2", "l_lambda_sigma=0", realizations=1, duration=0.3, workers=1)
    with pytest.raises(TypeError, match="read-only"):
        m.config["base"]["omega"] = 40.0
    with pytest.raises(TypeError, match="read-only"):
        m.config["x"]["name"] = "omega"
    copy = dict(m.config["base"])
    copy["omega"] = 40.0
    assert m.config["base"]["omega"] != 40.0


def test_freezing_keeps_namedtuples_and_reaches_lists_of_lists():
    """A namedtuple holding a dict was rebuilt from a generator (a TypeError); dicts inside a
    list of lists stayed writable."""
    from collections import namedtuple

    from chaoscam._util import FrozenDict

    Point = namedtuple("Point", "x y")
    rec = FrozenDict({"p": Point(1, {"a": 1}), "deep": [[{"b": 2}]]})
    assert rec["p"].x == 1
    with pytest.raises(TypeError, match="read-only"):
        rec["deep"][0][0]["b"] = 3
