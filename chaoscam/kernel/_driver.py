"""The kernel's compiled entry points, the one loop that drives them (:func:`drive_members`),
thread stop requests (:func:`stop_on`) and numba's threading layer."""

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


@njit(cache=True, _nrt=False)
def advance(y, cnt, c, n_stop, lam, series, section, impacts):
    """Advance one trajectory towards grid step ``n_stop`` with ``c[C_METHOD]``'s integrator
    (:func:`._rk4.run_chunk`'s arguments and codes); every entry point, the GPU's too, goes
    through it, so a realization is the same on every path."""
    if c[k.C_METHOD] == k.METHOD_ADAPTIVE:
        return run_chunk_adaptive(y, cnt, c, n_stop, lam, series, section, impacts)
    return run_chunk(y, cnt, c, n_stop, lam, series, section, impacts)


@njit(parallel=True, cache=True)
def run_members(y, cnt, c, n_stop, lam, series, section, impacts, status):
    """:func:`advance` over stacked members in parallel (bit-identical on any thread count)."""
    for i in prange(y.shape[0]):
        status[i] = advance(y[i], cnt[i], c[i], n_stop, lam[i], series[i], section[i], impacts[i])


@njit(parallel=True, cache=True)
def run_members_rk4(y, cnt, c, n_stop, lam, series, section, impacts, status):
    """:func:`run_members` on the RK4 kernel alone (the same bits, without the adaptive path's
    7 s of first compilation)."""
    for i in prange(y.shape[0]):
        status[i] = run_chunk(y[i], cnt[i], c[i], n_stop, lam[i], series[i], section[i], impacts[i])


def _all_rk4(c: np.ndarray) -> bool:
    return bool(np.all(c[..., k.C_METHOD] == k.METHOD_RK4))


def members_kernel(c: np.ndarray):
    """The parallel entry point for members with constants ``c`` (a row each)."""
    return run_members_rk4 if _all_rk4(c) else run_members


def alone_kernel(c: np.ndarray):
    """The nogil single-trajectory entry point for constants ``c``; the first RK4 call of a
    process starts :mod:`._precompile`'s second compiling process."""
    if not _all_rk4(c):
        return run_alone
    if not run_alone_rk4.signatures:  # its first call in this process: it will compile
        from ._precompile import start_once

        start_once()
    return run_alone_rk4


def fork_safe_threads() -> None:
    """Choose numba's fork-safe "workqueue" threading layer unless the user chose one: the GNU
    OpenMP layer aborts a process that forks after using it. Call before the first parallel call
    or ``numba.get_num_threads`` (they fix the layer)."""
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
    """:func:`advance` for one trajectory on the calling thread, without the GIL (several
    Python threads at once: the workqueue layer takes one parallel launch at a time)."""
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
    """Within this context the calling thread runs its members one by one through the nogil call
    (:func:`alone_kernel`), not numba's threads, with the same bits (the sweeps' thread backend);
    ``stop``: once set, the next call raises :class:`StopRequested`."""
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
    thread once ``stop`` is set. Contexts nest: an inner one cannot hide an outer stop."""
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
    """Fraction of the recorded time in contact (gap <= 0), NaN if none recorded: of grid steps
    for RK4, of integrated time when adaptive."""
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
    """Hold a Ctrl-C (or SIGTERM) during a launch for its handler after it (inside numba's C
    callbacks a KeyboardInterrupt would be lost: "Exception ignored"); main thread only."""
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
