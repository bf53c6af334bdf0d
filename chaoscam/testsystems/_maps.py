"""Discrete-time test systems: logistic map, Hénon map, sine circle map: one-step functions,
Jacobians and orbit generators (after a transient), with their values from the literature."""

from __future__ import annotations

import math

import numpy as np

from ._signals import GOLDEN

__all__ = [
    "circle_map_orbit",
    "circle_map_rotation_number",
    "henon_jacobian",
    "henon_orbit",
    "henon_step",
    "logistic_jacobian",
    "logistic_orbit",
    "logistic_step",
]


def _orbit(step, x, n: int, transient: int) -> list:
    """The iterates ``x_transient, ..., x_{transient + n - 1}`` of ``x -> step(x)``."""
    for _ in range(int(transient)):
        x = step(x)
    out = []
    for _ in range(int(n)):
        out.append(x)
        x = step(x)
    return out


def logistic_step(x: np.ndarray, r: float) -> np.ndarray:
    """One step of the logistic map ``x -> r x (1 - x)``, x in [0, 1], r in (0, 4]."""
    x = np.asarray(x, dtype=float)
    return r * x * (1.0 - x)


def logistic_jacobian(x: np.ndarray, r: float) -> np.ndarray:
    """Jacobian of the logistic map, ``[[r (1 - 2 x)]]`` (shape (1, 1))."""
    x = np.asarray(x, dtype=float).reshape(-1)
    return np.array([[r * (1.0 - 2.0 * x[0])]])


def logistic_orbit(r: float, n: int, *, x0: float = 0.1234, transient: int = 1000) -> np.ndarray:
    """Orbit of the logistic map ``x_{k+1} = r x_k (1 - x_k)``, r in (0, 4], from x0 in (0, 1):
    the `n` iterates ``x_{transient}, ..., x_{transient + n - 1}``.

    May 1976 (Nature 261, 459): period 2 for 3 < r < 1 + sqrt(6), period 4 up to r ≈ 3.5441,
    the period-3 window opens at r = 1 + sqrt(8) ≈ 3.8284; at r = 4 the map is conjugate to
    the tent map, Lyapunov exponent ln 2.
    """
    return np.array(_orbit(lambda x: r * x * (1.0 - x), float(x0), n, transient))


def henon_step(x: np.ndarray, a: float = 1.4, b: float = 0.3) -> np.ndarray:
    """One step of the Hénon map ``(x, y) -> (1 - a x² + y, b x)``."""
    return np.array([1.0 - a * x[0] * x[0] + x[1], b * x[0]])


def henon_jacobian(x: np.ndarray, a: float = 1.4, b: float = 0.3) -> np.ndarray:
    """Jacobian of the Hénon map, ``[[-2 a x, 1], [b, 0]]``; its determinant is ``-b``."""
    return np.array([[-2.0 * a * x[0], 1.0], [b, 0.0]])


def henon_orbit(
    n: int,
    *,
    a: float = 1.4,
    b: float = 0.3,
    x0: tuple[float, float] = (0.1, 0.1),
    transient: int = 1000,
) -> np.ndarray:
    """Orbit of the Hénon map (Hénon 1976, Commun. Math. Phys. 50, 69): the `n` iterates
    ``(x_k, y_k)`` after `transient`, shape (n, 2). For a = 1.4, b = 0.3 the largest Lyapunov
    exponent is ≈ 0.419 per iterate and the exponents sum to ln b."""

    def step(xy):
        x, y = xy
        return 1.0 - a * x * x + y, b * x

    orbit = _orbit(step, (float(x0[0]), float(x0[1])), n, transient)
    return np.array(orbit, dtype=float).reshape(-1, 2)


def circle_map_orbit(
    n: int,
    *,
    omega: float = GOLDEN,
    k: float = 0.5,
    x0: float = 0.0,
    transient: int = 1000,
    lift: bool = False,
) -> np.ndarray:
    """Orbit of the sine circle map ``θ_{j+1} = θ_j + Ω - (K / 2π) sin(2π θ_j)``, in turns.

    Returns the `n` angles after `transient` iterates from `x0`, in [0, 1) unless `lift`
    (not reduced mod 1, from which the rotation number is computed). Ω = `omega` (default
    the golden mean), K = `k`: for 0 <= K < 1 the map is an analytic circle diffeomorphism;
    outside the Arnold tongues (positive measure in Ω) its rotation number is irrational and
    the orbit quasiperiodic, dense on the circle.

    Reference: Arnold (1965); Jensen, Bak & Bohr (1984), Phys. Rev. A 30, 1960. Whether a
    given (Ω, K) lies outside every tongue cannot be proven numerically: finite orbits only
    bound the denominators of a possible locking (see `circle_map_rotation_number`).
    """
    two_pi = 2.0 * math.pi

    def step(x):
        return x + omega - k / two_pi * math.sin(two_pi * x)

    x = _orbit(step, float(x0), 1, transient)[0]  # after the transient
    out = np.array(_orbit(step, x - math.floor(x), n, 0))
    return out if lift else out - np.floor(out)


def circle_map_rotation_number(*, omega: float = GOLDEN, k: float = 0.5, n: int = 100_000) -> float:
    """Rotation number ``ρ = lim (θ_n - θ_0) / n`` of the sine circle map from its lift; the
    error after `n` iterates is below 1/n for a circle homeomorphism (K <= 1)."""
    lifted = circle_map_orbit(n + 1, omega=omega, k=k, lift=True)
    return float((lifted[-1] - lifted[0]) / n)
