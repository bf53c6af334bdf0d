"""``chaoscam paper``: run the stages of :mod:`._paper`, write the report through
:mod:`chaoscam.report`; :func:`figure_script` is the body of ``analyses/figN.py``."""

from __future__ import annotations

import argparse
import contextlib
import functools
import numbers
import signal
import sys
import time
import warnings
from dataclasses import dataclass
from pathlib import Path

import pandas as pd

from ..io import OutputError, OutputLock, check_output
from ..report import (
    ReportParts,
    add_bifurcation,
    add_regime_map,
    add_trajectory,
    frame_tags,
    in_words,
    mostly,
    write_report,
)
from ._paper import FIG6_STEPS, FIGURES, FULL_STEPS, SENSITIVITY, data_files, sensitivity_stage
from ._stage import FATE_S, FULL_EXTEND_TO, QUICK_EXTEND_TO, drawing, settle, store_mode
from ._step_audit import PER_SWEEP, audit_sentence, step_audit, sweep_names


@dataclass(frozen=True)
class PaperRun:
    """What :func:`run_paper` did: the report's path, the stages that failed ("title: failed
    with Error: message", as the report's "What is missing" names them)."""

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

RESUME_HINT = (
    "the finished sweeps are kept (a sweep under way in its .ckpt folder): run the same "
    "command with --resume to continue"
)
"""What an interrupted report or figure script says it kept and how to go on."""

DEFAULT_OUTDIR = "reports/paper-data"
"""Where ``analyses/figN.py`` writes when no OUTDIR is given (created when missing)."""

QUICK_NOTE = (
    "This is a quick run: coarse grids, few realizations, shorter fractal runs, undetermined "
    f"runs extended to {QUICK_EXTEND_TO:g} s recorded ({FULL_EXTEND_TO:g} s in the full report) "
    "except Fig. 6's, which are not extended (its labels are those of 8 s runs, 4 s recorded); "
    "Figs. 4 and 6 at coarser steps, at which their labels are not converged (the default dt "
    f"and {FIG6_STEPS[True]} RK4 steps per contact period, {FULL_STEPS} in the full report); "
    f"the ξ sweep's and (ω, ξ) map's chaotic or undetermined runs continued to {FATE_S[True]:g} "
    f"s ({FATE_S[False]:g} s) to see whether they stay in the cam's reach; the sensitivity "
    "sweeps' verdicts not checked at half the step and no step audit of the figures (both in "
    "the full report); run `chaoscam paper` without --quick for the full grids."
)
"""What a quick report says it left out ("What is missing")."""


def check_paper_outputs(out: str | Path, figures=None, *, force: bool = False) -> Path:
    """Check the report ``out`` (``.html``) and every data file the chosen figures will write in
    ``OUT_DIR/paper-data`` before any work (existing ones only with ``force``); returns the data
    folder. Raises :class:`chaoscam.io.OutputError`."""
    out = Path(out)
    check_output(out, force=force, suffixes=(".html",))
    outdir = out.parent / "paper-data"
    if outdir.exists() and not outdir.is_dir():
        raise OutputError(f"{outdir} exists and is not a folder; the figures' data go there")
    if outdir.is_dir():
        stages = sorted(set(figures or FIGURES)) + ([] if figures else [SENSITIVITY])
        names = dict.fromkeys(n for f in stages for n in data_files(f))
        _check_data_files(outdir, names, force, f"{outdir} already holds",
                          "write the report into another folder (--out OTHER/paper.html, its data "
                          "go to OTHER/paper-data), pass --resume to continue an interrupted "
                          "report with them, or --force to replace them",
                          " (the data of an earlier or an interrupted report)")  # fmt: skip
    return outdir


def _check_data_files(outdir: Path, names, force, holds: str, elsewhere: str, what="") -> None:
    """:func:`chaoscam.io.check_output` for data files, whose names the user cannot choose:
    an existing one is refused saying where else to write, not "choose another name"."""
    for name in names:
        if (outdir / name).exists() and not force:
            raise OutputError(f"{holds} {name}{what}; nothing was overwritten: {elsewhere}")
        check_output(outdir / name, flag="paper data", force=force)


def run_paper(*, quick: bool, out: str | Path, figures=None, workers=None, command=None,
              echo=False, force: bool = False, resume: bool = False) -> PaperRun:  # fmt: skip
    """Run the paper's stages (``figures``: numbers of :data:`FIGURES`; None: every figure and
    the sensitivity sweeps) and write the report ``out`` (``.html``, its data and PNGs in
    ``OUT_DIR/paper-data``), on the quick report's grids or the full one's.

    Every output and ``workers`` are checked before any work; existing files are replaced
    only with ``force``; ``resume`` continues an interrupted report (finished sweeps are read
    back, the one under way finishes from its checkpoint). ``echo``: stage times to stderr,
    the findings to stdout. A stage that raises is named in "What is missing" and
    :attr:`PaperRun.failed`; when all fail, an existing report is kept and this page goes to
    ``NAME.failed.html``. A second run into the same ``paper-data`` is refused meanwhile."""
    from ..sweep import local_workers

    if figures is not None:
        figures = [figures] if isinstance(figures, numbers.Integral) else list(figures)
        if not figures or [f for f in figures if f not in FIGURES]:
            raise ValueError(
                f"figures = {figures}: choose from {sorted(FIGURES)} (None: every figure and "
                "the sensitivity sweeps)"
            )
    if workers is not None:
        local_workers(workers)  # before any work: every sweep would refuse it
    out = Path(out)
    force = force or resume  # a resumed report finishes, and replaces, the same files
    check_paper_outputs(out, figures, force=force)  # the messages, before taking the lock
    with OutputLock(out.parent / "paper-data", "folder (--out OTHER/paper.html)"):
        outdir = check_paper_outputs(out, figures, force=force)  # again, under the lock
        outdir.mkdir(exist_ok=True)
        with store_mode(force=force, resume=resume):
            return _run_stages(quick, out, outdir, figures, workers, command, echo, force)


def _run_each(stages: dict, quick, outdir, workers, say, fail) -> tuple[list, set]:
    """Run each stage, its time on stderr; (the results, the functions that ran). A drawing's
    error fails its stage when it is settled, once every stage has run."""
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
                ran.add(fn)
                results.append(r)
            except Exception as err:
                fail(stage, title, err)
    return results, ran


def _run_stages(quick, out, outdir, figures, workers, command, echo, force) -> PaperRun:
    """The body of :func:`run_paper`, holding the report folder's lock."""
    say = functools.partial(print, file=sys.stderr, flush=True) if echo else lambda text: None
    stages, parts, failed = {}, ReportParts(paper=True), []  # stages: function -> first number
    for number in sorted(set(figures or FIGURES)):
        stages.setdefault(FIGURES[number], min(n for n in FIGURES if FIGURES[n] is FIGURES[number]))
    if figures is None:  # the whole report: the sweeps that explain the differences too
        stages[sensitivity_stage] = SENSITIVITY

    def fail(stage: int, title: str, err: Exception) -> None:  # reported, not hidden
        failed.append(f"{title}: failed with {type(err).__name__}: {err}")
        parts.missing.append(failed[-1])
        say(f"[{stage}/{len(stages)}] {failed[-1]}")

    t_all = time.perf_counter()
    results, ran = _run_each(stages, quick, outdir, workers, say, fail)
    audit, audit_s = _audit_stage(results, quick, workers, say, parts)
    done = [n for n in sorted(set(figures or FIGURES)) if FIGURES[n] in ran]
    done_text = f"{'Fig.' if len(done) == 1 else 'Figs.'} {', '.join(map(str, done)) or '(none)'}"
    done_text = "Figs. 3–10" if done == sorted(FIGURES) else done_text
    times = ", ".join(f"{r.name}: {r.seconds:.0f} s" for r in results)
    times += f", step audit: {audit_s:.0f} s" if audit else ""
    summary = f"{'Quick' if quick else 'Full'} reproduction of the paper's {done_text} in "
    summary += f"{time.perf_counter() - t_all:.0f} s ({times})."
    if failed:
        summary += f" {len(failed)} of {len(stages)} stages failed (see What is missing)."
    parts.summary.append(summary)
    _add_results(parts, results)
    parts.headline = paper_headline(results, parts.comparison, lead=parts.lead is not None)
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
    for r in results:
        before = (len(parts.paper_figures), len(parts.regime_maps), len(parts.bifurcations))
        parts.paper_figures.extend(r.figures)
        for path, rm, png in r.regime_maps:
            add_regime_map(parts, path, rm, png=png)
            if Path(path).name == OMEGA_XI:  # the figure the answer leads with
                parts.lead = parts.regime_maps[-1]["figure"]
        for path, bif, png in r.bifurcations:
            add_bifurcation(parts, path, bif, png=png)
        for path, run, png, verdict in r.trajectories:
            add_trajectory(parts, path, run, png=png, verdict=verdict)
        new = parts.paper_figures[before[0] :] + [
            t["figure"] for t in parts.regime_maps[before[1] :] + parts.bifurcations[before[2] :]
        ]
        for c in r.comparisons:
            c.anchor = c.anchor or (new[0].id if new else "")
        parts.comparison.extend(r.comparisons)
        parts.why.extend(r.why)
        parts.why_figures.extend(r.why_figures)


def _findings(parts, results, audit) -> list[str]:
    """The summary's findings, put after its first line (and returned): in short, the audit,
    the tally of the comparisons and each of them, and why the paper differs."""
    tally = pd.Series([c.verdict for c in parts.comparison]).value_counts()
    counted = ", ".join(f"{k}: {v}" for k, v in tally.items())
    head = [line for line in (_in_short(results), audit_sentence(audit)) if line]
    head += [f"Against the paper, figure by figure: {counted} (see the last table)."]
    head += [f"{c.figure}: {c.verdict} — {c.found}" for c in parts.comparison]
    head += [f"Why the paper differs: {line}" for line in parts.why]
    parts.summary[1:1] = head
    return head


def _audit_stage(results, quick, workers, say, parts):
    """The step audit of the paper figures' sweeps (the full run only): its rows and seconds.
    A failure goes to "What is missing"; the report is not marked incomplete."""
    if not PER_SWEEP[quick]:
        return [], 0.0
    t0 = time.perf_counter()
    try:
        sweeps = []
        for r in (r for r in results if r.number != SENSITIVITY):  # those are all checked
            found = [s for _, s, _ in r.bifurcations + r.regime_maps]
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


OMEGA_XI = "sensitivity-omega-xi.parquet"
"""The (ω, ξ) map: the figure the paper report's answer leads with, when it was made."""


def _and(items: list[str]) -> str:
    return items[0] if len(items) == 1 else ", ".join(items[:-1]) + " and " + items[-1]


def paper_headline(results, comparisons, *, lead: bool = False) -> list[str]:
    """The paper report's answer, computed from its verdicts: the regimes of each figure's
    runs (where the paper looks), which figures agree and differ, and (``lead``: the
    (ω, ξ) map is the figure shown with it) the regimes away from Table 1."""
    found, every = [], []
    for r in (r for r in results if r.number != SENSITIVITY):
        tags = [t for _, b, _ in r.bifurcations for t in frame_tags(b.verdicts)]
        tags += [t for _, m, _ in r.regime_maps for t in frame_tags(m.realizations)]
        if tags:
            what = STAGE_TITLES.get(r.number, r.name).split(": ", 1)[-1]
            found.append(f"{r.name} ({what}): {mostly(tags)}")
            every += tags
    lines = []
    if found:
        top = pd.Series(every).value_counts().index[0]
        text = f"Where the paper looks, the motion is mostly {top}: " + "; ".join(found) + "."
        if top.endswith("-band chaos"):
            n = top.split("-")[0]
            text += f" That is chaos on {n} narrow bands: at full scale it looks like period {n}"
            text += " (the bifurcation diagrams zoom on a band)."
        lines.append(text)
    verbs = {"agrees": ("agrees", "agree"), "differs": ("differs", "differ"),
             "not comparable": ("is not comparable", "are not comparable")}  # fmt: skip
    by = {v: [c.figure for c in comparisons if c.verdict == v] for v in verbs}
    said = [f"{_and(f)} {verbs[v][len(f) > 1]}" for v, f in by.items() if f]
    if said:
        lines.append("Against the paper's claims: " + "; ".join(said) + ".")
    maps = [m for r in results for p, m, _ in r.regime_maps if Path(p).name == OMEGA_XI]
    if maps and lead:
        cells = maps[0].cells
        periodic = cells.loc[cells["dominant"] == "periodic", "period"].dropna()
        periods = sorted({int(p) for p in periodic})
        notes = {"periodic": f" (periods {', '.join(map(str, periods))})"} if periods else {}
        text = in_words(cells["dominant"], "cells of the (ω, ξ) map shown here", notes=notes)
        lines.append("Away from Table 1 the regime moves with what the paper leaves open: "
                     + text[0].lower() + text[1:] + ".")  # fmt: skip
    return lines


_LABELS = ("periodic", "chaotic", "quasiperiodic", "undetermined")


def _label_counts(frames) -> tuple[int, str]:
    """(how many runs, their labels in words with the band counts and periods)."""
    if not frames:
        return 0, ""
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
    text = ", ".join(found) + f", {stopped} out of reach or diverged"
    return len(labels), text + (f" (periods {', '.join(map(str, shown))})" if shown else "")


def _in_short(results) -> str:
    """The summary's first sentence: the labels of the runs of the paper's figures and,
    apart, of the sensitivity sweeps, counted from their tables."""
    tables = {False: [], True: []}  # sensitivity stage?
    for r in results:
        tables[r.number == SENSITIVITY] += [s.verdicts for _, s, _ in r.bifurcations]
        tables[r.number == SENSITIVITY] += [m.realizations for _, m, _ in r.regime_maps]
    (n_fig, fig_text), (n_sens, sens_text) = map(_label_counts, (tables[False], tables[True]))
    if not n_fig:
        return ""
    text = f"In short: the {n_fig} runs of the paper's figures are {fig_text}."
    if n_sens:
        text += (
            f" The {n_sens} runs of the sensitivity sweeps, which move the stiffness, ξ and ω "
            f"away from Table 1, are {sens_text}."
        )
    return text


def figure_script(number: int, argv: list[str] | None = None) -> int:
    """The body of ``analyses/figN.py`` (``analyses/sensitivity.py`` for :data:`SENSITIVITY`):
    ``[--quick] [--force | --resume] [--workers N] [OUTDIR]`` runs one stage of ``chaoscam
    paper`` into OUTDIR (default reports/paper-data; a named one must exist), its files
    checked and OUTDIR locked as ``chaoscam paper`` does, and prints what it found. Bad
    arguments: exit 2; Ctrl-C: 130 (SIGTERM: 143), each with one line. Returns 0."""
    name = "sensitivity" if number == SENSITIVITY else f"fig{number}"
    what = "the sensitivity sweeps" if number == SENSITIVITY else f"Fig. {number}"
    ap = argparse.ArgumentParser(
        prog=f"analyses/{name}.py",
        description=f"Run {what} of the paper report and write its data and PNG into OUTDIR.",
    )
    # fmt: off
    ap.add_argument("outdir", nargs="?", default=DEFAULT_OUTDIR, metavar="OUTDIR",
                    help="folder for the data and PNG (default: reports/paper-data)")
    ap.add_argument("--quick", action="store_true", help="the quick report's grids")
    ap.add_argument("--force", action="store_true", help="replace this stage's files in OUTDIR")
    ap.add_argument("--resume", action="store_true", help="continue an interrupted run")
    ap.add_argument("--workers", type=int, default=None, help="cores (default: all)")
    # fmt: on
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


def _script_outputs(ap, args, number: int):
    """A figure script's arguments and outputs checked before any work: an ExitStack holding
    OUTDIR's lock, or exit 2 with one line."""
    from ..sweep import local_workers

    outdir = Path(args.outdir)
    held = contextlib.ExitStack()
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
        _check_data_files(outdir, data_files(number), args.force or args.resume,
                          f"OUTDIR {outdir} already holds", "give another OUTDIR, pass --resume "
                          "to continue an interrupted run, or --force to replace this stage's "
                          "files")  # fmt: skip
    except (OutputError, OSError, ValueError) as err:
        held.close()
        ap.error(str(err))  # exit 2
    return held


def _script_run(prog: str, held, args, fn, outdir: Path):
    """Run a figure script's stage holding OUTDIR's lock; SIGTERM is handled as Ctrl-C, as
    the chaoscam command handles it: exit 130 (143) with one line saying how to resume."""
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
