"""The one per-trajectory entry point every driver calls: it picks the integrator.

``advance`` has the signature of :func:`_kernel.run_chunk` and dispatches on the constant
``C_METHOD``: the fixed-step RK4 reference (:mod:`._kernel`) or the adaptive, event-driven
Dormand–Prince path (:mod:`._adaptive`). The CPU ensemble (``prange``), the single-run
driver, the Lyapunov driver and the GPU backend all go through it, so a realization is the
same on every path.
"""

from __future__ import annotations

from numba import njit

from . import _kernel as k
from ._adaptive import run_chunk_adaptive

__all__ = ["advance"]


@njit(cache=True, _nrt=False)
def advance(y, cnt, c, n_stop, lam, series, section, impacts):
    """Advance one trajectory towards grid step ``n_stop`` with the integrator ``c[C_METHOD]``.

    Same arguments and status codes as :func:`chaoscam.integrate._kernel.run_chunk`.
    """
    if c[k.C_METHOD] == k.METHOD_ADAPTIVE:
        return run_chunk_adaptive(y, cnt, c, n_stop, lam, series, section, impacts)
    return k.run_chunk(y, cnt, c, n_stop, lam, series, section, impacts)
