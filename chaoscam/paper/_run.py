"""``chaoscam paper``: run the figure computations of :mod:`._paper`, write the report.

:func:`run_paper` checks every output first (:func:`check_paper_outputs`), runs each stage
(the paper's figures, then the sensitivity sweeps) with its time on stderr, and renders one
self-contained HTML file whose summary sets each figure against the paper;
:func:`figure_script` is the body of ``analyses/figN.py``.
"""

from __future__ import annotations

import numbers
import time
import warnings
from dataclasses import dataclass
from pathlib import Path

import pandas as pd

from ._drawing import drawing, settle
from ._paper import FIGURES, SENSITIVITY, data_files, sensitivity_stage
from ._stage import FATE_S, FULL_EXTEND_TO, QUICK_EXTEND_TO
from ._step_audit import PER_SWEEP, audit_sentence, step_audit, sweep_names
from ._steps import FIG6_STEPS, FULL_STEPS

__all__ = ["RESUME_HINT", "PaperRun", "check_paper_outputs", "figure_script", "run_paper"]


@dataclass(frozen=True)
class PaperRun:
    """What :func:`run_paper` did: the report's path and the stages that failed (each
    "title: failed with Error: message", as the report's "What is missing" names them; a
    failed stage does not stop the others)."""

    path: Path
    failed: tuple[str, ...] = ()


STAGE_TITLES = {
    3: "Fig. 3: line-length draws",
    4: "Fig. 4: bifurcation over l_λ",
    5: "Fig. 5: fractal stiffness",
    6: "Fig. 6: bifurcation over D",
    7: "Figs. 7–10: random line length",
    SENSITIVITY: "why the paper differs: sensitivity sweeps",
}
"""What ``chaoscam paper`` calls each stage (by its first figure number) on the terminal."""


def check_paper_outputs(out: str | Path, figures=None, *, force: bool = False) -> Path:
    """Check the report and every data file the chosen figures will write, before any work.

    The report ``out`` (``.html``) and, in ``OUT_DIR/paper-data``, each file of
    :func:`data_files`: an existing one is refused unless ``force``, naming it; a missing or
    read-only folder, or a ``paper-data`` that is not a folder, is refused too. Returns the
    data folder. Raises :class:`chaoscam.io.OutputError`.
    """
    from ..io import OutputError, check_output

    out = Path(out)
    check_output(out, force=force, suffixes=(".html",))
    outdir = out.parent / "paper-data"
    if outdir.exists() and not outdir.is_dir():
        raise OutputError(f"{outdir} exists and is not a folder; the figures' data go there")
    if outdir.is_dir():
        stages = sorted(set(figures or FIGURES)) + ([] if figures else [SENSITIVITY])
        names = dict.fromkeys(n for f in stages for n in data_files(f))
        elsewhere = (
            "write the report into another folder (--out OTHER/paper.html, its data go to "
            "OTHER/paper-data), pass --resume to continue an interrupted report with them, or "
            "--force to replace them"
        )
        for name in names:
            _check_data_file(
                outdir,
                name,
                force,
                f"{outdir} already holds",
                elsewhere,
                " (the data of an earlier or an interrupted report)",
            )
    return outdir


def _check_data_file(
    outdir: Path, name: str, force: bool, holds: str, elsewhere: str, what: str = ""
) -> None:
    """:func:`chaoscam.io.check_output` for a figure's data file, whose name the user cannot
    choose: an existing one is refused saying where else to write (``elsewhere``), not
    "choose another name"."""
    from ..io import OutputError, check_output

    if (outdir / name).exists() and not force:
        raise OutputError(f"{holds} {name}{what}; nothing was overwritten: {elsewhere}")
    check_output(outdir / name, flag="paper data", force=force)


def run_paper(
    *,
    quick: bool,
    out: str | Path,
    figures=None,
    workers=None,
    command=None,
    echo=False,
    force: bool = False,
    resume: bool = False,
) -> PaperRun:
    """Run the figure scripts and write the report (data and PNGs in ``OUT_DIR/paper-data``).

    Every output is checked first (:func:`check_paper_outputs`), and ``workers`` too
    (:func:`chaoscam.sweep.local_workers`, a ValueError naming it): existing files are
    replaced only with ``force``. With ``echo`` (the command line), each stage's start and
    duration go to stderr and the findings, figure by figure, to stdout. A stage that raises
    is reported in the report's "What is missing" and in :attr:`PaperRun.failed`; the
    others still run. Where the RK4 kernel is not compiled yet (a fresh install), a second
    process compiles some of its callees meanwhile (at its first RK4 run).

    ``resume`` continues an interrupted report in the same folder: each sweep whose output
    is there and finished (same configuration) is read back, the one under way finishes from
    its checkpoint, the rest run (:mod:`._store`); the report is then written over the old
    one, if any. A second run into the same folder (the same ``paper-data``) is refused while
    this one works (:class:`chaoscam.io.OutputLock`), and without ``force`` the report
    is put in place only if its name is still free: a file that appeared there meanwhile is
    kept, and this run's report goes beside it with an ``OutputError`` naming both. When
    every stage failed, an existing report is kept and this run's page, which holds only
    what failed, goes to ``NAME.failed.html`` beside it (:attr:`PaperRun.path`).
    """
    from ..io import OutputLock
    from ..sweep import local_workers
    from ._store import store_mode

    if figures is not None:
        figures = [figures] if isinstance(figures, numbers.Integral) else list(figures)
        unknown = [f for f in figures if f not in FIGURES]
        if not figures or unknown:
            raise ValueError(
                f"figures = {figures}: choose from {sorted(FIGURES)} (None: every figure and "
                "the sensitivity sweeps)"
            )
    if workers is not None:
        local_workers(workers)  # before any work: every sweep would refuse it
    out = Path(out)
    force = force or resume  # a resumed report finishes, and replaces, the same files
    check_paper_outputs(out, figures, force=force)  # the messages, before taking the lock
    # One run at a time per report folder: reports beside each other share paper-data.
    with OutputLock(out.parent / "paper-data", "folder (--out OTHER/paper.html)"):
        outdir = check_paper_outputs(out, figures, force=force)  # again, under the lock
        outdir.mkdir(exist_ok=True)
        with store_mode(force=force, resume=resume):
            return _run_stages(quick, out, outdir, figures, workers, command, echo, force)


def _stage_functions(figures) -> dict:
    """The stages to run: function -> its first figure number (Figs. 7-10 share one), in
    figure order; with ``figures`` None the sensitivity sweeps too."""
    stages: dict = {}
    for number in sorted(set(figures or FIGURES)):
        stages.setdefault(FIGURES[number], min(n for n in FIGURES if FIGURES[n] is FIGURES[number]))
    if figures is None:  # the whole report: also the sweeps that explain the differences
        stages[sensitivity_stage] = SENSITIVITY
    return stages


def _run_each(stages: dict, quick, outdir, workers, say, fail) -> tuple[list, set]:
    """Run each stage, its time on stderr; (the results, the functions that ran). Each
    stage's figures are drawn on one thread while the stages go on (:mod:`._drawing`): a
    stage's seconds are its own work, its figures are settled once every stage has run, and
    a drawing's error fails its stage then."""
    n, drawn, results, ran = len(stages), [], [], set()
    with drawing(), warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)
        for stage, fn in enumerate(stages, 1):
            t0 = time.perf_counter()
            title = STAGE_TITLES.get(stages[fn], fn.__name__)
            say(f"[{stage}/{n}] {title} ...")
            try:
                r = fn(quick, outdir, workers=workers)
            except Exception as err:
                fail(stage, title, err)
                continue
            r.seconds = time.perf_counter() - t0
            say(f"[{stage}/{n}] {title}: {r.seconds:.0f} s")
            drawn.append((stage, title, fn, r))
        for stage, title, fn, r in drawn:
            try:
                settle(r)
            except Exception as err:
                fail(stage, title, err)
                continue
            ran.add(fn)
            results.append(r)
    return results, ran


def _run_stages(quick, out, outdir, figures, workers, command, echo, force) -> PaperRun:
    """The body of :func:`run_paper`, holding the report folder's lock."""
    import sys

    from ..report import ReportParts, write_report

    def say(text: str) -> None:
        if echo:
            print(text, file=sys.stderr, flush=True)

    stages, parts, failed = _stage_functions(figures), ReportParts(), []

    def fail(stage: int, title: str, err: Exception) -> None:  # reported, not hidden
        failed.append(f"{title}: failed with {type(err).__name__}: {err}")
        parts.missing.append(failed[-1])
        say(f"[{stage}/{len(stages)}] {failed[-1]}")

    t_all = time.perf_counter()
    results, ran = _run_each(stages, quick, outdir, workers, say, fail)
    audit, audit_s = _audit_stage(results, quick, workers, say, parts)
    done = [n for n in sorted(set(figures or FIGURES)) if FIGURES[n] in ran]
    if done == sorted(FIGURES):
        done_text = "Figs. 3–10"
    else:
        done_text = (
            f"{'Fig.' if len(done) == 1 else 'Figs.'} {', '.join(map(str, done)) or '(none)'}"
        )
    failures = f" {len(failed)} of {len(stages)} stages failed (see What is missing)."
    parts.summary.append(
        f"{'Quick' if quick else 'Full'} reproduction of the paper's {done_text} "
        f"in {time.perf_counter() - t_all:.0f} s "
        f"({', '.join(f'{r.name}: {r.seconds:.0f} s' for r in results)}"
        + (f", step audit: {audit_s:.0f} s" if audit else "")
        + ")."
        + (failures if failed else "")
    )
    _add_results(parts, results)
    head = _findings(parts, results, audit)
    if echo:
        print("\n".join([parts.summary[0], *head]), flush=True)
    if quick:
        parts.missing.append(QUICK_NOTE)
    title = f"chaoscam: the paper's {done_text} reproduced" + (" (quick run)" if quick else "")
    if failed:
        title += f" (incomplete: {len(failed)} of {len(stages)} stages failed)"
    if not results and out.exists():  # nothing ran: keep the report there, put this one beside
        out, force = out.with_name(f"{out.stem}.failed{out.suffix}"), True
    written = write_report(parts, out, title=title, command=command, replace=force)
    return PaperRun(written, tuple(failed))


def _add_results(parts, results) -> None:
    """Each stage's figures, sweeps, runs, comparisons and findings into the report parts;
    a comparison without an anchor points to its stage's first figure."""
    from ..report import add_bifurcation, add_regime_map, add_trajectory

    for r in results:
        before = (len(parts.paper_figures), len(parts.regime_maps), len(parts.bifurcations))
        parts.paper_figures.extend(r.figures)
        for path, rm, png in r.regime_maps:
            add_regime_map(parts, path, rm, png=png)
        for path, bif, png in r.bifurcations:
            add_bifurcation(parts, path, bif, png=png)
        for path, run, png, verdict in r.trajectories:
            add_trajectory(parts, path, run, png=png, verdict=verdict)
        new = (
            [f.id for f in parts.paper_figures[before[0] :]]
            + [m["figure"].id for m in parts.regime_maps[before[1] :]]
            + [b["figure"].id for b in parts.bifurcations[before[2] :]]
        )
        for c in r.comparisons:
            c.anchor = c.anchor or (new[0] if new else "")
        parts.comparison.extend(r.comparisons)
        parts.missing.extend(r.notes)
        parts.why.extend(r.why)
        parts.why_figures.extend(r.why_figures)


def _findings(parts, results, audit) -> list[str]:
    """The summary's findings, put after its first line: in short, the audit, the tally of
    the comparisons and each of them, and why the paper differs; returned too."""
    tally = pd.Series([c.verdict for c in parts.comparison]).value_counts()
    counted = ", ".join(f"{k}: {v}" for k, v in tally.items())
    head = [line for line in (_in_short(results), audit_sentence(audit)) if line]
    head += [f"Against the paper, figure by figure: {counted} (see the last table)."]
    head += [f"{c.figure}: {c.verdict} — {c.found}" for c in parts.comparison]
    head += [f"Why the paper differs: {line}" for line in parts.why]
    parts.summary[1:1] = head
    return head


QUICK_NOTE = (
    "This is a quick run: coarse grids, few realizations, shorter fractal runs, "
    f"undetermined runs extended to {QUICK_EXTEND_TO:g} s recorded "
    f"({FULL_EXTEND_TO:g} s in the full report) except Fig. 6's, which are not "
    "extended (its labels are those of 8 s runs, 4 s recorded); Figs. 4 and 6 at coarser "
    "steps, at which their labels are not converged (the default dt and "
    f"{FIG6_STEPS[True]} RK4 steps per contact period, {FULL_STEPS} in the full report); "
    "the ξ sweep's and "
    f"(ω, ξ) map's chaotic or undetermined runs continued to {FATE_S[True]:g} s "
    f"({FATE_S[False]:g} s) to see whether they stay in the cam's reach; "
    "the sensitivity sweeps' verdicts not checked at half the step and no step "
    "audit of the figures (both in the full report); "
    "run `chaoscam paper` without --quick for the full grids."
)
"""What a quick report says it left out ("What is missing")."""


def _audit_stage(results, quick, workers, say, parts):
    """The step audit of the paper figures' sweeps (:mod:`._step_audit`; the full run only):
    its rows and seconds. A failure goes to "What is missing" (the figures stand without it,
    so the report is not marked incomplete)."""
    if not PER_SWEEP[quick]:
        return [], 0.0
    t0 = time.perf_counter()
    try:
        sweeps = []
        for r in results:
            if r.number == SENSITIVITY:  # every verdict of these is checked at half the step
                continue
            found = [s for _, s, _ in r.bifurcations] + [s for _, s, _ in r.regime_maps]
            sweeps += zip(sweep_names(r.name, found), found, strict=True)
        if not sweeps:
            return [], 0.0
        say("step audit: the figures' sampled runs at half the step ...")
        rows = step_audit(sweeps, PER_SWEEP[quick], FULL_EXTEND_TO, workers=workers)
    except Exception as err:  # reported, not hidden
        parts.missing.append(f"Step audit: failed with {type(err).__name__}: {err}")
        say(parts.missing[-1])
        return [], 0.0
    seconds = time.perf_counter() - t0
    say(f"step audit: {seconds:.0f} s")
    return rows, seconds


_LABELS = ("periodic", "chaotic", "quasiperiodic", "undetermined")


def _in_short(results) -> str:
    """The summary's first sentence: how the runs of the paper's figures and of the
    sensitivity sweeps are labelled, counted from their tables (each run once; a σ = 0
    cell's one run once)."""
    tables = {False: [], True: []}  # sensitivity stage?
    for r in results:
        for _, sweep, _ in r.bifurcations:
            tables[r.number == SENSITIVITY].append(sweep.verdicts)
        for _, rm, _ in r.regime_maps:
            tables[r.number == SENSITIVITY].append(rm.realizations)

    def counts(frames) -> tuple[int, str, str]:
        if not frames:
            return 0, "", ""
        labels = pd.concat([f["label"] for f in frames], ignore_index=True)
        found = [f"{int((labels == k).sum())} {k}" for k in _LABELS]
        chaos = [f.loc[f["label"] == "chaotic"] for f in frames if "ev_banded_chaos" in f]
        bands = pd.concat([c["ev_banded_chaos"] for c in chaos]).dropna() if chaos else []
        if len(bands):  # chaos on n narrow bands: almost a period n, say so
            kinds = "/".join(f"{int(n)}" for n in sorted(set(bands)))
            found[_LABELS.index("chaotic")] += f" ({len(bands)} of them {kinds}-band chaos)"
        stopped = int((~labels.isin(_LABELS)).sum())
        periods = pd.concat([f.loc[f["label"] == "periodic", "period"] for f in frames])
        shown = sorted({int(p) for p in periods.dropna()})
        return (
            len(labels),
            ", ".join(found) + f", {stopped} out of reach or diverged",
            (f" (periods {', '.join(map(str, shown))})" if shown else ""),
        )

    n_fig, fig_text, fig_periods = counts(tables[False])
    n_sens, sens_text, sens_periods = counts(tables[True])
    if not n_fig:
        return ""
    text = f"In short: the {n_fig} runs of the paper's figures are {fig_text}{fig_periods}."
    if n_sens:
        text += (
            f" The {n_sens} runs of the sensitivity sweeps, which move the stiffness, ξ and ω "
            f"away from Table 1, are {sens_text}{sens_periods}."
        )
    return text


RESUME_HINT = (
    "the finished sweeps are kept (a sweep under way in its .ckpt folder): run the same "
    "command with --resume to continue"
)
"""What an interrupted report or figure script says it kept and how to go on."""


DEFAULT_OUTDIR = "reports/paper-data"
"""Where ``analyses/figN.py`` writes when no OUTDIR is given (created when missing)."""


def figure_script(number: int, argv: list[str] | None = None) -> int:
    """The body of ``analyses/figN.py`` (and, for :data:`SENSITIVITY`,
    ``analyses/sensitivity.py``): run one stage of ``chaoscam paper``, print what it found.

    Usage: ``python analyses/figN.py [--quick] [--force | --resume] [--workers N] [OUTDIR]``
    (default OUTDIR: reports/paper-data, created when missing; a named OUTDIR must exist, as
    the folder of any output named on the command line). The stage's data files
    (:func:`data_files`) are checked before any work, as ``chaoscam paper`` checks them: an
    existing one is replaced only with ``--force`` (the committed ``reports/paper-data``
    holds the full report's data, which a ``--quick`` run would otherwise overwrite), and
    OUTDIR is locked for the run, as ``chaoscam paper`` locks its data folder. Bad
    arguments or outputs (OUTDIR in use included): exit 2 with one line; Ctrl-C: exit 130
    with one line (SIGTERM: 143), saying how to resume. Returns the exit code (0) when it
    finishes.
    """
    import sys

    ap = _script_parser(number)
    args = ap.parse_args(sys.argv[1:] if argv is None else argv)
    outdir = Path(args.outdir)
    held = _script_outputs(ap, args, number)
    fn = sensitivity_stage if number == SENSITIVITY else FIGURES[number]
    result = _script_run(ap.prog, held, args, fn, outdir)
    for c in result.comparisons:
        print(f"{c.figure}: {c.verdict} - {c.found} ({c.reason})")
    for line in result.why:
        print(f"Why the paper differs: {line}")
    print(f"wrote {', '.join(data_files(number))} in {outdir}")
    return 0


def _script_parser(number: int):
    import argparse

    name = "sensitivity" if number == SENSITIVITY else f"fig{number}"
    what = "the sensitivity sweeps" if number == SENSITIVITY else f"Fig. {number}"
    ap = argparse.ArgumentParser(
        prog=f"analyses/{name}.py",
        description=f"Run {what} of the paper report and write its data and PNG into OUTDIR.",
    )
    ap.add_argument(
        "outdir",
        nargs="?",
        default=DEFAULT_OUTDIR,
        metavar="OUTDIR",
        help="folder for the data and PNG (default: reports/paper-data)",
    )
    ap.add_argument("--quick", action="store_true", help="the quick report's grids")
    ap.add_argument("--force", action="store_true", help="replace this stage's files in OUTDIR")
    ap.add_argument("--resume", action="store_true", help="continue an interrupted run")
    ap.add_argument("--workers", type=int, default=None, help="cores (default: all)")
    return ap


def _script_outputs(ap, args, number: int):
    """The checks of a figure script's arguments and outputs, before any work: OUTDIR locked
    (an ExitStack holding its lock), or exit 2 with one line."""
    import contextlib

    from ..io import OutputError, OutputLock
    from ..sweep import local_workers

    outdir = Path(args.outdir)
    held = contextlib.ExitStack()  # OUTDIR's lock, as chaoscam paper takes it
    try:
        if args.workers is not None:
            local_workers(args.workers)  # every sweep of the stage would refuse it
        if args.force and args.resume:
            raise OutputError("--force starts over and --resume continues: give one of them")
        if outdir.exists() and not outdir.is_dir():
            raise OutputError(f"OUTDIR {outdir}: is a file, not a folder")
        if args.outdir != DEFAULT_OUTDIR and not outdir.is_dir():
            raise OutputError(f"OUTDIR {outdir}: no such folder; create it first")
        outdir.mkdir(parents=True, exist_ok=True)  # the default folder is ours to create
        held.enter_context(OutputLock(outdir, "OUTDIR"))
        for file in data_files(number):
            _check_data_file(
                outdir,
                file,
                args.force or args.resume,
                f"OUTDIR {outdir} already holds",
                "give another OUTDIR, pass --resume to continue an interrupted run, or "
                "--force to replace this stage's files",
            )
    except (OutputError, OSError, ValueError) as err:
        held.close()
        ap.error(str(err))  # exit 2
    return held


def _script_run(prog: str, held, args, fn, outdir: Path):
    """Run a figure script's stage holding OUTDIR's lock; SIGTERM is handled as Ctrl-C, as
    the chaoscam command handles it: exit 130 (143) with one line saying how to resume."""
    import signal
    import sys

    from ._store import store_mode

    stopped = {}

    def on_term(signum, frame):
        stopped["term"] = True
        raise KeyboardInterrupt

    before = signal.signal(signal.SIGTERM, on_term)
    try:
        with held, store_mode(force=args.force, resume=args.resume), warnings.catch_warnings():
            warnings.simplefilter("ignore", RuntimeWarning)
            return fn(args.quick, outdir, workers=args.workers)
    except KeyboardInterrupt:
        word = "terminated" if stopped else "interrupted"
        print(f"{prog}: {word}; {RESUME_HINT}", file=sys.stderr)
        raise SystemExit(143 if stopped else 130) from None
    finally:
        signal.signal(signal.SIGTERM, before)
