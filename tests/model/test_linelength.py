"""The random contact-line length: truncated normal, reproducible per (seed, index)."""

import numpy as np
import pytest
from scipy import stats

from chaoscam import ParameterError, Params
from chaoscam.model import LineLengthStream, truncated_mass

P = Params(l_lambda=0.008, l_lambda_sigma=0.004, l_min=1e-4)


def test_same_seed_same_draws():
    """(seed, index) fixes the stream."""
    a = LineLengthStream(P, 7, 3).draw(100)
    b = LineLengthStream(P, 7, 3).draw(100)
    assert np.array_equal(a, b)


def test_draws_do_not_depend_on_block_sizes():
    """Drawing 10 then 90 gives the same values as drawing 100."""
    s = LineLengthStream(P, 7, 3)
    assert np.array_equal(
        np.concatenate([s.draw(10), s.draw(90)]), LineLengthStream(P, 7, 3).draw(100)
    )


def test_different_indices_are_independent():
    """Streams of neighbouring indices are uncorrelated (|r| < 4/sqrt(n))."""
    n = 20000
    a = LineLengthStream(P, 7, 0).draw(n)
    b = LineLengthStream(P, 7, 1).draw(n)
    assert not np.array_equal(a, b)
    assert abs(np.corrcoef(a, b)[0, 1]) < 4 / np.sqrt(n)


def test_truncated_normal_distribution():
    """Draws follow the truncated normal: support above l_min, KS test against scipy."""
    x = LineLengthStream(P, 11, 0).draw(20000)
    assert x.min() > P.l_min
    a = (P.l_min - P.l_lambda) / P.l_lambda_sigma
    ref = stats.truncnorm(a, np.inf, loc=P.l_lambda, scale=P.l_lambda_sigma)
    assert stats.kstest(x, ref.cdf).pvalue > 1e-3


def test_far_tail_truncation_stays_accurate():
    """With l_min many sigmas above mu the draws still lie above l_min."""
    p = Params(l_lambda=0.002, l_lambda_sigma=0.0002, l_min=0.003)
    x = LineLengthStream(p, 0, 0).draw(1000)
    assert x.min() >= 0.003 and x.mean() < 0.0032


def test_removed_mass():
    """The truncation removes Phi((l_min - mu)/sigma)."""
    assert truncated_mass(0.008, 0.004, 1e-4) == pytest.approx(
        stats.norm.cdf((1e-4 - 0.008) / 0.004)
    )
    assert truncated_mass(0.008, 0.0, 1e-4) == 0.0


def test_sigma_zero_is_deterministic():
    """sigma = 0 always gives mu."""
    assert np.all(LineLengthStream(Params(), 0, 5).draw(10) == 0.008)


def test_negative_seed_is_refused():
    """Seeds and indices must be non-negative."""
    with pytest.raises(ParameterError, match="seed"):
        LineLengthStream(P, -1, 0)
