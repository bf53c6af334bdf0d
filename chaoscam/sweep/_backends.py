"""Where a sweep's batches run: in this process, on its threads, a GPU's pipeline, or Dask.

Each backend offers the same verbs to the engine (``submit``, ``wait_any``, ``result``,
``cancel``, ``close``); a record never depends on which backend or how many workers ran it.

* :class:`SerialBackend` — one batch at a time, in this process.
* :class:`ThreadBackend` — ``workers`` threads of this process, each running its batches'
  members one at a time through the compiled call without the GIL: a batch's slowest member
  leaves no other core waiting, as a ``prange`` launch over one batch would.
* :class:`PipelineBackend` — a local GPU: a batch is launched at submission in the driver's
  thread and labelled on one labelling thread, so the device runs the next batch while the
  host labels the last.
* :class:`DaskBackend` — a ``distributed.Client`` on a scheduler address, on an existing
  client, or on a ``LocalCluster`` of worker processes bound to 127.0.0.1. Dask itself
  reschedules the tasks of a lost worker. A lost scheduler, or no worker connected for
  :data:`DASK_NO_WORKER_S`, is a :class:`BackendLost`: the engine saves what finished and
  stops with a resume hint instead of a ``FuturesCancelledError`` or a silent wait.
"""

from __future__ import annotations

import concurrent.futures as cf
import os
import threading
from collections.abc import Callable, Iterable
from typing import Any

__all__ = [
    "BackendLost",
    "DaskBackend",
    "PipelineBackend",
    "SerialBackend",
    "ThreadBackend",
    "WorkerLost",
    "local_workers",
    "make_backend",
]

_DASK_POLL_S = 2.0
_DASK_NOTICE_S = 10.0
DASK_NO_WORKER_S = 300.0
"""Seconds a Dask run waits with no worker connected (after saying so) before it stops."""
_DASK_LOST_ERRORS = ("FuturesCancelledError", "CancelledError", "CommClosedError")


class WorkerLost(RuntimeError):
    """The worker running a task died; the task can be submitted again."""


class BackendLost(RuntimeError):
    """The backend itself is gone (the Dask scheduler died or the connection to it broke):
    no task can run until it is restarted; the finished records are kept."""


WORKERS_PER_CORE = 4
"""Most local workers (processes, or the ensemble engine's batch threads) per core a sweep
accepts: more only compete for the cores, and each holds a run in memory (a typo such as
``--workers 99999`` would otherwise start thousands of processes)."""


def local_workers(workers: int | None) -> int:
    """The local worker count: ``workers``, or every core when None; a ValueError naming
    ``workers`` and its range [1, WORKERS_PER_CORE x cores] otherwise."""
    import numbers

    most = WORKERS_PER_CORE * default_workers()
    if workers is not None and (
        isinstance(workers, bool) or not isinstance(workers, numbers.Integral)
    ):  # 1.5, True and "2" were taken as 1, 1 and 2
        raise ValueError(f"workers = {workers!r} must be a whole number in [1, {most}]")
    n = default_workers() if workers is None else int(workers)
    if not 1 <= n <= most:
        raise ValueError(
            f"workers = {n} must be in [1, {most}] ({WORKERS_PER_CORE} per core on this "
            f"machine's {default_workers()}; more only compete for the cores)"
        )
    return n


def default_workers() -> int:
    """Cores this process may use."""
    try:
        return max(1, len(os.sched_getaffinity(0)))
    except AttributeError:  # pragma: no cover - not Linux
        return max(1, os.cpu_count() or 1)


class SerialBackend:
    """Runs each task at submission, in this process."""

    name = "serial"
    workers = 1

    def submit(self, fn: Callable, arg: Any) -> cf.Future:
        fut: cf.Future = cf.Future()
        try:
            fut.set_result(fn(arg))
        except Exception as err:  # KeyboardInterrupt passes through to the engine
            fut.set_exception(err)
        return fut

    def wait_any(self, futures: Iterable[cf.Future], timeout: float | None = None) -> set:
        return set(futures)  # each ran at its submission

    def result(self, fut: cf.Future) -> Any:
        return fut.result()

    def cancel(self, futures: Iterable[Any]) -> None:
        pass

    def close(self) -> None:
        pass


class ThreadBackend:
    """Tasks on ``workers`` threads of this process (the ensemble engine's local backend).

    Each task runs inside :func:`chaoscam.kernel.members_on_this_thread`: its
    ensembles' members one after another through the compiled call, which releases the GIL,
    so ``workers`` tasks simulate at once and a task's slow member delays only its own
    thread (numba's workqueue layer takes one parallel launch at a time, and a launch over a
    batch waits for its slowest member). The members are the same compiled kernel, so the
    records are the same bits as on one thread. ``cancel`` asks the running tasks to stop
    between two compiled calls (a prompt Ctrl-C); ``close`` joins the threads.
    """

    name = "threads"

    def __init__(self, workers: int, prefix: str = "chaoscam-batch") -> None:
        self.workers = int(workers)
        self._stop = threading.Event()
        self._pool = cf.ThreadPoolExecutor(self.workers, thread_name_prefix=prefix)

    def _run(self, fn: Callable, arg: Any) -> Any:
        from ..kernel import members_on_this_thread

        with members_on_this_thread(self._stop):
            return fn(arg)

    def submit(self, fn: Callable, arg: Any) -> cf.Future:
        return self._pool.submit(self._run, fn, arg)

    def wait_any(self, futures: Iterable[cf.Future], timeout: float | None = None) -> set:
        return cf.wait(list(futures), timeout=timeout, return_when=cf.FIRST_COMPLETED).done

    def result(self, fut: cf.Future) -> Any:
        return fut.result()

    def cancel(self, futures: Iterable[cf.Future]) -> None:
        self._stop.set()
        for fut in futures:
            fut.cancel()

    def close(self) -> None:
        self._stop.set()  # tasks still running stop at their next compiled call
        self._pool.shutdown(wait=True, cancel_futures=True)


class DaskBackend:
    """Tasks on a Dask distributed cluster.

    Parameters
    ----------
    scheduler : str, distributed.Client or None
        ``"tcp://HOST:PORT"`` of a running scheduler; a connected ``Client`` (left open on
        close); or ``None`` / ``"local"`` for a ``LocalCluster`` of ``workers`` single-thread
        worker processes on 127.0.0.1, closed on close.
    workers : int
        Worker processes of a local cluster (ignored for an address or a client).
    """

    name = "dask"
    _noticed = False

    def __init__(self, scheduler: Any = None, workers: int | None = None) -> None:
        try:
            import distributed
        except ModuleNotFoundError:  # pragma: no cover - optional dependency
            raise ModuleNotFoundError(
                "the Dask backend needs dask.distributed: pip install 'chaoscam[dask]'"
            ) from None
        self._distributed = distributed
        # Installed before the first connection: the background sender may log a closed
        # comm before the driver notices the scheduler is gone.
        _quiet_lost_connection_log()
        self._cluster = None
        self._own_client = True
        if isinstance(scheduler, distributed.Client):
            self.client = scheduler
            self._own_client = False
        elif scheduler is None or scheduler == "local":
            self._cluster = distributed.LocalCluster(
                n_workers=workers or default_workers(),
                threads_per_worker=1,
                processes=True,
                host="127.0.0.1",
                dashboard_address="127.0.0.1:0",  # loopback, any free port
            )
            self.client = distributed.Client(self._cluster)
        else:
            try:
                self.client = distributed.Client(scheduler, timeout="30s")
            except OSError as err:
                raise ConnectionError(
                    f"cannot reach the Dask scheduler at {scheduler!r} ({err}); start one "
                    "(dask scheduler) and its workers (dask worker ADDRESS), or use "
                    "--scheduler local"
                ) from None
        self.workers = max(1, sum(self.client.nthreads().values()))

    def submit(self, fn: Callable, arg: Any):
        try:
            return self.client.submit(fn, arg, pure=False)
        except Exception as err:
            if self.client.status != "running":  # closed after the scheduler was lost
                raise BackendLost(self._lost(err)) from None
            raise

    def wait_any(self, futures: Iterable[Any], timeout: float | None = None) -> set:
        """The finished futures (none after ``timeout`` seconds, if given).

        With no worker connected it says so once on stderr after ``_DASK_NOTICE_S`` and
        raises :class:`BackendLost` after :data:`DASK_NO_WORKER_S` without one; a lost
        scheduler raises it at once.
        """
        import time

        futures = list(futures)
        poll = _DASK_POLL_S if timeout is None else min(_DASK_POLL_S, timeout)
        started = time.monotonic()
        seen_worker = started  # the last time a worker was known to be connected
        while True:
            try:
                done = self._distributed.wait(futures, poll, return_when="FIRST_COMPLETED").done
            except self._distributed.TimeoutError:
                done = set()
            except Exception as err:  # the scheduler is gone or the connection broke
                raise BackendLost(self._lost(err)) from None
            if done:
                return done
            if self.client.status not in ("running", "connecting"):
                raise BackendLost(self._lost(None))
            now = time.monotonic()
            if timeout is not None and now - started >= timeout:
                return set()
            if now - started < _DASK_NOTICE_S:
                continue
            if self._workers_now():
                seen_worker = now
                continue
            self._notice_waiting()
            if now - seen_worker >= DASK_NO_WORKER_S:
                raise BackendLost(
                    f"no Dask worker was connected to the scheduler "
                    f"({self.client.scheduler.address}) for {DASK_NO_WORKER_S:g} s"
                )

    def _notice_waiting(self) -> None:
        import sys

        if self._noticed:
            return
        print(
            f"chaoscam: waiting: no Dask worker is connected to the scheduler "
            f"({self.client.scheduler.address}); start one with `dask worker ADDRESS`; "
            f"stopping if none connects within {DASK_NO_WORKER_S:g} s (finished runs are "
            "saved; --resume continues)",
            file=sys.stderr,
            flush=True,
        )
        self._noticed = True

    def _workers_now(self) -> int:
        try:
            return len(self.client.nthreads())
        except Exception:
            return 0

    def _lost(self, err: Exception | None) -> str:
        """One line for a lost scheduler (the error's own text spans several lines)."""
        address = getattr(getattr(self.client, "scheduler", None), "address", None) or "?"
        detail = f" ({type(err).__name__})" if err is not None else ""
        return f"the Dask scheduler at {address} was lost{detail}"

    def result(self, fut: Any) -> Any:
        try:
            return fut.result()
        except Exception as err:
            if fut.status == "cancelled" or type(err).__name__ in _DASK_LOST_ERRORS:
                raise BackendLost(self._lost(err)) from None
            raise

    def cancel(self, futures: Iterable[Any]) -> None:
        futures = list(futures)
        if futures:
            self.client.cancel(futures)

    def close(self) -> None:
        # A lost scheduler must not turn the closing into a hang or a traceback.
        try:
            if self._own_client:
                self.client.close(timeout=10)
            if self._cluster is not None:
                self._cluster.close(timeout=10)
        except Exception:
            pass


class _DropLostConnectionLog:
    """Drops what distributed logs in this process when its connection to the scheduler
    closes: "Failed to reconnect to scheduler", and the tracebacks of a closed comm
    (``CommClosedError``, e.g. "Batched Comm Closed" from the background sender) or of a
    cancelled reconnection. The lost scheduler is reported in one line
    (:meth:`DaskBackend._lost`); these records would put tracebacks around it, in an order
    that depends on which thread notices first."""

    def filter(self, record) -> bool:
        import asyncio

        from distributed.comm.core import CommClosedError

        if "Failed to reconnect to scheduler" in record.getMessage():
            return False
        exc = record.exc_info[1] if record.exc_info else None
        return not isinstance(exc, (asyncio.CancelledError, CommClosedError))


_LOST_CONNECTION_FILTER = _DropLostConnectionLog()

# The loggers that report a client's connection closing (a logger's filters apply to the
# records logged on it, not to those of its children, so each is named).
_CLIENT_CONNECTION_LOGGERS = (
    "distributed.client",
    "distributed.batched",
    "distributed.core",
    "distributed.comm.tcp",
    "distributed.utils",
)


def _quiet_lost_connection_log() -> None:
    import logging

    for name in _CLIENT_CONNECTION_LOGGERS:
        logging.getLogger(name).addFilter(_LOST_CONNECTION_FILTER)  # idempotent


def make_backend(workers: int | None = None, scheduler: Any = None):
    """The Dask backend of ``scheduler`` ("local", "tcp://HOST:PORT" or a client), with
    ``workers`` local Dask workers for "local"."""
    if not isinstance(scheduler, str) and not hasattr(scheduler, "submit"):
        from ._grid import SweepError

        raise SweepError(
            f"scheduler = {scheduler!r} is not a Dask scheduler: give 'local', the "
            "address of a running one ('tcp://HOST:PORT') or a distributed.Client"
        )
    return DaskBackend(scheduler, workers)


class PipelineBackend(ThreadBackend):
    """A local GPU's batches: launched at submission in the driver's thread (numba-cuda is
    used from that thread only, and Ctrl-C stops a launch when it returns), labelled on one
    labelling thread; the engine keeps two batches in flight, so the next launch runs while
    the last is labelled. ``threads``: numba's thread count for the labelling thread's CPU
    work. The records are those of the serial backend, bit for bit (a record depends on its
    member only)."""

    name = "pipeline"

    def __init__(self, threads: int | None = None) -> None:
        # the engine keeps 2 x workers tasks in flight: one labelled, one launched
        super().__init__(1, prefix="chaoscam-labels")
        self.threads = threads

    def _label(self, task: Any, launched: Any) -> Any:
        import numba

        from ..kernel import fork_safe_threads, stop_on

        if self.threads is not None:
            fork_safe_threads()  # set_num_threads starts the threads: the layer first
            numba.set_num_threads(self.threads)  # numba's count is per thread
        with stop_on(self._stop):  # stops between two compiled calls when cancelled
            return task.label(launched)

    def submit(self, fn: Callable, arg: Any) -> cf.Future:
        now = SerialBackend()  # runs a call here, as a finished future
        launched = now.submit(type(arg).launch, arg)  # here: the driver's thread, the device's
        if launched.exception() is not None:
            return launched
        return self._pool.submit(self._label, arg, launched.result())
