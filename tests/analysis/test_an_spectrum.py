"""Tests of the spectrum analysis."""

import math

import numpy as np
import pytest

from chaoscam.analysis import power_spectrum, spectrum_analysis
from chaoscam.testsystems import GOLDEN, torus_signal

DT = 0.01
T = np.arange(20_000) * DT


def test_periodogram_peaks_at_the_sine_frequency():
    """The Hann periodogram of a sine peaks in the bin of its frequency."""
    f, p = power_spectrum(np.sin(2 * math.pi * 1.3 * T), DT)
    assert abs(f[np.argmax(p)] - 1.3) <= f[1]


def test_linear_trend_is_removed():
    """Adding a linear trend does not change the periodogram beyond DC leakage."""
    x = np.sin(2 * math.pi * 1.3 * T)
    _, p1 = power_spectrum(x, DT)
    _, p2 = power_spectrum(x + 3.0 + 0.5 * T, DT)
    assert np.allclose(p1[5:], p2[5:], rtol=1e-6, atol=1e-9 * p1.max())


def test_harmonics_of_the_forcing_are_period_one():
    """A signal made of forcing harmonics is periodic with period 1."""
    x = np.cos(2 * math.pi * T) + 0.3 * np.sin(2 * math.pi * 3 * T + 0.4)
    res = spectrum_analysis(x, DT, forcing_frequency=1.0)
    assert res.model == "periodic" and res.period == 1


@pytest.mark.parametrize("n", [2, 3, 5])
def test_subharmonic_gives_the_period(n):
    """A subharmonic f/n holding power makes the period n forcing periods."""
    x = np.cos(2 * math.pi * T) + 0.2 * np.cos(2 * math.pi * T / n + 1.0)
    res = spectrum_analysis(x, DT, forcing_frequency=1.0)
    assert res.model == "periodic" and res.period == n


def test_unforced_fundamental_is_found_below_the_strongest_line():
    """Without forcing, the fundamental may lie below the strongest peak (its 2nd harmonic)."""
    x = 0.3 * np.cos(2 * math.pi * 0.7 * T) + np.cos(2 * math.pi * 1.4 * T)
    res = spectrum_analysis(x, DT)
    assert res.model == "periodic" and math.isclose(res.base_frequencies[0], 0.7, rel_tol=1e-3)


def test_two_incommensurate_frequencies_are_quasiperiodic():
    """The torus signal (bases 1 and the golden mean) is quasiperiodic with those bases."""
    res = spectrum_analysis(torus_signal(T), DT, forcing_frequency=1.0)
    assert res.model == "quasiperiodic"
    assert math.isclose(res.base_frequencies[1], GOLDEN, rel_tol=1e-3)


def test_white_noise_is_broadband():
    """White noise leaves most of its power outside any line model."""
    x = np.random.default_rng(np.random.SeedSequence(4)).standard_normal(T.size)
    res = spectrum_analysis(x, DT)
    assert res.model == "broadband" and res.residual_fraction > 0.5
    assert res.spectral_entropy > 0.9


def test_fractions_are_fractions():
    """Line fractions and entropy lie in [0, 1]."""
    res = spectrum_analysis(torus_signal(T), DT)
    for v in (res.line_fraction, res.periodic_fraction, res.spectral_entropy):
        assert 0.0 <= v <= 1.0 + 1e-12


def test_degenerate_input_is_undetermined():
    """Constant or too short signals, or too few cycles, give 'undetermined' with a message."""
    assert spectrum_analysis(np.ones(1000), DT).model == "undetermined"
    assert spectrum_analysis(np.arange(10.0), DT).model == "undetermined"
    few = spectrum_analysis(np.sin(2 * math.pi * 0.01 * T), DT, forcing_frequency=0.01)
    assert few.model == "undetermined" and "cycles" in few.message


def test_nan_raises():
    """NaN input is an error the user must fix."""
    x = np.sin(T)
    x[10] = np.nan
    with pytest.raises(ValueError, match="NaN"):
        spectrum_analysis(x, DT)
