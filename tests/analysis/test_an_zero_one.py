"""Tests of the 0–1 test for chaos."""

import math

import numpy as np

from chaoscam.analysis import zero_one_test
from chaoscam.testsystems import logistic_orbit


def _direct_k_c(phi, c, n_cut):
    """K_c by the defining sums, one lag at a time (independent of the FFT path)."""
    n = phi.size
    j = np.arange(1, n + 1)
    p = np.cumsum(phi * np.cos(j * c))
    q = np.cumsum(phi * np.sin(j * c))
    length = n - n_cut
    d = []
    for lag in range(1, n_cut + 1):
        m = np.mean(
            (p[lag : lag + length] - p[:length]) ** 2 + (q[lag : lag + length] - q[:length]) ** 2
        )
        d.append(m - phi.mean() ** 2 * (1 - math.cos(lag * c)) / (1 - math.cos(c)))
    return np.corrcoef(np.arange(1, n_cut + 1), d)[0, 1]


def test_fft_displacement_matches_direct_sums():
    """The FFT-based K_c equals K_c computed from the defining sums."""
    phi = logistic_orbit(3.9, 400)
    res = zero_one_test(phi, n_c=5, seed=3)
    for c, k in zip(res.c, res.k_c, strict=True):
        assert math.isclose(k, _direct_k_c(phi, c, res.n_cut), abs_tol=1e-9)


def test_chaotic_logistic_gives_k_near_one():
    """Chaotic logistic orbits (r = 3.9, 4) give K > 0.9."""
    for r in (3.9, 4.0):
        assert zero_one_test(logistic_orbit(r, 2000)).k > 0.9


def test_periodic_logistic_gives_k_near_zero():
    """Periodic logistic orbits (periods 2, 4, 3) give |K| < 0.1."""
    for r in (3.2, 3.5, 3.83):
        assert abs(zero_one_test(logistic_orbit(r, 2000)).k) < 0.1


def test_seeded_and_reproducible():
    """The same seed gives the same c values and K; another seed other c values."""
    x = logistic_orbit(3.9, 500)
    a, b, c = zero_one_test(x, seed=1), zero_one_test(x, seed=1), zero_one_test(x, seed=2)
    assert a.k == b.k and np.array_equal(a.c, b.c)
    assert not np.array_equal(a.c, c.c)
    assert np.all((a.c > math.pi / 5) & (a.c < 4 * math.pi / 5))


def test_short_and_constant_series_do_not_run():
    """Too short or constant series give K = NaN and a message, not an exception."""
    short = zero_one_test(np.arange(50.0))
    const = zero_one_test(np.ones(500))
    assert math.isnan(short.k) and "needs" in short.message
    assert math.isnan(const.k) and "constant" in const.message


def test_oversampled_sine_is_flagged():
    """A sine sampled 200 times per period is flagged as oversampled."""
    x = np.sin(2 * math.pi * np.arange(2000) / 200)
    assert zero_one_test(x).oversampled
