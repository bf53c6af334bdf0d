"""chaoscam: stochastic dynamics of a cam-follower oblique impact system.

The public face; every name is defined in a submodule and re-exported here.
"""

from ._version import __version__
from .integrate import Status, simulate_reference
from .model import ParameterError, Params
from .simulate import Trajectory, simulate

__all__ = ["ParameterError", "Params", "Status", "Trajectory", "__version__", "simulate",
           "simulate_reference"]
