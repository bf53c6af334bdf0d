"""Sweeps: bifurcation diagrams and Monte Carlo regime maps, run locally or on Dask.

The layer above :func:`chaoscam.simulate` and the classifier: it builds validated parameters
for each grid point, sends one realization per task to a backend (this process, local worker
processes, or a Dask cluster), checkpoints every finished record so that a killed run resumes
to the identical table, and summarises each cell with Wilson intervals.
"""

from ._backends import DaskBackend, ProcessBackend, SerialBackend, make_backend
from ._bifurcation import Bifurcation, bifurcation, initial_offsets, read_bifurcation
from ._checkpoint import checkpoint_dir, config_hash
from ._engine import SweepInterrupted
from ._grid import Axis, SweepError, parse_range, realization_index
from ._regime import RegimeMap, mu_sigma_axes, read_regime_map, regime_map
from ._stats import LABEL_ORDER, max_halfwidth, summarize_cells, wilson_interval
from ._tasks import DefaultClassifier, load_classifier, verdict_fields

__all__ = [
    "LABEL_ORDER",
    "Axis",
    "Bifurcation",
    "DaskBackend",
    "DefaultClassifier",
    "ProcessBackend",
    "RegimeMap",
    "SerialBackend",
    "SweepError",
    "SweepInterrupted",
    "bifurcation",
    "checkpoint_dir",
    "config_hash",
    "initial_offsets",
    "load_classifier",
    "make_backend",
    "max_halfwidth",
    "mu_sigma_axes",
    "parse_range",
    "read_bifurcation",
    "read_regime_map",
    "realization_index",
    "regime_map",
    "summarize_cells",
    "verdict_fields",
    "wilson_interval",
]
