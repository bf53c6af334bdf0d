"""Sweeps: bifurcation diagrams, Monte Carlo regime maps and ensembles, plans over one engine.

Realizations run in batches (:func:`chaoscam.solve`) on threads, a GPU or Dask, are labelled
(:func:`chaoscam.classify` or one's own classifier) and checkpointed, so a killed run resumes
to the identical table; cells are summarised with Wilson intervals.
"""

from __future__ import annotations

from .._util import lazy_face

_LAZY = {
    "default_workers": ("._backends", "default_workers"),
    "local_workers": ("._backends", "local_workers"),
    "Bifurcation": ("._bifurcation", "Bifurcation"),
    "bifurcation": ("._bifurcation", "bifurcation"),
    "initial_offsets": ("._bifurcation", "initial_offsets"),
    "read_bifurcation": ("._bifurcation", "read_bifurcation"),
    "companion": ("._common", "companion"),
    "SweepInterrupted": ("._engine", "SweepInterrupted"), "TaskFailed": ("._engine", "TaskFailed"),
    "Ensemble": ("._ensemble", "Ensemble"), "ensemble": ("._ensemble", "ensemble"),
    "read_ensemble": ("._ensemble", "read_ensemble"), "classified": ("._ensemble", "classified"),
    "label_shares": ("._ensemble", "label_shares"),
    "member_labels": ("._ensemble", "member_labels"),
    "Axis": ("._grid", "Axis"), "SweepError": ("._grid", "SweepError"),
    "parse_range": ("._grid", "parse_range"), "realization_index": ("._grid", "realization_index"),
    "RegimeMap": ("._regime", "RegimeMap"), "mu_sigma_axes": ("._regime", "mu_sigma_axes"),
    "read_regime_map": ("._regime", "read_regime_map"), "regime_map": ("._regime", "regime_map"),
    "replay": ("._replay", "replay"), "replay_params": ("._replay", "replay_params"),
    "Judge": ("._runs", "Judge"), "load_classifier": ("._runs", "load_classifier"),
    "verdict_fields": ("._runs", "verdict_fields"),
    "LABEL_ORDER": ("._stats", "LABEL_ORDER"), "continued_labels": ("._stats", "continued_labels"),
    "fate_clause": ("._stats", "fate_clause"), "fate_settled": ("._stats", "fate_settled"),
    "fate_split": ("._stats", "fate_split"), "max_halfwidth": ("._stats", "max_halfwidth"),
    "summarize_cells": ("._stats", "summarize_cells"),
    "wilson_interval": ("._stats", "wilson_interval"),
    "checkpoint_dir": ("._store", "checkpoint_dir"), "config_hash": ("._store", "config_hash"),
}  # fmt: skip

__all__ = sorted(_LAZY)

__getattr__, __dir__ = lazy_face(__name__, _LAZY)
