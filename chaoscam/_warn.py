"""Warnings that point at the user's line.

A fixed ``stacklevel`` is right for one call path only: ``simulate`` warns about its model at
level 3 when a user calls it, but the same warning raised while :func:`chaoscam.classify_trajectory`
re-simulates would name a line of chaoscam. :func:`warn` walks the stack past every frame of
this package, so the warning names the first line outside it (the user's script, the test,
the console script) whatever the depth. A stack that is chaoscam all the way (``python -m
chaoscam``) names the interpreter's frame above it, as ``warnings.warn`` does for a level past
the top.

Imports only the standard library, so any module may use it.
"""

from __future__ import annotations

import os
import sys
import warnings

_PACKAGE = os.path.dirname(os.path.abspath(__file__)) + os.sep


def _inside(filename: str) -> bool:
    return os.path.abspath(filename).startswith(_PACKAGE)


def user_stacklevel() -> int:
    """The ``stacklevel`` that, given to ``warnings.warn`` by the function that called this
    one, names the first frame outside the chaoscam package."""
    level = 2  # warnings.warn's level 2: the caller of the function calling user_stacklevel
    frame = sys._getframe(2)  # that caller
    while frame is not None and _inside(frame.f_code.co_filename):
        frame = frame.f_back
        level += 1
    return level


def warn(message: str, category: type[Warning] = RuntimeWarning) -> None:
    """``warnings.warn(message, category)`` attributed to the first line outside chaoscam."""
    warnings.warn(message, category, stacklevel=user_stacklevel())
