"""Integrators: the compiled RK4 + event kernel and the solve_ivp reference path."""

from ._constants import kernel_constants
from ._ensemble import Ensemble, simulate_ensemble
from ._reference import simulate_reference
from ._status import Status

__all__ = ["Ensemble", "Status", "kernel_constants", "simulate_ensemble", "simulate_reference"]
