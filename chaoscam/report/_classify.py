"""The classifier the report uses: ``chaoscam.classify.classify_trajectory``."""

from __future__ import annotations

__all__ = ["ReportClassifier", "classifier_fingerprint", "classifier_name", "classify"]


def classifier_name() -> str:
    """Which classifier :func:`classify` uses, in words."""
    return "chaoscam.classify.classify_trajectory(lyapunov=True)"


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
    """A :class:`~chaoscam.analysis.Verdict` for a trajectory, the model's Lyapunov exponent
    included (without it a broadband-poor spectrum can pass chaos off as quasiperiodic)."""
    from ..classify import classify_trajectory

    return classify_trajectory(traj, lyapunov=True)


class ReportClassifier:
    """A picklable sweep classifier calling :func:`classify` (for ``classify=`` of sweeps)."""

    needs_series = True

    def __call__(self, traj):
        return classify(traj)
