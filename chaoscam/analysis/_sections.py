"""Sections of sampled signals: local maxima and plane crossings."""

from __future__ import annotations

import numpy as np

from ._validate import as_points, as_series, check_settings

__all__ = ["crossing_section", "local_maxima"]


def local_maxima(x, dt: float = 1.0) -> tuple[np.ndarray, np.ndarray]:
    """Local maxima of a sampled signal, refined by a parabola through three samples.

    A strict interior maximum x_{i-1} < x_i >= x_{i+1} moves to the parabola's vertex,
    ``δ = (x_{i-1} - x_{i+1}) / (2 (x_{i-1} - 2 x_i + x_{i+1}))``, value ``x_i - (x_{i-1} -
    x_{i+1}) δ / 4``. Successive maxima form the flow's Lorenz map (Lorenz 1963, J. Atmos.
    Sci. 20, 130).

    Parameters
    ----------
    x : array_like, shape (N,)
        Signal.
    dt : float
        Sampling interval; the times returned are in its units.

    Returns
    -------
    times, values : ndarray
        Refined maxima: value error O(dt³) (time O(dt²)) when smooth, O(dt) at a kink (an impact).
    """
    x = as_series(x)
    check_settings("local_maxima", dt=(dt, "real>0"))
    if x.size < 3:
        return np.array([]), np.array([])
    i = peak_indices(x)
    a, b, c = x[i - 1], x[i], x[i + 1]
    delta = vertex_offset(a, b, c)
    return (i + delta) * dt, b - 0.25 * (a - c) * delta


def peak_indices(x: np.ndarray) -> np.ndarray:
    """Indices i of the strict interior maxima, x[i-1] < x[i] >= x[i+1]."""
    return np.nonzero((x[1:-1] > x[:-2]) & (x[1:-1] >= x[2:]))[0] + 1


def vertex_offset(a, b, c) -> np.ndarray:
    """Vertex of the parabola through (-1, a), (0, b), (1, c), clipped to ±0.5 (0 if none)."""
    den = a - 2.0 * b + c
    with np.errstate(invalid="ignore", divide="ignore"):
        delta = np.where(den < 0, 0.5 * (a - c) / den, 0.0)
    return np.clip(delta, -0.5, 0.5)


def crossing_section(
    t, states, *, index: int, level: float = 0.0, direction: int = 1
) -> tuple[np.ndarray, np.ndarray]:
    """Poincaré section of a sampled trajectory at ``states[:, index] = level``.

    Each crossing is located on the cubic through the four samples around the sign change
    (Lagrange interpolation, error O(dt⁴) when smooth), and every component interpolated.

    Limits: crossings in the first and last sample intervals are skipped; two within one step
    are missed. For a stroboscopic section, prefer the integrator's states at the instants.

    Parameters
    ----------
    t, states : array_like, shapes (N,) and (N, d)
        Sample times and sampled states.
    index, level : int, float
        The section is ``states[:, index] = level``.
    direction : int
        +1 (upwards), -1 (downwards) or 0 (both).

    Returns
    -------
    times : ndarray, shape (M,)
    points : ndarray, shape (M, d)
        States on the section (the `index` component equals `level` up to round-off).
    """
    t = as_series(t, "t")
    y = as_points(states, "states")
    check_settings("crossing_section", index=(index, "int>=0"), level=(level, "real"))
    if index >= y.shape[1] or direction not in (-1, 0, 1):
        raise ValueError(
            f"crossing_section: index = {index} must be < {y.shape[1]} (the states' "
            f"components) and direction = {direction!r} one of +1, -1, 0"
        )
    if t.size != y.shape[0]:
        raise ValueError(f"crossing_section: {t.size} times for {y.shape[0]} states")
    g = y[:, index] - level
    s = np.sign(g)
    idx = np.nonzero(s[:-1] * s[1:] < 0)[0]
    if direction > 0:
        idx = idx[g[idx] < 0]
    elif direction < 0:
        idx = idx[g[idx] > 0]
    idx = idx[(idx >= 1) & (idx + 2 < t.size)]
    if idx.size == 0:
        return np.empty(0), np.empty((0, y.shape[1]))
    win = idx[:, None] + np.arange(-1, 3)[None, :]  # four samples around each crossing
    tt = t[win]
    yy = y[win]  # (M, 4, d)
    h = tt[:, 2] - tt[:, 1]
    nodes = (tt - tt[:, 1:2]) / h[:, None]  # u of the samples; crossing in u ∈ (0, 1)

    def weights(u):
        """Lagrange weights of the four nodes at u, shape (M, 4)."""
        w = np.ones((u.size, 4))
        for a in range(4):
            for b in range(4):
                if a != b:
                    w[:, a] *= (u - nodes[:, b]) / (nodes[:, a] - nodes[:, b])
        return w

    lo = np.zeros(idx.size)
    hi = np.ones(idx.size)
    g_lo = yy[:, 1, index] - level
    for _ in range(60):  # bisection on the cubic, all crossings at once
        mid = 0.5 * (lo + hi)
        g_mid = np.einsum("ma,ma->m", weights(mid), yy[:, :, index]) - level
        same = np.sign(g_mid) == np.sign(g_lo)
        lo = np.where(same, mid, lo)
        g_lo = np.where(same, g_mid, g_lo)
        hi = np.where(same, hi, mid)
    u = 0.5 * (lo + hi)
    times = tt[:, 1] + u * h
    points = np.einsum("ma,mad->md", weights(u), yy)
    return times, points
