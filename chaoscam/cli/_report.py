"""``chaoscam report`` and ``chaoscam paper``: thin layers over the report API."""

from __future__ import annotations

import argparse
import shlex
import sys
from pathlib import Path

from ._options import path_arg

DEFAULT_PAPER = Path("out/paper.html")  # git ignores out/; reports/paper.html only when named


def register(sub) -> None:
    r = sub.add_parser(
        "report",
        help="one self-contained HTML report from trajectories, bifurcations, regime maps, "
        "ensembles",
        description="Read chaoscam outputs (simulate --out, bifurcation --out, regime-map "
        "--out, ensemble --out; .parquet) and write one HTML file with every figure inline: it "
        "opens from disk and refers to no network address.",
    )
    r.add_argument("inputs", nargs="+", metavar="INPUT", help="chaoscam .parquet outputs")
    r.add_argument("--out", type=path_arg, required=True, help="the report, FILE.html")
    r.add_argument("--title", default="chaoscam report", help="the report's title")
    r.add_argument("--force", action="store_true", help="replace an existing report")
    r.set_defaults(func=run_report)

    p = sub.add_parser(
        "paper",
        help="reproduce the paper's Figs. 3-10 and write the comparison report",
        description="Run the figure scripts (chaoscam.paper: Figs. 3-10 and the sensitivity "
        "sweeps), write each figure's data and PNG next to the report (DIR/paper-data/), and "
        "build the HTML report comparing the paper's statements with what this run finds.",
    )
    p.add_argument(
        "--quick",
        action="store_true",
        help="small grids and short runs (minutes on 2 cores); say so in the report",
    )
    p.add_argument(
        "--out",
        type=path_arg,
        help=f"the report (default {DEFAULT_PAPER}, created with its folder; git ignores "
        "it: the committed reports/paper.html is written only when named)",
    )
    p.add_argument(
        "--figures", metavar="LIST", help="only these figures, e.g. 3,5,7 (default: all)"
    )
    p.add_argument("--workers", type=int, help="threads for the sweeps (default: every core)")
    p.add_argument(
        "--force",
        action="store_true",
        help="replace an existing report and its paper-data files",
    )
    p.add_argument(
        "--resume",
        action="store_true",
        help="continue an interrupted report in the same folder: finished sweeps are read "
        "back, the one under way finishes from its checkpoint",
    )
    p.set_defaults(func=run_paper)


def run_report(args: argparse.Namespace) -> int:
    from ..io import check_output
    from ..report import build_report, load_inputs, write_report

    check_output(args.out, force=args.force, suffixes=(".html",))
    parts = build_report(load_inputs(args.inputs))
    command = shlex.join(
        ["chaoscam", "report", *map(str, args.inputs), "--out", str(args.out)]
        + (["--title", args.title] if args.title != "chaoscam report" else [])
    )
    write_report(parts, args.out, title=args.title, command=command, replace=args.force)
    print(f"report: {args.out}")
    return 0


def run_paper(args: argparse.Namespace) -> int:
    from ..paper import FIGURES, RESUME_HINT
    from ..paper import run_paper as _run
    from ..sweep import local_workers
    from . import UsageError

    if args.force and args.resume:
        raise UsageError("--force starts over and --resume continues: give one of them")
    if args.workers is not None:
        try:
            local_workers(args.workers)  # what every sweep of the report would refuse
        except ValueError as err:
            raise UsageError(f"--workers {args.workers}: {err}") from None
    figures = None
    if args.figures is not None:
        try:
            figures = [int(x) for x in args.figures.split(",")]
        except ValueError:
            raise UsageError(f"--figures {args.figures!r}: expected numbers like 3,5,7") from None
        bad = [f for f in figures if f not in FIGURES]
        if bad:
            raise UsageError(f"--figures: no figure {bad}; choose from {sorted(FIGURES)}")
    if args.out is None:  # the default folder is ours to create; a named one is the user's
        args.out = DEFAULT_PAPER
        args.out.parent.mkdir(parents=True, exist_ok=True)
    command = shlex.join(
        ["chaoscam", "paper"]
        + (["--quick"] if args.quick else [])
        + (["--figures", args.figures] if args.figures is not None else [])
        + (["--workers", str(args.workers)] if args.workers else [])
        + ["--out", str(args.out)]
        + (["--resume"] if args.resume else [])
    )
    try:
        run = _run(
            quick=args.quick, out=args.out, figures=figures, workers=args.workers,
            command=command, echo=True, force=args.force, resume=args.resume,
        )  # fmt: skip
    except KeyboardInterrupt:  # Ctrl-C or SIGTERM: say what is kept and how to go on, once
        from . import stop_word

        print(f"chaoscam: {stop_word()}; {RESUME_HINT}", file=sys.stderr)
        return 130
    except OSError as err:  # a full disk: the file (named by the write), and what is kept
        print(f"chaoscam: error: {err}; {RESUME_HINT}", file=sys.stderr)
        return 2
    print(f"report: {run.path}")
    if run.failed:
        print(
            f"chaoscam: {len(run.failed)} stage(s) failed, the report says what is missing:\n  "
            + "\n  ".join(run.failed),
            file=sys.stderr,
        )
        return 1
    return 0
