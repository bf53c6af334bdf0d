"""``chaoscam ensemble``: many realizations of one model (:func:`chaoscam.ensemble`)."""

from __future__ import annotations

import argparse

from ._options import add_sweep_options, counts, run_sweep, sweep_settings


def register(sub) -> None:
    p = sub.add_parser(
        "ensemble",
        help="simulate many realizations in parallel (CPU or GPU), keep sections and labels",
        description="Simulate realizations FIRST .. FIRST+MEMBERS-1 of one model in batches "
        "(threads over the cores, one CUDA thread each on a GPU, or Dask) and write one row "
        "per member (status, impact count, verdict with --classify) to FILE.parquet and "
        "their stroboscopic sections to FILE.sections.parquet.",
    )
    p.add_argument("--members", type=int, required=True, help="number of realizations")
    p.add_argument("--first", type=int, default=0, help="first realization index (default 0)")
    p.add_argument("--classify", action="store_true", help="judge each member (its verdict)")
    add_sweep_options(p)
    p.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    from ..sweep import companion, ensemble
    from . import UsageError, parse_assignments

    params, numerics = parse_assignments(args.set)
    settings = sweep_settings(args)
    if not args.classify and (args.lyapunov or args.check_step or settings["classify"]):
        raise UsageError("--lyapunov, --check-step and --classifier judge members: add --classify")
    settings["classify"] = settings["classify"] or args.classify
    res = run_sweep(
        ensemble, params, numerics, members=args.members, first=args.first, seed=args.seed,
        duration=args.duration, transient=args.transient, **settings,
    )  # fmt: skip
    if isinstance(res, int):
        return res
    _say_identical(params, args.members)
    m = res.members
    print(
        f"{len(m)} members: {counts(m['label' if args.classify else 'status'])}"
        f"\nmembers: {args.out}\nsections: {companion(args.out, 'sections')}"
    )
    return 0


def _say_identical(params, members: int) -> None:
    """Say once, at the end, when the members are all the same run."""
    from ..model import realizations_identical
    from . import show_warning

    if members < 2 or not realizations_identical(params):
        return
    why = "the fractal stiffness does not depend on the line length"
    if params.l_lambda_sigma == 0.0:
        why = "l_lambda_sigma = 0"
    show_warning(
        f"{why}: every member is the same deterministic run (an index draws only line lengths); "
        "one member is enough"
    )
