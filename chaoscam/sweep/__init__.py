"""Sweeps: bifurcation diagrams, Monte Carlo regime maps and ensembles, plans over one engine.

Each builds validated models for its grid points, runs their realizations in batches
(:func:`chaoscam.solve`) on the CPU's threads, a GPU or a Dask cluster, labels them
(:func:`chaoscam.classify`, or a classifier of one's own), checkpoints every finished record
so that a killed run resumes to the identical table, and summarises each cell with Wilson
intervals.
"""

from __future__ import annotations

from .._util import lazy_face

_LAZY = {
    "LABEL_ORDER": ("._stats", "LABEL_ORDER"),
    "Axis": ("._grid", "Axis"),
    "Bifurcation": ("._bifurcation", "Bifurcation"),
    "Ensemble": ("._ensemble", "Ensemble"),
    "Judge": ("._runs", "Judge"),
    "RegimeMap": ("._regime", "RegimeMap"),
    "SweepError": ("._grid", "SweepError"),
    "SweepInterrupted": ("._engine", "SweepInterrupted"),
    "TaskFailed": ("._engine", "TaskFailed"),
    "bifurcation": ("._bifurcation", "bifurcation"),
    "checkpoint_dir": ("._store", "checkpoint_dir"),
    "companion": ("._common", "companion"),
    "continued_labels": ("._stats", "continued_labels"),
    "default_workers": ("._backends", "default_workers"),
    "fate_clause": ("._stats", "fate_clause"),
    "fate_settled": ("._stats", "fate_settled"),
    "fate_split": ("._stats", "fate_split"),
    "local_workers": ("._backends", "local_workers"),
    "config_hash": ("._store", "config_hash"),
    "ensemble": ("._ensemble", "ensemble"),
    "initial_offsets": ("._bifurcation", "initial_offsets"),
    "load_classifier": ("._runs", "load_classifier"),
    "max_halfwidth": ("._stats", "max_halfwidth"),
    "mu_sigma_axes": ("._regime", "mu_sigma_axes"),
    "parse_range": ("._grid", "parse_range"),
    "read_bifurcation": ("._bifurcation", "read_bifurcation"),
    "read_ensemble": ("._ensemble", "read_ensemble"),
    "read_regime_map": ("._regime", "read_regime_map"),
    "realization_index": ("._grid", "realization_index"),
    "regime_map": ("._regime", "regime_map"),
    "replay": ("._replay", "replay"),
    "replay_params": ("._replay", "replay_params"),
    "summarize_cells": ("._stats", "summarize_cells"),
    "verdict_fields": ("._runs", "verdict_fields"),
    "wilson_interval": ("._stats", "wilson_interval"),
}

__all__ = sorted(_LAZY)

__getattr__, __dir__ = lazy_face(__name__, _LAZY)
