"""``chaoscam bifurcation`` and ``chaoscam regime-map``: thin layers over the sweep API."""

from __future__ import annotations

import argparse

from ._options import add_sweep_options, counts, path_arg, run_sweep, sweep_settings

AXIS = "START:STOP:NUM|V1,V2,..."


def _common(p: argparse.ArgumentParser) -> None:
    add_sweep_options(p)
    p.add_argument(
        "--fate",
        type=float,
        metavar="S",
        help="continue each run labelled chaotic, quasiperiodic or undetermined to S s "
        "(> --duration): whether it leaves the cam's reach (columns fate, left_at), else its "
        "verdict on the continued run's last half (fate_label, fate_period): transient chaos",
    )
    p.add_argument(
        "--plot", type=path_arg, help="also draw the figure to FILE (.png, .pdf or .svg)"
    )


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
        metavar=AXIS,
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
    r.add_argument("--mu", metavar=AXIS, help="mean line length l_lambda [m]")
    r.add_argument("--sigma", metavar=AXIS, help="spread l_lambda_sigma [m]")
    r.add_argument("--x", metavar=f"NAME={AXIS}", help="first axis (instead of --mu)")
    r.add_argument("--y", metavar=f"NAME={AXIS}", help="second axis (instead of --sigma)")
    r.add_argument(
        "--realizations",
        type=int,
        metavar="N",
        help="realizations per cell (default 20 where a cell has a random line length, else 1)",
    )
    r.add_argument(
        "--target-halfwidth",
        type=float,
        metavar="W",
        help="adaptive: add N more realizations to a cell while its widest 95%% interval "
        "half-width exceeds W",
    )
    r.add_argument(
        "--max-realizations",
        type=int,
        metavar="M",
        help="adaptive: at most M a cell (default 1000)",
    )
    _common(r)
    r.set_defaults(func=run_regime_map)


def _sweep(fn, args, swept: dict[str, str], **kwargs):
    """``fn`` with ``--set`` (refused for a ``swept`` name) and the shared options: its result,
    or the exit code of a stopped sweep."""
    from ..io import check_output
    from . import parse_assignments

    base, numerics = parse_assignments(args.set, swept)
    check_output(args.plot, flag="--plot", force=args.force, suffixes=(".png", ".pdf", ".svg"))
    return run_sweep(
        fn, base=base, numerics=numerics, duration=args.duration, transient=args.transient,
        seed=args.seed, **sweep_settings(args), fate=args.fate, **kwargs,
    )  # fmt: skip


def _fate(table) -> str:
    """The summary line of ``--fate``: how many runs left later, how many settled periodic."""
    from ..sweep import continued_labels, fate_settled, fate_split

    checked, left = fate_split(table)
    if not len(checked):
        return ""
    settled, late = fate_settled(table), ""
    if len(settled):
        periods = counts(settled["fate_period"].astype(int))
        late = f"; {len(settled)} periodic on the continued run's last half (period(s) {periods})"
    if not len(left):
        return f"\nfate: every run {continued_labels(checked)} stayed in the cam's reach{late}"
    t0, t1 = f"{left['left_at'].min():.4g}", f"{left['left_at'].max():.4g}"
    return (
        f"\nfate: {len(left)} of the {len(checked)} run(s) {continued_labels(checked)} "
        f"stopped later ({counts(left['fate'])}; last section at "
        f"{t0 if t0 == t1 else f'{t0}–{t1}'} s): transient motion{late}"
    )


def _finish(args, summary: str, draw) -> int:
    """Print the summary; then, with ``--plot``, draw the figure (``draw()``) and write it."""
    print(summary)
    if args.plot is not None:
        from ..io import atomic_path

        fig = draw()
        with atomic_path(args.plot) as tmp:
            fig.savefig(tmp, dpi=150)
        print(f"figure: {args.plot}")
    return 0


def run_bifurcation(args: argparse.Namespace) -> int:
    from .. import report
    from ..sweep import bifurcation, companion
    from . import UsageError

    if args.initial_conditions < 1:
        raise UsageError(f"--initial-conditions {args.initial_conditions}: must be >= 1")
    res = _sweep(
        bifurcation, args, {args.param: "--param"}, param=args.param, values=args.values,
        initial_conditions=args.initial_conditions, continuation=args.continuation,
    )  # fmt: skip
    if isinstance(res, int):
        return res
    v = res.verdicts
    summary = (
        f"bifurcation over {res.param}: {v['value_index'].nunique()} values x "
        f"{v['ic'].nunique()} initial condition(s), {len(res.points)} section points\n"
        f"verdicts: {counts(v['label'])}{_fate(v)}\n"
        f"points: {args.out}\nverdicts: {companion(args.out, 'verdicts')}"
    )
    return _finish(args, summary, lambda: report.sweep_diagram(res))


def _axes(args):
    """The regime map's axes from --mu/--x and --sigma/--y, and the option naming each."""
    from ..sweep import Axis, mu_sigma_axes
    from . import UsageError

    if (args.mu is None) == (args.x is None):
        raise UsageError("give the first axis with --mu or --x (one of them)")
    if (args.sigma is None) == (args.y is None):
        raise UsageError("give the second axis with --sigma or --y (one of them)")
    if args.mu is not None and args.sigma is not None:
        x, y = mu_sigma_axes(args.mu, args.sigma)
    else:
        x = Axis.parse(args.mu, name="l_lambda") if args.mu else Axis.parse(args.x)
        y = Axis.parse(args.sigma, name="l_lambda_sigma") if args.sigma else Axis.parse(args.y)
    return x, y, {x.name: "--mu" if args.mu else "--x", y.name: "--sigma" if args.sigma else "--y"}


def run_regime_map(args: argparse.Namespace) -> int:
    from .. import report
    from ..sweep import companion, regime_map

    x, y, swept = _axes(args)
    res = _sweep(
        regime_map, args, swept, x=x, y=y, realizations=args.realizations,
        target_halfwidth=args.target_halfwidth, max_realizations=args.max_realizations,
    )  # fmt: skip
    if isinstance(res, int):
        return res
    c = res.cells
    det = int(c["deterministic"].astype(bool).sum()) if "deterministic" in c else 0
    once = f" ({det} deterministic cell(s), sigma = 0: one run each)" if det else ""
    summary = (
        f"regime map {res.x} x {res.y}: {len(c)} cells, {len(res.realizations)} realizations"
        f"{once}\n"
        f"labels: {counts(res.realizations['label'])}\n"
        f"dominant: {counts(c['dominant'])}{_fate(res.realizations)}\n"
        f"realizations: {args.out}\ncells: {companion(args.out, 'cells')}"
    )
    confidence = res.config["confidence"]
    return _finish(
        args, summary, lambda: report.regime_map_figure(c, x=res.x, y=res.y, confidence=confidence)
    )
