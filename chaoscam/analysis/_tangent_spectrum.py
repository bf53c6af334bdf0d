"""Lyapunov exponents by repeated QR of map Jacobians (the model's: from the kernel's tangent)."""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from .._util import freeze_fields
from ._validate import check_settings

__all__ = ["TangentSpectrum", "spectrum_from_jacobians"]


@dataclass(frozen=True)
class TangentSpectrum:
    """Lyapunov exponents of a sequence of map Jacobians (`spectrum_from_jacobians`).

    ``exponents`` λ₁ ≥ λ₂ per unit time of `period` (λ₂ = -inf: a Floquet multiplier 0, as at a
    complete chattering); ``stderr`` by batch means (NaN: < `n_batches` iterates, infinite λ).
    """

    exponents: np.ndarray  # shape (2,)
    stderr: np.ndarray  # shape (2,)
    n_periods: int  # iterates (for the model: cam periods) averaged
    local: np.ndarray = field(repr=False)  # ln R_kk of each QR step, shape (n_periods, 2)
    det_log: float  # mean of ln|det J_k| per unit time (equals λ₁ + λ₂)
    settings: dict[str, Any] = field(default_factory=dict)

    def __post_init__(self) -> None:
        freeze_fields(self, "exponents", "stderr", "local", "settings")

    @property
    def exponent(self) -> float:
        """The largest exponent λ₁."""
        return float(self.exponents[0])

    def interval(self, z: float = 3.0) -> tuple[float, float]:
        """λ₁ ± z standard errors."""
        s = float(self.stderr[0])
        return self.exponent - z * s, self.exponent + z * s


def spectrum_from_jacobians(
    jacobians: np.ndarray, period: float, *, n_batches: int = 20
) -> TangentSpectrum:
    """Lyapunov exponents of a sequence of 2×2 map Jacobians by repeated QR.

    With ``Q_0 = I`` and ``J_k Q_{k-1} = Q_k R_k`` (positive diagonal),

        λ_i = 1 / (n T) Σ_{k=1}^{n} ln R_k[i, i]

    (Benettin, Galgani, Giorgilli & Strelcyn 1980, Meccanica 15, 9; Eckmann & Ruelle 1985,
    Rev. Mod. Phys. 57, 617, sec. IV.C); λ₁ + λ₂ is the mean of ``ln |det J_k|`` / T.

    Limits: the standard error shrinks as 1/sqrt(n) and omits the bias of a too-short
    transient. A singular J_k gives λ₂ = -inf; λ₁ goes on.

    Parameters
    ----------
    jacobians : ndarray, shape (n, 2, 2)
        J_k = DP at x_{k-1}, in order along the orbit (across an impact, with its
        `saltation_matrix`).
    period : float
        Time T per map iterate (1: exponents per iterate; the cam period [s]: per second).
    n_batches : int
        Batches (at least 2) for the standard error of the mean of the per-iterate growths.

    Returns
    -------
    TangentSpectrum
    """
    check_settings(
        "spectrum_from_jacobians", period=(period, "real>0"), n_batches=(n_batches, "int>=2")
    )
    jac = np.asarray(jacobians, dtype=float)
    if jac.ndim != 3 or jac.shape[1:] != (2, 2) or len(jac) == 0:
        raise ValueError(f"jacobians must have shape (n >= 1, 2, 2), got {jac.shape}")
    if not np.isfinite(jac).all():
        raise ValueError("jacobians hold NaN or inf (was the tangent integrated?)")
    q = np.eye(2)
    local = np.empty((len(jac), 2))
    with np.errstate(divide="ignore"):
        for i, m in enumerate(jac):
            a = m @ q
            # Gram–Schmidt; a singular J keeps q's orthogonal complement, so λ₁ goes on
            r11 = math.hypot(a[0, 0], a[1, 0])
            q1 = a[:, 0] / r11 if r11 > 0 else q[:, 0]
            r12 = q1 @ a[:, 1]
            v = a[:, 1] - r12 * q1
            r22 = math.hypot(v[0], v[1])
            q2 = np.array([-q1[1], q1[0]])
            local[i] = (
                math.log(r11) if r11 > 0 else -math.inf,
                math.log(abs(q2 @ v)) if r22 > 0 else -math.inf,
            )
            q = np.column_stack([q1, q2])
        det_log = np.log(np.abs(np.linalg.det(jac)))
    n = len(jac)
    exps = local.mean(axis=0) / period
    stderr = np.full(2, math.nan)
    per = n // n_batches
    if per >= 1:
        for j in range(2):
            if np.isfinite(local[:, j]).all():
                means = local[: per * n_batches, j].reshape(n_batches, per).mean(axis=1) / period
                stderr[j] = means.std(ddof=1) / math.sqrt(n_batches)
    return TangentSpectrum(
        exponents=exps,
        stderr=stderr,
        n_periods=n,
        local=local,
        det_log=float(det_log.mean() / period),
        settings={"method": "tangent-qr", "n_batches": n_batches, "period": period},
    )
