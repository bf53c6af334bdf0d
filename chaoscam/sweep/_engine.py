"""The one engine of every sweep: submit batches, collect records, checkpoint, follow up; a
:class:`Plan` decides from finished records only, so they do not depend on backend or batch."""

from __future__ import annotations

import contextlib
import errno
import json
import signal
import sys
import threading
from collections import Counter, deque
from collections.abc import Callable, Iterator
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from .._util import warn
from .._version import __version__
from ..io import lock_all
from ..kernel import StopRequested, by_size, check_stop, fork_safe_threads, runs_on_gpu, stops_here
from ._backends import BackendLost, DaskBackend, PipelineBackend, SerialBackend, ThreadBackend
from ._common import companion
from ._grid import SweepError
from ._runs import Batch, Judge
from ._store import open_store

STOP_POLL_S = 0.1
"""How often [s] a waiting sweep thread looks whether it was asked to stop (``kernel.stop_on``)."""


class TaskFailed(RuntimeError):
    """A task raised (a classifier's error, a bug); the message says how to reproduce it."""


class SweepInterrupted(KeyboardInterrupt):
    """Ctrl-C stopped a sweep: ``done`` of ``total`` records finished (earlier runs' too),
    saved in ``checkpoint`` (None without an output file); ``cause``: what else stopped it."""

    def __init__(self, done: int, total: int, checkpoint, cause: str | None = None) -> None:
        self.done, self.total, self.checkpoint, self.cause = done, total, checkpoint, cause
        self.message = self.describe()
        super().__init__(self.message)

    def describe(self, word: str = "interrupted") -> str:
        """The message, opening with ``word`` ("terminated" after a SIGTERM) unless a cause."""
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


class Plan:
    """A sweep's tasks: :meth:`start` yields the first, :meth:`on_record` a finished record's
    follow-ups (subclasses define ``start``, ``total``, ``keys``); each key counts once."""

    keys: tuple[str, ...]

    def __init__(self) -> None:
        self.finished: set[tuple] = set()
        self.done = 0

    def restore(self, record: dict[str, Any]) -> bool:
        """Count a finished record; False when its key was counted already."""
        key = tuple(record[k] for k in self.keys)
        if key in self.finished:
            return False
        self.finished.add(key)
        self.done += 1
        self.counted(record)
        return True

    def counted(self, record: dict[str, Any]) -> None:
        """What a plan learns from a record it counts."""

    def on_record(self, record: dict[str, Any]) -> list[Any]:
        return self.follow(record) if self.restore(record) else []

    def follow(self, record: dict[str, Any]) -> list[Any]:
        """The tasks a newly counted record asks for."""
        return []


def _bar(progress: bool, plan: Plan, desc: str):
    from tqdm.auto import tqdm

    class Bar(tqdm):
        monitor_interval = 0  # no monitor thread beside the batches

    return Bar(total=plan.total, initial=plan.done, desc=desc, unit="run", disable=not progress,
               file=sys.stderr, smoothing=0.05, dynamic_ncols=True)  # fmt: skip


def _next_task(queue: deque, source: Iterator[Any], pack, size: int):
    """Up to ``size`` of the plan's tasks packed into one batch; None when there is none."""
    tasks = []
    while len(tasks) < size:
        task = queue.popleft() if queue else next(source, None)
        if task is None:
            break
        tasks.append(task)
    return pack(tuple(tasks)) if tasks else None


def _share(plan: Plan, saved: int, inflight: dict, size: int, spread: int) -> int:
    """Tasks in the next pack: at most ``size``, fewer as they run out (guided scheduling)."""
    if spread <= 1:
        return size
    left = plan.total - saved - sum(len(batch.tasks) for batch in inflight.values())
    return max(1, min(size, -(-left // (2 * spread))))


def _finished(backend, futures: list) -> set:
    """``backend.wait_any(futures)``, polled on a thread that can be asked to stop."""
    if not stops_here():
        return backend.wait_any(futures)
    while True:
        check_stop()
        done = backend.wait_any(futures, timeout=STOP_POLL_S)
        if done:
            return done


def execute(plan: Plan, backend, store, eng: Engine, *, progress=False, desc="", spread=1) -> None:
    """Run ``plan`` on ``backend`` in batches, every record into ``store`` (its restored ones
    given to the plan first); :class:`SweepInterrupted` on Ctrl-C, after saving."""
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
    window = 1 if isinstance(backend, SerialBackend) else 2 * backend.workers
    bar = _bar(progress, plan, desc)
    try:
        while True:
            while len(inflight) < window:
                size = _share(plan, saved, inflight, eng.size, spread)
                task = _next_task(queue, source, eng.pack, size)
                if task is None:
                    break
                inflight[backend.submit(run_batch, task)] = task
            if not inflight:
                break
            for fut in _finished(backend, list(inflight)):
                task = inflight.pop(fut)
                try:
                    records = backend.result(fut)
                except StopRequested:  # this thread was asked to stop (serial: in the task)
                    raise
                except Exception as err:
                    raise TaskFailed(
                        f"task {task.key()} failed ({type(err).__name__}: {err}); reproduce "
                        f"it with {task.hint()}, then the classifier on that run"
                    ) from err
                for rec in records:
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
    """A second Ctrl-C ignored (in the main thread) while a stopped sweep cancels."""
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
"""Target wall time of one CPU batch [s]: a prompt Ctrl-C and checkpoints, yet balanced threads."""

MAX_BATCH = 256
"""Members per CPU batch at most (bounds the memory of one compiled call)."""

GPU_BATCH = 8_192
"""Members per GPU batch: the device's rate comes from many members in flight (on an H200,
0.25-s runs: 64 members took 1.09 s, 8,448 took 1.80 s)."""


@dataclass(frozen=True)
class Engine:
    """Where a sweep's batches of up to ``size`` tasks run: ``device``, ``threads`` numba
    threads here (None: leave it), ``batch_threads`` batches at once, or a GPU ``pipeline``."""

    judge: Judge
    device: str
    size: int
    threads: int | None = None
    batch_threads: int = 1
    pipeline: bool = False

    def pack(self, tasks: tuple) -> Batch:
        return Batch(tasks, self.judge, self.device)

    def config(self, kind: str, code: dict, **fields) -> dict[str, Any]:
        """A sweep's configuration: kind, version, ``fields``, classifier, device, code."""
        judge = self.judge.identity()
        return {"kind": kind, "version": __version__, **fields, "classifier": judge,
                "device": self.device, "code": code}  # fmt: skip


def batch_size(base, num, duration: float, transient: float, threads: int) -> int:
    """Members per CPU batch: about :data:`BATCH_SECONDS` of work on ``threads`` threads."""
    from ..simulation import estimate

    per_run = max(estimate(base, num, duration=duration, transient=transient).seconds, 1e-3)
    n = int(threads * BATCH_SECONDS / per_run)
    return max(threads, min(n, MAX_BATCH))


def resolve_engine(judge: Judge, device: str, base, num, run, workers, scheduler) -> Engine:
    """The engine for ``run`` = (duration, transient): a batch per core, a GPU, or Dask."""
    from ..kernel import GPUFallbackWarning, gpu_status
    from ._backends import local_workers

    if device not in ("cpu", "gpu", "auto"):
        raise SweepError(f"device = {device!r} must be one of cpu, gpu, auto")
    check_scheduler(scheduler)
    threads = None
    if scheduler is None:
        try:
            threads = local_workers(workers)
        except ValueError as err:
            raise SweepError(str(err)) from None
    gpu = scheduler is None and runs_on_gpu(device) and not judge.series
    if device == "gpu" and scheduler is None and not gpu:
        why = "a classifier that reads the series" if judge.series else gpu_status()[1]
        warn(f"GPU backend unavailable: {why}; the sweep runs on the CPU", GPUFallbackWarning)
    if gpu:
        return Engine(judge, "gpu", GPU_BATCH, threads, pipeline=True)
    if scheduler is not None:  # Dask workers: whole batches, on their GPUs when asked
        size = GPU_BATCH if device == "gpu" else batch_size(base, num, *run, 1)
        return Engine(judge, device, size)
    by_batch = threads if threads > 1 else 1
    size = batch_size(base, num, run[0], run[1], 1 if by_batch > 1 else threads)
    return Engine(judge, "cpu", size, None if by_batch > 1 else threads, by_batch)


RECORD_BYTES = 4096
"""Memory of one finished record held by the driver [bytes]."""


def plan_engine(judge, device, runs, base, num, duration, transient, workers, scheduler, *,
                what, reduce, sections, fate=None) -> Engine:  # fmt: skip
    """The engine of a sweep of ``runs`` runs like ``base``, after the budget check: refused past
    memory (a batch per worker, the records), warned past hours or where the (unestimated)
    extensions of undetermined runs could take far longer."""
    from ..simulation import WARN_SECONDS, JobEstimate, check_budget, estimate, human_seconds
    from ._backends import default_workers

    eng = resolve_engine(judge, by_size(device, runs), base, num, (duration, transient),
                         workers, scheduler)  # fmt: skip
    n = default_workers() if workers is None else max(1, int(workers))
    one = estimate(base, num, duration=duration, transient=transient, series=judge.series)
    if fate is not None:
        longer = estimate(base, num, duration=fate, transient=duration)
        one = JobEstimate((max(one.bytes, longer.bytes), one.seconds))
        reduce = f"{reduce}, or the fate horizon"
    kept = estimate(base, num, duration=duration, transient=transient) if sections else None
    memory = one.bytes * n + runs * (RECORD_BYTES + (kept.bytes / 3 if kept else 0.0))
    seconds = one.seconds * runs * (1 + judge.check_step + (fate / duration if fate else 0)) / n
    check_budget(JobEstimate((memory, seconds)), what=what, reduce=reduce,
                 run=dict(params=base, num=num, duration=duration,
                          what="each run of the base model"))  # fmt: skip
    recorded, extend_to = duration - transient, judge.extend_to
    if judge.custom is None and extend_to is not None and recorded < extend_to:
        more = one.seconds * runs / n * (extend_to - recorded) / duration
        if more > max(WARN_SECONDS, 10 * seconds):
            warn(
                f"{what} records {recorded:g} s per run; an undetermined run is extended up "
                f"to {extend_to:g} s recorded, which the time estimate does not count: if "
                f"most are, about {human_seconds(more)} more. Record more per run (duration "
                "- transient) for fewer extensions"
            )
    return eng


@contextlib.contextmanager
def _numba_threads(n: int | None):
    """A context in which numba runs ``n`` threads (None: leave it), restored after."""
    if n is None:
        yield
        return
    import numba

    fork_safe_threads()  # numba's threads start here, fixing the layer: fork-safe first
    before = numba.get_num_threads()
    numba.set_num_threads(max(1, min(int(n), numba.config.NUMBA_NUM_THREADS)))
    try:
        yield
    finally:
        numba.set_num_threads(before)


def check_scheduler(scheduler: Any) -> None:
    """Refuse, before any work, what cannot be a Dask scheduler: neither None, 'local', an
    address nor a client, or an address whose port is not 1..65535 (Dask would try it for 30 s)."""
    from urllib.parse import urlsplit

    if scheduler is None or scheduler == "local" or hasattr(scheduler, "submit"):
        return
    if not isinstance(scheduler, str):
        raise SweepError(
            f"scheduler = {scheduler!r} is not a Dask scheduler: give 'local', the "
            "address of a running one ('tcp://HOST:PORT') or a distributed.Client"
        )
    with contextlib.suppress(ValueError):  # a port out of range, or not a number
        if urlsplit(scheduler if "://" in scheduler else f"tcp://{scheduler}").port != 0:
            return  # a valid port, or none (Dask says so)
    raise SweepError(f"scheduler {scheduler!r}: the port must be a whole number in 1..65535")


def run_plan(plan, eng: Engine, store, *, workers, scheduler, progress: bool, desc: str) -> None:
    """Execute a sweep's plan on its engine's backend."""
    if scheduler is not None:
        try:
            backend = DaskBackend(scheduler, workers)
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
            execute(plan, backend, store, eng, progress=progress, desc=desc, spread=spread)
    finally:
        backend.close()


def run_sweep(plan: Plan, eng: Engine, cls, config: dict[str, Any], build: Callable, *, out,
              resume, force, flush_interval, workers, scheduler, progress, desc: str):  # fmt: skip
    """Lock ``out`` and its companion (None: in memory), open the checkpoint (or read back a
    finished ``cls`` of this ``config`` under ``resume``), run the plan, ``build`` and write."""
    out = None if out is None else Path(out)
    outputs = None if out is None else [out, companion(out, cls._tables[1])]
    if progress is None:
        progress = bool(getattr(sys.stderr, "isatty", lambda: False)())
    with contextlib.nullcontext() if out is None else lock_all(outputs):
        store, reuse = open_store(outputs, config, resume, flush_interval, force)
        if reuse:
            try:
                result = cls.read(out)
            except (OSError, ValueError) as err:  # pyarrow's errors are among them
                raise SweepError(
                    f"{out} is this configuration's finished run, but it or its companion "
                    f"cannot be read back ({err}); pass --force without --resume (force=True "
                    "in Python) to compute it again"
                ) from None
            if progress:
                print(f"already finished: {out} (same configuration); read, nothing run",
                      file=sys.stderr)  # fmt: skip
            return result
        # Outputs there now are this configuration's or --force's; one appearing later is kept.
        replace = force or (out is not None and any(p.exists() for p in outputs))
        try:
            run_plan(plan, eng, store, workers=workers, scheduler=scheduler,
                     progress=bool(progress), desc=desc)  # fmt: skip
            return _finish(plan, store, out, build, replace)
        except OSError as err:  # a full disk: say what is kept, and where
            if out is None or err.errno not in SAVE_ERRNOS:
                raise  # not a failure to save (a lost connection, a file that appeared)
            kept = (
                f"the runs finished and saved so far are kept in {store.path}: fix the cause "
                "(free space) and run the same command with --resume"
                if store.path.is_dir() else "nothing was saved: fix the cause (free space) "
                "and run the command again"
            )  # fmt: skip
            raise type(err)(
                err.errno,
                f"{err.strerror or err} while saving the results of {out}"
                + (f" ({err.filename})" if err.filename else "")
                + f"; {kept}",
            ) from None
        except Exception:
            # A run that finished nothing keeps no checkpoint (it would block the fixed command).
            if next(iter(store.records()), None) is None:
                store.remove()
            raise


SAVE_ERRNOS = frozenset({errno.ENOSPC, errno.EDQUOT, errno.EIO, errno.EROFS})
"""The errors of a disk that takes no more (full, over quota, failing, read-only)."""


def _finish(plan: Plan, store, out: Path | None, build: Callable, replace: bool):
    """The result from the finished records, written to ``out`` (its checkpoint removed)."""
    try:
        records = _unique_sorted(store.records(), plan.keys)
        counts = Counter(m for r in records for m in filter(None, r["warnings"].split(" | ")))
        for msg, n in counts.items():  # once per message (each row has its own)
            warn(f"{n} of {len(records)} runs: {msg}")
        result = build(records)
        if out is not None:
            result._write(out, replace=replace)
            store.remove()
    except KeyboardInterrupt:
        if out is None:  # else every record is in the checkpoint: a resume writes the tables
            raise
        raise SweepInterrupted(plan.total, plan.total, store.path) from None
    return result


def _unique_sorted(records, keys: tuple[str, ...]) -> list[dict]:
    """Records sorted by key, one per key (a duplicate must equal the first, as JSON)."""
    seen: dict[tuple, dict] = {}
    for r in records:
        k = tuple(r[f] for f in keys)
        if k in seen:
            if json.dumps(seen[k], sort_keys=True) != json.dumps(r, sort_keys=True):
                raise SweepError(f"two different records for {dict(zip(keys, k, strict=True))}")
            continue
        seen[k] = r
    return [seen[k] for k in sorted(seen)]
