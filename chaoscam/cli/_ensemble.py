"""``chaoscam ensemble``: many realizations of one model, their sections and verdicts.

A thin layer over :func:`chaoscam.ensemble`, a plan of the one sweep engine: the members run
in batches (the CPU's threads, a GPU or Dask), each finished record is checkpointed beside
the output (``FILE.parquet.ckpt/``), an interrupted run resumes with ``--resume`` to the same
tables, and the output is locked against a second process.
"""

from __future__ import annotations

import argparse
import sys

from ._options import (
    add_engine_options,
    add_run_options,
    add_sweep_options,
    engine_settings,
    sweep_settings,
)

__all__ = ["register"]


def register(sub) -> None:
    p = sub.add_parser(
        "ensemble",
        help="simulate many realizations in parallel (CPU or GPU), keep sections and labels",
        description="Simulate realizations FIRST .. FIRST+MEMBERS-1 of one model in batches "
        "(threads over the cores, one CUDA thread each on a GPU, or Dask) and write one row "
        "per member (status, impact count, verdict with --classify) to FILE.parquet and "
        "their stroboscopic sections to FILE.sections.parquet. Interrupted runs resume with "
        "--resume.",
    )
    p.add_argument("--members", type=int, required=True, help="number of realizations")
    p.add_argument("--first", type=int, default=0, help="first realization index (default 0)")
    add_run_options(p, transient=None)
    p.add_argument("--classify", action="store_true", help="judge each member (its verdict)")
    add_engine_options(p)
    add_sweep_options(p)
    p.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    from ..sweep import SweepError, SweepInterrupted, TaskFailed, companion, ensemble
    from . import UsageError, parse_assignments, stop_word

    params, numerics = parse_assignments(args.set)
    engine = engine_settings(args)
    if not args.classify and (engine["lyapunov"] or engine["check_step"] or engine["classify"]):
        raise UsageError("--lyapunov, --check-step and --classifier judge members: add --classify")
    classify = engine.pop("classify") or args.classify
    try:
        res = ensemble(
            params, numerics, members=args.members, first=args.first, seed=args.seed,
            duration=args.duration, transient=args.transient, classify=classify,
            **engine, **sweep_settings(args),
        )  # fmt: skip
    except SweepError as err:
        raise UsageError(str(err)) from None
    except TaskFailed as err:
        print(f"chaoscam: error: {err}", file=sys.stderr)
        return 1
    except SweepInterrupted as err:
        print(f"chaoscam: {err.describe(stop_word())}", file=sys.stderr)
        return 130 if err.cause is None else 1
    _say_identical(params, args.members)
    m = res.members
    counts = m["label" if args.classify else "status"].value_counts().to_dict()
    print(
        f"{len(m)} members: " + ", ".join(f"{k} {v}" for k, v in sorted(counts.items()))
        + f"\nmembers: {args.out}\nsections: {companion(args.out, 'sections')}"
    )  # fmt: skip
    return 0


def _say_identical(params, members: int) -> None:
    """Say, once, when the members are all the same run: an index draws only line lengths,
    which change nothing with ``l_lambda_sigma = 0`` or the fractal stiffness (with the
    runs' own warnings, at the end)."""
    from ..model import realizations_identical
    from . import show_warning

    if members > 1 and realizations_identical(params):
        why = (
            "l_lambda_sigma = 0"
            if params.l_lambda_sigma == 0.0
            else "the fractal stiffness does not depend on the line length"
        )
        show_warning(
            f"{why}: every member is the same deterministic run (an index draws only line "
            "lengths); one member is enough"
        )
