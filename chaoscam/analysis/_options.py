"""The settings a caller may pass through to the section classifier.

:func:`chaoscam.classify` forwards its ``**options`` to :func:`classify_section`; these are
what it takes less the inputs the model's verdict builds itself (the points, the tangent
exponent), so that a misspelt option is refused.
"""

from __future__ import annotations

import inspect

from ._classify_section import classify_section
from ._validate import check_atol

__all__ = ["SECTION_OPTIONS", "check_options", "section_options"]

_BUILT_BY_THE_CALLER = {"points", "lyapunov", "lyapunov_tol", "exponent", "exponent_time"}

SECTION_OPTIONS = frozenset(inspect.signature(classify_section).parameters) - _BUILT_BY_THE_CALLER
"""What a model verdict may pass through to :func:`classify_section`."""


def check_options(options: dict, caller: str) -> None:
    """Refuse (TypeError) an option :func:`classify_section` does not take here, naming the
    ones it does, and (ValueError) a bad ``atol`` (two coordinates)."""
    check_atol(caller, options.get("atol"), 2)
    unknown = sorted(set(options) - SECTION_OPTIONS)
    if unknown:
        raise TypeError(
            f"{caller} got an unknown option {unknown[0]!r}; the options are "
            f"classify_section's: {', '.join(sorted(SECTION_OPTIONS))}"
        )


def section_options(options: dict) -> dict:
    """``options`` less those :func:`classify_section` does not take."""
    return {k: v for k, v in options.items() if k in SECTION_OPTIONS}
