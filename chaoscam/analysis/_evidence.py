"""Evidence builders shared by the classifiers: section, 0–1 test, Birkhoff, Lyapunov exponent."""

from __future__ import annotations

import math
from dataclasses import replace
from fractions import Fraction

import numpy as np

from ._birkhoff import weighted_birkhoff
from ._periodicity import _floor, delays, embed_angles, rotation_order, section_period
from ._set_measures import correlation_dimension, neighbour_expansion, stationarity_ratio
from ._thresholds import Thresholds
from ._validate import as_points, check_settings
from ._verdict import Evidence
from ._zero_one import zero_one_test

__all__ = ["as_exponent", "exponent_evidence", "zero_one_evidence"]


def safe(name: str, fn, *args, **kwargs):
    """Run one method; a failure becomes an abstaining Evidence instead of a crash."""
    try:
        return fn(*args, **kwargs), None
    except (ValueError, FloatingPointError, np.linalg.LinAlgError, ArithmeticError) as err:
        return None, Evidence(name, None, None, f"failed: {err}")


def _k_side(k: float, thr: Thresholds) -> str | None:
    if k >= thr.zero_one_chaotic:
        return "chaotic"
    if k <= thr.zero_one_regular:
        return "not_chaotic"
    return None


def zero_one_evidence(
    name: str, series, what: str, seed: int, thresholds: Thresholds | None = None
) -> Evidence:
    """The 0–1 test's vote on `series` (named `what` in the detail), where valid and converged.

    Votes only with at least `Thresholds.zero_one_min_points` samples, not oversampled, and
    K of the first half and of the whole on the same side of `Thresholds.zero_one_chaotic`
    / `zero_one_regular` within `Thresholds.zero_one_max_change`; else abstains, saying why.
    References: Gottwald & Melbourne, Nonlinearity 22 (2009) 1367 (N ~ 1000 separates 0 from
    1); Melosik & Marszalek, Bull. Pol. Acad. Sci. Tech. Sci. 64 (2016) (oversampling).
    """
    thr = thresholds or Thresholds()
    x = np.asarray(series, dtype=float)
    if x.size < thr.zero_one_min_points:
        more = math.ceil(thr.zero_one_min_points / max(x.size, 1))
        why = f"{x.size} samples < {thr.zero_one_min_points}: the 0-1 test is not valid this short"
        return Evidence(name, None, None, f"{what}: {why} (run ~{more}x longer)")
    res, failed = safe(name, zero_one_test, x, seed=seed)
    if failed:
        return failed
    if res.message:
        return Evidence(name, None, None, f"{what}: {res.message}")
    k = res.k
    txt = f"{what}: K = {k:.3f} (median over {res.c.size} c, N = {res.n})"
    if res.oversampled:
        return Evidence(name, k, None, txt + "; flagged as oversampled, not used")
    half, failed = safe(name, zero_one_test, x[: x.size // 2], seed=seed)
    if failed or half.message:
        return Evidence(name, k, None, txt + "; the first half could not be tested, not used")
    side, side_half = _k_side(k, thr), _k_side(half.k, thr)
    txt += f", first half K = {half.k:.3f}"
    if side is None:
        why = f": between {thr.zero_one_regular} and {thr.zero_one_chaotic}, inconclusive"
        return Evidence(name, k, None, txt + why)
    if side_half != side or abs(half.k - k) > thr.zero_one_max_change:
        why = (
            f": K has not converged in N (|ΔK| = {abs(half.k - k):.2f}, limit "
            f"{thr.zero_one_max_change}); not used, run longer"
        )
        return Evidence(name, k, None, txt + why)
    bound = f">= {thr.zero_one_chaotic}" if side == "chaotic" else f"<= {thr.zero_one_regular}"
    return Evidence(name, k, side, txt + f", both {bound}")


def as_exponent(exponent, time_per_iterate: float = 1.0) -> tuple[float, float, int | None]:
    """``(λ, stderr, n_intervals)`` per iterate from a number, a tuple or a result object.

    A float (stderr NaN), ``(λ, stderr)``, ``(λ, stderr, n_intervals)`` or an object with
    ``exponent``, ``stderr`` (and ``n_intervals``); λ and stderr times `time_per_iterate`.
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

    With z = `Thresholds.exponent_z`, ε = `Thresholds.exponent_zero`, σ the standard error,
    ``[λ - z σ, λ + z σ]`` votes "chaotic" when above ε, "not_chaotic" when below (a torus or
    a stable periodic orbit) or λ = -inf (a zero Floquet multiplier); otherwise it abstains
    and says how much longer to run (σ ∝ 1/sqrt(run length)).

    Limits: σ is statistical only, not the bias of a short transient; chaos with λ₁ < ε per
    iterate reads as not chaotic.

    Parameters
    ----------
    exponent : float
        λ₁, in `unit` (the thresholds are per iterate of the section map).
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
    """
    thr = thresholds or Thresholds()
    lam = float(exponent)
    se = math.nan if stderr is None else float(stderr)
    if lam == -math.inf:
        why = ("λ₁ = -inf: the tangent vector collapsed (a zero Floquet multiplier, e.g. "
               "sticking): not chaotic")  # fmt: skip
        return Evidence(name, lam, "not_chaotic", why)
    if not math.isfinite(lam):
        return Evidence(name, None, None, f"λ₁ = {lam}: not computed, not used")
    eps, z = thr.exponent_zero, thr.exponent_z
    runs = "" if n_intervals is None else f" over {n_intervals} intervals"
    if not math.isfinite(se):
        why = (f"λ₁ = {lam:.4g} {unit}{runs} without a standard error: run the exponent "
               "longer (at least 20 intervals) so that its confidence interval can be "
               "judged")  # fmt: skip
        return Evidence(name, lam, None, why)
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


def lyapunov_evidence(lyap: float, tol: float | None, unit: str) -> Evidence:
    """Vote of an exponent without error bar: > tol chaotic, else not chaotic."""
    lyap = float(lyap)
    if tol is None:
        return Evidence(
            "lyapunov", lyap, None, "no time scale to judge λ₁ against: pass lyapunov_tol"
        )
    if not math.isfinite(lyap):
        if lyap == -math.inf:
            return Evidence("lyapunov", lyap, "not_chaotic", "λ₁ = -inf (superstable)")
        return Evidence("lyapunov", None, None, "λ₁ is NaN: not used")
    txt = f"λ₁ = {lyap:.4g} {unit} (threshold ± {tol:.3g})"
    if lyap > tol:
        return Evidence("lyapunov", lyap, "chaotic", txt + ": positive")
    return Evidence("lyapunov", lyap, "not_chaotic", txt + ": not positive")


def exponent_votes(thr, exponent, exponent_time, lyapunov, tol, unit):
    """A classifier's exponent and lyapunov evidence, and the exponent record (or None)."""
    ev, record = [], None
    if exponent is not None:
        lam, se, n_int = as_exponent(exponent, exponent_time)
        record = dict(exponent=lam, stderr=se, n_intervals=n_int)
        ev.append(exponent_evidence(lam, se, n_int, thresholds=thr))
    if lyapunov is not None:
        ev.append(lyapunov_evidence(lyapunov, tol, unit))
    return ev, record


def _fmt(a) -> str:
    return "[" + ", ".join(f"{v:.2g}" for v in np.atleast_1d(a)) + "]"


def birkhoff_evidence(name: str, z: np.ndarray, thr: Thresholds) -> Evidence:
    """Quasiperiodic when the weighted Birkhoff averages converge fast (no period found)."""
    n = z.shape[0]
    if n < thr.birkhoff_min_points:
        why = f"{n} points < {thr.birkhoff_min_points}: too few for the Birkhoff averages"
        more = math.ceil(thr.birkhoff_min_points / n)
        return Evidence(name, None, None, f"{why} (run ~{more}x longer)")
    res, failed = safe(name, weighted_birkhoff, z)
    if failed:
        return failed
    rho = res.rotation_number
    value = rho if math.isfinite(rho) else None
    txt = (
        f"weighted Birkhoff averages converged to {res.digits:.1f} digits over 2 x "
        f"{res.n // 2} points" + (f", rotation number {rho:.10f}" if value is not None else "")
    )
    near = _rational_near(rho, n // 2, thr.birkhoff_rational_tol)
    if res.digits >= thr.birkhoff_quasi_digits and near:
        return Evidence(name, value, None, txt + f" = {near} to within "
                        f"{thr.birkhoff_rational_tol:g}: a periodic orbit's rotation number "
                        "as much as a torus's at resonance, not a vote")  # fmt: skip
    if res.digits >= thr.birkhoff_quasi_digits:
        why = f" >= {thr.birkhoff_quasi_digits:g}: a smooth invariant curve (torus)"
        return Evidence(name, value, "quasiperiodic", txt + why)
    why = f" < {thr.birkhoff_quasi_digits:g}: slow convergence (chaos, noise or a non-smooth set)"
    return Evidence(name, value, None, txt + why + ", not a vote")


def _rational_near(rho: float, q_max: int, tol: float) -> str:
    """ "p/q" when ``rho`` lies within ``tol`` of a rational with 1 <= q <= ``q_max``, else ""."""
    if not math.isfinite(rho) or q_max < 1:
        return ""
    f = Fraction(rho).limit_denominator(q_max)
    return f"{f.numerator}/{f.denominator}" if abs(rho - f) <= tol else ""


def _periodic_evidence(prefix, pr, rtol, zero_one):
    """Evidence list of a section found periodic, with the methods that then abstain."""
    what = (
        "all points coincide (a fixed point)"
        if pr.coincident
        else f"every point recurs after {pr.period} iterates"
    )
    trans = f"; first {pr.transient} points left out as transient" if pr.transient else ""
    rel = np.max(pr.jitter / np.where(pr.extent > 0, pr.extent, np.inf))
    why = (f"{what}: bands {_fmt(pr.jitter)} on an orbit of extent {_fmt(pr.extent)} "
           f"(per coordinate; widest band {rel:.2g} of the extent), within the tolerance "
           f"{_fmt(pr.tolerance)} = max(atol, rtol {rtol:g} x extent){trans}")  # fmt: skip
    skip = "the section is periodic to the tolerance: only its jitter is left, not used"
    skipped = ["expansion", "birkhoff"] + (["zero_one"] if zero_one else [])
    return [Evidence(f"{prefix}period", pr.period, "periodic", why)] + [
        Evidence(f"{prefix}{name}", None, None, skip) for name in skipped
    ]


def section_evidence(
    points, thr: Thresholds, *, angle_periods=None, atol=None, max_period=None, zero_one=True,
    seed=0, prefix="section_",
):  # fmt: skip
    """Evidence from section points; returns (evidence list, periods dict, reasons).

    A scalar's period and expansion are judged on its 3-delay vectors (`delays`: its states,
    of which a value seen through a fold, cos θ, is not), its rotation by `rotation_order`.
    """
    rtol, min_points_aperiodic = thr.period_rtol, thr.min_points_aperiodic
    x = as_points(points)
    n = x.shape[0]
    z = embed_angles(x, angle_periods)
    states = z
    if z.shape[1] == 1 and n > 3:
        states, atol = delays(z[:, 0], 3), None if atol is None else float(np.max(atol))
    name = f"{prefix}period"
    pr, failed = safe(name, section_period, states, rtol=rtol, atol=atol, max_period=max_period,
                      noise_floor=thr.noise_floor, band_separation=thr.band_separation)  # fmt: skip
    if failed:
        return [failed], {}, []
    if pr.message:
        return [Evidence(name, None, None, pr.message)], {}, [f"section: {pr.message}"]
    if pr.period is not None:
        if states is not z:  # each delay coordinate holds the scalar's bands: report one
            pr = replace(pr, tolerance=pr.tolerance[:1], jitter=pr.jitter[:1], extent=pr.extent[:1])
        return _periodic_evidence(prefix, pr, rtol, zero_one), {name: pr.period}, []
    ratio = stationarity_ratio(z)
    if math.isfinite(ratio) and not thr.stationary_low <= ratio <= thr.stationary_high:
        reason = (f"section: the points have not settled (second-half/first-half spread "
                  f"{ratio:.2f}); discard more transient")  # fmt: skip
        why = (f"no period <= {pr.max_period}, but the points are still "
               f"converging or escaping (spread ratio {ratio:.2f})")  # fmt: skip
        return [Evidence(name, None, None, why)], {}, [reason]
    why = (f"no lag 1..{pr.max_period} has all its bands within rtol = {rtol:g} of the "
           f"extent (narrowest: {pr.mismatch:.3g} tol)")  # fmt: skip
    few = ""
    if n < min_points_aperiodic:
        few = (
            f"; {n} points < {min_points_aperiodic}: too few to separate quasiperiodic from chaotic"
        )
    ev = [
        Evidence(name, None, "not_periodic", why),
        _rotation_evidence(f"{prefix}rotation", z, thr, few),
        birkhoff_evidence(f"{prefix}birkhoff", z, thr),
        _expansion_evidence(f"{prefix}expansion", states, atol, thr, few),
    ]
    if z.shape[1] >= 2 and n >= thr.dimension_min_points:
        ev.append(_dimension_evidence(f"{prefix}dimension", z, thr))
    if zero_one:
        what = "0-1 test on the first section coordinate"
        ev.append(zero_one_evidence(f"{prefix}zero_one", z[:, 0], what, seed, thr))
    return ev, {}, []


def _vote(name, value, txt, few, passed, vote, yes, no) -> Evidence:
    """``vote`` when `passed`, else an abstention (``few``: too few points)."""
    if few:
        return Evidence(name, value, None, txt + few)
    if passed:
        return Evidence(name, value, vote, txt + yes)
    return Evidence(name, value, None, txt + no)


def _rotation_evidence(name: str, z: np.ndarray, thr: Thresholds, few: str) -> Evidence:
    """Rank-shift consistency (`rotation_order`): quasiperiodic from ``rotation_quasi``."""
    rot = rotation_order(z)
    r, q = rot.consistency, thr.rotation_quasi
    txt = f"rank-shift consistency R = {r:.3f}, rotation number {rot.rotation_number:.4f}"
    yes, no = f" >= {q}: points turn along a closed curve", f" < {q}: no rotation order"
    return _vote(name, r, txt, few, r >= q, "quasiperiodic", yes, no)


def _expansion_evidence(name: str, z: np.ndarray, atol, thr: Thresholds, few: str) -> Evidence:
    """`neighbour_expansion` beyond the noise floor: chaotic above ``expansion_chaotic``."""
    g = neighbour_expansion(z, atol=_floor(z, atol, thr.noise_floor))
    if not math.isfinite(g):
        return Evidence(name, None, None, "too few distinct neighbours above the noise floor")
    c = thr.expansion_chaotic
    txt = f"mean one-step log growth of nearest-neighbour distances {g:.3f}"
    yes, no = f" > {c}: neighbours separate", f" <= {c}: no clear stretching"
    return _vote(name, g, txt, few, g > c, "chaotic", yes, no)


def _dimension_evidence(name: str, z: np.ndarray, thr: Thresholds) -> Evidence:
    """`correlation_dimension`: chaotic (not a curve) from ``dimension_chaotic``."""
    d2, c = correlation_dimension(z), thr.dimension_chaotic
    txt = f"correlation dimension D2 = {d2:.2f}"
    yes, no = f" >= {c}: not a curve", f" < {c}: a curve or unresolved"
    return _vote(name, d2, txt, "", math.isfinite(d2) and d2 >= c, "chaotic", yes, no)
