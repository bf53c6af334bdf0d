"""Continuous-time test systems: Lorenz, Rössler and the Ueda (forced Duffing) oscillator.

The vector fields are compiled with numba and integrated by classical fixed-step RK4;
`flow_reference` integrates them with scipy's DOP853 at tight tolerances (an independent
path). Forced systems carry time as the last state component (``t' = 1``).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numba
import numpy as np

__all__ = ["FlowSystem", "flow_reference", "flow_trajectory", "lorenz", "rossler", "ueda"]

LORENZ, ROSSLER, UEDA = 0, 1, 2


@numba.njit(cache=True)
def _rhs(kind, y, p, out):
    """Vector field of system `kind` at y with parameters p, written into out."""
    if kind == LORENZ:
        out[0] = p[0] * (y[1] - y[0])
        out[1] = y[0] * (p[1] - y[2]) - y[1]
        out[2] = y[0] * y[1] - p[2] * y[2]
    elif kind == ROSSLER:
        out[0] = -y[1] - y[2]
        out[1] = y[0] + p[0] * y[1]
        out[2] = p[1] + y[2] * (y[0] - p[2])
    else:
        # Ueda: x'' + k x' + x^3 = B cos t, state (x, x', t)
        out[0] = y[1]
        out[1] = -p[0] * y[1] - y[0] * y[0] * y[0] + p[1] * math.cos(y[2])
        out[2] = 1.0


@numba.njit(cache=True)
def _rk4_run(kind, y0, p, h, n_steps, every):
    """RK4 with step h for n_steps; returns the states every `every` steps (first included)."""
    d = y0.size
    n_out = n_steps // every + 1
    out = np.empty((n_out, d))
    y = y0.copy()
    k1, k2, k3, k4, tmp = np.empty(d), np.empty(d), np.empty(d), np.empty(d), np.empty(d)
    out[0] = y
    j = 1
    for s in range(1, n_steps + 1):
        _rhs(kind, y, p, k1)
        for i in range(d):
            tmp[i] = y[i] + 0.5 * h * k1[i]
        _rhs(kind, tmp, p, k2)
        for i in range(d):
            tmp[i] = y[i] + 0.5 * h * k2[i]
        _rhs(kind, tmp, p, k3)
        for i in range(d):
            tmp[i] = y[i] + h * k3[i]
        _rhs(kind, tmp, p, k4)
        for i in range(d):
            y[i] += h / 6.0 * (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i])
        if s % every == 0:
            out[j] = y
            j += 1
    return out


@dataclass(frozen=True)
class FlowSystem:
    """A test flow ``y' = f(y; p)``: its compiled right-hand side and parameters."""

    name: str
    kind: int  # which compiled vector field (LORENZ, ROSSLER, UEDA) the kernels evaluate
    params: tuple[float, ...]  # in the order the vector field reads them
    dim: int  # state dimension (time included for forced systems)
    forcing_period: float | None = None  # of a non-autonomous system (time is then y[-1])


def lorenz(sigma: float = 10.0, rho: float = 28.0, beta: float = 8.0 / 3.0) -> FlowSystem:
    """Lorenz (1963) system ``x' = σ(y - x), y' = x(ρ - z) - y, z' = xy - βz``: at (10, 28,
    8/3) λ₁ ≈ 0.906 (Sprott 2003, "Chaos and Time-Series Analysis", table A.1: 0.9056)."""
    return FlowSystem("lorenz", LORENZ, (sigma, rho, beta), 3)


def rossler(a: float = 0.2, b: float = 0.2, c: float = 5.7) -> FlowSystem:
    """Rössler (1976) system ``x' = -y - z, y' = x + a y, z' = b + z (x - c)``: with a = b =
    0.2, a period-1 limit cycle at c = 2.5, period 2 at c = 3.5, chaos at c = 5.7 with
    λ₁ ≈ 0.0714 (Sprott 2003, table A.1)."""
    return FlowSystem("rossler", ROSSLER, (a, b, c), 3)


def ueda(k: float = 0.05, b: float = 7.5) -> FlowSystem:
    """Ueda oscillator ``x'' + k x' + x³ = B cos t``, state ``(x, x', t)``: at k = 0.05,
    B = 7.5 (Ueda 1979, J. Stat. Phys. 20, 181) chaotic with λ₁ ≈ 0.0999 per unit time in
    the (x, x') directions (the time direction adds the trivial zero exponent)."""
    return FlowSystem("ueda", UEDA, (k, b), 3, forcing_period=2.0 * math.pi)


def flow_trajectory(
    system: FlowSystem,
    y0: np.ndarray,
    *,
    dt: float,
    n_samples: int,
    sample_every: int = 1,
    transient_time: float = 0.0,
) -> tuple[np.ndarray, np.ndarray]:
    """Integrate a test flow with fixed-step RK4 and sample it uniformly.

    Parameters
    ----------
    system : FlowSystem
    y0 : array_like, shape (dim,)
        Initial state (time last for forced systems).
    dt : float
        RK4 step: global error O(dt⁴); 0.005 for Lorenz, 0.01 for Rössler and Ueda keep it
        far below what the tests resolve.
    n_samples, sample_every : int
        Samples returned, and steps between them (interval ``dt * sample_every``).
    transient_time : float
        Integrated first and discarded (rounded to whole steps).

    Returns
    -------
    t : ndarray, shape (n_samples,)
        Sample times from 0 after the transient (``states[:, -1]`` is a forced system's
        absolute time).
    states : ndarray, shape (n_samples, dim)
    """
    p = np.asarray(system.params, dtype=float)
    y = np.asarray(y0, dtype=float).copy()
    n_tr = int(round(transient_time / dt))
    if n_tr > 0:
        y = _rk4_run(system.kind, y, p, dt, n_tr, n_tr)[-1]
    every = int(sample_every)
    n_steps = (int(n_samples) - 1) * every
    states = _rk4_run(system.kind, y, p, dt, n_steps, every)
    t = np.arange(int(n_samples)) * dt * every
    return t, states


def flow_reference(
    system: FlowSystem,
    y0: np.ndarray,
    t_eval: np.ndarray,
    *,
    rtol: float = 1e-11,
    atol: float = 1e-12,
) -> np.ndarray:
    """The states at `t_eval`, shape (len(t_eval), dim), by scipy's DOP853 at tight
    tolerances: the path RK4 is checked against."""
    from scipy.integrate import solve_ivp

    p = np.asarray(system.params, dtype=float)
    out = np.empty(system.dim)

    def f(_t, y):
        _rhs(system.kind, y, p, out)
        return out.copy()

    t_eval = np.asarray(t_eval, dtype=float)
    y0 = np.asarray(y0, dtype=float)
    span = (t_eval[0], t_eval[-1])
    sol = solve_ivp(f, span, y0, method="DOP853", t_eval=t_eval, rtol=rtol, atol=atol)
    if not sol.success:
        raise RuntimeError(f"solve_ivp failed: {sol.message}")
    return sol.y.T
