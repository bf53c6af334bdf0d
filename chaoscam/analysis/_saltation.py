"""Generic saltation matrix of a state jump: the reference the kernel's formula is tested on."""

from __future__ import annotations

import numpy as np

__all__ = ["saltation_matrix"]


def saltation_matrix(g_x, g_t, f_minus, f_plus, h_x, h_t: float) -> np.ndarray:
    """Saltation matrix S: maps a perturbation across a state jump (Müller 1995).

    For a flow ``x' = f(t, x)`` that jumps ``x+ = g(t, x-)`` where ``h(t, x) = 0``,

        S = g_x + (f+ - g_x f- - g_t) h_x^T / (h_t + h_x · f-)

    (Müller 1995, Chaos Solitons Fractals 5(9), eq. 16; Leine & Nijmeijer 2004, *Dynamics
    and Bifurcations of Non-smooth Mechanical Systems*, sec. 3.5).

    Parameters
    ----------
    g_x, g_t : array_like, shapes (n, n) and (n,)
        Jacobian of the jump map with respect to the state, and its time derivative.
    f_minus, f_plus : array_like, shape (n,)
        The vector field before and after the jump, at the event.
    h_x, h_t : array_like, shape (n,), and float
        Gradient of the event function with respect to the state, and its time derivative.

    Returns
    -------
    ndarray, shape (n, n)
        S; raises ValueError for a grazing event (``h_t + h_x · f- = 0``), where none exists.
    """
    g_x, h_x = np.asarray(g_x, dtype=float), np.asarray(h_x, dtype=float)
    rate = float(h_t) + float(h_x @ np.asarray(f_minus, dtype=float))
    if rate == 0.0:
        raise ValueError("grazing event (h_t + h_x . f- = 0): the saltation matrix is undefined")
    f_minus = np.asarray(f_minus, dtype=float)
    w = np.asarray(f_plus, dtype=float) - g_x @ f_minus - np.asarray(g_t, dtype=float)
    return g_x + np.outer(w, h_x) / rate
