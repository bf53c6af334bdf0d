"""Warnings that point at the user's line.

A fixed ``stacklevel`` is right for one call path only: ``simulate`` warns about its model at
level 3 when a user calls it, but the same warning raised while :func:`chaoscam.classify`
re-simulates would name a line of chaoscam. :func:`warn` walks the stack past every frame of
this package, so the warning names the first line outside it (the user's script, the test,
the console script) whatever the depth. A stack that is chaoscam all the way (``python -m
chaoscam``) names the interpreter's frame above it, as ``warnings.warn`` does for a level past
the top.

:func:`recorded` is ``warnings.catch_warnings(record=True)`` for code that runs on several
threads at once (the sweeps' batch threads): ``catch_warnings`` swaps module-wide state, so
two threads that enter and leave it out of order leave the process with a dead record list
as its warning printer and an "always" filter installed (measured: after a regime map on 2
batch threads, every later warning of the process vanished, the sweep's own step warning
first).

Imports only the standard library, so any module may use it.
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


_SINK: contextvars.ContextVar[list | None] = contextvars.ContextVar("chaoscam_warns", default=None)
"""Where this thread's (this context's) warnings go while :func:`recorded` is active."""

_HUB_LOCK = threading.Lock()
_hub: dict = {"users": 0, "ctx": None, "show": None, "impl": None}


def _dispatch(msg: warnings.WarningMessage) -> None:
    """The process's warning printer while any :func:`recorded` is active: a warning goes
    to the list of the context that raised it, or, from any other thread, where it went
    before (a replaced ``showwarning``, as ``logging.captureWarnings`` or pytest install
    one, or the printer)."""
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
    """Every warning raised in this context (this thread, and threads that run a copy of
    its context: :func:`contextvars.copy_context`), as ``warnings.WarningMessage`` objects,
    none printed; other threads' warnings go where they went before.

    Thread-safe where ``catch_warnings(record=True)`` with ``simplefilter("always")`` is
    not: the module-wide state is swapped once, by the first of any number of concurrent
    ``recorded`` contexts, and restored by the last. While any is active, every thread's
    warnings pass an "always" filter (repeats are not folded) and the process's filters
    are those of when the first one began.
    """
    sink: list[warnings.WarningMessage] = []
    token = _SINK.set(sink)
    _enter_hub()
    try:
        yield sink
    finally:
        _leave_hub()
        _SINK.reset(token)


def quiet() -> contextlib.AbstractContextManager:
    """``catch_warnings()`` + ``simplefilter("ignore")`` for this context only, safe on
    several threads at once: :func:`recorded`, its list dropped."""
    return recorded()
