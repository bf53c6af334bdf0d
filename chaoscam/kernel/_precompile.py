"""The RK4 kernel's first compilation on two cores: a second process compiles some callees.

numba compiles :func:`._rk4.run_chunk` once per install, on one core. The first RK4 run of a
process whose cache lacks them (:func:`start_once`) starts ``python -m
chaoscam.kernel._precompile`` to compile the callees typed last (:func:`_callees`) into the cache
(the same machine code): a fresh install's first ``simulate`` on 2 cores takes 14.8 s, not 25.6
s. Drifted signatures break nothing (a slow test checks each is a cache hit).
"""

from __future__ import annotations

import atexit
import os
import subprocess
import sys
import threading


def _callees():
    """[(dispatcher, signature)] the second process compiles, in the reverse of the order in
    which ``run_chunk``'s typing reaches them (the two processes meet in the middle)."""
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
    """Whether numba's cache holds an index for ``dispatcher`` (internals; False if changed)."""
    try:
        return os.path.exists(dispatcher._cache._cache_file._index_path)
    except AttributeError:
        return False


def start_beside() -> subprocess.Popen | None:
    """Start the second process where a callee of :func:`_callees` is not cached (a fresh
    install), else None; output discarded, ``terminate()`` safe (its cache writes are atomic)."""
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
    """:func:`start_beside` the first time a process asks, unless it is a multiprocessing
    child; the second process ends with this one at the latest."""
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
    """End this process when the one that started it ends (a killed run leaves no compiler)."""
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
