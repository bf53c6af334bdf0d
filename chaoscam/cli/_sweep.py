"""``chaoscam bifurcation`` and ``chaoscam regime-map``: thin layers over the sweep API."""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

from ._options import (
    add_engine_options,
    add_run_options,
    add_sweep_options,
    engine_settings,
    path_arg,
    sweep_settings,
)

__all__ = ["register"]

_PLOT_SUFFIXES = (".png", ".pdf", ".svg")


def _common(p: argparse.ArgumentParser) -> None:
    add_run_options(p, transient=None)
    add_engine_options(p)
    p.add_argument(
        "--fate",
        type=float,
        default=None,
        metavar="S",
        help="continue each run labelled chaotic, quasiperiodic or undetermined to S seconds "
        "(> --duration) and record whether it leaves the cam's reach before (columns fate, "
        "left_at) and, if it stays, its verdict on the continued run's last half (columns "
        "fate_label, fate_period): transient chaos",
    )
    p.add_argument(
        "--plot",
        type=path_arg,
        default=None,
        help="also draw the figure to FILE (.png, .pdf or .svg)",
    )
    add_sweep_options(p)


def register(sub) -> None:
    b = sub.add_parser(
        "bifurcation",
        help="bifurcation diagram over one parameter (stroboscopic section + verdict)",
        description="For each value of a model parameter, simulate, keep the stroboscopic "
        "section points after the transient and classify the motion. Writes the points to "
        "FILE.parquet and one verdict per value and initial condition to "
        "FILE.verdicts.parquet. Paper Fig. 4: --param l_lambda --values 0.001:0.018:69.",
    )
    b.add_argument("--param", required=True, metavar="NAME", help="the swept parameter")
    b.add_argument(
        "--values",
        required=True,
        metavar="START:STOP:NUM|V1,V2,...",
        help="NUM values from START to STOP, both included, or exact values V1,V2,...",
    )
    b.add_argument(
        "--initial-conditions",
        type=int,
        default=1,
        metavar="N",
        help="initial conditions per value: the default state plus N-1 spread ones",
    )
    b.add_argument(
        "--continuation",
        action="store_true",
        help="start each value from the previous value's last section point",
    )
    _common(b)
    b.set_defaults(func=run_bifurcation)

    r = sub.add_parser(
        "regime-map",
        help="Monte Carlo regime map over (mu, sigma) or any two parameters",
        description="In each cell of a grid, simulate and classify N realizations of the "
        "random line length. Writes one row per realization to FILE.parquet and the "
        "per-cell fractions with 95% Wilson intervals to FILE.cells.parquet.",
    )
    r.add_argument("--mu", metavar="START:STOP:NUM|V1,V2,...", help="mean line length l_lambda [m]")
    r.add_argument("--sigma", metavar="START:STOP:NUM|V1,V2,...", help="spread l_lambda_sigma [m]")
    r.add_argument(
        "--x", metavar="NAME=START:STOP:NUM|V1,V2,...", help="first axis (instead of --mu)"
    )
    r.add_argument(
        "--y", metavar="NAME=START:STOP:NUM|V1,V2,...", help="second axis (instead of --sigma)"
    )
    r.add_argument(
        "--realizations",
        type=int,
        default=None,
        metavar="N",
        help="realizations per cell (default 20 where a cell has a random line length, "
        "else 1)",
    )
    r.add_argument(
        "--target-halfwidth",
        type=float,
        default=None,
        metavar="W",
        help="adaptive: add N more realizations to a cell while its widest 95%% interval "
        "half-width exceeds W",
    )
    r.add_argument(
        "--max-realizations",
        type=int,
        default=None,
        metavar="M",
        help="adaptive: at most M per cell (default 1000)",
    )
    _common(r)
    r.set_defaults(func=run_regime_map)


def _execution(args) -> dict:
    from ..io import check_output

    check_output(args.plot, flag="--plot", force=args.force, suffixes=_PLOT_SUFFIXES)
    return dict(
        duration=args.duration,
        transient=args.transient,
        seed=args.seed,
        **engine_settings(args),
        **sweep_settings(args),
        fate=args.fate,
    )


def _transient(table) -> str:
    """The summary line of a sweep with a fate horizon: how many runs left later, and how
    many settled on a periodic orbit."""
    from ..sweep import continued_labels, fate_settled, fate_split

    checked, left = fate_split(table)
    if not len(checked):
        return ""
    settled = fate_settled(table)
    late = (
        f"; {len(settled)} periodic on the continued run's last half (period(s) "
        f"{_counts(settled['fate_period'].astype(int))})"
        if len(settled)
        else ""
    )
    if not len(left):
        return f"\nfate: every run {continued_labels(checked)} stayed in the cam's reach{late}"
    t0, t1 = f"{left['left_at'].min():.4g}", f"{left['left_at'].max():.4g}"
    return (
        f"\nfate: {len(left)} of the {len(checked)} run(s) {continued_labels(checked)} "
        f"stopped later ({_counts(left['fate'])}; last section at "
        f"{t0 if t0 == t1 else f'{t0}–{t1}'} s): transient motion{late}"
    )


def _call(fn, **kwargs):
    """Run a sweep; bad settings become usage errors (exit 2); a stopped run returns its
    exit code (130 Ctrl-C, 1 a lost Dask scheduler or a failed task) after saying how to
    resume or reproduce it."""
    from ..sweep import SweepError, SweepInterrupted, TaskFailed
    from . import UsageError, stop_word

    try:
        return fn(**kwargs)
    except SweepError as err:
        raise UsageError(str(err)) from None
    except TaskFailed as err:
        print(f"chaoscam: error: {err}", file=sys.stderr)
        return 1
    except SweepInterrupted as err:
        print(f"chaoscam: {err.describe(stop_word())}", file=sys.stderr)
        return 130 if err.cause is None else 1


def _counts(labels) -> str:
    return ", ".join(f"{k} {v}" for k, v in labels.value_counts().sort_index().items())


def _not_set(items: list[str] | None, swept: dict[str, str]) -> None:
    """Refuse ``--set NAME=VALUE`` for a parameter the sweep varies: the axis would silently
    override it."""
    from . import UsageError

    for item in items or []:
        name = item.partition("=")[0].strip()
        if name in swept:
            raise UsageError(
                f"--set {item}: {name} is swept by {swept[name]}, which gives its values; "
                "drop the --set"
            )


def run_bifurcation(args: argparse.Namespace) -> int:
    from ..sweep import bifurcation, companion
    from . import parse_assignments

    _not_set(args.set, {args.param: "--param"})
    base, numerics = parse_assignments(args.set)
    if args.initial_conditions < 1:
        from . import UsageError

        raise UsageError(f"--initial-conditions {args.initial_conditions}: must be >= 1")
    res = _call(
        bifurcation,
        param=args.param,
        values=args.values,
        base=base,
        numerics=numerics,
        initial_conditions=args.initial_conditions,
        continuation=args.continuation,
        **_execution(args),
    )
    if isinstance(res, int):
        return res
    v = res.verdicts
    print(
        f"bifurcation over {res.param}: {v['value_index'].nunique()} values x "
        f"{v['ic'].nunique()} initial condition(s), {len(res.points)} section points\n"
        f"verdicts: {_counts(v['label'])}{_transient(v)}\n"
        f"points: {args.out}\nverdicts: {companion(args.out, 'verdicts')}"
    )
    if args.plot is not None:
        from ..report import sweep_diagram

        _save_figure(sweep_diagram(res), args.plot)
        print(f"figure: {args.plot}")
    return 0


def run_regime_map(args: argparse.Namespace) -> int:
    from ..sweep import Axis, SweepError, companion, mu_sigma_axes, regime_map
    from . import UsageError, parse_assignments

    try:
        if (args.mu is None) == (args.x is None):
            raise UsageError("give the first axis with --mu or --x (one of them)")
        if (args.sigma is None) == (args.y is None):
            raise UsageError("give the second axis with --sigma or --y (one of them)")
        if args.mu is not None and args.sigma is not None:
            x, y = mu_sigma_axes(args.mu, args.sigma)
        else:
            x = Axis.parse(args.mu, name="l_lambda") if args.mu else Axis.parse(args.x)
            y = Axis.parse(args.sigma, name="l_lambda_sigma") if args.sigma else Axis.parse(args.y)
    except SweepError as err:
        raise UsageError(str(err)) from None
    _not_set(
        args.set, {x.name: "--mu" if args.mu else "--x", y.name: "--sigma" if args.sigma else "--y"}
    )
    base, numerics = parse_assignments(args.set)
    res = _call(
        regime_map,
        x=x,
        y=y,
        base=base,
        numerics=numerics,
        realizations=args.realizations,
        target_halfwidth=args.target_halfwidth,
        max_realizations=args.max_realizations,
        **_execution(args),
    )
    if isinstance(res, int):
        return res
    c = res.cells
    det = int(c["deterministic"].astype(bool).sum()) if "deterministic" in c else 0
    once = f" ({det} deterministic cell(s), sigma = 0: one run each)" if det else ""
    print(
        f"regime map {res.x} x {res.y}: {len(c)} cells, {len(res.realizations)} realizations"
        f"{once}\n"
        f"labels: {_counts(res.realizations['label'])}\n"
        f"dominant: {_counts(c['dominant'])}{_transient(res.realizations)}\n"
        f"realizations: {args.out}\ncells: {companion(args.out, 'cells')}"
    )
    if args.plot is not None:
        from ..report import regime_map_figure

        _save_figure(
            regime_map_figure(c, x=res.x, y=res.y, confidence=res.config["confidence"]),
            args.plot,
        )
        print(f"figure: {args.plot}")
    return 0


def _save_figure(fig, path: Path) -> None:
    from ..io import atomic_path

    with atomic_path(path) as tmp:
        fig.savefig(tmp, dpi=150)
