"""The classifier the report uses: ``chaoscam.classify.classify_trajectory``."""

from __future__ import annotations

__all__ = ["ReportClassifier", "classifier_fingerprint", "classifier_name", "classify"]


def classifier_name() -> str:
    """Which classifier :func:`classify` uses, in words."""
    return "chaoscam.classify.classify_trajectory() (tangent exponent, orbit certificate)"


def classifier_fingerprint() -> str:
    """The classifier's name and the sha256 (12 hex digits) of its source, for provenance."""
    import hashlib
    from pathlib import Path

    from .. import classify as module

    try:
        digest = hashlib.sha256(Path(module.__file__).read_bytes()).hexdigest()[:12]
    except (OSError, TypeError):
        digest = "unknown"
    return f"{classifier_name()} (source sha256 {digest})"


def classify(traj):
    """A :class:`~chaoscam.analysis.Verdict` for a trajectory: the package's default
    classifier (the tangent exponent through the impacts and, for a periodic section, the
    periodic-orbit certificate), the same configuration the sweeps use."""
    from ..classify import classify_trajectory

    return classify_trajectory(traj)


class ReportClassifier:
    """A picklable sweep classifier calling :func:`classify` (for ``classify=`` of sweeps)."""

    needs_series = True
    needs_tangent = True

    def __call__(self, traj):
        return classify(traj)
