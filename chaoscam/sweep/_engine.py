"""The loop every sweep runs: submit tasks, collect records, checkpoint, follow up.

A *plan* decides which tasks exist (a regime map's realizations, a bifurcation diagram's
values); the engine feeds them to a backend with a bounded number in flight (so memory does
not grow with the grid), stores each record as it completes, and asks the plan for
follow-up tasks (continuation to the next value, more realizations for an adaptive cell).
Plans decide from finished records only, never from their completion order, so the set of
records is the same for any backend and worker count.
"""

from __future__ import annotations

import sys
from collections import Counter, deque
from collections.abc import Iterator
from typing import Any, Protocol

from ..integrate._driver import StopRequested, check_stop, stops_here
from ._backends import BackendLost, SerialBackend, WorkerLost
from ._grid import SweepError
from ._tasks import run_task

__all__ = ["SweepInterrupted", "TaskFailed", "execute"]

MAX_RETRIES = 3
"""Times a task may lose its worker before the run stops with an error."""

STOP_POLL_S = 0.1
"""How often [s] a sweep whose thread can be asked to stop (inside
:func:`chaoscam.integrate._driver.stop_on`: a sweep run beside another,
:func:`chaoscam.experiments._side_by_side.beside`) looks whether it was, while it waits for
its tasks. Only the main thread gets Ctrl-C; another thread learns of it this way."""


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
                inflight[backend.submit(run_task, task)] = task
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
        backend.cancel(list(inflight))
        store.flush()  # a record stored but not yet counted by the plan is saved too
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
