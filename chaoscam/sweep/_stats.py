"""Per-cell statistics of a regime map: label fractions with Wilson intervals.

Reference: E. B. Wilson, "Probable inference, the law of succession, and statistical
inference", J. Am. Stat. Assoc. 22 (1927) 209-212; L. D. Brown, T. T. Cai, A. DasGupta,
"Interval estimation for a binomial proportion", Statist. Sci. 16 (2001) 101-133.
"""

from __future__ import annotations

from collections.abc import Mapping

import numpy as np
import pandas as pd
from scipy.special import ndtri, stdtrit

LABEL_ORDER = ("periodic", "quasiperiodic", "chaotic", "undetermined", "left_reach", "diverged")
"""Labels of a map in display order: the verdicts, then the statuses of runs that left the
cam's reach or diverged (counted like any label, never dropped). Ties for the dominant label
go to the earlier one."""


def wilson_interval(k, n, confidence: float = 0.95) -> tuple[np.ndarray, np.ndarray]:
    """Wilson score interval for a binomial proportion ``k / n``.

    ``(p + z^2/2n -+ z sqrt(p(1-p)/n + z^2/4n^2)) / (1 + z^2/n)``, ``z`` the two-sided normal
    quantile of ``confidence``; unlike Wald's it stays in [0, 1] and near its nominal
    coverage for small ``n`` and ``p`` near 0 or 1 (Brown, Cai & DasGupta 2001).

    Parameters
    ----------
    k, n : int or array_like
        Successes and trials, 0 <= k <= n; n = 0 gives (0, 1).
    confidence : float
        Two-sided level in (0, 1).

    Returns
    -------
    (lo, hi) : ndarray
        The interval's ends, broadcast over ``k`` and ``n``.
    """
    if not 0.0 < confidence < 1.0:
        raise ValueError(f"confidence = {confidence!r} must be in (0, 1)")
    k, n = np.asarray(k, dtype=float), np.asarray(n, dtype=float)
    if not (np.isfinite(k).all() and np.isfinite(n).all()) or (k % 1).any() or (n % 1).any():
        raise ValueError(f"k = {k} and n = {n} must be whole numbers (counts)")
    if np.any(k < 0) or np.any(k > n):
        raise ValueError("need 0 <= k <= n")
    z = float(ndtri(0.5 + confidence / 2.0))
    z2 = z * z
    with np.errstate(invalid="ignore", divide="ignore"):
        p = np.where(n > 0, k / n, 0.5)
        denom = 1.0 + z2 / n
        centre = (p + z2 / (2.0 * n)) / denom
        half = z * np.sqrt(p * (1.0 - p) / n + z2 / (4.0 * n * n)) / denom
        lo = np.where(n > 0, np.clip(centre - half, 0.0, 1.0), 0.0)
        hi = np.where(n > 0, np.clip(centre + half, 0.0, 1.0), 1.0)
    # Exact ends where the formula's rounding could leave them off 0 or 1.
    lo = np.where(k == 0, 0.0, lo)
    hi = np.where(k == n, 1.0, hi)
    return lo, hi


def max_halfwidth(counts: Mapping[str, int], n: int, confidence: float = 0.95) -> float:
    """Largest Wilson half-width over the labels of one cell (1 when ``n`` = 0); a label
    never seen is no wider than the observed ones, so they suffice."""
    if n <= 0:
        return 1.0
    ks = list(counts.values()) or [0]
    lo, hi = wilson_interval(ks, [n] * len(ks), confidence)
    return float(np.max((hi - lo) / 2.0))


def summarize_cells(rows: pd.DataFrame, cells: pd.DataFrame, *, confidence=0.95) -> pd.DataFrame:
    """One row per grid cell: label fractions, intervals, dominant label, Lyapunov spread.

    Parameters
    ----------
    rows : DataFrame
        One row per realization: ``cell``, ``label``, ``truncated_mass`` (and
        ``ev_lyapunov_1``, ``period``, the fate columns where recorded).
    cells : DataFrame
        One row per cell: ``cell``, ``ix``, ``iy``, the axis values; cells flagged in a
        boolean ``deterministic`` column (one run standing for all) get a point interval.
    confidence : float
        Level of the Wilson intervals.

    Returns
    -------
    DataFrame
        The columns of ``cells``, then ``n``, ``dominant``, for each label L of
        `LABEL_ORDER` (and any other observed) ``n_L``, ``p_L``, ``p_L_lo``, ``p_L_hi``;
        ``halfwidth`` (the widest); ``lyapunov_mean``, ``lyapunov_std`` (sample, NaN below
        two) and ``lyapunov_n`` over the finite exponents; ``period`` (the modal period of
        the periodic runs, smallest on a tie); ``truncated_mass`` (of Normal(mu, sigma^2)
        below ``l_min``); ``n_transient`` (runs a ``fate`` horizon found to stop later),
        ``n_settled`` and ``settled_period`` (found periodic there, :func:`fate_settled`);
        the random response of :func:`_random_response` (``lyapunov_lo``, ``lyapunov_hi``,
        ``n_twins``, ``p_synchronised``, ``section_q0`` .. ``section_q20``).
    """
    labels = [*LABEL_ORDER, *sorted(set(rows["label"]) - set(LABEL_ORDER))]
    out = cells.sort_values("cell").reset_index(drop=True).copy()
    counts = (
        pd.crosstab(rows["cell"], rows["label"]).reindex(
            index=out["cell"], columns=labels, fill_value=0
        )
        if len(rows)
        else pd.DataFrame(0, index=out["cell"], columns=labels)
    )
    n = counts.sum(axis=1).to_numpy()
    out["n"] = n.astype(np.int64)
    k_mat = counts.to_numpy()
    # argmax keeps the first maximum: ties go to the earlier label of LABEL_ORDER.
    dominant = np.array(labels, dtype=object)[np.argmax(k_mat, axis=1)]
    out["dominant"] = np.where(n > 0, dominant, "")
    half = np.zeros(len(out))
    for j, lab in enumerate(labels):
        k = k_mat[:, j]
        lo, hi = wilson_interval(k, n, confidence)
        p = np.where(n > 0, k / np.maximum(n, 1), np.nan)
        out[f"n_{lab}"], out[f"p_{lab}"] = k.astype(np.int64), p
        if "deterministic" in out:  # one run stands for the cell: no sampling interval
            det = out["deterministic"].to_numpy(dtype=bool)
            lo, hi = np.where(det, p, lo), np.where(det, p, hi)
        out[f"p_{lab}_lo"] = lo
        out[f"p_{lab}_hi"] = hi
        half = np.maximum(half, (hi - lo) / 2.0)
    out["halfwidth"] = half
    col = "ev_lyapunov_1"  # the largest exponent [1/s], with lyapunov=True
    lam = rows[["cell", col]] if col in rows else pd.DataFrame({"cell": rows["cell"], col: np.nan})
    lam = lam[np.isfinite(lam[col].to_numpy(dtype=float))]
    g = lam.groupby("cell")[col]
    out["lyapunov_mean"] = out["cell"].map(g.mean()).astype(float)
    out["lyapunov_std"] = out["cell"].map(g.std(ddof=1)).astype(float)
    out["lyapunov_n"] = out["cell"].map(g.size()).fillna(0).astype(np.int64)
    out = _random_response(out, rows, lam, col, confidence)
    per = rows[rows["label"] == "periodic"] if "period" in rows else rows.iloc[:0]
    per = per[per["period"].notna()] if len(per) else per
    out["period"] = _modal_period(out["cell"], per, "period")
    mass = rows.groupby("cell")["truncated_mass"].first() if len(rows) else pd.Series(dtype=float)
    out["truncated_mass"] = out["cell"].map(mass).astype(float)
    stopped = fate_split(rows)[1]["cell"]
    out["n_transient"] = out["cell"].map(stopped.value_counts()).fillna(0).astype(np.int64)
    settled = fate_settled(rows)
    out["n_settled"] = out["cell"].map(settled["cell"].value_counts()).fillna(0).astype(np.int64)
    out["settled_period"] = _modal_period(out["cell"], settled, "fate_period")
    return out


SECTION_QUANTILES = tuple(np.linspace(0.0, 1.0, 21))
"""The levels of the section's theta_f quantiles a realization records (``ev_section_q0`` ..
``ev_section_q20``: minimum, every 5 %, maximum of its recorded section)."""


def _random_response(out: pd.DataFrame, rows: pd.DataFrame, lam: pd.DataFrame, col: str,
                     confidence: float) -> pd.DataFrame:  # fmt: skip
    """The random system's per-cell response: ``lyapunov_lo``, ``lyapunov_hi`` (Student's
    interval of the mean exponent over the realizations, each a finite-time estimate of the one
    top exponent of the cocycle; a single run's own ``stderr`` interval), ``n_twins`` and
    ``p_synchronised`` (realizations whose common-noise twins ran, and the share of them that
    synchronised) and ``section_q0`` .. ``section_q20`` (the cell's stationary section
    distribution of theta_f [rad] as the mean of the realizations' quantile functions)."""
    n, mean, sd = (out[f"lyapunov_{c}"].to_numpy(dtype=float) for c in ("n", "mean", "std"))
    t = stdtrit(np.maximum(n - 1, 1), 0.5 + confidence / 2.0)  # Student's quantile
    half = np.where(n >= 2, t * sd / np.sqrt(np.maximum(n, 1)), np.nan)
    se = f"{col}_stderr"
    if se in rows:  # one run: its own interval
        one = rows.groupby("cell")[se].first()
        z = ndtri(0.5 + confidence / 2.0)
        half = np.where(n == 1, z * out["cell"].map(one).to_numpy(dtype=float), half)
    out["lyapunov_lo"], out["lyapunov_hi"] = mean - half, mean + half
    sync = rows[["cell", "ev_synchronised"]].dropna() if "ev_synchronised" in rows else None
    g = sync.groupby("cell")["ev_synchronised"] if sync is not None else None
    out["n_twins"] = out["cell"].map(g.size()).fillna(0).astype(np.int64) if g is not None else 0
    out["p_synchronised"] = out["cell"].map(g.mean()).astype(float) if g is not None else np.nan
    for k in range(len(SECTION_QUANTILES)):
        name = f"ev_section_q{k}"
        q = rows.groupby("cell")[name].mean() if name in rows else pd.Series(dtype=float)
        out[f"section_q{k}"] = out["cell"].map(q).astype(float)
    return out


def _modal_period(cells: pd.Series, rows: pd.DataFrame, column: str):
    """Per cell, the most frequent ``column`` of ``rows`` (smallest on a tie; else NA)."""
    mode = rows.groupby("cell")[column].agg(lambda s: s.mode().min()) if len(rows) else {}
    return pd.array(cells.map(mode), dtype="Int64")


def fate_settled(rows: pd.DataFrame) -> pd.DataFrame:
    """The rows a ``fate`` horizon continued that stayed in reach and were periodic on the
    continued run's last half (empty without those columns)."""
    if "fate_label" not in rows:
        return rows.iloc[:0]
    return rows[(rows["fate"] == "OK") & (rows["fate_label"] == "periodic")]


def fate_split(rows: pd.DataFrame) -> tuple[pd.DataFrame, pd.DataFrame]:
    """(the rows a ``fate`` horizon continued, those of them that stopped before it); both
    empty without a ``fate`` column."""
    if "fate" not in rows:
        return rows.iloc[:0], rows.iloc[:0]
    checked = rows[rows["fate"].notna()]
    return checked, checked[checked["fate"] != "OK"]


def continued_labels(checked: pd.DataFrame) -> str:
    """How the continued rows were labelled, for a sentence ("labelled chaotic or ...")."""
    labels = [x for x in ("chaotic", "quasiperiodic", "undetermined") if x in set(checked["label"])]
    if not labels:
        return "continued"
    head = ", ".join(labels[:-1])
    return "labelled " + (f"{head} or {labels[-1]}" if head else labels[-1])


def fate_clause(rows, fate, what: str) -> str:
    """A report's clause on a fate horizon: how many continued runs stopped before it and
    how many are periodic later; empty without a horizon."""
    checked, stopped = fate_split(rows) if fate else (rows.iloc[:0], None)
    if not len(checked):  # no horizon, or no run to continue (all periodic or out of reach)
        return ""
    judged = "fate_label" in rows and rows["fate_label"].notna().any()  # not adaptive runs
    settled = len(fate_settled(rows)) if judged else 0
    return (
        f"; continued to {float(fate):g} s, {len(stopped)} of the {len(checked)} {what} "
        f"{continued_labels(checked)} stop before it"
        + (f" and {settled} are periodic later" if judged else "")
        + (" (transient motion)" if len(stopped) or settled else "")  # else none was
    )
