"""The classifier the report uses: the package's, or a documented fallback while it is absent.

``chaoscam.classify.classify_trajectory`` is the package classifier. Where a build does not
have it yet, the report falls back to :func:`chaoscam.analysis.classify_signal` on the
follower angle sampled every ``output_dt`` with the stroboscopic section (or to
:func:`chaoscam.analysis.classify_section` without a series), and says so in the report.
"""

from __future__ import annotations

import importlib

__all__ = [
    "ReportClassifier",
    "classifier_fingerprint",
    "classifier_name",
    "classify",
    "package_classifier",
]


def package_classifier():
    """``chaoscam.classify.classify_trajectory`` or None when this build lacks it."""
    try:
        module = importlib.import_module("chaoscam.classify")
    except ModuleNotFoundError as err:
        if err.name != "chaoscam.classify":
            raise
        return None
    return getattr(module, "classify_trajectory", None)


def classifier_name() -> str:
    """Which classifier :func:`classify` uses, in words."""
    if package_classifier() is not None:
        return "chaoscam.classify.classify_trajectory"
    return (
        "fallback: chaoscam.analysis.classify_signal on theta_f with the stroboscopic section "
        "(chaoscam.classify is not in this build)"
    )


def classifier_fingerprint() -> str:
    """The classifier's name and the sha256 (12 hex digits) of its source, for provenance."""
    import hashlib
    from pathlib import Path

    fn = package_classifier()
    module = importlib.import_module(fn.__module__ if fn else "chaoscam.analysis._classify")
    try:
        digest = hashlib.sha256(Path(module.__file__).read_bytes()).hexdigest()[:12]
    except (OSError, TypeError):
        digest = "unknown"
    return f"{classifier_name()} (source sha256 {digest})"


def classify(traj):
    """A :class:`~chaoscam.analysis.Verdict` for a trajectory (package classifier or fallback)."""
    fn = package_classifier()
    if fn is not None:
        return fn(traj)
    from ..analysis import classify_section, classify_signal

    section = traj.section[["theta_f", "omega_f"]].to_numpy()
    if traj.series is not None and len(traj.series) > 64:
        dt = float(traj.series["t"].diff().median())
        return classify_signal(
            traj.series["theta_f"].to_numpy(),
            dt,
            traj.params.cam_period,
            section=section if len(section) >= 8 else None,
        )
    if len(section) < 8:
        from ..analysis import combine

        return combine([], reasons=[f"only {len(section)} section points (8 needed)"])
    return classify_section(section)


class ReportClassifier:
    """A picklable sweep classifier calling :func:`classify` (for ``classify=`` of sweeps)."""

    needs_series = True

    def __call__(self, traj):
        return classify(traj)
