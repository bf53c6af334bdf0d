"""The compiled entry points of the kernel and the one loop that drives them.

:func:`advance` picks the integrator for one trajectory; :func:`run_members` (numba
``prange`` over members) and :func:`run_alone` (one trajectory on the calling thread, without
the GIL) are the CPU's entry points, and the GPU launches the same :func:`advance`. The
kernel advances each member until the end step or until an output buffer or the line-length
draws need attention, and returns ``NEED_BUFFER`` then. :func:`drive_members` is the loop
every run goes through: launch the members still to run, let the caller empty the buffers and
refill the draws of those that asked, launch those again, until none asks; the CPU's and the
GPU's runs differ only in what a launch is. A resumed member is bit-identical to one that was
not interrupted (the kernel keeps everything it needs in ``y`` and ``cnt``), so how often the
loop pauses changes no result. The threads' stop requests (:func:`stop_on`) and numba's
threading layer are set up here too.
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
    "advance",
    "contact_fraction",
    "drive_members",
    "fork_safe_threads",
    "alone_kernel",
    "members_kernel",
    "members_on_this_thread",
    "on_this_thread",
    "stop_on",
    "stops_here",
    "run_members",
    "run_alone",
    "run_alone_rk4",
    "run_members_rk4",
    "thread_count",
    "StopRequested",
    "check_stop",
]

@njit(cache=True, _nrt=False)
def advance(y, cnt, c, n_stop, lam, series, section, impacts):
    """Advance one trajectory towards grid step ``n_stop`` with the integrator ``c[C_METHOD]``:
    the fixed-step RK4 reference (:func:`._rk4.run_chunk`) or the adaptive Dormand–Prince
    path (:func:`._adaptive.run_chunk_adaptive`). Same arguments and status codes as
    :func:`._rk4.run_chunk`; every CPU and GPU entry point goes through it, so a realization
    is the same on every path."""
    if c[k.C_METHOD] == k.METHOD_ADAPTIVE:
        return run_chunk_adaptive(y, cnt, c, n_stop, lam, series, section, impacts)
    return run_chunk(y, cnt, c, n_stop, lam, series, section, impacts)


@njit(parallel=True, cache=True)
def run_members(y, cnt, c, n_stop, lam, series, section, impacts, status):
    """:func:`advance` for each member ``i`` of stacked arrays, in parallel.

    The compiled entry point of every CPU simulation (a single trajectory is a batch of
    one), so that a realization is bit-identical on every path and thread count; a batch
    whose members all use the fixed-step kernel goes through :func:`run_members_rk4`
    instead (:func:`members_kernel` picks).
    """
    for i in prange(y.shape[0]):
        status[i] = advance(y[i], cnt[i], c[i], n_stop, lam[i], series[i], section[i], impacts[i])


@njit(parallel=True, cache=True)
def run_members_rk4(y, cnt, c, n_stop, lam, series, section, impacts, status):
    """:func:`run_members` for members that all use the fixed-step RK4 kernel.

    The same compiled :func:`._rk4.run_chunk` that :func:`advance` calls for them
    (so the same bits; ``analyses/hash_check.py`` compares), without the adaptive path: a
    fresh install that runs only RK4 compiles about 7 s less.
    """
    for i in prange(y.shape[0]):
        status[i] = run_chunk(y[i], cnt[i], c[i], n_stop, lam[i], series[i], section[i], impacts[i])


def _all_rk4(c: np.ndarray) -> bool:
    """Whether every member with constants ``c`` (one row each, or one row) uses RK4."""
    return bool(np.all(c[..., k.C_METHOD] == k.METHOD_RK4))


def members_kernel(c: np.ndarray):
    """The compiled entry point for members with constants ``c`` (one row per member):
    :func:`run_members_rk4` when every member uses the RK4 kernel, else
    :func:`run_members`."""
    return run_members_rk4 if _all_rk4(c) else run_members


def alone_kernel(c: np.ndarray):
    """The compiled single-trajectory call for constants ``c``, without the GIL:
    :func:`run_alone_rk4` for the RK4 kernel, else :func:`run_alone`. Picking keeps the
    adaptive kernel out of an RK4 process: compiling it costs a fresh install ~10 s.
    Before the RK4 kernel is compiled or loaded in this process, a fresh install's second
    compiling process is started (:mod:`._precompile`: the first run 25 s -> 15 s)."""
    if not _all_rk4(c):
        return run_alone
    if not run_alone_rk4.signatures:  # its first call in this process: it will compile
        from ._precompile import start_once

        start_once()
    return run_alone_rk4


def fork_safe_threads() -> None:
    """Choose numba's fork-safe "workqueue" threading layer, unless the user chose one.

    numba's GNU OpenMP layer aborts a process that forks after using it, and the sweeps fork
    their workers from a driver that may have simulated. The layer is fixed at the first
    parallel call, and by ``numba.get_num_threads`` / ``set_num_threads`` (they start the
    threads), so every launch of :func:`run_members` and every such call comes here first;
    nothing is changed on import. A user's choice (``NUMBA_THREADING_LAYER``, or
    ``numba.config.THREADING_LAYER`` set before the first run) wins.
    """
    import numba

    if "NUMBA_THREADING_LAYER" not in os.environ and numba.config.THREADING_LAYER == "default":
        numba.config.THREADING_LAYER = "workqueue"


def thread_count() -> int:
    """numba's thread count, asked after :func:`fork_safe_threads` (asking starts the
    threads, which fixes the layer); 1 inside :func:`members_on_this_thread`."""
    import numba

    if on_this_thread():
        return 1
    fork_safe_threads()
    return numba.get_num_threads()


@njit(nogil=True, cache=True)
def run_alone(y, cnt, c, n_stop, lam, series, section, impacts):
    """:func:`advance` for one trajectory on the calling thread, without the GIL.

    For callers that run single trajectories from several Python threads at once (the
    periodic-orbit shooting of :mod:`chaoscam.tangent`, run per member by the ensemble
    verdicts): numba's workqueue threading layer cannot take parallel launches
    (:func:`run_one`) from two threads at a time. The same compiled kernel, so the same bits.
    """
    return advance(y, cnt, c, n_stop, lam, series, section, impacts)


@njit(nogil=True, cache=True)
def run_alone_rk4(y, cnt, c, n_stop, lam, series, section, impacts):
    """:func:`run_alone` for a trajectory on the fixed-step RK4 kernel: the same compiled
    :func:`._rk4.run_chunk` that :func:`advance` calls for it (the same bits),
    without compiling the adaptive path (:func:`alone_kernel` picks)."""
    return run_chunk(y, cnt, c, n_stop, lam, series, section, impacts)


_here = threading.local()


class StopRequested(Exception):
    """A run driven by :func:`members_on_this_thread` was asked to stop (its ``stop`` event
    was set): raised between two compiled calls, the members' state left as it was."""


@contextlib.contextmanager
def members_on_this_thread(stop: threading.Event | None = None):
    """Within this context the calling thread runs its ensembles' members one after another
    through the compiled nogil call (:func:`alone_kernel`), not on numba's ``prange``
    threads; :func:`on_this_thread` says so to :func:`._members.run_on_cpu` and to the
    verdicts.

    For callers that run several ensembles at once from their own threads (the sweeps'
    thread backend, one batch per core): numba's workqueue layer takes one parallel launch
    at a time, and a batch on one thread leaves no core waiting for its slowest member while
    other batches run. The members are the same compiled :func:`._rk4.run_chunk`, so the
    same bits. ``stop``: when set, the next call raises :class:`StopRequested` (a prompt
    Ctrl-C; a compiled call itself cannot be interrupted).
    """
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
    thread once ``stop`` is set (between two compiled calls), while its ensembles run as
    anywhere else (numba's threads): a GPU sweep's labelling thread
    (:class:`chaoscam.sweep._pipeline.PipelineBackend`), a sweep run beside another
    (:func:`chaoscam.experiments._side_by_side.beside`). The contexts nest: the events of
    the enclosing ones are still watched, so an inner context (a serial sweep's
    :func:`members_on_this_thread`) cannot hide a stop asked of the whole thread."""
    before = stops_here()
    _here.stops = before if stop is None else (*before, stop)
    try:
        yield
    finally:
        _here.stops = before


def stops_here() -> tuple[threading.Event, ...]:
    """The stop events :func:`check_stop` watches on the calling thread (none: it is not
    inside :func:`stop_on`)."""
    return getattr(_here, "stops", ())


def on_this_thread() -> bool:
    """Whether the calling thread is inside :func:`members_on_this_thread`."""
    return getattr(_here, "active", False)


def check_stop() -> None:
    """Raise :class:`StopRequested` if this thread's run was asked to stop."""
    if any(stop.is_set() for stop in stops_here()):
        raise StopRequested("stopped on request")


def contact_fraction(y, cnt, c) -> float:
    """Fraction of the recorded time spent in contact (gap <= 0); NaN if nothing recorded.

    The fixed-step kernel counts grid steps ending in contact; the adaptive one integrates
    time (slots ``Y_RECORDED`` and ``Y_CONTACT``).
    """
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
    """The buffer-refill loop over ``n`` members (those in ``need``; default all).

    ``launch(need)`` runs the members whose indices are in ``need`` until each ends or asks
    for room, and returns their status codes (in the order of ``need``). ``refill(need)``
    empties the output buffers and renews the line-length draws of the members in ``need``
    (those that returned ``NEED_BUFFER``); they are then launched again, until none asks.
    """
    need = np.arange(n) if need is None else np.asarray(need, dtype=np.int64)
    while need.size:
        with _interrupts_held():
            codes = launch(need)
        need = need[codes == k.NEED_BUFFER]
        if need.size:
            refill(need)


@contextlib.contextmanager
def _interrupts_held():
    """Hold a Ctrl-C (or a SIGTERM handled in Python) that arrives during a launch until
    the launch returns, then hand it to the handler that was in place.

    Compiled code cannot be interrupted anyway, but a launch also runs Python inside C
    callbacks: numba's LLVM object cache is called back that way whenever a kernel compiles
    or its runtime is set up (~0.4 s into every process). A KeyboardInterrupt raised there
    cannot propagate: Python prints it as "Exception ignored ... Traceback" and the run goes
    on, the Ctrl-C lost. Only in the main thread (where signal handlers live), and only for
    signals handled by Python functions (an ignored or default signal is left alone).
    """
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
