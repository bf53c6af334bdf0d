"""A quasiperiodic two-torus signal and its stroboscopic section, in closed form."""

from __future__ import annotations

import math

import numpy as np

__all__ = ["GOLDEN", "torus_section", "torus_signal"]

GOLDEN = (math.sqrt(5.0) - 1.0) / 2.0
"""The golden mean (sqrt(5) - 1) / 2, the 'most irrational' frequency ratio."""


def torus_signal(
    t: np.ndarray, *, f1: float = 1.0, f2: float = GOLDEN, a: float = 0.5, b: float = 0.3
) -> np.ndarray:
    """Quasiperiodic signal on a two-torus: an amplitude- and phase-modulated carrier,

        x(t) = (1 + a cos 2π f2 t) cos 2π f1 t + b sin 2π f2 t,

    quasiperiodic when f2 / f1 is irrational (default the golden mean). Its spectrum holds
    lines at f1, f2 and f1 ± f2 only (a trigonometric polynomial on the torus), so it is
    exactly a two-frequency signal.
    """
    t = np.asarray(t, dtype=float)
    p1 = 2.0 * math.pi * f1 * t
    p2 = 2.0 * math.pi * f2 * t
    return (1.0 + a * np.cos(p2)) * np.cos(p1) + b * np.sin(p2)


def torus_section(
    n: int, *, f1: float = 1.0, f2: float = GOLDEN, a: float = 0.5, b: float = 0.3,
    phase: float = 0.0,
) -> np.ndarray:  # fmt: skip
    """Stroboscopic section of `torus_signal` at the period 1/f1: the points ``(x(t_k),
    x'(t_k))``, shape (n, 2), at ``t_k = (k + phase) / f1`` (x' analytic). They lie on a
    closed curve (an ellipse for phase 0) and advance along it by f2 / f1 each step."""
    t = (np.arange(int(n)) + phase) / f1
    w1 = 2.0 * math.pi * f1
    w2 = 2.0 * math.pi * f2
    x = torus_signal(t, f1=f1, f2=f2, a=a, b=b)
    dx = (
        -a * w2 * np.sin(w2 * t) * np.cos(w1 * t)
        - (1.0 + a * np.cos(w2 * t)) * w1 * np.sin(w1 * t)
        + b * w2 * np.cos(w2 * t)
    )
    return np.column_stack([x, dx])
