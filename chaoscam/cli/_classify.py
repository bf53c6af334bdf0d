"""``chaoscam classify`` (a one-line verdict; ``--json``: with its evidence) and
``chaoscam classify-series`` (a verdict as JSON on stdout)."""

from __future__ import annotations

import argparse
import json
import math

from ._options import path_arg


def register(sub) -> None:
    p = sub.add_parser(
        "classify",
        help="classify a simulated trajectory (Parquet) as periodic/quasiperiodic/chaotic",
        description="Classify a trajectory written by `chaoscam simulate --out FILE.parquet` "
        "from its stroboscopic section and the tangent exponent through the impacts (with the "
        "periodic-orbit certificate for the deterministic model): one line, e.g. 'chaotic "
        "(lambda_1 = +1.4 +- 0.1 /s)' or 'undetermined: REASON'; --json: as JSON (label, period, "
        "evidence, reasons; extended: the recorded time, when a longer run settled it).",
    )
    p.add_argument("trajectory", type=path_arg, metavar="TRAJ.parquet")
    p.add_argument("--json", action="store_true", help="print the verdict and its evidence as JSON")
    p.add_argument(
        "--no-extend",
        action="store_true",
        help="do not run an undetermined realization longer (default: up to 120 s recorded)",
    )
    p.add_argument(
        "--check-step",
        action="store_true",
        help="judge the realization at dt/2 too and report undetermined if the verdict changes",
    )
    p.add_argument(
        "--discard",
        type=float,
        default=0.0,
        metavar="S",
        help="leave out the first S seconds after the run's transient (default 0: a run "
        "simulated without --transient is classified from t = 0, start-up included)",
    )
    p.set_defaults(func=run_classify)

    q = sub.add_parser(
        "classify-series",
        help="classify one column of a CSV file (a sampled signal or section points)",
        description="Classify a column of a CSV file, printed as JSON (label, period, "
        "evidence, reasons). With --dt the rows are a uniformly sampled signal of a flow; "
        "with --section they are already Poincaré-section points (map iterates).",
    )
    q.add_argument("file", type=path_arg, metavar="FILE.csv")
    q.add_argument(
        "--column",
        action="append",
        required=True,
        metavar="NAME",
        help="the column to classify; with --section it may be repeated for points with "
        "several coordinates",
    )
    mode = q.add_mutually_exclusive_group()
    mode.add_argument("--dt", type=float, metavar="SECONDS", help="sampling interval [s]")
    mode.add_argument(
        "--section", action="store_true", help="rows are section points / map iterates"
    )
    q.add_argument(
        "--forcing-period",
        type=float,
        metavar="S",
        help="period of the forcing [s] (with --dt): e.g. 2 pi / omega for the cam",
    )
    q.set_defaults(func=run_classify_series)


def run_classify(args: argparse.Namespace) -> int:
    from ..simulation import read_trajectory
    from ..verdict import EXTEND_TO, classify

    traj = read_trajectory(args.trajectory)
    extend_to = None if args.no_extend else EXTEND_TO
    verdicts = classify(traj, extend_to=extend_to, check_step=args.check_step, discard=args.discard)
    if not args.json:  # one line a member
        print("\n".join(map(verdict_line, verdicts)), flush=True)
        return 0
    (verdict,) = verdicts  # a trajectory file holds one run
    out = verdict.to_dict()
    extended = verdict.settings.get("extended")
    if extended:  # the evidence is that of the longer run: say how long (not the wall time)
        out["extended"] = {k: extended[k] for k in ("recorded_s", "why")}
    print(json.dumps(out, indent=2, ensure_ascii=False))
    return 0


def verdict_line(v) -> str:
    """A verdict in one line: the label and period, a certified orbit or the common-noise twins'
    outcome and noise width, the tangent lambda_1 and its standard error [1/s]; an undetermined
    one with its first reason."""
    if v.label == "undetermined":
        return "undetermined" + (f": {v.reasons[0]}" if v.reasons else "")
    certified = any(e.name == "periodic_orbit" and e.vote == "periodic" for e in v.evidence)
    notes = ["certified orbit"] if certified else []
    twins = (v.settings.get("twins") or {}).get("outcome")
    if twins in ("synchronised", "separated"):
        notes.append(f"twins sharing the draws {twins}")
    noisy = v.settings.get("noisy")
    if v.label == "periodic" and noisy:
        notes.append(f"noise width {noisy['band_width']:.2g} rad")
    tangent = v.settings.get("tangent") or {}
    lam, err = (tangent.get("exponents") or [math.nan])[0], (tangent.get("stderr") or [0.0])[0]
    if math.isfinite(lam):
        notes.append(f"lambda_1 = {lam:+.2g} +- {err:.1g} /s")
    period = f", period {v.period}" if v.period else ""
    return v.label + period + (f" ({', '.join(notes)})" if notes else "")


def run_classify_series(args: argparse.Namespace) -> int:
    from ..analysis import SAMPLING_DT, classify_section, classify_signal
    from . import UsageError

    if args.dt is None and not args.section:
        raise UsageError(
            "say what the rows are: --dt SECONDS (a uniformly sampled signal) or --section "
            "(section points / map iterates)"
        )
    lo, hi = SAMPLING_DT
    if args.dt is not None and not lo <= args.dt <= hi:
        raise UsageError(f"--dt {args.dt}: the sampling interval must be in [{lo:g}, {hi:g}] s")
    if args.forcing_period is not None:
        if args.section:
            raise UsageError(
                "--forcing-period applies to a sampled signal (--dt); section points are "
                "already one per forcing period"
            )
        if not (math.isfinite(args.forcing_period) and args.forcing_period >= 2 * args.dt):
            raise UsageError(f"--forcing-period {args.forcing_period}: must be >= 2 x --dt")
    if args.dt is not None and len(args.column) != 1:
        raise UsageError("--dt takes one --column (a scalar signal)")
    twice = sorted({c for c in args.column if args.column.count(c) > 1})
    if twice:  # a repeated coordinate would weigh twice in the section's distances
        raise UsageError(
            f"--column {', '.join(map(repr, twice))} given more than once: name each once"
        )
    data = _read_columns(args.file, args.column)  # refused unless finite numbers, enough rows
    try:
        if args.section:
            points = data[:, 0] if data.shape[1] == 1 else data
            verdict = _uncertified(classify_section(points), points)
        else:
            verdict = classify_signal(data[:, 0], args.dt, args.forcing_period)
    except ValueError as err:
        raise UsageError(f"{args.file}: {err}") from None
    print(json.dumps(verdict.to_dict(), indent=2, ensure_ascii=False))
    return 0


def _read_columns(path, columns: list[str]):
    import numpy as np
    import pandas as pd

    from ..simulation import check_enough
    from . import UsageError

    if not path.is_file():
        what = "is a directory; give a CSV file" if path.is_dir() else "no such file"
        raise UsageError(f"{path}: {what}")
    try:
        frame = pd.read_csv(path)
        header = [str(c) for c in pd.read_csv(path, header=None, nrows=1).iloc[0]]
    except (ValueError, OSError, UnicodeDecodeError, IndexError) as err:
        raise UsageError(f"{path}: not a readable CSV file ({err})") from None
    twice = sorted({c for c in columns if header.count(c) > 1})
    if twice:  # pandas would read the first and rename the others "NAME.1"
        raise UsageError(
            f"{path}: the header names column {', '.join(map(repr, twice))} more than once; "
            "rename the copies so that --column picks one"
        )
    missing = [c for c in columns if c not in frame.columns]
    if missing:
        raise UsageError(
            f"{path}: no column {', '.join(repr(c) for c in missing)}; the columns are "
            f"{', '.join(repr(str(c)) for c in frame.columns)}"
        )
    try:
        data = frame[columns].apply(pd.to_numeric, errors="raise").to_numpy(dtype=float)
    except (ValueError, TypeError):
        raise UsageError(
            f"{path}: column(s) {', '.join(columns)} hold values that are not numbers"
        ) from None
    bad = ~np.isfinite(data).all(axis=1)
    if bad.any():
        rows = np.flatnonzero(bad)
        raise UsageError(
            f"{path}: {rows.size} row(s) with NaN or infinite values in "
            f"{', '.join(columns)} (first at data row {int(rows[0]) + 1}); remove them"
        )
    check_enough(len(data), "rows", path, "record a longer signal")
    return data


def _uncertified(verdict, points):
    """A periodic section verdict whose bands are over 1e-6 of the orbit's extent wide gets a
    reason saying it is not certified: points alone cannot tell it from chaos confined to
    narrow bands (the default model's 8 bands, chaotic by its tangent exponent)."""
    import dataclasses

    import numpy as np

    from ..analysis import section_period

    if verdict.label != "periodic":
        return verdict
    # a scalar's period is found on its delays, whose centres differ where its values repeat
    pr = section_period(points, rtol=verdict.settings.get("rtol"), distinct=np.ndim(points) > 1)
    extent = np.where(pr.extent > 0, pr.extent, np.inf)
    widest = float(np.max(pr.jitter / extent)) if pr.period else 0.0
    if not widest > 1e-6:
        return verdict
    why = (
        f"periodic to the tolerance, not certified: its {verdict.period} band(s) are up to "
        f"{widest:.2g} of the orbit's extent wide, and chaos confined to bands that narrow "
        "looks the same on points alone; for a chaoscam run, `chaoscam classify RUN` decides "
        "it with the tangent exponent and a certified orbit"
    )
    return dataclasses.replace(verdict, reasons=(*verdict.reasons, why))
