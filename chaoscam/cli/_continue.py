"""``chaoscam continue``: follow a periodic orbit in one parameter (thin over
:func:`chaoscam.continuation.continuation`)."""

from __future__ import annotations

import argparse

from ._options import path_arg


def register(sub) -> None:
    p = sub.add_parser(
        "continue",
        help="follow a period-n orbit in one parameter (pseudo-arclength) and its bifurcations",
        description="Follow a period-n orbit of the stroboscopic map from --from to --to in "
        "one model parameter by pseudo-arclength continuation through the impacts, with its "
        "Floquet multipliers, impacts and sticking, and locate the folds, period doublings "
        "and changes of the impact pattern on it. Writes the points to FILE.parquet and the "
        "events to FILE.events.parquet. docs/continuation.md describes the method.",
    )
    p.add_argument("--param", default="omega", metavar="NAME", help="the followed parameter")
    p.add_argument("--from", dest="start", type=float, required=True, help="its start value")
    p.add_argument("--to", type=float, required=True, help="the value to follow it to")
    p.add_argument("--period", type=int, default=1, help="n, in cam periods (default 1)")
    p.add_argument(
        "--set",
        action="append",
        metavar="NAME=VALUE",
        default=[],
        help="override a model parameter or numerics setting (repeatable), e.g. --set xi=0.1",
    )
    p.add_argument(
        "--x0",
        type=float,
        nargs=2,
        metavar=("THETA_F", "OMEGA_F"),
        help="start Newton here (rad, rad/s at t = 0); default: the last section point of a "
        "--transient run from the model's initial state",
    )
    p.add_argument("--transient", type=float, default=20.0, help="start run [s] (default 20)")
    p.add_argument("--switch", action="store_true", help="follow the period-2n branch "
                   "from each period doubling too")  # fmt: skip
    p.add_argument("--max-points", type=int, default=500, help="most points (default 500)")
    p.add_argument("--force", action="store_true", help="replace existing output files")
    p.add_argument("--out", type=path_arg, required=True, help="output FILE.parquet")
    p.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    from ..continuation import NoOrbitError, continuation, events_path
    from ..io import check_output, lock_all
    from . import UsageError, parse_assignments

    out = check_output(args.out, force=args.force, suffixes=(".parquet",))
    events = check_output(events_path(out), flag="--out (its events)", force=args.force)
    if any(item.partition("=")[0].strip() == args.param for item in args.set):
        raise UsageError(f"--set {args.param}=...: --from gives the start of {args.param}")
    params, numerics = parse_assignments([*args.set, f"{args.param}={args.start!r}"])
    with lock_all([out, events]):
        try:
            branch = continuation(params, args.x0, param=args.param, to=args.to,
                                  period=args.period, numerics=numerics, switch=args.switch,
                                  max_points=args.max_points, transient=args.transient)  # fmt: skip
        except NoOrbitError as err:
            raise UsageError(str(err)) from None
        branch.to_parquet(out, replace=args.force)
    ev = branch.events
    for row in ev.itertuples():
        note = f" ({row.detail})" if row.detail else ""
        print(f"branch {row.branch}: {row.kind} at {args.param} = {row.value:.8g}{note}")
    n = branch.points.groupby("branch")["point"].nunique().sum()
    print(f"points: {out} ({n} orbits); events: {events}")
    return 0
