"""Evidence builders shared by the classifiers: section, 0–1 test, Birkhoff, Lyapunov exponent."""

from __future__ import annotations

import math
from fractions import Fraction

import numpy as np

from ._birkhoff import weighted_birkhoff
from ._periodicity import _floor, embed_angles, rotation_order, section_period
from ._set_measures import correlation_dimension, neighbour_expansion, stationarity_ratio
from ._thresholds import Thresholds
from ._validate import as_points
from ._verdict import Evidence
from ._zero_one import zero_one_test


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
    """The 0–1 test's vote, cast only where the test is valid and has converged in N.

    `zero_one_test` on `series` votes only when (1) the sequence has at least
    `Thresholds.zero_one_min_points` samples, (2) it is not flagged as oversampled, and
    (3) K of the first half and K of the whole lie on the same side of the thresholds
    (both >= `zero_one_chaotic` or both <= `zero_one_regular`) and differ by at most
    `zero_one_max_change`. Otherwise it abstains and the detail says which condition
    failed; `what` names the sequence in the detail.

    References: K separates 0 from 1 cleanly only for N ~ 1000 samples of a map-like
    sequence (Gottwald & Melbourne, "On the validity of the 0-1 test for chaos",
    Nonlinearity 22 (2009) 1367; "On the implementation of the 0-1 test for chaos", SIAM
    J. Appl. Dyn. Syst. 8 (2009) 129); an oversampled regular signal can give K near 1
    (Melosik & Marszalek, "On the 0/1 test for chaos in continuous systems", Bull. Pol.
    Acad. Sci. Tech. Sci. 64 (2016)).
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


def lyapunov_evidence(lyap: float, tol: float, unit: str) -> Evidence:
    """Vote of an exponent without error bar: > tol chaotic, else not chaotic."""
    lyap = float(lyap)
    if not math.isfinite(lyap):
        if lyap == -math.inf:
            return Evidence("lyapunov", lyap, "not_chaotic", "λ₁ = -inf (superstable)")
        return Evidence("lyapunov", None, None, "λ₁ is NaN: not used")
    txt = f"λ₁ = {lyap:.4g} {unit} (threshold ± {tol:.3g})"
    if lyap > tol:
        return Evidence("lyapunov", lyap, "chaotic", txt + ": positive")
    return Evidence("lyapunov", lyap, "not_chaotic", txt + ": not positive")


def _fmt(a) -> str:
    return "[" + ", ".join(f"{v:.2g}" for v in np.atleast_1d(a)) + "]"


def birkhoff_evidence(name: str, z: np.ndarray, thr: Thresholds) -> Evidence:
    """Quasiperiodic when the weighted Birkhoff averages converge fast (no period found)."""
    n = z.shape[0]
    if n < thr.birkhoff_min_points:
        why = f"{n} points < {thr.birkhoff_min_points}: too few for the Birkhoff averages"
        return Evidence(
            name, None, None, f"{why} (run ~{math.ceil(thr.birkhoff_min_points / n)}x longer)"
        )
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


def _periodic_evidence(prefix, pr, rtol, thr, zero_one):
    """Evidence list of a section found periodic, with the methods that then abstain."""
    what = (
        "all points coincide (a fixed point)"
        if pr.coincident
        else f"every point recurs after {pr.period} iterates"
    )
    trans = f"; first {pr.transient} points left out as transient" if pr.transient else ""
    rel = np.max(pr.jitter / np.where(pr.extent > 0, pr.extent, np.inf))
    ev = [
        Evidence(
            f"{prefix}period",
            pr.period,
            "periodic",
            f"{what}: bands {_fmt(pr.jitter)} on an orbit of extent {_fmt(pr.extent)} "
            f"(per coordinate; widest band {rel:.2g} of the extent), within the tolerance "
            f"{_fmt(pr.tolerance)} = max(atol, rtol {rtol:g} x extent){trans}",
        )
    ]
    skip = "the section is periodic to the tolerance: only its jitter is left, not used"
    ev.append(Evidence(f"{prefix}expansion", None, None, skip))
    ev.append(Evidence(f"{prefix}birkhoff", None, None, skip))
    if zero_one:
        ev.append(Evidence(f"{prefix}zero_one", None, None, skip))
    return ev


def section_evidence(
    points,
    thr: Thresholds,
    *,
    angle_periods=None,
    atol=None,
    max_period=None,
    zero_one=True,
    seed=0,
    prefix="section_",
):
    """Evidence from section points; returns (evidence list, periods dict, reasons)."""
    rtol, min_points_aperiodic = thr.period_rtol, thr.min_points_aperiodic
    reasons: list[str] = []
    x = as_points(points)
    n = x.shape[0]
    z = embed_angles(x, angle_periods)
    pr, failed = safe(
        f"{prefix}period",
        section_period,
        z,
        rtol=rtol,
        atol=atol,
        max_period=max_period,
        noise_floor=thr.noise_floor,
        band_separation=thr.band_separation,
    )
    if failed:
        return [failed], {}, reasons
    if pr.message:
        reasons.append(f"section: {pr.message}")
        return [Evidence(f"{prefix}period", None, None, pr.message)], {}, reasons
    if pr.period is not None:
        ev = _periodic_evidence(prefix, pr, rtol, thr, zero_one)
        return ev, {f"{prefix}period": pr.period}, reasons

    ratio = stationarity_ratio(z)
    settled = thr.stationary_low <= ratio <= thr.stationary_high if math.isfinite(ratio) else True
    if not settled:
        reasons.append(
            f"section: the points have not settled (second-half/first-half spread "
            f"{ratio:.2f}); discard more transient"
        )
        why = (
            f"no period <= {pr.max_period}, but the points are still "
            f"converging or escaping (spread ratio {ratio:.2f})"
        )
        return [Evidence(f"{prefix}period", None, None, why)], {}, reasons
    why = (
        f"no lag 1..{pr.max_period} has all its bands within rtol = {rtol:g} of the "
        f"extent (narrowest: {pr.mismatch:.3g} tol)"
    )
    ev = [Evidence(f"{prefix}period", None, "not_periodic", why)]
    few = ""
    if n < min_points_aperiodic:
        few = (
            f"; {n} points < {min_points_aperiodic}: too few to separate quasiperiodic from chaotic"
        )
    ev.append(_rotation_evidence(f"{prefix}rotation", z, thr, few))
    ev.append(birkhoff_evidence(f"{prefix}birkhoff", z, thr))
    ev.append(_expansion_evidence(f"{prefix}expansion", z, atol, thr, few))
    if z.shape[1] >= 2 and n >= thr.dimension_min_points:
        ev.append(_dimension_evidence(f"{prefix}dimension", z, thr))
    if zero_one:
        what = "0-1 test on the first section coordinate"
        ev.append(zero_one_evidence(f"{prefix}zero_one", z[:, 0], what, seed, thr))
    return ev, {}, reasons


def _rotation_evidence(name: str, z: np.ndarray, thr: Thresholds, few: str) -> Evidence:
    """Rank-shift consistency (`rotation_order`): quasiperiodic from ``rotation_quasi``; no
    vote on fewer points than ``min_points_aperiodic`` (``few`` says so)."""
    rot = rotation_order(z)
    r = rot.consistency
    txt = f"rank-shift consistency R = {r:.3f}, rotation number {rot.rotation_number:.4f}"
    if few:
        return Evidence(name, r, None, txt + few)
    if r >= thr.rotation_quasi:
        why = f" >= {thr.rotation_quasi}: points turn along a closed curve"
        return Evidence(name, r, "quasiperiodic", txt + why)
    return Evidence(name, r, None, txt + f" < {thr.rotation_quasi}: no rotation order")


def _expansion_evidence(name: str, z: np.ndarray, atol, thr: Thresholds, few: str) -> Evidence:
    """Nearest-neighbour expansion beyond the noise floor (`neighbour_expansion`): chaotic
    above ``expansion_chaotic``; no vote on fewer points than ``min_points_aperiodic``."""
    g = neighbour_expansion(z, atol=_floor(z, atol, thr.noise_floor))
    txt = f"mean one-step log growth of nearest-neighbour distances {g:.3f}"
    if not math.isfinite(g):
        return Evidence(name, None, None, "too few distinct neighbours above the noise floor")
    if few:
        return Evidence(name, g, None, txt + few)
    if g > thr.expansion_chaotic:
        return Evidence(
            name, g, "chaotic", txt + f" > {thr.expansion_chaotic}: neighbours separate"
        )
    return Evidence(name, g, None, txt + f" <= {thr.expansion_chaotic}: no clear stretching")


def _dimension_evidence(name: str, z: np.ndarray, thr: Thresholds) -> Evidence:
    """Correlation dimension (`correlation_dimension`): chaotic (not a curve) from
    ``dimension_chaotic``."""
    d2 = correlation_dimension(z)
    txt = f"correlation dimension D2 = {d2:.2f}"
    if math.isfinite(d2) and d2 >= thr.dimension_chaotic:
        return Evidence(name, d2, "chaotic", txt + f" >= {thr.dimension_chaotic}: not a curve")
    return Evidence(name, d2, None, txt + f" < {thr.dimension_chaotic}: a curve or unresolved")
