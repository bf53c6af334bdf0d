"""Integrators: the compiled RK4 + event kernel and the solve_ivp reference path."""

from __future__ import annotations

from pathlib import Path

from .._lazy import lazy_face
from .._numba_cache import guard

# numba's cached kernels call functions of this package's other files: compiled from these
# sources only (a callee's edit does not reach a cached caller; see chaoscam._numba_cache).
guard(Path(__file__).parent)

# Public names and the submodule that defines each: imported on first use (PEP 562),
# so that importing the package stays cheap.
_LAZY = {
    "Ensemble": ("._ensemble", "Ensemble"),
    "Status": ("._status", "Status"),
    "extend_ensemble": ("._ensemble", "extend_ensemble"),
    "kernel_constants": ("._constants", "kernel_constants"),
    "simulate_ensemble": ("._ensemble", "simulate_ensemble"),
    "simulate_reference": ("._reference", "simulate_reference"),
}

__all__ = [
    "Ensemble",
    "Status",
    "extend_ensemble",
    "kernel_constants",
    "simulate_ensemble",
    "simulate_reference",
]


__getattr__, __dir__ = lazy_face(__name__, _LAZY)
