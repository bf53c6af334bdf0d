"""The options the run-making commands share, and how a sweep's outcome becomes an exit code."""

from __future__ import annotations

import argparse
import sys
from pathlib import Path


def path_arg(text: str) -> Path:
    """The argparse type of every file argument: an empty text (the current folder) is refused."""
    if not text.strip():
        raise argparse.ArgumentTypeError("an empty path: give a file name")
    return Path(text)


def add_run_options(p, *, transient: float | None) -> None:
    """``--set``, ``--duration``, ``--transient`` (default ``transient`` [s]; None: half the
    duration) and ``--seed`` on parser ``p``."""
    p.add_argument(
        "--set",
        action="append",
        metavar="NAME=VALUE",
        default=[],
        help="override a model parameter or numerics setting (repeatable), e.g. --set "
        "omega=30 or --set dt=1e-6; `chaoscam params` lists them",
    )
    p.add_argument("--duration", type=float, default=20.0, help="simulated time [s] (default 20)")
    shown = "half the duration" if transient is None else f"{transient:g}"
    p.add_argument(
        "--transient", type=float, default=transient, help=f"discarded start [s] (default: {shown})"
    )
    p.add_argument("--seed", type=int, default=0, help="master seed of the line-length process")


def add_sweep_options(p) -> None:
    """The run options, how a sweep (or ensemble) judges and runs them, and its outputs."""
    add_run_options(p, transient=None)
    p.add_argument(
        "--lyapunov",
        action="store_true",
        help="also record each run's tangent Lyapunov spectrum (lambda_1 with its standard "
        "error, lambda_2; 1/s): a regime map's per-cell top exponent",
    )
    p.add_argument(
        "--check-step",
        action="store_true",
        help="judge each run at dt/2 too; a changed verdict becomes undetermined",
    )
    p.add_argument(
        "--classifier",
        metavar="MODULE:NAME",
        help="a classifier of one's own instead of chaoscam.classify: a function, or a class "
        "instantiated without arguments, taking one run (a chaoscam.Solution)",
    )
    p.add_argument(
        "--workers",
        type=int,
        help="threads, one batch each (default: every core); with --scheduler local, the "
        "local Dask cluster's workers",
    )
    p.add_argument(
        "--device",
        choices=("cpu", "gpu", "auto"),
        default="cpu",
        help="where the batches run (gpu: NVIDIA, numba-cuda; equal to the CPU only within "
        "GPU_TOLERANCE; auto: the GPU where one runs and there are 4,096 runs or more); "
        "default cpu",
    )
    p.add_argument(
        "--scheduler",
        metavar="ADDRESS",
        help="run on Dask: tcp://HOST:PORT of a running scheduler, or 'local' for a local "
        "cluster on 127.0.0.1",
    )
    p.add_argument(
        "--resume",
        action="store_true",
        help="finish an interrupted run of the same command from its checkpoint",
    )
    p.add_argument(
        "--checkpoint-interval",
        type=float,
        default=1.0,
        metavar="S",
        help="seconds between checkpoint writes (default 1; 0 = after every run)",
    )
    p.add_argument("--quiet", action="store_true", help="no progress bar")
    p.add_argument(
        "--force",
        action="store_true",
        help="start over: replace the outputs, discard a checkpoint",
    )
    p.add_argument("--out", type=path_arg, required=True, help="output FILE.parquet")


def sweep_settings(args) -> dict:
    """The keyword arguments of :func:`add_sweep_options`' own options, checked."""
    import math

    from . import UsageError

    classify = None
    if args.classifier is not None:
        from ..sweep import load_classifier

        try:
            classify = load_classifier(args.classifier)
        except (ValueError, ImportError, AttributeError) as err:
            raise UsageError(f"--classifier {args.classifier}: {err}") from None
    if args.workers is not None and args.workers < 1:
        raise UsageError(f"--workers {args.workers}: must be >= 1")
    if args.scheduler not in (None, "local") and args.workers is not None:
        raise UsageError("--workers applies to local runs and --scheduler local only")
    if args.out.suffix != ".parquet":
        raise UsageError(f"--out {args.out}: the output must end in .parquet")
    if not (math.isfinite(args.checkpoint_interval) and args.checkpoint_interval >= 0):
        raise UsageError(
            f"--checkpoint-interval {args.checkpoint_interval}: must be a finite number >= 0"
        )
    if args.force and args.resume:
        raise UsageError("--force starts over and --resume continues: give one of them")
    return dict(
        classify=classify, lyapunov=args.lyapunov, check_step=args.check_step,
        workers=args.workers, device=args.device, scheduler=args.scheduler, out=args.out,
        resume=args.resume, progress=not args.quiet, flush_interval=args.checkpoint_interval,
        force=args.force,
    )  # fmt: skip


def run_sweep(fn, *args, **kwargs):
    """``fn(*args, **kwargs)``; a stopped sweep says how to go on and returns its exit code (130
    a Ctrl-C, 1 a lost Dask scheduler or a failed task)."""
    from ..sweep import SweepInterrupted, TaskFailed
    from . import stop_word

    try:
        return fn(*args, **kwargs)
    except TaskFailed as err:
        print(f"chaoscam: error: {err}", file=sys.stderr)
        return 1
    except SweepInterrupted as err:
        print(f"chaoscam: {err.describe(stop_word())}", file=sys.stderr)
        return 130 if err.cause is None else 1


def counts(labels) -> str:
    """``"chaotic 3, periodic 5"``: each value of a column with its count, in order."""
    return ", ".join(f"{k} {v}" for k, v in labels.value_counts().sort_index().items())
