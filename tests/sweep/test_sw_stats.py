"""Wilson intervals and the per-cell summary."""

import numpy as np
import pandas as pd
import pytest

from chaoscam.sweep import LABEL_ORDER, max_halfwidth, summarize_cells, wilson_interval


def test_wilson_known_values():
    """5/10 gives (0.2366, 0.7634); 0/10 gives (0, z^2/(n+z^2)) (Brown et al. 2001)."""
    lo, hi = wilson_interval(5, 10)
    assert lo == pytest.approx(0.2366, abs=1e-4) and hi == pytest.approx(0.7634, abs=1e-4)
    lo, hi = wilson_interval(0, 10)
    z2 = 1.959963984540054**2
    assert lo == 0.0 and hi == pytest.approx(z2 / (10 + z2), rel=1e-12)


def test_wilson_invariants():
    """lo <= k/n <= hi, inside [0, 1], and symmetric under k -> n - k."""
    n = np.full(51, 50)
    k = np.arange(51)
    lo, hi = wilson_interval(k, n)
    assert np.all((lo <= k / n) & (k / n <= hi) & (lo >= 0) & (hi <= 1))
    lo2, hi2 = wilson_interval(n - k, n)
    assert np.allclose(lo, 1 - hi2, atol=1e-14) and np.allclose(hi, 1 - lo2, atol=1e-14)


def test_wilson_coverage_is_near_nominal():
    """Over 20000 binomial draws (n = 40, p = 0.3) the 95 % interval covers p 93-97 % of
    the time."""
    rng = np.random.default_rng(np.random.SeedSequence(5))
    k = rng.binomial(40, 0.3, size=20000)
    lo, hi = wilson_interval(k, np.full(k.size, 40))
    cover = np.mean((lo <= 0.3) & (0.3 <= hi))
    assert 0.93 <= cover <= 0.97


def test_max_halfwidth_is_widest_label():
    """The widest label interval; an unseen label never widens it."""
    lo, hi = wilson_interval(3, 10)
    assert max_halfwidth({"chaotic": 3, "periodic": 7}, 10) == pytest.approx((hi - lo) / 2)
    assert max_halfwidth({"chaotic": 10}, 10) == max_halfwidth({"chaotic": 10, "x": 0}, 10)
    assert max_halfwidth({}, 0) == 1.0


def test_summary_fractions_sum_to_one_and_keep_non_regular_labels():
    """Per cell the label fractions sum to 1; left_reach counts like any label."""
    rows = pd.DataFrame(
        {
            "cell": [0, 0, 0, 1, 1],
            "label": ["chaotic", "chaotic", "periodic", "left_reach", "periodic"],
            "truncated_mass": [0.1] * 3 + [0.0] * 2,
            "ev_lyapunov_1": [1.0, 3.0, np.nan, np.nan, -2.0],
        }
    )
    cells = pd.DataFrame(
        {"cell": [0, 1], "ix": [0, 1], "iy": [0, 0], "a": [1.0, 2.0], "b": [0.0, 0.0]}
    )
    s = summarize_cells(rows, cells)
    total = sum(s[f"p_{lab}"] for lab in LABEL_ORDER)
    assert np.allclose(total, 1.0)
    assert list(s["dominant"]) == ["chaotic", "periodic"]  # tie 1-1 -> earlier label
    assert list(s["n_left_reach"]) == [0, 1]
    assert s.loc[0, "lyapunov_mean"] == 2.0 and s.loc[0, "lyapunov_std"] == pytest.approx(
        np.sqrt(2.0)
    )
    assert s.loc[1, "lyapunov_n"] == 1 and np.isnan(s.loc[1, "lyapunov_std"])
    assert list(s["truncated_mass"]) == [0.1, 0.0]


def test_summary_gives_the_random_response_of_each_cell():
    """The random response: the exponent's Student interval over the realizations (a single
    run's own stderr interval), the synchronised share among the twins run, and the section's
    quantile function averaged over the realizations (Vincent average)."""
    from scipy import stats

    lam = np.array([1.0, 1.4, 0.9, 1.3])
    rows = pd.DataFrame({
        "cell": [0, 0, 0, 0, 1], "label": ["chaotic"] * 4 + ["periodic"],
        "truncated_mass": 0.0, "ev_lyapunov_1": [*lam, -0.5],
        "ev_lyapunov_1_stderr": [0.1, 0.1, 0.1, 0.1, 0.05],
        "ev_synchronised": [0.0, 1.0, np.nan, 0.0, np.nan],
        **{f"ev_section_q{k}": [k, k + 1, k + 2, k + 3, 10 * k] for k in range(21)},
    })  # fmt: skip
    cells = pd.DataFrame({"cell": [0, 1], "ix": [0, 1], "iy": [0, 0],
                          "deterministic": [False, True]})  # fmt: skip
    out = summarize_cells(rows, cells).set_index("cell")
    half = stats.t.ppf(0.975, 3) * lam.std(ddof=1) / 2.0
    assert out.loc[0, "lyapunov_lo"] == pytest.approx(lam.mean() - half)
    assert out.loc[0, "lyapunov_hi"] == pytest.approx(lam.mean() + half)
    assert out.loc[1, "lyapunov_hi"] - out.loc[1, "lyapunov_lo"] == pytest.approx(
        2 * 1.959964 * 0.05
    )
    assert (out.loc[0, "n_twins"], out.loc[0, "p_synchronised"]) == (3, pytest.approx(1 / 3))
    assert out.loc[1, "n_twins"] == 0 and np.isnan(out.loc[1, "p_synchronised"])
    assert [out.loc[0, f"section_q{k}"] for k in range(21)] == [k + 1.5 for k in range(21)]
