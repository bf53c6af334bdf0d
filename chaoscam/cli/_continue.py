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
    p.add_argument("--no-switch", dest="switch", action="store_false",
                   help="do not follow the period-2n branch from each period doubling")  # fmt: skip
    p.add_argument("--max-points", type=int, default=500, help="most points (default 500)")
    p.add_argument("--curve", metavar="NAME", help="continue each fold and period doubling of "
                   "the branch in (--param, NAME) too, into FILE.curves.parquet")  # fmt: skip
    p.add_argument("--curve-to", type=float, metavar="VALUE", help="follow NAME to this value")
    p.add_argument("--force", action="store_true", help="replace existing output files")
    p.add_argument("--resume", action="store_true", help="follow an interrupted branch on from "
                   "its checkpoint FILE.parquet.ckpt")  # fmt: skip
    p.add_argument("--out", type=path_arg, required=True, help="output FILE.parquet")
    p.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    from ..continuation import NoOrbitError, continuation, events_path
    from ..io import check_output, lock_all
    from . import UsageError, parse_assignments

    if args.force and args.resume:
        raise UsageError("--force starts over and --resume continues: give one of them")
    if (args.curve is None) != (args.curve_to is None):
        raise UsageError("--curve NAME and --curve-to VALUE go together")
    force = args.force or args.resume
    out = check_output(args.out, force=force, suffixes=(".parquet",))
    paths = [out, events_path(out)]
    curves_out = out.with_name(f"{out.stem}.curves.parquet")
    paths += [curves_out, events_path(curves_out)] if args.curve else []
    for path in paths[1:]:
        check_output(path, flag="--out (its events, curves)", force=force)
    ckpt = out.with_name(out.name + ".ckpt")
    if any(item.partition("=")[0].strip() == args.param for item in args.set):
        raise UsageError(f"--set {args.param}=...: --from gives the start of {args.param}")
    params, numerics = parse_assignments([*args.set, f"{args.param}={args.start!r}"])
    with lock_all(paths):
        if ckpt.exists() and not args.resume:
            if not args.force:
                raise UsageError(f"{ckpt}: an interrupted branch; pass --resume to follow it "
                                 "on, or --force to start over")  # fmt: skip
            ckpt.unlink()
        try:
            branch = continuation(params, args.x0, param=args.param, to=args.to,
                                  period=args.period, numerics=numerics, switch=args.switch,
                                  max_points=args.max_points, transient=args.transient,
                                  checkpoint=ckpt)  # fmt: skip
            curves = _curves(branch, params, numerics, args) if args.curve else None
        except (NoOrbitError, ValueError) as err:
            raise UsageError(str(err)) from None
        branch.to_parquet(out, replace=force)
        if curves is not None:
            curves.to_parquet(curves_out, replace=force)
    ev = branch.events
    for row in ev.itertuples():
        note = f" ({row.detail})" if row.detail else ""
        print(f"branch {row.branch}: {row.kind} at {args.param} = {row.value:.8g}{note}")
    n = branch.points.groupby("branch")["point"].nunique().sum()
    print(f"points: {out} ({n} orbits); events: {paths[1]}")
    if curves is not None:
        for row in curves.events.itertuples():
            print(f"curve {row.curve}: {row.kind} at ({args.param}, {args.curve}) = "
                  f"({row.value:.8g}, {row.value2:.8g}) {row.detail}")  # fmt: skip
        print(f"curves: {curves_out} ({len(curves.points)} points); events: {paths[3]}")
    return 0


def _curves(branch, params, numerics, args):
    """Each fold and period doubling of branch 0 continued in (--param, --curve), as one
    Curve whose ``curve`` column numbers them."""
    import pandas as pd

    from ..continuation import CURVE_KINDS, Curve, curve

    ev = branch.events
    starts = ev[(ev.branch == 0) & ev.kind.isin(list(CURVE_KINDS))]
    found = [curve(params.replace(**{args.param: row.value}), row, second=args.curve,
                   to=args.curve_to, period=args.period, numerics=numerics)
             for _, row in starts.iterrows()]  # fmt: skip
    frames = [(c.points.assign(curve=i), c.events.assign(curve=i)) for i, c in enumerate(found)]
    if not frames:
        return Curve(pd.DataFrame(columns=["curve"]), pd.DataFrame(columns=["curve"]), {})
    pts, evs = (pd.concat(f, ignore_index=True) for f in zip(*frames, strict=True))
    return Curve(pts, evs, {"curves": [c.settings for c in found]})
