"""The kernel's compiled entry points and the one loop that drives them.

:func:`advance` picks the integrator for one trajectory; :func:`run_members` (``prange`` over
members) and :func:`run_alone` (one trajectory, without the GIL) are the CPU's entry points; the
GPU launches :func:`advance` too. :func:`drive_members` launches the members still to run, lets
the caller empty the buffers and refill the draws of those that returned ``NEED_BUFFER``, and
launches those again until none asks; a resumed member is bit-identical (all it needs is in
``y`` and ``cnt``). Thread stop requests (:func:`stop_on`) and numba's threading layer are here.
"""

from __future__ import annotations

import contextlib
import os
import signal
import threading
from collections.abc import Callable

import numpy as np
from numba import njit, prange

from . import layout as k
from ._adaptive import run_chunk_adaptive
from ._rk4 import run_chunk

__all__ = [
    "advance", "contact_fraction", "drive_members", "fork_safe_threads", "alone_kernel",
    "members_kernel", "members_on_this_thread", "on_this_thread", "stop_on", "stops_here",
    "run_members", "run_alone", "run_alone_rk4", "run_members_rk4", "thread_count",
    "StopRequested", "check_stop",
]  # fmt: skip


@njit(cache=True, _nrt=False)
def advance(y, cnt, c, n_stop, lam, series, section, impacts):
    """Advance one trajectory towards grid step ``n_stop`` with ``c[C_METHOD]``'s integrator,
    :func:`._rk4.run_chunk` or :func:`._adaptive.run_chunk_adaptive` (their arguments and
    codes); every entry point goes through it, so a realization is the same on every path."""
    if c[k.C_METHOD] == k.METHOD_ADAPTIVE:
        return run_chunk_adaptive(y, cnt, c, n_stop, lam, series, section, impacts)
    return run_chunk(y, cnt, c, n_stop, lam, series, section, impacts)


@njit(parallel=True, cache=True)
def run_members(y, cnt, c, n_stop, lam, series, section, impacts, status):
    """:func:`advance` for each member ``i`` of stacked arrays, in parallel (bit-identical on
    any thread count); all-RK4 batches take :func:`run_members_rk4` (:func:`members_kernel`)."""
    for i in prange(y.shape[0]):
        status[i] = advance(y[i], cnt[i], c[i], n_stop, lam[i], series[i], section[i], impacts[i])


@njit(parallel=True, cache=True)
def run_members_rk4(y, cnt, c, n_stop, lam, series, section, impacts, status):
    """:func:`run_members` for all-RK4 members: the same compiled :func:`._rk4.run_chunk`
    (the same bits, ``analyses/hash_check.py``) without the adaptive path, which costs a fresh
    install about 7 s of compilation."""
    for i in prange(y.shape[0]):
        status[i] = run_chunk(y[i], cnt[i], c[i], n_stop, lam[i], series[i], section[i], impacts[i])


def _all_rk4(c: np.ndarray) -> bool:
    """Whether every member with constants ``c`` (one row each, or one row) uses RK4."""
    return bool(np.all(c[..., k.C_METHOD] == k.METHOD_RK4))


def members_kernel(c: np.ndarray):
    """The compiled entry point for members with constants ``c`` (a row each):
    :func:`run_members_rk4` when all use RK4, else :func:`run_members`."""
    return run_members_rk4 if _all_rk4(c) else run_members


def alone_kernel(c: np.ndarray):
    """The compiled nogil single-trajectory call for constants ``c``: :func:`run_alone_rk4`
    for RK4 (compiling the adaptive kernel costs a fresh install ~10 s), else
    :func:`run_alone`. The first RK4 call of a process starts :mod:`._precompile`'s second
    compiling process (a fresh install's first run 25 s -> 15 s)."""
    if not _all_rk4(c):
        return run_alone
    if not run_alone_rk4.signatures:  # its first call in this process: it will compile
        from ._precompile import start_once

        start_once()
    return run_alone_rk4


def fork_safe_threads() -> None:
    """Choose numba's fork-safe "workqueue" threading layer unless the user chose one
    (``NUMBA_THREADING_LAYER``, or ``numba.config.THREADING_LAYER`` before the first run).

    numba's GNU OpenMP layer aborts a process that forks after using it (a multiprocessing
    pool or Dask worker started after a simulation). The layer is fixed by the first parallel
    call and by ``numba.get_num_threads`` / ``set_num_threads``, so those come here first;
    nothing is changed on import."""
    import numba

    if "NUMBA_THREADING_LAYER" not in os.environ and numba.config.THREADING_LAYER == "default":
        numba.config.THREADING_LAYER = "workqueue"


def thread_count() -> int:
    """numba's thread count after :func:`fork_safe_threads` (asking fixes the layer); 1
    inside :func:`members_on_this_thread`."""
    import numba

    if on_this_thread():
        return 1
    fork_safe_threads()
    return numba.get_num_threads()


@njit(nogil=True, cache=True)
def run_alone(y, cnt, c, n_stop, lam, series, section, impacts):
    """:func:`advance` for one trajectory on the calling thread, without the GIL: for single
    trajectories run from several Python threads at once (the verdicts' periodic-orbit
    shooting), as the workqueue layer takes parallel launches from one thread at a time."""
    return advance(y, cnt, c, n_stop, lam, series, section, impacts)


@njit(nogil=True, cache=True)
def run_alone_rk4(y, cnt, c, n_stop, lam, series, section, impacts):
    """:func:`run_alone` on the RK4 kernel alone (the same bits; :func:`alone_kernel`)."""
    return run_chunk(y, cnt, c, n_stop, lam, series, section, impacts)


_here = threading.local()


class StopRequested(Exception):
    """A run was asked to stop (its ``stop`` event was set): raised between two compiled
    calls, the members' state left as it was."""


@contextlib.contextmanager
def members_on_this_thread(stop: threading.Event | None = None):
    """Within this context the calling thread runs its members one after another through the
    nogil call (:func:`alone_kernel`), not on numba's threads (:func:`on_this_thread` tells
    :func:`chaoscam.simulation.run_batch` and the verdicts). For the sweeps' thread backend,
    one batch per core: the workqueue layer takes one parallel launch at a time, and no core
    waits for another batch's slowest member. The same compiled kernel, so the same bits.
    ``stop``: once set, the next call raises :class:`StopRequested` (a compiled call itself
    cannot be interrupted)."""
    before = getattr(_here, "active", False)
    _here.active = True
    try:
        with stop_on(stop):
            yield
    finally:
        _here.active = before


@contextlib.contextmanager
def stop_on(stop: threading.Event | None):
    """Within this context :func:`check_stop` raises :class:`StopRequested` on the calling
    thread once ``stop`` is set, its runs on numba's threads as anywhere (a GPU sweep's
    labelling thread, a paper run beside another). Contexts nest: an inner one (a serial
    sweep's :func:`members_on_this_thread`) cannot hide a stop asked of the whole thread."""
    before = stops_here()
    _here.stops = before if stop is None else (*before, stop)
    try:
        yield
    finally:
        _here.stops = before


def stops_here() -> tuple[threading.Event, ...]:
    """The stop events :func:`check_stop` watches on the calling thread (:func:`stop_on`)."""
    return getattr(_here, "stops", ())


def on_this_thread() -> bool:
    """Whether the calling thread is inside :func:`members_on_this_thread`."""
    return getattr(_here, "active", False)


def check_stop() -> None:
    """Raise :class:`StopRequested` if this thread's run was asked to stop."""
    if any(stop.is_set() for stop in stops_here()):
        raise StopRequested("stopped on request")


def contact_fraction(y, cnt, c) -> float:
    """Fraction of the recorded time in contact (gap <= 0), NaN if none recorded: grid steps
    ending in contact for RK4, integrated time (``Y_RECORDED``, ``Y_CONTACT``) when adaptive."""
    if c[k.C_METHOD] == k.METHOD_ADAPTIVE:
        rec = y[k.Y_RECORDED]
        return float(y[k.Y_CONTACT] / rec) if rec > 0 else float("nan")
    counted = cnt[k.I_COUNTED_STEPS]
    return float(cnt[k.I_CONTACT_STEPS] / counted) if counted else float("nan")


def drive_members(
    n: int,
    launch: Callable[[np.ndarray], np.ndarray],
    refill: Callable[[np.ndarray], None],
    need: np.ndarray | None = None,
) -> None:
    """The buffer-refill loop over ``n`` members (those in ``need``; default all):
    ``launch(need)`` runs them until each ends or asks for room and returns their codes (in
    ``need``'s order); ``refill(need)`` empties the buffers and renews the draws of those that
    returned ``NEED_BUFFER``, which are launched again, until none asks."""
    need = np.arange(n) if need is None else np.asarray(need, dtype=np.int64)
    while need.size:
        with _interrupts_held():
            codes = launch(need)
        need = need[codes == k.NEED_BUFFER]
        if need.size:
            refill(need)


@contextlib.contextmanager
def _interrupts_held():
    """Hold a Ctrl-C (or a SIGTERM handled in Python) that arrives during a launch until it
    returns, then hand it to the handler in place. A launch runs Python inside C callbacks
    (numba's LLVM object cache, whenever a kernel compiles or its runtime starts), where a
    KeyboardInterrupt cannot propagate: Python prints "Exception ignored" and the Ctrl-C is
    lost. Main thread only, and only signals handled by Python functions."""
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    held: list[tuple[int, object]] = []
    before = {}
    for sig in (signal.SIGINT, signal.SIGTERM):
        handler = signal.getsignal(sig)
        if callable(handler):
            before[sig] = signal.signal(sig, lambda signum, frame: held.append((signum, frame)))
    try:
        yield
    finally:
        for sig, handler in before.items():
            signal.signal(sig, handler)
        if held:
            signum, frame = held[0]
            before[signum](signum, frame)  # KeyboardInterrupt, from the default or the CLI's
