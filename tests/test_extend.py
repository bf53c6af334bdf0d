"""extend: a resumable run made longer equals the run made that long from t = 0."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest

import chaoscam
from chaoscam import Numerics, ParameterError, Params, extend, simulate

RUN = dict(transient=3.0, seed=1, index=4, tangent=True)


def _assert_same(a, b) -> None:
    """Every output of two runs, to the bit (statistics NaN-aware)."""
    for name in ("section", "impacts"):
        pd.testing.assert_frame_equal(getattr(a, name), getattr(b, name), check_exact=True)
    assert (a.series is None) == (b.series is None)
    if a.series is not None:
        pd.testing.assert_frame_equal(a.series, b.series, check_exact=True)
    np.testing.assert_array_equal(a.jacobians, b.jacobians)
    np.testing.assert_array_equal(a.divergence, b.divergence)
    assert a.stats.keys() == b.stats.keys()
    for key, va in a.stats.items():
        assert va == b.stats[key] or (va != va and b.stats[key] != b.stats[key]), key
    assert a.final_state == b.final_state
    assert a.status == b.status


MODELS = {
    "default": Params(),
    "sigma": Params(l_lambda_sigma=0.002),
    "interval draws": Params(resample="interval", l_lambda_sigma=0.002),
    "periodic": Params(xi=0.2),
}


@pytest.mark.parametrize("series", [True, False], ids=["series", "sections"])
@pytest.mark.parametrize("params", MODELS.values(), ids=MODELS.keys())
def test_two_extensions_equal_runs_made_long_from_the_start(params, series):
    """Continued twice from kept copies (6 -> 15 -> 21 s), a run equals the runs made that
    long from t = 0, every output to the bit."""
    short = simulate(params, duration=6.0, series=series, resumable=True, **RUN)
    mid = extend(short, 15.0, resumable=True)
    long = extend(mid, 21.0)
    _assert_same(mid, simulate(params, duration=15.0, series=series, **RUN))
    _assert_same(long, simulate(params, duration=21.0, series=series, **RUN))
    dt = short.numerics.dt
    assert 0.0 < mid.settings["continued_from"] * dt < 6.0
    assert 15.0 - params.cam_period <= long.settings["continued_from"] * dt < 15.0
    assert mid.settings["duration"] == 15.0


def test_series_dropped_on_the_way_changes_nothing_else():
    """An extension that keeps no series has every other output of the run made long."""
    short = simulate(duration=6.0, series=True, resumable=True, **RUN)
    longer = extend(short, 21.0, series=False)
    assert longer.series is None
    _assert_same(longer, simulate(duration=21.0, series=False, **RUN))


def test_a_run_that_leaves_the_cam_on_the_way_or_before_the_copy():
    """xi = 0.7 leaves the cam's reach at t = 1.59 s: the 1.6 s run keeps its copy at
    7 T = 1.53 s, before that (the continuation meets it again); the 3 s run's copy is
    after it (nothing is continued)."""
    p = Params(xi=0.7)
    kw = dict(RUN, transient=0.5)
    full = simulate(p, duration=10.0, **kw)
    assert full.status.name == "LEFT_REACH" and 1.53 < full.final_state[0] < 1.6
    for short_duration, ended in ((1.6, False), (3.0, True)):
        short = simulate(p, duration=short_duration, resumable=True, **kw)
        assert bool(short.resume.status[0] != 0) is ended  # ended before the copy: not run on
        longer = extend(short, 10.0)
        _assert_same(longer, full)


def test_without_a_copy_the_run_is_simulated_again():
    """Adaptive runs and runs not kept resumable carry no copy; the extension is then a run
    from t = 0, resumable if asked (the same result)."""
    for num, resumable in ((Numerics(integrator="adaptive"), True), (Numerics(), False)):
        kw = dict(RUN, transient=1.0)
        short = simulate(Params(), num, duration=2.0, resumable=resumable, **kw)
        assert short.resume is None
        longer = extend(short, 4.0, resumable=True)
        assert longer.settings["continued_from"] is None
        assert (longer.resume is None) == (num.integrator == "adaptive")
        _assert_same(longer, simulate(Params(), num, duration=4.0, **kw))


def test_a_resumable_run_is_the_same_run():
    """Keeping the copy on the way changes no output of the run."""
    a = simulate(duration=5.0, resumable=True, **RUN)
    _assert_same(a, simulate(duration=5.0, **RUN))
    assert a.resume is not None and a.resume.step * a.numerics.dt < 5.0


@pytest.mark.parametrize(
    "kwargs, words",
    [
        (dict(duration=4.0), "must be >= the run's duration"),
        (dict(duration=float("nan")), "duration"),
        (dict(duration=8.0, series=True), "kept no time series"),
    ],
)
def test_bad_requests_say_what_is_wrong(kwargs, words):
    """A shorter or non-finite duration, or a series the run never kept: refused, named."""
    short = simulate(duration=5.0, series=False, resumable=True, **RUN)
    with pytest.raises(ParameterError, match=words):
        extend(short, **kwargs)


def test_public_name():
    """chaoscam.extend is the simulation layer's extend."""
    from chaoscam import simulation

    assert chaoscam.extend is extend is simulation.extend


@pytest.mark.parametrize("duration", [3.0, 7.0], ids=["same duration", "longer"])
def test_from_t_zero_with_the_initial_sample(duration):
    """A run recording from t = 0 (its series starts with the initial state) extended to
    its own duration or beyond."""
    kw = dict(RUN, transient=0.0)
    short = simulate(duration=3.0, resumable=True, **kw)
    _assert_same(extend(short, duration), simulate(duration=duration, **kw))
