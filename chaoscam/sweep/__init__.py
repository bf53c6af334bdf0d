"""Sweeps: bifurcation diagrams and Monte Carlo regime maps, run locally or on Dask.

The layer above :func:`chaoscam.simulate` and the classifier: it builds validated parameters
for each grid point, sends one realization per task to a backend (this process, local worker
processes, or a Dask cluster), checkpoints every finished record so that a killed run resumes
to the identical table, and summarises each cell with Wilson intervals.
"""

from __future__ import annotations

from .._lazy import lazy_face

# Public names and the submodule that defines each: imported on first use (PEP 562),
# so that importing the package stays cheap.
_LAZY = {
    "Axis": ("._grid", "Axis"),
    "Bifurcation": ("._bifurcation", "Bifurcation"),
    "DaskBackend": ("._backends", "DaskBackend"),
    "DefaultClassifier": ("._tasks", "DefaultClassifier"),
    "LABEL_ORDER": ("._stats", "LABEL_ORDER"),
    "ProcessBackend": ("._backends", "ProcessBackend"),
    "RegimeMap": ("._regime", "RegimeMap"),
    "SerialBackend": ("._backends", "SerialBackend"),
    "SweepError": ("._grid", "SweepError"),
    "SweepInterrupted": ("._engine", "SweepInterrupted"),
    "bifurcation": ("._bifurcation", "bifurcation"),
    "checkpoint_dir": ("._checkpoint", "checkpoint_dir"),
    "config_hash": ("._checkpoint", "config_hash"),
    "initial_offsets": ("._bifurcation", "initial_offsets"),
    "load_classifier": ("._tasks", "load_classifier"),
    "make_backend": ("._backends", "make_backend"),
    "max_halfwidth": ("._stats", "max_halfwidth"),
    "mu_sigma_axes": ("._regime", "mu_sigma_axes"),
    "parse_range": ("._grid", "parse_range"),
    "read_bifurcation": ("._bifurcation", "read_bifurcation"),
    "read_regime_map": ("._regime", "read_regime_map"),
    "realization_index": ("._grid", "realization_index"),
    "regime_map": ("._regime", "regime_map"),
    "replay": ("._replay", "replay"),
    "replay_params": ("._replay", "replay_params"),
    "summarize_cells": ("._stats", "summarize_cells"),
    "verdict_fields": ("._tasks", "verdict_fields"),
    "wilson_interval": ("._stats", "wilson_interval"),
}

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
    "replay",
    "replay_params",
    "summarize_cells",
    "verdict_fields",
    "wilson_interval",
]


__getattr__, __dir__ = lazy_face(__name__, _LAZY)
