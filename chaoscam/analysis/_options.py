"""The settings a caller may pass through to the analysis classifiers.

:func:`chaoscam.classify_trajectory` forwards its ``**options`` to :func:`classify_signal`
(a run with a series) or :func:`classify_section` (a section alone); this is the list of
what they take, without the inputs it builds from the trajectory itself (the samples, the
section, the exponents), so that a misspelt option is refused with the list.
"""

from __future__ import annotations

import inspect

from ._classify import classify_signal
from ._classify_section import classify_section

__all__ = ["ANALYSIS_OPTIONS", "check_options"]

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

ANALYSIS_OPTIONS = tuple(
    sorted(
        (
            set(inspect.signature(classify_signal).parameters)
            | set(inspect.signature(classify_section).parameters)
        )
        - _BUILT_BY_THE_CALLER
    )
)
"""The keyword settings of the analysis classifiers a caller may pass through."""


def check_options(options: dict, caller: str) -> None:
    """Refuse (TypeError) an option no analysis classifier takes, naming the ones they do."""
    unknown = sorted(set(options) - set(ANALYSIS_OPTIONS))
    if unknown:
        raise TypeError(
            f"{caller} got an unknown option {unknown[0]!r}; the analysis options are: "
            f"{', '.join(ANALYSIS_OPTIONS)}"
        )
