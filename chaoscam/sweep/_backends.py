"""Where a sweep's batches run: in this process, on its threads, a GPU's pipeline, or Dask;
each offers ``submit``, ``wait_any``, ``result``, ``cancel`` and ``close``."""

from __future__ import annotations

import concurrent.futures as cf
import logging
import numbers
import os
import sys
import threading
import time
from collections.abc import Callable, Iterable
from typing import Any

_DASK_POLL_S = 2.0
_DASK_NOTICE_S = 10.0
DASK_NO_WORKER_S = 300.0
"""Seconds a Dask run waits with no worker connected (after saying so) before it stops."""
_DASK_LOST_ERRORS = ("FuturesCancelledError", "CancelledError", "CommClosedError")


class BackendLost(RuntimeError):
    """The Dask scheduler died or the connection to it broke; the finished records are kept."""


WORKERS_PER_CORE = 4
"""Most local workers per core: more only compete for the cores, each holding a run in memory."""


def local_workers(workers: int | None) -> int:
    """``workers``, or every core when None; a ValueError outside [1, 4 x cores]."""
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
    """Tasks on ``workers`` threads, each running its members one by one without the GIL
    (:func:`chaoscam.kernel.members_on_this_thread`): a slow member delays only its own
    thread. ``cancel`` stops the running tasks between two compiled calls."""

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
    """Tasks on Dask: ``scheduler`` ``"tcp://HOST:PORT"``, a ``Client`` (left open), or None /
    ``"local"`` for a ``LocalCluster`` of ``workers`` one-thread processes on 127.0.0.1; Dask
    reschedules a lost worker's tasks, a lost scheduler is a :class:`BackendLost`."""

    _noticed = False

    def __init__(self, scheduler: Any = None, workers: int | None = None) -> None:
        try:
            import distributed
        except ModuleNotFoundError:  # pragma: no cover - optional dependency
            raise ModuleNotFoundError(
                "the Dask backend needs dask.distributed: pip install 'chaoscam[dask]'"
            ) from None
        self._distributed = distributed
        _quiet_lost_connection_log()  # before connecting: the sender may log first
        self._cluster, self._own_client = None, not isinstance(scheduler, distributed.Client)
        if not self._own_client:
            self.client = scheduler
        elif scheduler is None or scheduler == "local":
            self._cluster = distributed.LocalCluster(
                n_workers=workers or default_workers(), threads_per_worker=1, processes=True,
                host="127.0.0.1", dashboard_address="127.0.0.1:0",
            )  # fmt: skip
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
            except MemoryError:  # a frame length read from a peer that does not speak Dask
                raise ConnectionError(
                    f"{scheduler!r} answered, but not as a Dask scheduler (its reply is not "
                    "Dask's protocol): give the address of a running `dask scheduler`"
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
        """The finished futures (none after ``timeout`` s); :class:`BackendLost` for a lost
        scheduler, or no worker for :data:`DASK_NO_WORKER_S` (after a notice)."""
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
            if not self._noticed:
                self._noticed = True
                print(
                    f"chaoscam: waiting: no Dask worker is connected to the scheduler "
                    f"({self.client.scheduler.address}); start one with `dask worker ADDRESS`; "
                    f"stopping if none connects within {DASK_NO_WORKER_S:g} s (finished runs "
                    "are saved; --resume continues)",
                    file=sys.stderr, flush=True,
                )  # fmt: skip
            if now - seen_worker >= DASK_NO_WORKER_S:
                raise BackendLost(
                    f"no Dask worker was connected to the scheduler "
                    f"({self.client.scheduler.address}) for {DASK_NO_WORKER_S:g} s"
                )

    def _workers_now(self) -> int:
        try:
            return len(self.client.nthreads())
        except Exception:
            return 0

    def _lost(self, err: Exception | None) -> str:
        """One line for a lost scheduler."""
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
        try:  # a lost scheduler: no hang, no traceback
            if self._own_client:
                self.client.close(timeout=10)
            if self._cluster is not None:
                self._cluster.close(timeout=10)
        except Exception:
            pass


def _drop_lost_connection(record) -> bool:
    """Logging filter: drop distributed's lost-connection noise (``DaskBackend._lost`` says it)."""
    import asyncio

    from distributed.comm.core import CommClosedError

    if "Failed to reconnect to scheduler" in record.getMessage():
        return False
    exc = record.exc_info[1] if record.exc_info else None
    return not isinstance(exc, (asyncio.CancelledError, CommClosedError))


_CLIENT_CONNECTION_LOGGERS = ("distributed.client", "distributed.batched", "distributed.core",
                              "distributed.comm.tcp", "distributed.utils")  # fmt: skip
"""The loggers that report a client's connection closing (a filter misses child loggers)."""


def _quiet_lost_connection_log() -> None:
    for name in _CLIENT_CONNECTION_LOGGERS:
        logging.getLogger(name).addFilter(_drop_lost_connection)  # idempotent


class PipelineBackend(ThreadBackend):
    """A local GPU's batches: launched in the driver's thread (numba-cuda's only one), labelled
    on one thread with ``threads`` numba threads meanwhile; the serial backend's records."""

    def __init__(self, threads: int | None = None) -> None:
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
