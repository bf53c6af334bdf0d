"""chaoscam: stochastic dynamics of a cam-follower oblique impact system.

The public face; every name is defined in a submodule and re-exported here. Heavy layers
(sweeps, reports) are imported from their subpackages: ``chaoscam.sweep``, ``chaoscam.report``.
"""

from ._version import __version__
from .classify import classify_file, classify_trajectory, load_trajectory
from .integrate import Status, simulate_reference
from .lyapunov import lyapunov_model
from .model import ParameterError, Params
from .simulate import Trajectory, simulate

__all__ = [
    "ParameterError",
    "Params",
    "Status",
    "Trajectory",
    "__version__",
    "classify_file",
    "classify_trajectory",
    "load_trajectory",
    "lyapunov_model",
    "simulate",
    "simulate_reference",
]
