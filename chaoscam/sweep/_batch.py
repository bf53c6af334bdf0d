"""The ensemble engine of the sweeps: many realizations in one compiled call.

A :class:`BatchTask` packs a sweep's tasks (:class:`~._tasks.RealizationTask`,
:class:`~._tasks.BranchTask`) and runs them through
:func:`chaoscam.integrate.simulate_ensemble` (numba threads over the cores; a Dask worker
runs a whole batch) with the tangent dynamics, then labels each member from its section and
stroboscopic Jacobians (:func:`chaoscam.classify_ensemble`: section structure, tangent
exponent, n-band chaos, periodic-orbit certificate). Each task's record is built by the task
itself (``task.record``), so it has the same fields as on the process engine. The two
phases, running and labelling, live in :mod:`._batch_run`.

Bit-identity: an ensemble member equals ``simulate(params, seed=seed, index=sim_index)``
bit for bit, and its verdict uses its own arrays only, so a record does not depend on the
batch it ran in, the thread count or an interruption.
"""

from __future__ import annotations

import errno
import sys
import warnings
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from ..model import Params
from ._batch_run import Launched, _fates, label_batch, launch_batch, run_batch  # noqa: F401

__all__ = ["ENGINE_CLASSIFIER", "BatchTask", "batch_size", "run_batch", "run_sweep"]

ENGINE_CLASSIFIER = "chaoscam.classify_ensemble(section + tangent exponent)"
"""The classifier identity a sweep records when it runs on the ensemble engine."""

BATCH_SECONDS = 2.0
"""Target wall time of one batch [s]: short enough for a prompt Ctrl-C and frequent
checkpoints, long enough that every thread has several members to balance."""

MAX_BATCH = 256
"""Members per batch at most (bounds the memory of one compiled call)."""

GPU_MAP_BATCH = 8_192
"""Members per batch when a sweep's batches run on a GPU (each member one CUDA thread; on Dask,
with ``device="gpu"``, every worker's batch: a CPU-sized batch of ~100 members held a GPU
for as long as one member's run, a lone thread simulating about 0.23 s a second). One
thread is slow and the device's rate comes from many in flight (measured on an H200,
2026-11-27, 0.25-s runs: 64 members took 1.09 s of launch, 8,448 took 1.80 s, a full wave of
33,792 took 5.1 s; a 1,024-run regime map of 20 s with the tangent took 132 s, as fast as 2
CPU cores), so batches must be large. 8,192, a quarter of an H200's wave (at 0.71 of a
wave's rate a member), keeps a checkpoint every few minutes and the host's labels of a
batch (8 ms a member in that map, its extension included; on this machine now about 2.8 ms
a random member, verdict and record) near a minute, which the next batch's launch overlaps
(:class:`._pipeline.PipelineBackend`). A Ctrl-C is answered when the launch under way
returns."""


def batch_size(base: Params, duration: float, transient: float, threads: int) -> int:
    """Members per batch: about :data:`BATCH_SECONDS` of work on ``threads`` threads, from
    the run-time estimate of :func:`chaoscam._budget.estimate` (at least one per thread)."""
    from .._budget import estimate

    per_run = max(estimate(base, duration=duration, transient=transient).seconds, 1e-3)
    n = int(threads * BATCH_SECONDS / per_run)
    return max(threads, min(n, MAX_BATCH))


@dataclass(frozen=True)
class BatchTask:
    """Several sweep tasks run as one ensemble; ``run`` returns their records in order."""

    tasks: tuple[Any, ...]
    backend: str = "cpu"
    extend_to: float | None = 120.0

    def key(self) -> tuple[int, int]:
        return self.tasks[0].key()

    def hint(self) -> str:
        return f"a batch of {len(self.tasks)} runs from {self.tasks[0].key()}: " + ", ".join(
            t.hint() for t in self.tasks[:3]
        )

    def run(self) -> list[dict[str, Any]]:
        return run_batch(self.tasks, self.backend, self.extend_to)

    def launch(self) -> list[Launched]:
        """The first phase of :meth:`run`: the members run (:func:`._batch_run.launch_batch`)."""
        return launch_batch(self.tasks, self.backend, self.extend_to)

    def label(self, launched: list[Launched]) -> list[dict[str, Any]]:
        """The second phase: their records from what :meth:`launch` gave."""
        return label_batch(self.tasks, launched, self.extend_to)


ENGINES = ("auto", "ensemble", "process")
"""How a sweep runs its realizations: ``"ensemble"`` (batches through the compiled
ensemble call, labelled by :func:`chaoscam.classify_ensemble`), ``"process"`` (one task per
realization in worker processes, classified from its trajectory by any classifier), or
``"auto"``: the ensemble engine for the default classifier and the RK4 integrator, else the
process engine."""


@dataclass(frozen=True)
class Engine:
    """A sweep's resolved engine: its name, the classifier identity it records, and how
    the driver runs it (``pack``/``pack_size`` for :func:`._engine.execute`, ``threads``
    numba threads in this process when local, ``task_threads`` > 1: that many batches at
    once on the threads of a :class:`._backends.ThreadBackend`; ``pipeline``: a local GPU's
    batches, launched while the last is labelled, :class:`._pipeline.PipelineBackend`)."""

    name: str
    identity: str
    pack: Any = None
    pack_size: int = 1
    threads: int | None = None
    task_threads: int = 1
    pipeline: bool = False


def resolve_engine(
    engine: str,
    device: str,
    classify: Any,
    identity: str,
    base: Params,
    run: tuple[float, float],
    workers: int | None,
    scheduler: Any,
) -> Engine:
    """The engine a sweep runs on (see :data:`ENGINES`) for ``classify`` (identity
    ``identity``), the model ``base`` and ``run`` = (duration, transient) [s]; SweepError
    for a bad choice."""
    from ._backends import local_workers
    from ._grid import SweepError
    from ._tasks import DefaultClassifier

    if engine not in ENGINES:
        raise SweepError(f"engine = {engine!r} must be one of {', '.join(ENGINES)}")
    if device not in ("cpu", "gpu", "auto"):
        raise SweepError(f"device = {device!r} must be one of cpu, gpu, auto")
    default = (
        isinstance(classify, DefaultClassifier)
        and classify.needs_tangent
        and not classify.check_step
    )
    if engine == "auto":
        engine = "ensemble" if default and base.integrator == "rk4" else "process"
    if engine == "process":
        if device != "cpu":
            raise SweepError(
                "device (--device) applies to engine='ensemble' (--engine ensemble) only"
            )
        return Engine("process", identity)
    if not default:
        raise SweepError(
            "engine='ensemble' (--engine ensemble) labels members from their sections and "
            "tangent exponents (chaoscam.classify_ensemble): it takes the default classifier, "
            "without lyapunov or check_step (--lyapunov, --check-step); use engine='process' "
            "(--engine process) for another classifier"
        )
    if base.integrator != "rk4":
        raise SweepError(
            "engine='ensemble' (--engine ensemble) runs the fixed-step RK4 integrator "
            "(integrator = 'rk4'); use engine='process' (--engine process) for the adaptive one"
        )
    threads = None
    if scheduler is None:
        try:
            threads = local_workers(workers)
        except ValueError as err:
            raise SweepError(str(err)) from None
    from ..integrate._gpu import runs_on_gpu

    # Local CPU batches run one per thread, each a batch's work on one core (a GPU batch
    # fills its device; a Dask worker runs numba threads over its own cores). Without a GPU
    # here, device="gpu" or "auto" runs the CPU's batches.
    gpu = scheduler is None and runs_on_gpu(device)
    by_task = threads if threads is not None and threads > 1 and not gpu else 1
    size = batch_size(base, run[0], run[1], 1 if by_task > 1 else threads or 1)

    extend_to = classify.extend_to

    # Locally, the backend that will run, said once here rather than in every record; a
    # Dask scheduler's workers decide for themselves.
    backend = device if scheduler is not None else ("gpu" if gpu else "cpu")
    if device == "gpu" and backend == "cpu":
        from ..integrate._gpu import GPUFallbackWarning, gpu_status

        reason = gpu_status()[1]
        warnings.warn(
            f"GPU backend unavailable: {reason}; the sweep runs on the CPU",
            GPUFallbackWarning,
            stacklevel=4,
        )

    def pack(tasks: tuple) -> BatchTask:
        return BatchTask(tasks, backend, extend_to)

    identity = f"{ENGINE_CLASSIFIER}, extend_to={extend_to}"
    if gpu:
        return Engine("ensemble", identity, pack, GPU_MAP_BATCH, threads, pipeline=True)
    if scheduler is not None and device == "gpu":  # Dask workers' GPUs: batches they can fill
        return Engine("ensemble", identity, pack, GPU_MAP_BATCH)
    if by_task > 1:
        return Engine("ensemble", identity, pack, size, None, by_task)
    return Engine("ensemble", identity, pack, size, threads)


def engine_device(eng: Engine, device: str) -> str:
    """Where a sweep's realizations run: "gpu" when the ensemble engine was asked for a GPU
    ("gpu" or "auto") and one can run here (else the CPU path runs them, see
    :func:`chaoscam.integrate._gpu.gpu_status`), otherwise "cpu". Recorded in the
    configuration: a GPU's results equal the CPU's only within ``GPU_TOLERANCE``."""
    from ..integrate._gpu import runs_on_gpu

    return "gpu" if eng.name == "ensemble" and runs_on_gpu(device) else "cpu"


def sweep_engine(
    classify,
    lyapunov: bool,
    check_step: bool,
    engine: str,
    device: str,
    base: Params,
    run: tuple[float, float],
    workers,
    scheduler,
):
    """(classifier, engine, series?) of a sweep: the classifier resolved
    (:func:`._common.resolve_classifier`), its engine (:func:`resolve_engine`), and whether
    its runs keep a series (only the process engine's, for a classifier that asks)."""
    from ._common import resolve_classifier
    from ._tasks import needs_series

    classify, identity = resolve_classifier(classify, lyapunov, check_step)
    eng = resolve_engine(engine, device, classify, identity, base, run, workers, scheduler)
    return classify, eng, eng.name == "process" and needs_series(classify)


def numba_threads(n: int | None):
    """A context in which numba runs ``n`` threads (None: leave it), restored after."""
    import contextlib

    if n is None:
        return contextlib.nullcontext()

    @contextlib.contextmanager
    def scope():
        import numba

        from ..integrate._driver import fork_safe_threads

        fork_safe_threads()  # numba's threads start here, fixing the layer: fork-safe first
        before = numba.get_num_threads()
        numba.set_num_threads(max(1, min(int(n), numba.config.NUMBA_NUM_THREADS)))
        try:
            yield
        finally:
            numba.set_num_threads(before)

    return scope()


def run_plan(plan, eng: Engine, store, *, workers, scheduler, progress: bool, desc: str) -> None:
    """Execute a sweep's plan on its engine: the ensemble engine in this process, one batch
    per thread on ``eng.task_threads`` threads or one batch at a time on ``eng.threads``
    numba threads (a GPU's: launched while the last is labelled; or its batches on Dask),
    the process engine on a pool of ``workers`` processes (or Dask)."""
    from ._backends import SerialBackend, ThreadBackend
    from ._common import backend_for
    from ._engine import execute
    from ._pipeline import PipelineBackend

    if eng.name == "ensemble" and scheduler is None and eng.pipeline:
        backend = PipelineBackend(eng.threads)
    elif eng.name == "ensemble" and scheduler is None:
        backend = ThreadBackend(eng.task_threads) if eng.task_threads > 1 else SerialBackend()
    else:
        backend = backend_for(workers, scheduler)
    try:
        with numba_threads(eng.threads):
            execute(
                plan,
                backend,
                store,
                progress=progress,
                desc=desc,
                pack=eng.pack,
                pack_size=eng.pack_size,
                spread=eng.task_threads if isinstance(backend, ThreadBackend) else 1,
            )
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
    from ._grid import SweepError

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
    from ._engine import SweepInterrupted

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
