"""The RK4 kernel's first compilation on two cores: a second process compiles some callees.

Started by the first RK4 run of a process (:func:`start_once`, from
:func:`._driver.alone_kernel`) where numba's cache lacks these callees: the first
``simulate``, sweep, ensemble or ``chaoscam paper`` of a fresh install.

numba compiles :func:`._kernel.run_chunk` once per install (``cache=True``), in one process,
on one core: 22-25 s on the 2-core machine, most of it numba's own Python (type inference
and lowering of each callee, each compiled on its own as the caller's typing reaches it),
while the other core waits. :func:`start_beside` starts ``python -m
chaoscam.kernel._precompile``, which compiles the callees that the kernel's typing
reaches last (:func:`_callees`, in the reverse order) into numba's cache; when the kernel's
compilation in this process reaches one of them, numba loads it from that cache instead of
compiling it, as every later process does. The machine code is the same, so the results are
the same bits (tested). A callee the second process has not finished is compiled here as
before: nothing waits on it.

Measured (2-core AMD EPYC, empty caches, 2026-11-28): the first ``simulate`` 25.6 s alone,
14.8 s with the second process beside it.

The signatures must be the ones the kernel asks for; a slow test compiles the kernel after
this process and checks that each callee was a cache hit. Where they drift, nothing breaks:
the kernel compiles them itself, as without this module.
"""

from __future__ import annotations

import atexit
import os
import subprocess
import sys
import threading

__all__ = ["start_beside", "start_once"]


def _callees():
    """[(dispatcher, signature)] the second process compiles, in its order: the reverse of
    the order in which ``run_chunk``'s typing reaches them (numba's compile events), so that
    the two processes meet in the middle. Built when asked (numba imported)."""
    from numba import types

    from . import _events, _physics, _tangent

    f, i, b = types.float64, types.int64, types.boolean
    a = types.Array(types.float64, 1, "C")  # the kernel's rows and constants
    u4 = types.UniTuple(f, 4)  # a step's shared trigonometry
    return [
        (_tangent.saltation, (f, f, f, f, f, f, f, a)),
        (_tangent.rk4_tangent_trig, (f, f, f, f, f, a, f, f, f, f, i, i, f, f, f, f)),
        (_events.locate_crossing, (f, f, f, f, f, f, f, f, a, b, u4)),
        (_events.graze_point, (f, f, f, f, f, f, f, a, u4)),
        (_physics.rk4_trig, (f, f, f, f, f, a, f, f, f, f)),
    ]


def _cached(dispatcher) -> bool:
    """Whether numba's cache holds an index for ``dispatcher`` (numba's internals: when they
    change, False, and the second process runs, at a cost of under a second of its import)."""
    try:
        return os.path.exists(dispatcher._cache._cache_file._index_path)
    except AttributeError:
        return False


def start_beside() -> subprocess.Popen | None:
    """Start the second process when some callee of :func:`_callees` is not in numba's cache
    yet (a fresh install); None when all are (every later run). Its output is discarded;
    the caller may ``terminate()`` it when done (its cache writes are atomic)."""
    if all(_cached(d) for d, _ in _callees()):
        return None
    root = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
    env = dict(os.environ)
    env["PYTHONPATH"] = os.pathsep.join(p for p in (root, env.get("PYTHONPATH")) if p)
    return subprocess.Popen(
        [sys.executable, "-m", "chaoscam.kernel._precompile"],
        env=env,
        stdin=subprocess.DEVNULL,
        stdout=subprocess.DEVNULL,
        stderr=subprocess.DEVNULL,
    )


_started = False
_start_lock = threading.Lock()


def start_once() -> None:
    """:func:`start_beside` the first time a process asks (the first RK4 run, through
    :func:`._driver.alone_kernel`), in a process that is not a sweep's worker (those fork or
    spawn by the dozen: one second process is enough); the second process ends by itself,
    and is ended with this one at the latest."""
    global _started
    with _start_lock:
        if _started:
            return
        _started = True
    import multiprocessing

    if multiprocessing.parent_process() is not None:
        return
    proc = start_beside()
    if proc is not None:
        atexit.register(_end, proc)


def _end(proc: subprocess.Popen) -> None:
    proc.terminate()  # nothing once it has ended
    proc.wait()


def _end_with_parent() -> None:
    """End this process (at once, in a thread beside the compilation) when the process that
    started it ends: a run killed on a fresh install leaves no compiler behind."""
    import time

    parent = os.getppid()

    def watch() -> None:
        while os.getppid() == parent:
            time.sleep(0.1)
        os._exit(0)

    threading.Thread(target=watch, name="chaoscam-parent-watch", daemon=True).start()


def main() -> None:
    """Compile each callee of :func:`_callees` into numba's cache, in order."""
    _end_with_parent()
    for dispatcher, signature in _callees():
        dispatcher.compile(signature)


if __name__ == "__main__":
    main()
