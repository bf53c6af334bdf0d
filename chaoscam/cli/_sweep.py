"""``chaoscam bifurcation`` and ``chaoscam regime-map``: thin layers over the sweep API."""

from __future__ import annotations

import argparse
import math
import sys
from pathlib import Path

from ._options import add_run_options, path_arg

__all__ = ["register"]

_PLOT_SUFFIXES = (".png", ".pdf", ".svg")


def _common(p: argparse.ArgumentParser) -> None:
    add_run_options(p, transient=None)
    p.add_argument(
        "--lyapunov",
        action="store_true",
        help="classify with the model's two-trajectory Lyapunov exponent and the "
        "series-based evidence instead of the default tangent verdict (no orbit certificate, "
        "no extension; kept for comparison, about twice the cost)",
    )
    p.add_argument(
        "--check-step",
        action="store_true",
        help="re-run each realization with dt/2; a changed verdict becomes undetermined",
    )
    p.add_argument(
        "--classifier",
        metavar="MODULE:NAME",
        default=None,
        help="a classifier other than chaoscam.classify.classify_trajectory: a function, or "
        "a class instantiated without arguments, importable by the workers",
    )
    p.add_argument(
        "--workers",
        type=int,
        default=None,
        help="cores: worker processes, or the ensemble engine's threads (default: every "
        "core; 1 = this process, one thread); with --scheduler local, the local Dask "
        "cluster's workers",
    )
    p.add_argument(
        "--engine",
        choices=("auto", "ensemble", "process"),
        default="auto",
        help="ensemble: realizations in batches through the compiled ensemble call (threads "
        "over the cores), labelled from section and tangent exponent; process: one worker "
        "process per core, one task per realization, any classifier; auto (default): "
        "ensemble for the default classifier, else process",
    )
    p.add_argument(
        "--device",
        choices=("cpu", "gpu", "auto"),
        default="cpu",
        help="where the ensemble engine runs its batches (gpu: NVIDIA, numba-cuda; equal to "
        "the CPU only within GPU_TOLERANCE; auto: the GPU where one runs and the sweep has "
        "4,096 runs or more); default cpu",
    )
    p.add_argument(
        "--scheduler",
        metavar="ADDRESS",
        default=None,
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
    p.add_argument("--quiet", action="store_true", help="no progress bar")
    p.add_argument(
        "--force",
        action="store_true",
        help="start over: replace existing outputs and discard an existing checkpoint",
    )
    p.add_argument("--out", type=path_arg, required=True, help="output FILE.parquet")


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
        "--realizations", type=int, default=1, metavar="N", help="realizations per cell (default 1)"
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
    from .._outputs import check_output
    from ..sweep._tasks import load_classifier
    from . import UsageError

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
    check_output(args.plot, flag="--plot", force=args.force, suffixes=_PLOT_SUFFIXES)
    classify = None
    if args.classifier is not None:
        try:
            classify = load_classifier(args.classifier)
        except (ValueError, ImportError, AttributeError) as err:
            raise UsageError(f"--classifier {args.classifier}: {err}") from None
    return dict(
        duration=args.duration,
        transient=args.transient,
        seed=args.seed,
        classify=classify,
        lyapunov=args.lyapunov,
        check_step=args.check_step,
        workers=args.workers,
        scheduler=args.scheduler,
        engine=args.engine,
        device=args.device,
        out=args.out,
        resume=args.resume,
        progress=not args.quiet,
        flush_interval=args.checkpoint_interval,
        force=args.force,
        fate=args.fate,
    )


def _transient(table) -> str:
    """The summary line of a sweep with a fate horizon: how many runs left later, and how
    many settled on a periodic orbit."""
    from ..sweep._stats import continued_labels, fate_settled, fate_split

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
    from ..sweep._engine import SweepInterrupted, TaskFailed
    from ..sweep._grid import SweepError
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
    from ..sweep._bifurcation import bifurcation
    from ..sweep._common import companion
    from . import parse_assignments

    _not_set(args.set, {args.param: "--param"})
    base = parse_assignments(args.set)
    if args.initial_conditions < 1:
        from . import UsageError

        raise UsageError(f"--initial-conditions {args.initial_conditions}: must be >= 1")
    res = _call(
        bifurcation,
        param=args.param,
        values=args.values,
        base=base,
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
        from ..report._sweep_figures import sweep_diagram

        _save_figure(sweep_diagram(res), args.plot)
        print(f"figure: {args.plot}")
    return 0


def run_regime_map(args: argparse.Namespace) -> int:
    from ..sweep._common import companion
    from ..sweep._grid import Axis, SweepError
    from ..sweep._regime import mu_sigma_axes, regime_map
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
    base = parse_assignments(args.set)
    res = _call(
        regime_map,
        x=x,
        y=y,
        base=base,
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
        from ..report._sweep_figures import regime_map_figure

        _save_figure(
            regime_map_figure(c, x=res.x, y=res.y, confidence=res.config["confidence"]),
            args.plot,
        )
        print(f"figure: {args.plot}")
    return 0


def _save_figure(fig, path: Path) -> None:
    from .._outputs import atomic_path

    with atomic_path(path) as tmp:
        fig.savefig(tmp, dpi=150)
