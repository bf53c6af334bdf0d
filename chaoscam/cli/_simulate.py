"""``chaoscam simulate``: one trajectory, a short summary, optional files."""

from __future__ import annotations

import argparse
import sys
import warnings

from ._options import add_run_options, path_arg


def register(sub) -> None:
    p = sub.add_parser(
        "simulate",
        help="simulate one trajectory and print a summary",
        description="Simulate one realization of the cam-follower model (RK4 with located "
        "impacts) and print a summary: impacts, contact fraction, status.",
    )
    add_run_options(p, transient=0.0)
    p.add_argument("--index", type=int, default=0, help="realization index under the seed")
    p.add_argument("--output-dt", type=float, default=1e-3, help="series sampling [s]")
    p.add_argument("--out", type=path_arg, help="time series to FILE.parquet or FILE.csv")
    p.add_argument("--section", type=path_arg, help="stroboscopic section to FILE.csv")
    p.add_argument("--impacts", type=path_arg, help="impact list to FILE.csv")
    p.add_argument("--plot", type=path_arg, help="the run's figure to FILE.png: θ_f and θ_fc "
                   "over the last 2 s, phase portrait, section, spectrum")  # fmt: skip
    p.add_argument("--force", action="store_true", help="replace existing output files")
    p.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    from ..io import check_output, lock_all

    out = check_output(args.out, force=args.force, suffixes=(".parquet", ".csv"))
    section = check_output(args.section, flag="--section", force=args.force, suffixes=(".csv",))
    impacts = check_output(args.impacts, flag="--impacts", force=args.force, suffixes=(".csv",))
    plot = check_output(args.plot, flag="--plot", force=args.force, suffixes=(".png",))
    _distinct(("--out", out), ("--section", section), ("--impacts", impacts), ("--plot", plot))
    written: list = []
    asked = [p for p in (out, section, impacts, plot) if p is not None]
    with lock_all(asked):  # as a sweep's outputs: a second run writing one is refused
        try:
            return _run(args, (out, section, impacts, plot), written)
        except KeyboardInterrupt:  # one message, saying what is on disk
            if not asked:
                raise  # nothing to write: the plain "interrupted"
            from . import stop_word

            print(
                f"chaoscam: {stop_word()}; "
                + (f"written: {', '.join(map(str, written))}; " if written else "")
                + "no output is half-written (each is written whole or not at all)",
                file=sys.stderr,
            )
            return 130


def _run(args: argparse.Namespace, paths, written: list) -> int:
    """Simulate, write the files asked for; 0 when the run simulated what was asked, else 1
    with the cause on stderr (the first warning first: then the likely one)."""
    from ..io import atomic_path, write_table
    from ..simulation import simulate
    from . import parse_assignments, show_warning

    out, section, impacts, plot = paths
    params, numerics = parse_assignments(args.set)
    notes: list[str] = []

    def note(message, *rest, **kwargs) -> None:  # printed at once: a time estimate comes first
        notes.append(str(message))
        show_warning(message)

    with warnings.catch_warnings():
        warnings.simplefilter("always")
        warnings.showwarning = note
        traj = simulate(
            params, numerics, duration=args.duration, transient=args.transient, seed=args.seed,
            index=args.index, series=out is not None or plot is not None, output_dt=args.output_dt,
        )  # fmt: skip
    print(traj.summary())
    impact_rows = traj.impacts.drop(columns="member")

    def series(tmp) -> None:
        if out.suffix.lower() == ".parquet":
            write_table(traj.parquet_table(), tmp)
        else:
            traj.series.drop(columns="member").to_csv(tmp, index=False)

    def figure(tmp) -> None:
        from ..report import png_bytes, response_figure

        tmp.write_bytes(
            png_bytes(response_figure(traj, title=f"{plot.name}: status {traj.status}"))
        )

    for path, label, write in (
        (out, "series", series),
        (section, "section", lambda tmp: traj.section.to_csv(tmp, index=False)),
        (impacts, "impacts", lambda tmp: impact_rows.to_csv(tmp, index=False)),
        (plot, "figure", figure),
    ):
        if path is not None:
            try:
                with atomic_path(path, replace=args.force) as tmp:
                    write(tmp)
            except OSError as err:  # a full disk (the write names the file): nothing half-written
                if isinstance(err, FileExistsError):
                    raise
                raise type(err)(
                    err.errno, f"{err.strerror or err}; nothing was written there (atomic "
                    "write): fix the cause and run again"
                ) from None  # fmt: skip
            written.append(path)
            print(f"{label}: {path}")
    if traj.ok:
        return 0
    cause = f"likely cause: {notes[0]}. " if notes else ""
    print(
        f"chaoscam: the run ended {traj.status.name} at t = {traj.final_state[0]:.6g} s "
        f"of {traj.settings['duration']:g} s, not the end asked for. {cause}{traj.message}",
        file=sys.stderr,
    )
    return 1


def _distinct(*named) -> None:
    """Refuse two outputs of one run that name the same file."""
    from ..io import OutputError

    seen: dict = {}
    for flag, path in named:
        if path is not None and seen.setdefault(path.resolve(), flag) != flag:
            first = seen[path.resolve()]
            raise OutputError(f"{first} and {flag} both name {path}; give each its own file")
