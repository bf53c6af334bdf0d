"""Largest Lyapunov exponent from a measured series, wrapping nolds (Rosenstein, Eckmann)."""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from .._util import recorded
from .._util import warn as warn_user
from ._validate import as_series, check_settings

__all__ = ["DoubtfulEstimateWarning", "SeriesLyapunovResult", "lyapunov_from_series"]


class DoubtfulEstimateWarning(UserWarning):
    """An estimate was computed but its diagnostics make it doubtful."""


@dataclass(frozen=True)
class SeriesLyapunovResult:
    """Largest Lyapunov exponent estimated from a series by `lyapunov_from_series`."""

    exponent: float  # per unit time (NaN if the estimate could not be made)
    method: str  # "rosenstein" (nolds.lyap_r) or "eckmann" (nolds.lyap_e)
    doubtful: bool  # a diagnostic failed; `reasons` says which
    reasons: tuple[str, ...]
    stride: int  # subsampling stride applied to the series
    n_used: int  # samples passed to nolds
    exponents: np.ndarray  # all exponents returned (Eckmann: `matrix_dim` of them)
    fit_r2: float  # Rosenstein: R² of the line fitted to the mean log divergence, else NaN
    settings: dict = field(default_factory=dict)  # every setting passed to nolds, and dt


def lyapunov_from_series(
    x,
    dt: float,
    *,
    method: str = "rosenstein",
    max_points: int = 2000,
    emb_dim: int = 10,
    lag: int | None = None,
    min_tsep: int | None = None,
    trajectory_len: int = 20,
    matrix_dim: int = 4,
    min_points: int = 500,
    warn: bool = True,
) -> SeriesLyapunovResult:
    """Largest Lyapunov exponent of a scalar series by delay embedding (nolds).

    "rosenstein" fits the mean log divergence of nearest neighbours, ``<ln d_j(i)> ≈ λ₁ i Δt
    + const`` (``nolds.lyap_r``; Rosenstein, Collins & De Luca 1993, Physica D 65, 117);
    "eckmann" takes QR products of local linear maps (``nolds.lyap_e``; Eckmann, Kamphorst,
    Ruelle & Ciliberto 1986, Phys. Rev. A 34, 4971); nolds: Schölzel 2019,
    https://doi.org/10.5281/zenodo.3814723. The series is first subsampled by ``stride =
    ceil(N / max_points)`` (both cost O(N²)) and nolds given ``dt * stride``: λ₁ per unit time.

    Limits: biased low for weak chaos and rough on short or noisy data (Rosenstein reads
    7-27 % low on 20 000 samples of Lorenz, Rössler, Ueda); Eckmann gives spurious positive
    exponents on periodic signals. Prefer `spectrum_from_jacobians` where Jacobians are known.

    Parameters
    ----------
    x : array_like, shape (N,)
        Scalar observable after the transient.
    dt : float
        Sampling interval of `x` (the exponent is per this unit of time).
    method : {"rosenstein", "eckmann"}
    max_points, min_points : int
        Most samples kept after subsampling; fewer than `min_points` make it doubtful.
    emb_dim : int
        Embedding dimension; "eckmann" needs ``(emb_dim - 1) % (matrix_dim - 1) == 0``.
    lag, min_tsep : int, optional
        Embedding lag and neighbours' temporal separation in subsampled steps (None: nolds').
    trajectory_len, matrix_dim : int
        Rosenstein: steps the divergence is fitted over; Eckmann: size of the local Jacobians.
    warn : bool
        Emit a `DoubtfulEstimateWarning` when the estimate is doubtful.

    Returns
    -------
    SeriesLyapunovResult
        ``doubtful`` on too few samples, a near-constant series, nolds' warnings; Rosenstein:
        a non-linear (R² < 0.95) or saturating divergence (last third's slope < 30 % of the
        first's); Eckmann: a positive exponent sum, or no exponent near zero (for a flow).
    """
    x = as_series(x)
    if method not in ("rosenstein", "eckmann"):
        raise ValueError(f"method must be 'rosenstein' or 'eckmann', got {method!r}")
    check_settings(
        "lyapunov_from_series",
        dt=(dt, "real>0"),
        max_points=(max_points, "int>=1"),
        emb_dim=(emb_dim, "int>=1"),
        lag=(lag, "int>=1?"),
        min_tsep=(min_tsep, "int>=0?"),
        trajectory_len=(trajectory_len, "int>=2"),
        matrix_dim=(matrix_dim, "int>=1"),
        min_points=(min_points, "int>=1"),
    )
    stride = max(1, math.ceil(x.size / max_points))
    y = x[::stride]
    tau = dt * stride
    settings = dict(method=method, max_points=max_points, emb_dim=emb_dim, lag=lag,
                    min_tsep=min_tsep, trajectory_len=trajectory_len, matrix_dim=matrix_dim,
                    tau=tau, dt=dt, stride=stride)  # fmt: skip
    reasons: list[str] = []
    le, exps, r2 = math.nan, [], math.nan
    needed = (emb_dim - 1) * (lag or 1) + trajectory_len + 2 * (min_tsep or 0) + 20
    if np.ptp(y) <= 1e-12 * max(1.0, float(np.max(np.abs(y)))):
        reasons.append("constant series: no exponent can be estimated")
    elif y.size < max(needed, 50):
        reasons.append(f"only {y.size} samples after subsampling: too few for the embedding")
    else:
        if y.size < min_points:
            reasons.append(f"only {y.size} samples (< {min_points})")
        le, exps, r2 = _nolds(y, method, settings, reasons)
    if reasons and warn:
        warn_user(
            f"Lyapunov estimate from the series is doubtful: {'; '.join(reasons)}",
            DoubtfulEstimateWarning,
        )
    return SeriesLyapunovResult(float(le), method, bool(reasons), tuple(reasons), stride,
                                int(y.size), np.asarray(exps, dtype=float), float(r2),
                                settings)  # fmt: skip


def _nolds(y, method, s, reasons) -> tuple[float, list, float]:
    """(λ₁, the exponents, R²) by nolds; appends to ``reasons`` what makes it doubtful."""
    import nolds

    with recorded() as caught:  # nolds's warnings, kept as reasons (thread-safe)
        try:
            if method == "rosenstein":
                le, (ks, div, poly) = nolds.lyap_r(
                    y, emb_dim=s["emb_dim"], lag=s["lag"], min_tsep=s["min_tsep"], tau=s["tau"],
                    trajectory_len=s["trajectory_len"], fit="poly", debug_data=True,
                )  # fmt: skip
                exps = [le]
            else:
                exps = nolds.lyap_e(y, emb_dim=s["emb_dim"], matrix_dim=s["matrix_dim"],
                                    min_tsep=s["min_tsep"] or 0, tau=s["tau"])  # fmt: skip
                le = float(np.max(exps))
        except Exception as err:  # nolds raises on degenerate embeddings
            reasons.append(f"nolds failed: {err}")
            return math.nan, [], math.nan
    reasons.extend(f"nolds warned: {w.message}" for w in caught)
    if method != "rosenstein":
        exps_arr = np.asarray(exps, dtype=float)
        if exps_arr.sum() > 0:
            reasons.append("the exponents sum to a positive number")
        if np.min(np.abs(exps_arr)) > 0.1 * np.max(np.abs(exps_arr)):
            reasons.append("no exponent near zero, as a flow must have (ignore for maps)")
        return le, exps, math.nan
    div = np.asarray(div, dtype=float)
    ok = np.isfinite(div)
    if ok.sum() < 3:
        reasons.append("divergence curve undefined (no neighbours)")
        return le, exps, math.nan
    k, d = np.asarray(ks, dtype=float)[ok], div[ok]
    ss = float(np.sum((d - d.mean()) ** 2))
    r2 = 1.0 - float(np.sum((d - np.polyval(poly, k)) ** 2)) / ss if ss > 0 else math.nan
    if not (r2 >= 0.95):
        reasons.append(f"the log divergence is not linear in time (R² = {r2:.3f})")
    third = max(2, k.size // 3)
    s_first = np.polyfit(k[:third], d[:third], 1)[0]
    s_last = np.polyfit(k[-third:], d[-third:], 1)[0]
    if s_first > 0 and s_last < 0.3 * s_first:
        reasons.append("the divergence saturates within the fit range")
    return le, exps, r2
