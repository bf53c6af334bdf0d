"""The settings a caller may pass through to the analysis classifiers.

:func:`chaoscam.classify_trajectory` forwards its ``**options`` to :func:`classify_signal`
(a run with a series) or :func:`classify_section` (a section alone); these are what they
take less the inputs built from the trajectory, so that a misspelt option is refused.
"""

from __future__ import annotations

import inspect

from .._util import warn
from ._classify import classify_signal
from ._classify_section import classify_section
from ._validate import check_atol, check_settings

__all__ = ["SECTION_OPTIONS", "SIGNAL_OPTIONS", "check_options", "section_options"]

_BUILT_BY_THE_CALLER = {
    "x",
    "dt",
    "forcing_period",
    "section",
    "points",
    "lyapunov",
    "exponent",
    "exponent_time",
}


def _settings(fn) -> frozenset[str]:
    return frozenset(inspect.signature(fn).parameters) - _BUILT_BY_THE_CALLER


SIGNAL_OPTIONS = _settings(classify_signal)
"""What a run with a series may pass through (to :func:`classify_signal`)."""

SECTION_OPTIONS = _settings(classify_section)
"""What a run with its section alone may pass through (to :func:`classify_section`)."""


def check_options(options: dict, caller: str, *, series: bool, tangent: bool = False) -> None:
    """Refuse (TypeError) an option the classifier of this run does not take, naming the
    ones it does: :func:`classify_signal`'s for a run with a series, else
    :func:`classify_section`'s; refuse (ValueError) a bad ``atol`` (two coordinates) or
    ``lyapunov_tol``, and warn that the tangent verdict does not use ``lyapunov_tol``."""
    check_atol(caller, options.get("atol"), 2)
    check_settings(caller, lyapunov_tol=(options.get("lyapunov_tol"), "real>=0?"))
    if tangent and options.get("lyapunov_tol") is not None:
        warn(
            f"{caller}: lyapunov_tol judges the two-trajectory exponent (lyapunov=True); the "
            "tangent verdict judges its exponent by its confidence interval "
            "(Thresholds.exponent_zero, exponent_z), so lyapunov_tol is not used"
        )
    allowed = SIGNAL_OPTIONS if series else SECTION_OPTIONS
    fn = "classify_signal" if series else "classify_section"
    unknown = sorted(set(options) - allowed)
    if unknown:
        what = "a run with a series" if series else "a run kept without its series"
        raise TypeError(
            f"{caller} got an unknown option {unknown[0]!r}; for {what} the options are "
            f"{fn}'s: {', '.join(sorted(allowed))}"
        )


def section_options(options: dict) -> dict:
    """``options`` less those :func:`classify_section` does not take (for a run with a
    series judged from its section alone, where its signal options have no use)."""
    return {k: v for k, v in options.items() if k in SECTION_OPTIONS}
