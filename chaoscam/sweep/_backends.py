"""Execution backends: in-process, local worker processes, Dask distributed.

Each backend offers the same four verbs to the engine (``submit``, ``wait_any``, ``result``,
``close``); a record never depends on which backend or how many workers computed it.

* :class:`SerialBackend` — one worker, in this process (no start-up cost).
* :class:`ProcessBackend` — ``concurrent.futures.ProcessPoolExecutor``, workers ignoring
  SIGINT so that Ctrl-C reaches the driver alone. On Linux the workers are forked from the
  driver after it has loaded the compiled kernels, so they start in milliseconds instead of
  the ~1.3 s a ``spawn`` start spends importing chaoscam and loading numba's cache (which
  would cost a short 2-core map much of its speed-up). The workers are all forked when the
  backend is made, before the pool's own thread starts, and only from a driver running a
  single thread; a driver holding threads (a Dask client, say) gets ``spawn``. A worker
  that dies breaks the pool: the pool is started again and the lost tasks resubmitted.
* :class:`DaskBackend` — a ``distributed.Client`` on a scheduler address, on an existing
  client, or on a ``LocalCluster`` of worker processes bound to 127.0.0.1. Dask itself
  reschedules the tasks of a lost worker.
"""

from __future__ import annotations

import concurrent.futures as cf
import multiprocessing
import os
import signal
import threading
from collections.abc import Callable, Iterable
from typing import Any

__all__ = ["SerialBackend", "ProcessBackend", "DaskBackend", "WorkerLost", "make_backend"]


class WorkerLost(RuntimeError):
    """The worker running a task died; the task can be submitted again."""


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

    def wait_any(self, futures: Iterable[cf.Future]) -> set:
        return set(futures)

    def result(self, fut: cf.Future) -> Any:
        return fut.result()

    def cancel(self, futures: Iterable[Any]) -> None:
        pass

    def close(self) -> None:
        pass


def _ignore_sigint() -> None:
    signal.signal(signal.SIGINT, signal.SIG_IGN)


def _warm_kernels() -> None:
    """Load the compiled kernels (numba cache) in this process: a run of a few steps."""
    from ..model import Params
    from ..simulate import simulate

    simulate(Params(), duration=1e-4, series=False)


class ProcessBackend:
    """A pool of ``workers`` local processes.

    Parameters
    ----------
    workers : int
        Worker processes.
    start_method : str, optional
        ``"fork"``, ``"spawn"`` or ``"forkserver"``. Default: ``"fork"`` where available
        and the driver runs a single thread (the workers inherit the loaded kernels),
        else ``"spawn"``.
    """

    name = "processes"

    def __init__(self, workers: int, start_method: str | None = None) -> None:
        self.workers = int(workers)
        self._requested = start_method
        self._pool = self._start()
        self._pool.submit(int).result()  # start the workers now, before any other thread

    def _method(self) -> str:
        if self._requested is not None:
            return self._requested
        # Fork only a single-threaded driver: a lock held by another thread at the fork
        # would stay held in the child forever.
        single = threading.active_count() == 1
        return "fork" if single and "fork" in multiprocessing.get_all_start_methods() else "spawn"

    def _start(self) -> cf.ProcessPoolExecutor:
        self.start_method = self._method()
        if self.start_method == "fork":
            _warm_kernels()
        return cf.ProcessPoolExecutor(
            max_workers=self.workers,
            mp_context=multiprocessing.get_context(self.start_method),
            initializer=_ignore_sigint,
        )

    def submit(self, fn: Callable, arg: Any) -> cf.Future:
        try:
            return self._pool.submit(fn, arg)
        except cf.process.BrokenProcessPool:
            self.recover()
            return self._pool.submit(fn, arg)

    def wait_any(self, futures: Iterable[cf.Future]) -> set:
        return cf.wait(list(futures), return_when=cf.FIRST_COMPLETED).done

    def result(self, fut: cf.Future) -> Any:
        try:
            return fut.result()
        except cf.process.BrokenProcessPool as err:
            raise WorkerLost(str(err)) from err

    def recover(self) -> None:
        """Start a fresh pool if the current one is broken (a worker died)."""
        if getattr(self._pool, "_broken", False):
            self._pool.shutdown(wait=False, cancel_futures=True)
            self._pool = self._start()

    def cancel(self, futures: Iterable[cf.Future]) -> None:
        for fut in futures:
            fut.cancel()
        self._terminate()

    def _terminate(self) -> None:
        # Running tasks are abandoned: their records would be recomputed on --resume.
        processes = list((getattr(self._pool, "_processes", None) or {}).values())
        self._pool.shutdown(wait=False, cancel_futures=True)
        for proc in processes:
            if proc.is_alive():
                proc.terminate()
        for proc in processes:
            proc.join(timeout=5)

    def close(self) -> None:
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

    def __init__(self, scheduler: Any = None, workers: int | None = None) -> None:
        try:
            import distributed
        except ModuleNotFoundError:  # pragma: no cover - optional dependency
            raise ModuleNotFoundError(
                "the Dask backend needs dask.distributed: pip install 'chaoscam[dask]'"
            ) from None
        self._distributed = distributed
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
        return self.client.submit(fn, arg, pure=False)

    def wait_any(self, futures: Iterable[Any]) -> set:
        return self._distributed.wait(list(futures), return_when="FIRST_COMPLETED").done

    def result(self, fut: Any) -> Any:
        return fut.result()

    def cancel(self, futures: Iterable[Any]) -> None:
        futures = list(futures)
        if futures:
            self.client.cancel(futures)

    def close(self) -> None:
        if self._own_client:
            self.client.close()
        if self._cluster is not None:
            self._cluster.close()


def make_backend(workers: int | None = None, scheduler: Any = None):
    """The backend for ``workers`` local processes, or Dask when ``scheduler`` is given.

    ``workers`` = None uses every core; 1 runs in this process.
    """
    if scheduler is not None:
        return DaskBackend(scheduler, workers)
    n = default_workers() if workers is None else int(workers)
    if n < 1:
        raise ValueError(f"workers = {n} must be >= 1")
    return SerialBackend() if n == 1 else ProcessBackend(n)
