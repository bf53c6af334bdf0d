"""chaoscam: stochastic dynamics of a cam-follower oblique impact system.

The public face; every name is defined in a submodule and re-exported here. Heavy layers
(sweeps, reports) are imported from their subpackages: ``chaoscam.sweep``, ``chaoscam.report``.
"""

from __future__ import annotations

from ._util import lazy_face
from ._version import __version__

# Public names and the submodule that defines each: imported on first use (PEP 562),
# so that importing the package stays cheap.
_LAZY = {
    "ParameterError": (".model", "ParameterError"),
    "Params": (".model", "Params"),
    "Status": (".integrate", "Status"),
    "Trajectory": ("._simulate", "Trajectory"),
    "contact_period": ("._simulate", "contact_period"),
    "lyapunov_spectrum": (".tangent", "lyapunov_spectrum"),
    "periodic_orbit": (".tangent", "periodic_orbit"),
    "classify_ensemble": ("._ensemble_verdicts", "classify_ensemble"),
    "classify_file": (".classify", "classify_file"),
    "classify_trajectory": (".classify", "classify_trajectory"),
    "extend_trajectory": ("._extend", "extend_trajectory"),
    "load_trajectory": (".classify", "load_trajectory"),
    "lyapunov_model": (".lyapunov", "lyapunov_model"),
    "simulate": ("._simulate", "simulate"),
    "simulate_reference": (".integrate", "simulate_reference"),
}

__all__ = [
    "ParameterError",
    "Params",
    "Status",
    "Trajectory",
    "__version__",
    "classify_ensemble",
    "classify_file",
    "contact_period",
    "classify_trajectory",
    "extend_trajectory",
    "load_trajectory",
    "lyapunov_model",
    "lyapunov_spectrum",
    "periodic_orbit",
    "simulate",
    "simulate_reference",
]


__getattr__, __dir__ = lazy_face(__name__, _LAZY)
