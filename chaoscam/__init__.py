"""chaoscam: stochastic dynamics of a cam-follower oblique impact system.

The public face; every name is defined in a subpackage and resolved on first use, so that
``import chaoscam`` stays cheap. The pipeline, down the folders: ``model`` (the physics) and
``numerics`` (the integrator) -> ``kernel`` (compiled) -> ``solve`` (a batch of runs, one
:class:`Solution`) -> ``analysis`` (arrays in, evidence out) -> ``verdict`` (the model's
verdict) -> ``continuation`` (branches of periodic orbits) -> ``sweep`` (maps, diagrams,
ensembles) -> ``report`` / ``paper`` -> ``cli``.
"""

from __future__ import annotations

from ._util import lazy_face
from ._version import __version__

_LAZY = {
    "Numerics": (".numerics", "Numerics"),
    "ParameterError": ("._util", "ParameterError"),
    "Params": (".model", "Params"),
    "Solution": (".simulation", "Solution"),
    "Status": (".kernel", "Status"),
    "Verdict": (".analysis", "Verdict"),
    "bifurcation": (".sweep", "bifurcation"),
    "classify": (".verdict", "classify"),
    "contact_period": (".model", "contact_period"),
    "continuation": (".continuation", "continuation"),
    "ensemble": (".sweep", "ensemble"),
    "extend": (".simulation", "extend"),
    "kick_test": (".verdict", "kick_test"),
    "load_trajectory": (".simulation", "load_trajectory"),
    "lyapunov_spectrum": (".verdict", "lyapunov_spectrum"),
    "periodic_orbit": (".verdict", "periodic_orbit"),
    "regime_map": (".sweep", "regime_map"),
    "replay": (".sweep", "replay"),
    "simulate": (".simulation", "simulate"),
    "simulate_reference": (".simulation", "simulate_reference"),
    "solve": (".simulation", "solve"),
}

__all__ = ["__version__", *sorted(_LAZY)]

__getattr__, __dir__ = lazy_face(__name__, _LAZY)
