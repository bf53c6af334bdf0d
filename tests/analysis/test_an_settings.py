"""Every public analysis function refuses a setting outside its range with a ValueError (or
a TypeError for an unknown option) naming the function, the setting and the range; before,
a zero, a negative count or an infinite value gave ZeroDivisionError, IndexError or
OverflowError from inside, was taken silently, or (inside a classifier) turned the
evidence it fed into "failed" without a word."""

import math

import numpy as np
import pytest

import chaoscam.analysis as an

RNG = np.random.default_rng(0)
X = np.sin(np.arange(4000) * 0.05) + 0.01 * RNG.standard_normal(4000)
PTS = np.c_[np.tile([0.1, 0.2, 0.3], 100), np.tile([1.0, 2.0, 3.0], 100)]
JAC = np.tile(np.array([[0.5, 0.1], [0.0, 0.4]]), (200, 1, 1))


CASES = [
    (lambda: an.power_spectrum(X, 0.0), "power_spectrum: dt = 0.0 must be a finite number > 0"),
    (lambda: an.spectrum_analysis(X, math.inf), "spectrum_analysis: dt = inf must be a finite"),
    (lambda: an.spectrum_analysis(X, 0.01, min_cycles=0), "min_cycles = 0 must be a finite"),
    (lambda: an.spectrum_analysis(X, 0.01, max_order=-1), "max_order = -1 must be an integer >= 1"),
    (lambda: an.spectrum_analysis(X, 0.01, half_width=10**9), "half_width = 1000000000 bins"),
    (lambda: an.section_period(PTS, min_repeats=0), "min_repeats = 0 must be an integer >= 1"),
    (lambda: an.section_period(PTS, max_period=2.5), "max_period = 2.5 must be an integer"),
    (lambda: an.spectrum_from_jacobians(JAC, 0.2, n_batches=0), "n_batches = 0 must be an"),
    (lambda: an.spectrum_from_jacobians(JAC, 0.0), "period = 0.0 must be a finite number > 0"),
    (lambda: an.as_exponent(0.1, 0), "as_exponent: time_per_iterate = 0 must be"),
    (lambda: an.lyapunov_from_series(X, 0.01, max_points=0), "max_points = 0 must be an integer"),
    (lambda: an.lyapunov_from_series(X, -1.0), "lyapunov_from_series: dt = -1.0 must be"),
    (lambda: an.zero_one_test(X, n_c=math.inf), "zero_one_test: n_c = inf must be an integer"),
    (lambda: an.zero_one_test(X, c_range=(0.0, 1.0)), "c_range = (0.0, 1.0) must be two"),
    (lambda: an.local_maxima(X, dt=0), "local_maxima: dt = 0 must be"),
    (lambda: an.crossing_section(np.arange(5.0), np.ones((5, 2)), index=2), "index = 2 must be <"),
    (lambda: an.birkhoff_weights(0), "birkhoff_weights: n = 0 must be an integer >= 1"),
    (lambda: an.correlation_dimension(PTS, quantiles=(0.2, 0.1)), "quantiles = (0.2, 0.1)"),
    (lambda: an.neighbour_expansion(PTS, max_points=0), "max_points = 0 must be an integer"),
    (lambda: an.classify_section(PTS, exponent_time=0), "classify_section: exponent_time = 0"),
    (lambda: an.classify_section(PTS, seed=-1), "seed = -1 must be an integer >= 0"),
    (
        lambda: an.classify_signal(X, 0.01, 0.2, zero_one_per_period=math.inf),
        "zero_one_per_period = inf must be an integer",
    ),
    (
        lambda: an.classify_signal(X, 0.01, 0.2, zero_one_per_period=10**6),
        "zero_one_per_period = 1000000 must be <= 20, the samples per forcing period",
    ),
    (
        lambda: an.classify_signal(X, 0.01, 0.2, spectrum_options={"half_width": -1}),
        "classify_signal: spectrum_options: half_width = -1 must be an integer >= 0",
    ),
]


@pytest.mark.parametrize("call, message", CASES)
def test_a_setting_out_of_range_is_refused_naming_it(call, message):
    with pytest.raises(ValueError) as err:
        call()
    assert message in str(err.value)


def test_an_unknown_spectrum_option_is_refused_naming_the_known_ones():
    """A misspelt spectrum option (it gave a 'failed' spectrum evidence and a verdict
    without its spectrum) is a TypeError listing what spectrum_analysis takes."""
    with pytest.raises(TypeError, match="unknown spectrum option 'halfwidth'; .* half_width"):
        an.classify_signal(X, 0.01, 0.2, spectrum_options={"halfwidth": 2})


def test_the_limits_themselves_are_taken():
    """The edge of each range still runs: zero where zero is allowed, one sample per
    forcing period per sample, the smallest counts."""
    an.spectrum_analysis(X, 0.01, half_width=0, n_peaks=0)
    an.section_period(PTS, min_repeats=1, max_period=1)
    an.spectrum_from_jacobians(JAC, 0.2, n_batches=2)
    an.classify_signal(X, 0.01, 0.2, zero_one_per_period=20, seed=0)
    an.neighbour_expansion(PTS, min_distance=0.0)


def test_a_coarse_series_and_an_estimate_of_minus_infinity_are_taken():
    """A review's findings: a series sampled 3 times per forcing period is classified with
    the 0-1 test at its own rate (the default 4 refused it); lyapunov = -inf (a collapsed
    tangent vector) and NaN are an estimate's values, not bad settings; a band
    separation of 0 is refused by Thresholds itself (it became a 'failed' evidence)."""
    coarse = np.sin(2 * np.pi * np.arange(300) / 3.0)
    v = an.classify_signal(coarse, 0.1, 0.3)
    assert v.settings["zero_one_per_period"] == 3
    assert an.classify_section(PTS, lyapunov=-math.inf).label == "periodic"
    an.classify_section(PTS, lyapunov=math.nan)
    with pytest.raises(ValueError, match="band_separation must be > 0"):
        an.Thresholds(band_separation=0.0)
