"""Evidence from a largest Lyapunov exponent with its standard error (e.g. a tangent exponent)."""

from __future__ import annotations

import math

from ._thresholds import Thresholds
from ._validate import check_settings
from ._verdict import Evidence

__all__ = ["as_exponent", "exponent_evidence"]


def as_exponent(exponent, time_per_iterate: float = 1.0) -> tuple[float, float, int | None]:
    """``(λ, stderr, n_intervals)`` per iterate from a number, a tuple or a result object.

    Accepted: a float (stderr unknown: NaN), a pair ``(λ, stderr)``, a triple ``(λ, stderr,
    n_intervals)``, or an object with attributes ``exponent`` and ``stderr`` (and optionally
    ``n_intervals``). λ and stderr are multiplied by `time_per_iterate` (the forcing period
    T for an exponent in 1/s and a stroboscopic section).
    """
    check_settings("as_exponent", time_per_iterate=(time_per_iterate, "real>0"))
    n = None
    if hasattr(exponent, "exponent"):
        lam = exponent.exponent
        se = getattr(exponent, "stderr", math.nan)
        n = getattr(exponent, "n_intervals", None)
    elif isinstance(exponent, tuple | list):
        if len(exponent) not in (2, 3):
            raise ValueError(
                f"exponent must be (λ, stderr) or (λ, stderr, n_intervals), got {exponent!r}"
            )
        lam, se = exponent[0], exponent[1]
        n = exponent[2] if len(exponent) == 3 else None
    else:
        lam, se = exponent, math.nan
    lam = float(lam) * time_per_iterate
    se = math.nan if se is None else abs(float(se)) * time_per_iterate
    return lam, se, None if n is None else int(n)


def exponent_evidence(
    exponent: float,
    stderr: float | None = None,
    n_intervals: int | None = None,
    *,
    thresholds: Thresholds | None = None,
    name: str = "exponent",
    unit: str = "per iterate",
) -> Evidence:
    """Vote of a largest Lyapunov exponent judged by its confidence interval.

    With z = `Thresholds.exponent_z` and ε = `Thresholds.exponent_zero`, the interval
    ``[λ - z σ, λ + z σ]`` (σ the standard error, e.g. from batch means of the per-iterate
    log growths) votes

    * "chaotic" when ``λ - z σ > ε`` (positive beyond doubt),
    * "not_chaotic" when ``λ + z σ < ε`` (zero within ε: a torus; or negative: a stable
      periodic orbit), and always for λ = -inf (the tangent vector collapsed: a zero
      Floquet multiplier, as after sticking),
    * and abstains otherwise, with the run length that would decide, σ taken to shrink as
      1/sqrt(run length) (the batch-means error of an ergodic average).

    Parameters
    ----------
    exponent : float
        λ₁, in the units named by `unit` (the thresholds are per iterate of the section map).
    stderr : float, optional
        Standard error of λ₁ in the same units; None or NaN abstains (unless λ₁ = -inf).
    n_intervals : int, optional
        Intervals (iterates) averaged; only used to say how many more to run.
    thresholds : Thresholds, optional
        Default `Thresholds()`.
    name, unit : str
        Name of the evidence; unit written after the numbers in the detail.

    Returns
    -------
    Evidence
        Value λ₁; detail with the interval and why it votes (or what to run).

    Notes
    -----
    Limits: σ is statistical only; the bias of a too-short transient is not in it. A
    weakly chaotic orbit with λ₁ below ε per iterate is read as not chaotic.
    """
    thr = thresholds or Thresholds()
    lam = float(exponent)
    se = math.nan if stderr is None else float(stderr)
    if lam == -math.inf:
        return Evidence(
            name,
            lam,
            "not_chaotic",
            "λ₁ = -inf: the tangent vector collapsed (a zero Floquet multiplier, e.g. "
            "sticking): not chaotic",
        )
    if not math.isfinite(lam):
        return Evidence(name, None, None, f"λ₁ = {lam}: not computed, not used")
    eps, z = thr.exponent_zero, thr.exponent_z
    runs = "" if n_intervals is None else f" over {n_intervals} intervals"
    if not math.isfinite(se):
        return Evidence(
            name,
            lam,
            None,
            f"λ₁ = {lam:.4g} {unit}{runs} without a standard error: run the exponent "
            "longer (at least 20 intervals) so that its confidence interval can be judged",
        )
    lo, hi = lam - z * se, lam + z * se
    txt = f"λ₁ = {lam:.4g} ± {se:.2g} {unit}{runs}, {z:g}σ interval [{lo:.3g}, {hi:.3g}]"
    if lo > eps:
        return Evidence(name, lam, "chaotic", txt + f" > {eps:g}: positive")
    if hi < eps:
        what = "negative: a stable periodic orbit" if hi < -eps else "zero within the threshold"
        return Evidence(name, lam, "not_chaotic", txt + f" < {eps:g}: {what}")
    gap = abs(lam - eps)
    factor = math.inf if gap == 0 else (z * se / gap) ** 2
    if math.isfinite(factor) and factor <= 1e4:
        times = f"{factor:.3g}" if factor < 10 else f"{math.ceil(factor)}"  # not ~2x for 1.13x
        more = f"run the exponent ~{times}x longer"
        if n_intervals is not None:
            more += f" ({n_intervals} -> {math.ceil(factor * n_intervals)} intervals)"
        more += " to decide"
    else:
        more = f"λ₁ sits at the threshold {eps:g}: no run of practical length decides"
    return Evidence(name, lam, None, txt + f" contains {eps:g}: {more}")
