"""Period and rotation order of Poincaré-section points (other set measures: `_set_measures`)."""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, field

import numpy as np

from .._util import freeze_fields
from ._thresholds import Thresholds
from ._validate import as_points, check_atol, check_settings

__all__ = ["PeriodResult", "RotationResult", "embed_angles", "rotation_order", "section_period"]


def embed_angles(points, angle_periods: Sequence[float | None] | None = None) -> np.ndarray:
    """Replace angular coordinates by (cos, sin) pairs so that distances ignore the wrap.

    Coordinate j of period P_j (2π for a phase, 1 for turns) becomes ``(P_j / 2π) (cos 2π
    x_j / P_j, sin 2π x_j / P_j)``: the chord, in the coordinate's own units.

    Parameters
    ----------
    points : array_like, shape (N,) or (N, d)
    angle_periods : sequence of float or None, length d, optional
        Period of each angular coordinate, None for ordinary ones.

    Returns
    -------
    ndarray, shape (N, d + number of angular coordinates)
    """
    x = as_points(points)
    if angle_periods is None:
        return x
    if len(angle_periods) != x.shape[1]:
        raise ValueError(
            f"angle_periods has {len(angle_periods)} entries for {x.shape[1]} coordinates"
        )
    cols = []
    for j, period in enumerate(angle_periods):
        if period is None:
            cols.append(x[:, j])
        else:
            a = 2.0 * math.pi * x[:, j] / period
            r = period / (2.0 * math.pi)
            cols.extend([r * np.cos(a), r * np.sin(a)])
    return np.column_stack(cols)


def delays(x: np.ndarray, dim: int) -> np.ndarray:
    """Delay vectors ``(x_k, x_{k+1}, ..., x_{k+dim-1})`` of a series x, shape (N - dim + 1, dim).

    The delay vectors of a generic smooth scalar observable of a map on a set of box
    dimension D embed that set for ``dim > 2 D`` (Takens 1981, Lecture Notes in Math. 898,
    366; Sauer, Yorke & Casdagli 1991, J. Stat. Phys. 65, 579): 3 for a closed curve; with
    2 a curve may cross itself. Lag 1 (one iterate). Limit: for a rotation number near 0 or
    1/2 the delays of cos θ are nearly ±cos θ, a thin curve.
    """
    n = x.shape[0] - dim + 1
    return np.column_stack([x[j : j + n] for j in range(dim)])


def _floor(x: np.ndarray, atol, noise_floor: float) -> np.ndarray:
    """Per-coordinate absolute floor: `atol` if given, else ``noise_floor · max_j max_k |x_kj|``."""
    d = x.shape[1]
    if atol is not None:
        return np.broadcast_to(np.asarray(atol, dtype=float), (d,)).copy()
    mag = float(np.max(np.abs(x))) if x.size else 0.0
    return np.full(d, noise_floor * mag)


def _tolerance(x: np.ndarray, rtol: float, atol, noise_floor: float) -> np.ndarray:
    """Per-coordinate tolerance ``max(rtol · extent_j, atol_j)``, extent_j the range of x_j."""
    return np.maximum(np.maximum(rtol * np.ptp(x, axis=0), _floor(x, atol, noise_floor)), 1e-300)


def _band_widths(y: np.ndarray, p: int) -> np.ndarray:
    """Range of each band ``y[r::p]`` (r = 0 .. p - 1), shape (p, d)."""
    m, d = y.shape
    full = (m // p) * p
    blocks = y[:full].reshape(-1, p, d)
    lo, hi = blocks.min(axis=0), blocks.max(axis=0)
    tail = y[full:]
    if tail.shape[0]:
        t = tail.shape[0]
        lo[:t] = np.minimum(lo[:t], tail)
        hi[:t] = np.maximum(hi[:t], tail)
    return hi - lo


@dataclass(frozen=True)
class PeriodResult:
    """Result of `section_period`; arrays are per coordinate, in the units of the points."""

    period: int | None  # smallest n whose bands x[r::n] (after `transient`) are all narrow
    transient: int  # leading points left out to find the period
    max_period: int  # largest lag tested
    mismatch: float  # max_{r,j} width_rj / tol_j at the period (<= 1), else the least tested
    tolerance: np.ndarray  # max(atol_j, rtol · extent_j)
    coincident: bool  # all points coincide within tolerance (a fixed point: period 1)
    message: str = ""  # why no period could be tested (too few points)
    settings: dict = field(default_factory=dict)
    jitter: np.ndarray = field(default_factory=lambda: np.array([]))  # widest band; NaN: none
    extent: np.ndarray = field(default_factory=lambda: np.array([]))  # range of the points kept
    # least band-centre distance / max(band_separation · jitter, round-off); > 1: distinct
    separation: float = math.inf

    def __post_init__(self) -> None:
        freeze_fields(self, "tolerance", "settings", "jitter", "extent")


def _separation(y: np.ndarray, p: int, scale: np.ndarray) -> float:
    """Smallest Chebyshev distance between the p band centres, in units of ``scale``."""
    if p == 1:
        return math.inf
    c = np.array([np.median(y[r::p], axis=0) for r in range(p)]) / scale
    d = np.max(np.abs(c[:, None, :] - c[None, :, :]), axis=-1)
    d[np.diag_indices(p)] = np.inf
    return float(d.min())


def section_period(
    points,
    *,
    rtol: float | None = None,
    atol=None,
    max_period: int | None = None,
    min_repeats: int = 2,
    allow_transient: bool = True,
    min_points: int = 8,
    noise_floor: float | None = None,
    distinct: bool = True,
    band_separation: float | None = None,
) -> PeriodResult:
    """Period of section points by fixed-lag bands: the smallest n whose n bands are narrow.

    Period n: every band ``B_r = {x_{r + kn}}`` is narrow in every coordinate j,

        max_k x_{r+kn, j} - min_k x_{r+kn, j} <= tol_j = max(atol_j, rtol · extent_j),

    extent_j the range of coordinate j. Bands of a lag, unlike clusters, also check the
    order of the visits; a slow drift along a curve (a torus near p/n) widens them.

    Limits: periods above N / `min_repeats` are not seen; jitter above `rtol` × extent hides
    any; a torus with rotation number within ~rtol / (π N) of p/n reads as period n; points
    closer than the tolerance are one (period n for 2n just after a period doubling).

    Parameters
    ----------
    points : array_like, shape (N,) or (N, d)
        Section points in time order, after the transient; angles through `embed_angles`.
    rtol : float, optional
        Band width allowed relative to the extent; default `Thresholds.period_rtol`.
    atol : float or array_like, optional
        Absolute floor per coordinate, in the units of the points (pass the integrator's
        accuracy when scales differ); default per `Thresholds.noise_floor`.
    max_period : int, optional
        Largest lag tested; default ``N // min_repeats``.
    min_repeats, min_points : int
        Fewest repeats of the pattern (N - transient >= min_repeats n); fewest points to test.
    allow_transient : bool
        Also try leaving out the first 10 %, 20 %, ..., 50 % of the points.
    noise_floor : float, optional
        `atol` as a fraction of ``max_j max_k |x_kj|``; default `Thresholds.noise_floor`.
    distinct : bool
        Refuse a lag two of whose band centres lie within `band_separation` widths (or 64
        ulps) in every coordinate. False: whether the points keep to bands visited in order
        (banded chaos), not whether they repeat.
    band_separation : float, optional
        See `distinct`; default `Thresholds.band_separation`.

    Returns
    -------
    PeriodResult
        Period 1 for points all within `atol` (a fixed point of the section map).
    """
    check_settings(
        "section_period",
        band_separation=(band_separation, "real>0?"),
        rtol=(rtol, "real>=0?"),
        max_period=(max_period, "int>=1?"),
        min_repeats=(min_repeats, "int>=1"),
        min_points=(min_points, "int>=1"),
        noise_floor=(noise_floor, "real>=0?"),
    )
    default = Thresholds()
    rtol = default.period_rtol if rtol is None else float(rtol)
    noise_floor = default.noise_floor if noise_floor is None else float(noise_floor)
    band_separation = default.band_separation if band_separation is None else band_separation
    x = as_points(points)
    n = x.shape[0]
    check_atol("section_period", atol, x.shape[1])
    settings = dict(rtol=rtol, atol=atol, noise_floor=noise_floor, max_period=max_period,
                    min_repeats=min_repeats, allow_transient=allow_transient,
                    min_points=min_points, distinct=distinct,
                    band_separation=band_separation)  # fmt: skip
    d = x.shape[1]
    nan = np.full(d, math.nan)
    if n < min_points:
        why = f"only {n} section points; the period test needs >= {min_points}"
        ext = np.ptp(x, axis=0) if n else nan
        return PeriodResult(None, 0, 0, math.nan, np.array([]), False, why, settings, nan, ext)
    starts = [0]
    if allow_transient:
        step = max(1, n // 10)
        starts += list(range(step, n // 2 + 1, step))
    best = math.inf
    max_p_used = 0
    tol_out = _tolerance(x, rtol, atol, noise_floor)
    round_off = np.maximum(64 * np.finfo(float).eps * np.max(np.abs(x), axis=0), 1e-300)
    for k0 in starts:
        y = x[k0:]
        m = y.shape[0]
        tol = _tolerance(y, rtol, atol, noise_floor)
        ext = np.ptp(y, axis=0)
        if np.all(ext <= tol):
            top, mis = max(1, m // min_repeats), float(np.max(ext / tol))
            return PeriodResult(1, k0, top, mis, tol, True, "", settings, ext, ext)
        max_p = m // min_repeats if max_period is None else min(max_period, m // min_repeats)
        max_p_used = max(max_p_used, max_p)
        for p in range(1, max_p + 1):
            width = _band_widths(y, p)
            mis = float(np.max(width / tol))
            if mis <= 1.0:
                jitter = width.max(axis=0)
                sep = _separation(y, p, np.maximum(band_separation * jitter, round_off))
                if sep > 1.0 or not distinct:
                    return PeriodResult(
                        p, k0, max_p, mis, tol, False, "", settings, jitter, ext, sep
                    )
            best = min(best, mis)
    msg = "" if max_p_used >= 1 else f"too few points ({n}) to test any period"
    return PeriodResult(
        None, 0, max_p_used, best, tol_out, False, msg, settings, nan, np.ptp(x, axis=0)
    )


@dataclass(frozen=True)
class RotationResult:
    """Result of `rotation_order`."""

    consistency: float  # mean resultant length R in [0, 1] of the rank shifts (1: a rotation)
    rotation_number: float  # mean rank shift / N in [0, 1) (1 - ρ when it turns the other way)


def _curve_angles(z: np.ndarray) -> np.ndarray:
    """Angle of each point about the centroid after whitening by the two leading axes."""
    c = z - z.mean(axis=0)
    _, s, vt = np.linalg.svd(c, full_matrices=False)
    s = np.where(s > 0, s, 1.0)
    w = (c @ vt.T[:, :2]) / s[:2]
    return np.arctan2(w[:, 1], w[:, 0])


def rotation_order(z) -> RotationResult:
    """Rank-shift consistency: does the orbit advance along a closed curve like a rotation?

    The points are ordered around the curve by the angle about the centroid after whitening
    by the two leading principal axes; a scalar (d = 1) both by value (a monotone observable
    of the angle, e.g. the angle itself) and by the angle of its delay pairs ``(x_k,
    x_{k+1})`` (a folding one, e.g. cos θ; `delays`), keeping the more consistent order. With
    r_k the rank of point k, the shift ``s_k = (r_{k+1} - r_k) mod N`` of an irrational
    rotation by ρ stays within O(log N) of ρN (three-gap theorem; Weyl 1916), so ``R =
    |<exp(2πi s_k / N)>|`` is near 1; chaos scrambles the order (both orders), R ~ 1/sqrt(N).

    Limits: a curve not star-shaped about its centroid lowers R; phase-coherent chaos on a
    thin band (a breaking torus) can keep R high, so R supports quasiperiodicity only with a
    non-positive exponent or a low 0–1 K. A periodic orbit is trivially consistent.

    Parameters
    ----------
    z : array_like, shape (N,) or (N, d)
        Section points (angles embedded with `embed_angles`).

    Returns
    -------
    RotationResult
    """
    x = as_points(z)
    if x.shape[1] > 1:
        return _rank_shifts(_curve_angles(x))
    orders = [x[:, 0]] + ([_curve_angles(delays(x[:, 0], 2))] if x.shape[0] > 2 else [])
    return max(map(_rank_shifts, orders), key=lambda r: r.consistency)


def _rank_shifts(angles: np.ndarray) -> RotationResult:
    """`rotation_order`'s R and ρ from the points' positions ``angles`` around the curve."""
    n = angles.shape[0]
    ranks = np.empty(n, dtype=np.int64)
    ranks[np.argsort(angles, kind="stable")] = np.arange(n)
    s = np.mod(np.diff(ranks), n)
    phasor = np.mean(np.exp(2j * math.pi * s / n))
    rho = float(np.mod(np.angle(phasor) / (2.0 * math.pi), 1.0))
    return RotationResult(float(np.abs(phasor)), rho)
