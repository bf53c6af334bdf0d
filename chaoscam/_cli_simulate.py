"""``chaoscam simulate``: one trajectory, a short summary, optional files."""

from __future__ import annotations

import argparse
from pathlib import Path

__all__ = ["register"]


def register(sub) -> None:
    p = sub.add_parser(
        "simulate",
        help="simulate one trajectory and print a summary",
        description="Simulate one realization of the cam-follower model (RK4 with located "
        "impacts) and print a summary: impacts, contact fraction, status.",
    )
    p.add_argument("--duration", type=float, default=20.0, help="end time [s] (default 20)")
    p.add_argument("--transient", type=float, default=0.0, help="discarded start [s]")
    p.add_argument(
        "--set", action="append", metavar="NAME=VALUE", default=[],
        help="override a model parameter (repeatable), e.g. --set omega=30",
    )
    p.add_argument("--seed", type=int, default=0, help="seed of the line-length process")
    p.add_argument("--index", type=int, default=0, help="realization index under the seed")
    p.add_argument("--output-dt", type=float, default=1e-3, help="series sampling [s]")
    p.add_argument("--out", type=Path, help="time series to FILE.parquet or FILE.csv")
    p.add_argument("--section", type=Path, help="stroboscopic section to FILE.csv")
    p.add_argument("--impacts", type=Path, help="impact list to FILE.csv")
    p.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    from .cli import UsageError, parse_assignments
    from .simulate import simulate

    if args.out is not None and args.out.suffix not in (".parquet", ".csv"):
        raise UsageError(f"--out {args.out}: the file must end in .parquet or .csv")
    params = parse_assignments(args.set)
    traj = simulate(
        params,
        duration=args.duration,
        transient=args.transient,
        seed=args.seed,
        index=args.index,
        series=args.out is not None,
        output_dt=args.output_dt,
    )
    print(traj.summary())
    if args.out is not None:
        if args.out.suffix == ".parquet":
            traj.to_parquet(args.out)
        else:
            traj.series.to_csv(args.out, index=False)
        print(f"series: {args.out}")
    if args.section is not None:
        traj.section.to_csv(args.section, index=False)
        print(f"section: {args.section}")
    if args.impacts is not None:
        traj.impacts.to_csv(args.impacts, index=False)
        print(f"impacts: {args.impacts}")
    return 0
