"""Evidence builders shared by the classifiers: section, 0–1 test, Lyapunov exponent."""

from __future__ import annotations

import math

import numpy as np

from ._periodicity import (
    correlation_dimension,
    embed_angles,
    neighbour_expansion,
    rotation_order,
    section_period,
    stationarity_ratio,
)
from ._validate import as_points
from ._verdict import Evidence
from ._zero_one import zero_one_test

# Decision thresholds (documented in classify_section and classify_signal).
K_CHAOTIC, K_REGULAR = 0.8, 0.2
ROTATION_QUASI = 0.9
EXPANSION_CHAOTIC = 0.1
D2_CHAOTIC = 1.3
STATIONARY = (0.5, 2.0)


def safe(name: str, fn, *args, **kwargs):
    """Run one method; a failure becomes an abstaining Evidence instead of a crash."""
    try:
        return fn(*args, **kwargs), None
    except (ValueError, FloatingPointError, np.linalg.LinAlgError, ArithmeticError) as err:
        return None, Evidence(name, None, None, f"failed: {err}")


def zero_one_evidence(name: str, series, what: str, seed: int) -> Evidence:
    res, failed = safe(name, zero_one_test, series, seed=seed)
    if failed:
        return failed
    if res.message:
        return Evidence(name, None, None, f"{what}: {res.message}")
    k = res.k
    txt = f"{what}: K = {k:.3f} (median over {res.c.size} c, N = {res.n})"
    if res.oversampled:
        return Evidence(name, k, None, txt + "; flagged as oversampled, not used")
    if k >= K_CHAOTIC:
        return Evidence(name, k, "chaotic", txt + f" >= {K_CHAOTIC}")
    if k <= K_REGULAR:
        return Evidence(name, k, "not_chaotic", txt + f" <= {K_REGULAR}")
    return Evidence(name, k, None, txt + f": between {K_REGULAR} and {K_CHAOTIC}, inconclusive")


def lyapunov_evidence(lyap: float, tol: float, unit: str) -> Evidence:
    lyap = float(lyap)
    if not math.isfinite(lyap):
        if lyap == -math.inf:
            return Evidence("lyapunov", lyap, "not_chaotic", "λ₁ = -inf (superstable)")
        return Evidence("lyapunov", None, None, "λ₁ is NaN: not used")
    txt = f"λ₁ = {lyap:.4g} {unit} (threshold ± {tol:.3g})"
    if lyap > tol:
        return Evidence("lyapunov", lyap, "chaotic", txt + ": positive")
    return Evidence("lyapunov", lyap, "not_chaotic", txt + ": not positive")


def section_evidence(
    points,
    *,
    prefix,
    angle_periods,
    rtol,
    atol,
    max_period,
    min_points_aperiodic,
    zero_one,
    seed,
):
    """Evidence from section points; returns (evidence list, periods dict, reasons)."""
    ev: list[Evidence] = []
    reasons: list[str] = []
    x = as_points(points)
    n = x.shape[0]
    z = embed_angles(x, angle_periods)
    pr, failed = safe(
        f"{prefix}period", section_period, z, rtol=rtol, atol=atol, max_period=max_period
    )
    if failed:
        return [failed], {}, reasons
    if pr.message:
        reasons.append(f"section: {pr.message}")
        return [Evidence(f"{prefix}period", None, None, pr.message)], {}, reasons
    if pr.period is not None:
        what = (
            "all points coincide (a fixed point)"
            if pr.coincident
            else (f"every point recurs after {pr.period} iterates")
        )
        trans = f"; first {pr.transient} points left out as transient" if pr.transient else ""
        ev.append(
            Evidence(
                f"{prefix}period",
                pr.period,
                "periodic",
                f"{what} within rtol = {rtol:g} of the extent "
                f"(worst mismatch {pr.mismatch:.2g} tol){trans}",
            )
        )
        return ev, {f"{prefix}period": pr.period}, reasons

    ratio = stationarity_ratio(z)
    settled = STATIONARY[0] <= ratio <= STATIONARY[1] if math.isfinite(ratio) else True
    if not settled:
        reasons.append(
            f"section: the points have not settled (second-half/first-half spread "
            f"{ratio:.2f}); discard more transient"
        )
        ev.append(
            Evidence(
                f"{prefix}period",
                None,
                None,
                f"no period <= {pr.max_period}, but the points are still "
                f"converging or escaping (spread ratio {ratio:.2f})",
            )
        )
        return ev, {}, reasons
    ev.append(
        Evidence(
            f"{prefix}period",
            None,
            "not_periodic",
            f"no lag 1..{pr.max_period} recurs within rtol = {rtol:g} "
            f"(closest: {pr.mismatch:.3g} tol)",
        )
    )

    enough = n >= min_points_aperiodic
    few = f"; {n} points < {min_points_aperiodic}: too few to separate quasiperiodic from chaotic"
    rot = rotation_order(z)
    txt = (
        f"rank-shift consistency R = {rot.consistency:.3f}, rotation number "
        f"{rot.rotation_number:.4f}"
    )
    if not enough:
        ev.append(Evidence(f"{prefix}rotation", rot.consistency, None, txt + few))
    elif rot.consistency >= ROTATION_QUASI:
        ev.append(
            Evidence(
                f"{prefix}rotation",
                rot.consistency,
                "quasiperiodic",
                txt + f" >= {ROTATION_QUASI}: points turn along a closed curve",
            )
        )
    else:
        ev.append(
            Evidence(
                f"{prefix}rotation",
                rot.consistency,
                None,
                txt + f" < {ROTATION_QUASI}: no rotation order",
            )
        )

    g = neighbour_expansion(z)
    txt = f"mean one-step log growth of nearest-neighbour distances {g:.3f}"
    if not math.isfinite(g):
        ev.append(Evidence(f"{prefix}expansion", None, None, "too few distinct neighbours"))
    elif not enough:
        ev.append(Evidence(f"{prefix}expansion", g, None, txt + few))
    elif g > EXPANSION_CHAOTIC:
        ev.append(
            Evidence(
                f"{prefix}expansion",
                g,
                "chaotic",
                txt + f" > {EXPANSION_CHAOTIC}: neighbours separate",
            )
        )
    else:
        ev.append(
            Evidence(
                f"{prefix}expansion", g, None, txt + f" <= {EXPANSION_CHAOTIC}: no clear stretching"
            )
        )

    if z.shape[1] >= 2 and n >= 500:
        d2 = correlation_dimension(z)
        txt = f"correlation dimension D2 = {d2:.2f}"
        if math.isfinite(d2) and d2 >= D2_CHAOTIC:
            ev.append(
                Evidence(
                    f"{prefix}dimension", d2, "chaotic", txt + f" >= {D2_CHAOTIC}: not a curve"
                )
            )
        else:
            ev.append(
                Evidence(
                    f"{prefix}dimension", d2, None, txt + f" < {D2_CHAOTIC}: a curve or unresolved"
                )
            )
    if zero_one:
        if n >= 100:
            ev.append(
                zero_one_evidence(
                    f"{prefix}zero_one", z[:, 0], "0-1 test on the first section coordinate", seed
                )
            )
        else:
            ev.append(
                Evidence(
                    f"{prefix}zero_one", None, None, f"{n} section points < 100: 0-1 test not run"
                )
            )
    return ev, {}, reasons
