"""Weighted Birkhoff averages: quasiperiodicity shown by fast convergence; rotation number."""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from ._periodicity import _curve_angles
from ._validate import as_points, check_settings

__all__ = ["BirkhoffResult", "birkhoff_weights", "weighted_birkhoff"]

_MIN_HALF = 8


def birkhoff_weights(n: int) -> np.ndarray:
    """Normalised bump weights ``ŵ_k ∝ exp(-1 / (t (1 - t)))`` at ``t = k / (n + 1)``, k = 1 .. n.

    The weights of the weighted Birkhoff average ``WB_n(f) = Σ_k ŵ_k f(x_k)`` (Das, Saiki,
    Sander & Yorke 2017): w and all its derivatives vanish at both ends.
    """
    check_settings("birkhoff_weights", n=(n, "int>=1"))
    t = np.arange(1, n + 1) / (n + 1.0)
    w = np.exp(-1.0 / (t * (1.0 - t)))
    return w / w.sum()


@dataclass(frozen=True)
class BirkhoffResult:
    """Result of `weighted_birkhoff`.

    ``digits_by_observable``: the converged digits (at most 16) of each observable, "x0",
    "x1", ... (coordinates), "cos", "sin" (angle about the centroid), "turn" (its increment);
    ``digits`` their minimum (NaN on too few points). ``rotation_number`` in [0, 1) (1 - ρ
    seen from the other side, d > 2; NaN for d = 1).
    """

    digits: float
    digits_by_observable: dict
    rotation_number: float
    n: int  # points used, 2 h + 1 (two averages of h points, h increments each)
    message: str = ""  # why nothing was computed (too few points), else empty
    settings: dict = field(default_factory=dict)  # the weight function and h


def _plane_angles(x: np.ndarray) -> np.ndarray:
    """Angle about the centroid: d = 2 axes scaled by their spread, d > 2 principal plane."""
    if x.shape[1] > 2:
        return _curve_angles(x)
    c = x - x.mean(axis=0)
    s = c.std(axis=0)
    u = c / np.where(s > 0, s, 1.0)
    return np.arctan2(u[:, 1], u[:, 0])


def _lifted_turns(phi: np.ndarray) -> np.ndarray:
    """Angle increments in turns, cut opposite their circular mean so they vary smoothly."""
    inc = np.diff(phi)
    mu = float(np.angle(np.mean(np.exp(1j * inc))))
    return (mu + np.angle(np.exp(1j * (inc - mu)))) / (2.0 * math.pi)


def weighted_birkhoff(points) -> BirkhoffResult:
    """Converged digits of weighted Birkhoff averages, and the rotation number of a curve.

    With the weights of `birkhoff_weights`, ``WB_h(f)(x_m) = Σ_{k=1}^{h} ŵ_k f(x_{m+k-1})``
    converges faster than any power of 1/h on a smooth Diophantine torus, as h^{-1/2} on a
    chaotic orbit (Das, Saiki, Sander & Yorke, Nonlinearity 30 (2017) 4111; Das & Yorke,
    Nonlinearity 31 (2018) 491). The digits compare the first h iterates with the next h,

        ``dig = -log10 |WB_h(f)(x_0) - WB_h(f)(x_h)|``,

    f scaled by its range, the minimum over the coordinates, cos and sin of the angle φ
    about the centroid, and the lifted increment Δφ_k, whose average in turns is ρ.

    Limits: a periodic orbit converges as fast (test the period first); noise of relative
    size ε caps the digits near -log10 ε (a noisy torus reads like weak chaos); ρ is the
    rotation number only for a curve star-shaped about its centroid.

    Parameters
    ----------
    points : array_like, shape (N,) or (N, d)
        Section points (or map iterates) in time order, after the transient; angles
        embedded with `embed_angles`.

    Returns
    -------
    BirkhoffResult
    """
    x = as_points(points)
    n = x.shape[0]
    h = (n - 1) // 2
    settings = dict(weight="exp(-1/(t(1-t)))", half=h)
    if h < _MIN_HALF:
        why = f"only {n} points; the Birkhoff averages need >= {2 * _MIN_HALF + 1}"
        return BirkhoffResult(math.nan, {}, math.nan, n, why, settings)
    obs = {f"x{j}": x[: 2 * h, j] for j in range(x.shape[1])}
    rho = math.nan
    w = birkhoff_weights(h)
    if x.shape[1] >= 2:
        phi = _plane_angles(x[: 2 * h + 1])
        obs["cos"] = np.cos(phi[: 2 * h])
        obs["sin"] = np.sin(phi[: 2 * h])
        obs["turn"] = _lifted_turns(phi)
    digits = {}
    for name, f in obs.items():
        a, b = float(w @ f[:h]), float(w @ f[h : 2 * h])
        scale = 1.0 if name == "turn" else float(np.ptp(f))
        if scale <= 0:
            digits[name] = 16.0
            continue
        digits[name] = float(-math.log10(max(abs(a - b) / scale, 1e-16)))
        if name == "turn":
            rho = float(np.mod(w @ f[:h] * 0.5 + w @ f[h : 2 * h] * 0.5, 1.0))
    return BirkhoffResult(min(digits.values()), digits, rho, 2 * h + 1, "", settings)
