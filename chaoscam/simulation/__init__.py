"""Solving the model: :func:`solve` runs members (a run is a batch of one) on the CPU's threads
or a GPU and returns one :class:`Solution`; :func:`extend` continues it bit for bit;
:func:`simulate` is the one-run convenience; :func:`simulate_reference` the independent
``solve_ivp`` path the kernels are checked against."""

from .._util import lazy_face

_LAZY = {
    "available_memory": ("._budget", "available_memory"),
    "BACKENDS": ("._solve", "BACKENDS"),
    "check_budget": ("._budget", "check_budget"),
    "check_enough": ("._files", "check_enough"),
    "check_run": ("._budget", "check_run"),
    "check_window": ("._solve", "check_window"),
    "CPU_BATCH": ("._solve", "CPU_BATCH"),
    "estimate": ("._budget", "estimate"),
    "extend": ("._solve", "extend"),
    "fresh": ("._batch", "fresh"),
    "ignored_sigma_warning": ("._warnings", "ignored_sigma_warning"),
    "IMPACT_COLUMNS": ("._solution", "IMPACT_COLUMNS"),
    "IMPACT_KINDS": ("._solution", "IMPACT_KINDS"),
    "JobEstimate": ("._budget", "JobEstimate"),
    "WARN_SECONDS": ("._budget", "WARN_SECONDS"),
    "human_bytes": ("._budget", "human_bytes"),
    "human_seconds": ("._budget", "human_seconds"),
    "load_trajectory": ("._files", "load_trajectory"),
    "MEMBER_COLUMNS": ("._solution", "MEMBER_COLUMNS"),
    "MIN_POINTS": ("._files", "MIN_POINTS"),
    "models_digest": ("._solve", "models_digest"),
    "numerics_arg": ("._solve", "numerics_arg"),
    "read_trajectory": ("._files", "read_trajectory"),
    "ReferenceResult": ("._reference", "ReferenceResult"),
    "resolution_warning": ("._warnings", "resolution_warning"),
    "Resume": ("._batch", "Resume"),
    "ROOM": ("._batch", "ROOM"),
    "run_batch": ("._batch", "run_batch"),
    "run_warnings": ("._warnings", "run_warnings"),
    "SECTION_COLUMNS": ("._solution", "SECTION_COLUMNS"),
    "SERIES_COLUMNS": ("._solution", "SERIES_COLUMNS"),
    "simulate": ("._solve", "simulate"),
    "simulate_reference": ("._reference", "simulate_reference"),
    "snapshot_step": ("._batch", "snapshot_step"),
    "Solution": ("._solution", "Solution"),
    "solve": ("._solve", "solve"),
    "split_overrides": ("._solve", "split_overrides"),
    "TrajectoryFileError": ("._files", "TrajectoryFileError"),
}

__all__ = sorted(_LAZY)

__getattr__, __dir__ = lazy_face(__name__, _LAZY)
