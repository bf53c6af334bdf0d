"""The one engine of every sweep: submit batches, collect records, checkpoint, follow up.

A *plan* decides which tasks exist (a regime map's realizations, a bifurcation diagram's
values and initial conditions, an ensemble's members); the engine packs them into batches
(:class:`._runs.Batch`), feeds those to a backend with a bounded number in flight (so memory
does not grow with the grid), stores each record as it completes, and asks the plan for
follow-up tasks (continuation to the next value, more realizations for an adaptive cell).
Plans decide from finished records only, never from their completion order, so the set of
records is the same for any backend, batch size and worker count. Locally the batches run
one per core on threads (each member through the compiled call without the GIL), or, on a
GPU, the next batch launched while the last is labelled; on Dask each worker runs whole
batches.
"""

from __future__ import annotations

import contextlib
import errno
import sys
from collections import Counter, deque
from collections.abc import Callable, Iterator
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Protocol

from ..kernel import StopRequested, check_stop, fork_safe_threads, runs_on_gpu, stops_here
from ._backends import (
    BackendLost,
    PipelineBackend,
    SerialBackend,
    ThreadBackend,
    WorkerLost,
    make_backend,
)
from ._grid import SweepError
from ._runs import Batch, Judge

__all__ = ["Engine", "SweepInterrupted", "TaskFailed", "execute", "resolve_engine", "run_sweep"]

MAX_RETRIES = 3
"""Times a task may lose its worker before the run stops with an error."""

STOP_POLL_S = 0.1
"""How often [s] a sweep whose thread can be asked to stop (inside
:func:`chaoscam.kernel.stop_on`: a sweep run beside another) looks whether it was, while it
waits for its tasks. Only the main thread gets Ctrl-C; another thread learns of it this way."""


class TaskFailed(RuntimeError):
    """A task raised (a classifier's error, a bug); the finished records are saved. The
    message says how to reproduce it; the command line prints it and exits 1."""


class SweepInterrupted(KeyboardInterrupt):
    """Ctrl-C stopped a sweep; the finished records are saved (when it has an output).

    Attributes
    ----------
    done, total : int
        Records finished (including those of earlier runs) and records planned.
    checkpoint : Path or None
        Where they are saved; None when the sweep had no output file.
    """

    def __init__(self, done: int, total: int, checkpoint, cause: str | None = None) -> None:
        self.done, self.total, self.checkpoint, self.cause = done, total, checkpoint, cause
        super().__init__(self.message)

    @property
    def message(self) -> str:
        return self.describe()

    def describe(self, word: str = "interrupted") -> str:
        """The message, opening with ``word`` (the command line says "terminated" after a
        SIGTERM) unless a cause stopped the run."""
        why = word if self.cause is None else f"stopped: {self.cause};"
        if self.checkpoint is None:
            return (
                f"{why} after {self.done} of {self.total} runs; nothing was saved "
                "(no output file given)"
            )
        return (
            f"{why.rstrip(';')}; {self.done} of {self.total} runs are saved in {self.checkpoint}; "
            "run the same command with --resume to finish"
        )


class Plan(Protocol):
    """What the engine needs from a sweep."""

    total: int
    done: int

    def restore(self, record: dict[str, Any]) -> bool: ...

    def start(self) -> Iterator[Any]: ...

    def on_record(self, record: dict[str, Any]) -> list[Any]: ...


def _bar(progress: bool, plan: Plan, desc: str):
    from tqdm.auto import tqdm

    class Bar(tqdm):
        # No monitor thread: a later local pool forks its workers only from a driver
        # running a single thread (see ProcessBackend).
        monitor_interval = 0

    return Bar(
        total=plan.total,
        initial=plan.done,
        desc=desc,
        unit="run",
        disable=not progress,
        file=sys.stderr,
        smoothing=0.05,
        dynamic_ncols=True,
    )


def _next_task(queue: deque, source: Iterator[Any], pack, size: int):
    """The next task to submit: one of the plan's, or up to ``size`` of them packed into
    one (``pack(tasks)``, the ensemble engine's batches); None when there is none."""
    tasks = []
    while len(tasks) < size:
        task = queue.popleft() if queue else next(source, None)
        if task is None:
            break
        tasks.append(task)
    if not tasks:
        return None
    return pack(tuple(tasks)) if pack is not None else tasks[0]


def _share(plan: Plan, saved: int, inflight: dict, size: int, spread: int) -> int:
    """How many tasks the next pack takes when ``spread`` packs run at once: at most
    ``size``, and at most the tasks not yet submitted over twice ``spread`` (guided
    scheduling), so that a sweep of few tasks, or a sweep's last ones, keep every thread
    busy instead of one thread running one large pack while the others wait. Measured on
    2 cores: the quick report's small sweeps (3-11 values of 20 s, one pack each) ran on
    one core."""
    if spread <= 1:
        return size
    flying = sum(len(getattr(task, "tasks", (task,))) for task in inflight.values())
    left = plan.total - saved - flying
    return max(1, min(size, -(-left // (2 * spread))))


def _finished(backend, futures: list) -> set:
    """``backend.wait_any(futures)``; on a thread that can be asked to stop (:func:`stops_here`
    is not empty), :data:`STOP_POLL_S` at a time, raising
    :class:`~chaoscam.integrate._driver.StopRequested` once it is asked."""
    if not stops_here():
        return backend.wait_any(futures)
    while True:
        check_stop()
        done = backend.wait_any(futures, timeout=STOP_POLL_S)
        if done:
            return done


def execute(
    plan: Plan,
    backend,
    store,
    *,
    progress: bool = False,
    desc: str = "",
    pack=None,
    pack_size: int = 1,
    spread: int = 1,
) -> None:
    """Run ``plan`` on ``backend``, storing every record in ``store``.

    Records already in ``store`` (a resumed checkpoint) are given to the plan first and not
    run again. With ``pack``, up to ``pack_size`` tasks travel as one (``pack(tasks)``, whose
    ``run`` returns their records in a list: the ensemble engine); the plan sees each record
    as if its task ran alone. With ``spread`` > 1 (packs run that many at once, one a
    thread), a pack takes fewer tasks as they run out (:func:`_share`); a member's record
    does not depend on its pack. Raises :class:`SweepInterrupted` on Ctrl-C after saving
    what finished.
    """
    size = pack_size if pack is not None else 1
    store.open()
    for record in store.restored():
        try:
            plan.restore(record)
        except (KeyError, IndexError, TypeError, ValueError) as err:
            raise SweepError(
                f"{store.path} holds a record that does not fit this run "
                f"({type(err).__name__}: {err}); delete that folder to start over"
            ) from None
    source = plan.start()
    saved = plan.done  # records restored; each one stored below adds one
    queue: deque = deque()
    inflight: dict[Any, Any] = {}
    retries: Counter = Counter()
    window = 1 if isinstance(backend, SerialBackend) else 2 * backend.workers
    bar = _bar(progress, plan, desc)
    try:
        while True:
            while len(inflight) < window:
                task = _next_task(queue, source, pack, _share(plan, saved, inflight, size, spread))
                if task is None:
                    break
                inflight[backend.submit(run_batch, task)] = task
            if not inflight:
                break
            for fut in _finished(backend, list(inflight)):
                task = inflight.pop(fut)
                try:
                    record = backend.result(fut)
                except StopRequested:  # this thread was asked to stop (serial: in the task)
                    raise
                except WorkerLost as err:
                    retries[task.key()] += 1
                    if retries[task.key()] > MAX_RETRIES:
                        raise TaskFailed(
                            f"task {task.key()} lost its worker {MAX_RETRIES + 1} times; "
                            f"the finished records are saved, resume after fixing it ({err})"
                        ) from err
                    getattr(backend, "recover", lambda: None)()
                    queue.extendleft(reversed(getattr(task, "tasks", (task,))))
                    continue
                except Exception as err:
                    raise TaskFailed(
                        f"task {task.key()} failed ({type(err).__name__}: {err}); reproduce "
                        f"it with {task.hint()}, then the classifier on that run"
                    ) from err
                for rec in record if isinstance(record, list) else [record]:
                    store.add(rec)
                    saved += 1
                    queue.extend(plan.on_record(rec))
                    if bar.total != plan.total:
                        bar.total = plan.total
                    bar.update(1)
            store.maybe_flush()
    except (KeyboardInterrupt, StopRequested):
        with _second_interrupt_ignored():  # the batches under way stop all the same
            backend.cancel(list(inflight))
            store.flush()  # a record stored but not yet counted by the plan is saved too
            backend.close()  # they stop at their next compiled call or member
        raise SweepInterrupted(max(saved, plan.done), plan.total, store.path) from None
    except BackendLost as err:
        store.flush()
        raise SweepInterrupted(
            max(saved, plan.done), plan.total, store.path, cause=str(err)
        ) from None
    except BaseException:
        backend.cancel(list(inflight))
        store.flush()
        raise
    finally:
        bar.close()
    store.flush()


@contextlib.contextmanager
def _second_interrupt_ignored():
    """A context in which a second Ctrl-C is ignored (in the main thread, where handlers
    live): a sweep stopped by the first waits for its batches under way to stop, then says
    once what it kept, instead of leaving with a bare KeyboardInterrupt."""
    import signal
    import threading

    before = signal.getsignal(signal.SIGINT)
    if threading.current_thread() is not threading.main_thread() or before is None:
        yield  # no handler to put back (one not set from Python): left alone
        return
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    try:
        yield
    finally:
        signal.signal(signal.SIGINT, before)


def run_batch(batch: Batch) -> list[dict[str, Any]]:
    """Run one batch (the function every backend calls)."""
    return batch.run()


BATCH_SECONDS = 2.0
"""Target wall time of one CPU batch [s]: short enough for a prompt Ctrl-C and frequent
checkpoints, long enough that every thread has several members to balance."""

MAX_BATCH = 256
"""Members per CPU batch at most (bounds the memory of one compiled call)."""

GPU_BATCH = 8_192
"""Members per batch when a sweep's batches run on a GPU: one thread is slow and the device's
rate comes from many in flight (on an H200, 0.25-s runs: 64 members took 1.09 s of launch,
8,448 took 1.80 s, a full wave of 33,792 took 5.1 s), so batches must be large; a quarter
of an H200's wave keeps a checkpoint every few minutes."""


@dataclass(frozen=True)
class Engine:
    """Where and how a sweep's batches run: ``pack`` makes a batch of up to ``size`` tasks;
    ``threads`` numba threads in this process (local; None: leave it), ``batch_threads``
    batches at once on threads, ``pipeline`` a local GPU's batches launched while the last
    is labelled; ``device`` "gpu" or "cpu"."""

    judge: Judge
    device: str
    size: int
    threads: int | None = None
    batch_threads: int = 1
    pipeline: bool = False

    def pack(self, tasks: tuple) -> Batch:
        return Batch(tasks, self.judge, self.device)


def batch_size(base, num, duration: float, transient: float, threads: int) -> int:
    """Members per CPU batch: about :data:`BATCH_SECONDS` of work on ``threads`` threads,
    from the run-time estimate (at least one per thread)."""
    from ..simulation import estimate

    per_run = max(estimate(base, num, duration=duration, transient=transient).seconds, 1e-3)
    n = int(threads * BATCH_SECONDS / per_run)
    return max(threads, min(n, MAX_BATCH))


def resolve_engine(judge: Judge, device: str, base, num, run, workers, scheduler) -> Engine:
    """The engine of a sweep of ``base`` and ``num`` with ``run`` = (duration, transient):
    one batch per core on threads, a GPU's pipeline, or batches on Dask workers."""
    from ..kernel import GPUFallbackWarning, gpu_status
    from ._backends import local_workers

    if device not in ("cpu", "gpu", "auto"):
        raise SweepError(f"device = {device!r} must be one of cpu, gpu, auto")
    threads = None
    if scheduler is None:
        try:
            threads = local_workers(workers)
        except ValueError as err:
            raise SweepError(str(err)) from None
    gpu = scheduler is None and runs_on_gpu(device) and not judge.series
    if device == "gpu" and scheduler is None and not gpu:
        import warnings

        why = "a classifier that reads the series" if judge.series else gpu_status()[1]
        warnings.warn(f"GPU backend unavailable: {why}; the sweep runs on the CPU",
                      GPUFallbackWarning, stacklevel=4)  # fmt: skip
    if gpu:
        return Engine(judge, "gpu", GPU_BATCH, threads, pipeline=True)
    if scheduler is not None:  # Dask workers: whole batches, on their GPUs when asked
        size = GPU_BATCH if device == "gpu" else batch_size(base, num, *run, 1)
        return Engine(judge, device, size)
    by_batch = threads if threads > 1 else 1
    size = batch_size(base, num, run[0], run[1], 1 if by_batch > 1 else threads)
    return Engine(judge, "cpu", size, None if by_batch > 1 else threads, by_batch)


def _numba_threads(n: int | None):
    """A context in which numba runs ``n`` threads (None: leave it), restored after."""
    if n is None:
        return contextlib.nullcontext()

    @contextlib.contextmanager
    def scope():
        import numba

        fork_safe_threads()  # numba's threads start here, fixing the layer: fork-safe first
        before = numba.get_num_threads()
        numba.set_num_threads(max(1, min(int(n), numba.config.NUMBA_NUM_THREADS)))
        try:
            yield
        finally:
            numba.set_num_threads(before)

    return scope()


def run_plan(plan, eng: Engine, store, *, workers, scheduler, progress: bool, desc: str) -> None:
    """Execute a sweep's plan on its engine's backend."""
    if scheduler is not None:
        try:
            backend = make_backend(workers, scheduler)
        except (ValueError, ConnectionError) as err:
            where = "" if "scheduler" in str(err) else f"scheduler {scheduler!r}: "
            raise SweepError(f"{where}{err}") from None
    elif eng.pipeline:
        backend = PipelineBackend(eng.threads)
    elif eng.batch_threads > 1:
        backend = ThreadBackend(eng.batch_threads)
    else:
        backend = SerialBackend()
    try:
        with _numba_threads(eng.threads):
            spread = eng.batch_threads if isinstance(backend, ThreadBackend) else 1
            execute(plan, backend, store, progress=progress, desc=desc, pack=eng.pack,
                    pack_size=eng.size, spread=spread)  # fmt: skip
    finally:
        backend.close()


def run_sweep(
    plan,
    eng: Engine,
    *,
    out: Path | None,
    second: str,
    config: dict[str, Any],
    keys: tuple[str, str],
    read: Callable[[Path], Any],
    build: Callable[[list[dict[str, Any]]], Any],
    resume: bool,
    force: bool,
    flush_interval: float,
    workers,
    scheduler,
    progress: bool,
    desc: str,
):
    """The steps every sweep takes around its plan, in one place.

    Lock the output ``out`` (FILE.parquet, with FILE.<second>.parquet beside it; None: kept
    in memory), open its checkpoint (a finished output of the same ``config`` is reused
    through ``read`` under ``resume``), run the plan (:func:`run_plan`), sort the records by
    ``keys`` (one per key), warn once per message the runs raised, ``build`` the result
    from the records, write it to ``out`` and remove the checkpoint.
    """
    from ._common import companion, lock_outputs, open_store

    with lock_outputs(out, second):
        store, reuse = open_store(out, second, config, resume, flush_interval, force)
        if reuse:
            try:
                result = read(out)
            except (OSError, ValueError) as err:  # pyarrow's errors are among them
                raise SweepError(
                    f"{out} is this configuration's finished run, but it or its companion "
                    f"cannot be read back ({err}); pass --force without --resume (force=True "
                    "in Python) to compute it again"
                ) from None
            if progress:
                print(
                    f"already finished: {out} (same configuration); read, nothing run",
                    file=sys.stderr,
                )
            return result
        # Outputs there now are this configuration's (a resumed run's) or --force's; any
        # other that appears while the plan runs is not replaced at the end.
        replace = force or (
            out is not None and any(p.exists() for p in (out, companion(out, second)))
        )
        try:
            run_plan(
                plan, eng, store, workers=workers, scheduler=scheduler, progress=progress,
                desc=desc,
            )  # fmt: skip
            return _finish(plan, store, out, keys, build, replace)
        except OSError as err:  # a full disk: say what is kept, and where
            if out is None or err.errno not in SAVE_ERRNOS:
                raise  # not a failure to save (a lost connection, a file that appeared)
            raise type(err)(
                err.errno,
                f"{err.strerror or err} while saving the results of {out}"
                + (f" ({err.filename})" if err.filename else "")
                + f"; the runs finished and saved so far are kept in {store.path}: fix the "
                "cause (free space) and run the same command with --resume",
            ) from None
        except Exception:
            # A run that failed before finishing any (a bad initial condition, a classifier
            # that cannot be pickled) keeps no checkpoint: it would only block the corrected
            # command ("holds the checkpoint of an interrupted run").
            if next(iter(store.records()), None) is None:
                store.remove()
            raise


SAVE_ERRNOS = frozenset({errno.ENOSPC, errno.EDQUOT, errno.EIO, errno.EROFS})
"""The errors of a disk that takes no more (full, over quota, failing, read-only): a sweep
stopped by one says where its finished runs are kept and to --resume once it is fixed."""


def _finish(plan, store, out: Path | None, keys, build, replace: bool):
    """The result from the finished records, written to ``out`` (its checkpoint removed)."""
    from ._common import reemit_warnings, unique_sorted

    try:
        records = unique_sorted(store.records(), keys)
        reemit_warnings(records)
        result = build(records)
        if out is not None:
            result._write(out, replace=replace)
            store.remove()
    except KeyboardInterrupt:
        # Every record is in the checkpoint; a resume writes the tables from it.
        if out is None:
            raise
        raise SweepInterrupted(plan.total, plan.total, store.path) from None
    return result
