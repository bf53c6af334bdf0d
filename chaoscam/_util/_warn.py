"""Warnings that point at the user's line, and warning capture that is safe on threads.

:func:`warn` walks the stack past every frame of this package to the first line outside it (a
fixed ``stacklevel`` is right for one call path only); a stack that is chaoscam all the way
(``python -m chaoscam``) names the interpreter's frame above it. :func:`recorded` is
``warnings.catch_warnings(record=True)`` for code on several threads at once:
``catch_warnings`` swaps module-wide state, and two threads leaving it out of order leave a dead
record list as the process's printer, so every later warning vanishes. Standard library only.
"""

from __future__ import annotations

import contextlib
import contextvars
import os
import sys
import threading
import warnings
from collections.abc import Iterator

_PACKAGE = os.path.dirname(os.path.dirname(os.path.abspath(__file__))) + os.sep


def user_stacklevel() -> int:
    """The ``stacklevel`` that, given to ``warnings.warn`` by the function that called this
    one, names the first frame outside the chaoscam package."""
    level = 2  # warnings.warn's level 2: the caller of the function calling user_stacklevel
    frame = sys._getframe(2)  # that caller
    while frame is not None and os.path.abspath(frame.f_code.co_filename).startswith(_PACKAGE):
        frame = frame.f_back
        level += 1
    return level


def warn(message: str, category: type[Warning] = RuntimeWarning) -> None:
    """``warnings.warn(message, category)`` attributed to the first line outside chaoscam."""
    warnings.warn(message, category, stacklevel=user_stacklevel())


_SINK: contextvars.ContextVar[list | None] = contextvars.ContextVar("chaoscam_warns", default=None)
"""Where this thread's (this context's) warnings go while :func:`recorded` is active."""

_HUB_LOCK = threading.Lock()
_hub: dict = {"users": 0, "ctx": None, "show": None, "impl": None}


def _dispatch(msg: warnings.WarningMessage) -> None:
    """The process's warning printer while any :func:`recorded` is active: a warning goes to the
    list of the context that raised it, else where it went before (a replaced ``showwarning``,
    as ``logging.captureWarnings`` or pytest install one, or the printer)."""
    sink = _SINK.get()
    if sink is not None:
        sink.append(msg)
        return
    show, impl = _hub["show"], _hub["impl"]
    if show is not None and show is not warnings._showwarning_orig:
        show(msg.message, msg.category, msg.filename, msg.lineno, msg.file, msg.line)
    else:
        impl(msg)


def _enter_hub() -> None:
    with _HUB_LOCK:
        if _hub["users"] == 0:
            ctx = warnings.catch_warnings()
            ctx.__enter__()
            warnings.simplefilter("always")  # every warning reaches _dispatch, none is lost
            _hub.update(ctx=ctx, show=warnings.showwarning, impl=warnings._showwarnmsg_impl)
            warnings.showwarning = warnings._showwarning_orig  # which calls the impl
            warnings._showwarnmsg_impl = _dispatch
        _hub["users"] += 1


def _leave_hub() -> None:
    with _HUB_LOCK:
        _hub["users"] -= 1
        if _hub["users"] == 0:
            ctx = _hub["ctx"]
            _hub.update(ctx=None, show=None, impl=None)
            ctx.__exit__(None, None, None)  # the filters, showwarning and printer as before


@contextlib.contextmanager
def recorded() -> Iterator[list[warnings.WarningMessage]]:
    """Every warning raised in this context (this thread, and threads running a copy of its
    context) as ``warnings.WarningMessage`` objects, none printed; other threads' warnings go
    where they went before. The module-wide state is swapped by the first of any number of
    concurrent ``recorded`` contexts and restored by the last; meanwhile every thread's warnings
    pass an "always" filter (repeats not folded) under the filters of when the first began."""
    sink: list[warnings.WarningMessage] = []
    token = _SINK.set(sink)
    _enter_hub()
    try:
        yield sink
    finally:
        _leave_hub()
        _SINK.reset(token)


quiet = recorded
"""``catch_warnings()`` + ``simplefilter("ignore")`` for this context only, safe on several
threads at once: :func:`recorded`, its list dropped."""
