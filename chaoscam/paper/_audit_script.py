"""``python analyses/step_audit.py``: the step audit of a finished report's figure sweeps.

The full report audits 5 runs per sweep (:mod:`._step_audit`); this reads the sweeps a report
wrote into its data folder and audits as many as asked (``--per-sweep``, every decided run of
a sweep with a large number), printing one line per run and the report's sentence. With
``--ladder 2,4,8`` it follows the drawn runs (any label) down several halvings of the step
instead (:mod:`._ladder`); ``--label undetermined`` follows only the runs a report left
undetermined, and ``--figures s`` reads the sensitivity sweeps too. It writes nothing.
"""

from __future__ import annotations

from pathlib import Path

from ._paper import G_FIG6, _fig6_tag
from ._stage import FULL_EXTEND_TO
from ._step_audit import AUDIT_SEED, PER_SWEEP, step_audit, sweep_names

__all__ = ["SENSITIVITY_KEY", "SWEEP_FILES", "read_sweeps", "audit_script"]

SWEEP_FILES = {
    4: ("Fig. 4", ["fig4.parquet"]),
    6: ("Fig. 6", [f"{_fig6_tag(g)}.parquet" for g in G_FIG6]),
    7: ("Figs. 7–10", ["fig7-10.parquet"]),
}
"""The paper figures that are sweeps: number -> (name, their files in the data folder)."""

SENSITIVITY_KEY = "s"
"""``--figures`` names the sensitivity stage's sweeps so: every ``sensitivity-*.parquet``
of the folder (diagrams and the (ω, ξ) map), each named by its file."""


def read_sweeps(folder: Path, figures) -> list[tuple[str, object]]:
    """``(name, sweep)`` for each sweep of ``figures`` (numbers of :data:`SWEEP_FILES`, or
    :data:`SENSITIVITY_KEY`) in the report's data ``folder``; a missing file is a
    FileNotFoundError that names it and the command that writes it."""
    out = []
    for number in figures:
        if number == SENSITIVITY_KEY:
            out += _sensitivity_sweeps(folder)
            continue
        name, files = SWEEP_FILES[number]
        found = []
        for file in files:
            path = folder / file
            if not path.is_file():
                raise FileNotFoundError(f"{path} is missing: write it with {_how(folder, number)}")
            found.append(_read_sweep(path))
        out += zip(sweep_names(name, found), found, strict=True)
    return out


def _how(folder: Path, number) -> str:
    """The command that writes figure ``number``'s data (or the sensitivity sweeps') into
    ``folder``."""
    script = "sensitivity" if number == SENSITIVITY_KEY else f"fig{number}"
    how = f"`python analyses/{script}.py {folder}`"
    if folder.name == "paper-data":  # where chaoscam paper writes its data
        how = f"`chaoscam paper --out {folder.parent}/paper.html` or {how}"
    return how


def _read_sweep(path: Path):
    """The diagram or regime map in ``path``, as its sweep record says it is."""
    from ..sweep import SweepError, read_bifurcation, read_regime_map

    try:
        return read_regime_map(path)
    except SweepError:  # another kind: a diagram, or read_bifurcation says what it is
        return read_bifurcation(path)


def _sensitivity_sweeps(folder: Path) -> list[tuple[str, object]]:
    """``(file stem, sweep)`` for every sensitivity sweep in ``folder``, by name."""
    paths = sorted(
        p
        for p in folder.glob("sensitivity-*.parquet")
        if not p.name.endswith((".verdicts.parquet", ".cells.parquet"))
    )
    if not paths:
        raise FileNotFoundError(
            f"{folder}: no sensitivity-*.parquet: write them with {_how(folder, SENSITIVITY_KEY)}"
        )
    return [(p.stem, _read_sweep(p)) for p in paths]


def audit_script(argv: list[str] | None = None) -> int:
    """The body of ``analyses/step_audit.py``. Bad arguments or a missing data file: exit 2
    with one line; Ctrl-C: exit 130 with one line. Returns 0 when it finishes."""
    import sys

    from ..sweep import local_workers
    from ._step_audit import audit_sentence

    ap = _parser()
    args = ap.parse_args(sys.argv[1:] if argv is None else argv)
    figures, halvings = _checked(ap, args)
    try:
        if args.workers is not None:
            local_workers(args.workers)
        sweeps = read_sweeps(Path(args.folder), dict.fromkeys(figures))
    except (OSError, ValueError) as err:
        ap.error(str(err))  # exit 2
    try:
        if halvings:
            return _ladder(sweeps, halvings, args)
        rows = step_audit(
            sweeps, args.per_sweep, args.extend_to, workers=args.workers, seed=args.seed
        )
    except KeyboardInterrupt:
        print(f"{ap.prog}: interrupted; nothing was written", file=sys.stderr)
        raise SystemExit(130) from None
    for r in rows:
        mark = "holds" if r.held else "CHANGES"
        print(f"{r.figure} | {r.where} | recorded {r.recorded} | dt: {r.replayed} | "
              f"dt/2: {r.half} | {mark} | {r.seconds:.1f} s")  # fmt: skip
    print(audit_sentence(rows) or "no decided run to audit")
    return 0


def _parser():
    import argparse

    from ..sweep import LABEL_ORDER

    ap = argparse.ArgumentParser(
        prog="analyses/step_audit.py",
        description="Replay sampled runs of a report's figure sweeps and classify them again "
        "with the step halved (the full report's step audit, at any size).",
    )
    ap.add_argument("folder", nargs="?", default="reports/paper-data", metavar="DATA",
                    help="the report's data folder (default: reports/paper-data)")  # fmt: skip
    ap.add_argument(
        "--figures",
        default=",".join(map(str, SWEEP_FILES)),
        metavar="N,N",
        help="which figures' sweeps, comma-separated (default: 4,6,7; 7 stands for Figs. 7-10, "
        f"{SENSITIVITY_KEY} for every sensitivity-*.parquet of the folder)",
    )
    ap.add_argument(
        "--per-sweep",
        type=int,
        default=PER_SWEEP[False],
        metavar="K",
        help="runs drawn per sweep (decided ones; any with --ladder), K >= 1 (default "
        f"{PER_SWEEP[False]}, the full report's; more than a sweep holds: all of them)",
    )
    ap.add_argument("--seed", type=int, default=AUDIT_SEED, help="seed of the draw")
    ap.add_argument(
        "--extend-to",
        type=float,
        default=FULL_EXTEND_TO,
        metavar="S",
        help=f"longest recorded time of an extended verdict, S > 0 (default {FULL_EXTEND_TO:g} "
        "s, the full report's)",
    )
    ap.add_argument(
        "--ladder",
        default=None,
        metavar="K,K",
        help="a step ladder instead: each drawn run (any label) classified at dt and at dt/K "
        "for each K, powers of two >= 2 in increasing order (e.g. 2,4,8), and compared with "
        "the finest",
    )
    ap.add_argument("--label", default=None, choices=LABEL_ORDER,
                    help="with --ladder: follow only the runs the sweep labelled so (e.g. "
                    "undetermined)")  # fmt: skip
    ap.add_argument("--workers", type=int, default=None, help="cores (default: all)")
    return ap


def _checked(ap, args) -> tuple[list, tuple[int, ...] | None]:
    """(the figures asked, as numbers and :data:`SENSITIVITY_KEY`; the ladder's halvings or
    None), or exit 2 with one line naming the bad argument."""
    figures = [f.strip() for f in args.figures.split(",")]
    keys = [*map(str, SWEEP_FILES), SENSITIVITY_KEY]
    if not all(f in keys for f in figures):
        ap.error(f"--figures {args.figures}: choose among {', '.join(keys)}")
    if args.per_sweep < 1:
        ap.error(f"--per-sweep {args.per_sweep}: must be at least 1")
    if not 0 < args.extend_to < float("inf"):
        ap.error(f"--extend-to {args.extend_to}: must be a finite number of seconds > 0")
    if args.seed < 0:
        ap.error(f"--seed {args.seed}: must be an integer >= 0")
    halvings = _halvings(args.ladder) if args.ladder is not None else None
    if halvings == ():
        ap.error(f"--ladder {args.ladder}: give powers of two >= 2 in increasing order, e.g. 2,4,8")
    if args.label is not None and halvings is None:
        ap.error(f"--label {args.label}: only with --ladder (the audit takes decided runs)")
    return [f if f == SENSITIVITY_KEY else int(f) for f in figures], halvings


def _halvings(text: str) -> tuple[int, ...]:
    """ "2,4,8" -> (1, 2, 3); () when a value is not a power of two >= 2 or the values do not
    increase."""
    try:
        ks = [int(k) for k in text.split(",")]
    except ValueError:
        return ()
    if not ks or any(k < 2 or k & (k - 1) for k in ks) or ks != sorted(set(ks)):
        return ()
    return tuple(k.bit_length() - 1 for k in ks)


def _ladder(sweeps, halvings: tuple[int, ...], args) -> int:
    """The ladder's lines (one per run: its verdict and exponent at every step) and its
    sentence."""
    from ._ladder import ladder_sentence, step_ladder, step_name

    rows = step_ladder(
        sweeps,
        halvings,
        args.per_sweep,
        args.extend_to,
        workers=args.workers,
        seed=args.seed,
        label=args.label,
    )
    for r in rows:
        rungs = " | ".join(f"{step_name(h)}: {tag} ({lam:+.3f})" for h, tag, lam in r.rungs)
        print(f"{r.figure} | {r.where} | recorded {r.recorded} | {rungs} | {r.seconds:.1f} s")
    print(ladder_sentence(rows) or "no run to follow")
    return 0
