"""The step audit (sampled decided runs of the figures' sweeps replayed alone, their label must
come back, and classified with ``check_step=True``; it samples, it does not correct), the
step ladder (runs of any label down several halvings), and :func:`audit_script`, the body
of ``analyses/step_audit.py`` over the sweeps a report wrote into its data folder."""

from __future__ import annotations

import argparse
import math
import sys
import time
import warnings
from collections import Counter
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd

from ..numerics import Numerics
from ._findings import verdict_tag
from ._paper import G_FIG6, fig6_tag
from ._side_by_side import side_by_side
from ._stage import FULL_EXTEND_TO

PER_SWEEP = {True: 0, False: 5}  # runs audited per sweep of the paper's figures (quick, full)

AUDIT_SEED = 20261126
"""Seed of the draw: sweeps with as many decided runs are audited at the same rows (paired)."""

LABELS = ("periodic", "quasiperiodic", "chaotic")
"""Labels the audit draws from (an undetermined one has nothing a half step could change)."""


@dataclass(frozen=True)
class AuditRow:
    """One audited run: its verdict ``recorded`` in the figure, ``replayed`` on the grid and at
    ``half`` the step ("not re-run" when undetermined); ``held``: the check kept it."""

    figure: str
    where: str
    recorded: str
    replayed: str
    half: str
    held: bool
    seconds: float

    @property
    def reproduced(self) -> bool:
        return self.replayed == self.recorded


@dataclass(frozen=True)
class LadderRow:
    """One run down the ladder: ``rungs``, (halvings, tag, exponent per iterate or NaN), from 0."""

    figure: str
    where: str
    recorded: str
    rungs: tuple[tuple[int, str, float], ...]
    seconds: float


def sweep_names(name: str, sweeps: list) -> list[str]:
    """``name`` for each of a figure's sweeps, with the parameters in which they differ and the
    step when it is not the default ("Fig. 6 (G = 1e-09, dt = 3.9e-07)"): the audit halves it."""
    if not sweeps:  # Figs. 3 and 5 have no sweep
        return []
    default_dt = Numerics().dt
    bases = [{**s.config["base"], **s.config.get("numerics", {})} for s in sweeps]
    keys = [k for k in bases[0] if len({repr(b.get(k)) for b in bases}) > 1]
    if "dt" not in keys and bases[0].get("dt", default_dt) != default_dt:
        keys.append("dt")  # the same step for all, not the default

    same_base = len(sweeps) > 1 and len({repr(b) for b in bases}) == 1  # axes or windows differ
    names = []
    for i, base in enumerate(bases, start=1):
        values = [(k, base.get(k, default_dt if k == "dt" else None)) for k in keys]
        parts = [f"{k} = {v:g}" if isinstance(v, float) else f"{k} = {v}" for k, v in values]
        parts += [f"sweep {i}"] if same_base else []
        names.append(f"{name} ({', '.join(parts)})" if parts else name)
    return names


def ladder_sample(table: pd.DataFrame, k: int, seed: int = AUDIT_SEED) -> pd.DataFrame:
    """Up to ``k`` rows of ``table`` drawn without replacement with ``seed`` (all when there
    are fewer), in table order."""
    if len(table) <= k:
        return table
    pick = np.random.default_rng(seed).choice(len(table), size=k, replace=False)
    return table.iloc[np.sort(pick)]


def audit_sample(table: pd.DataFrame, k: int, seed: int = AUDIT_SEED) -> pd.DataFrame:
    """:func:`ladder_sample` of the rows labelled as in :data:`LABELS`."""
    return ladder_sample(table[table["label"].isin(LABELS)], k, seed)


def _jobs(sweeps: list[tuple[str, Any]], sample, k: int, seed: int, *extra):
    """``(figure name, sweep, row, *extra)`` for the rows ``sample(table, k, seed)`` draws
    from each sweep's table (a map's realizations, a diagram's verdicts)."""
    for figure, sweep in sweeps:
        table = sweep.realizations if sweep.config["kind"] == "regime_map" else sweep.verdicts
        for row in sample(table, k, seed).to_dict("records"):
            yield figure, sweep, row, *extra


def _where(cfg: dict, row: dict) -> str:
    if cfg["kind"] == "regime_map":
        at = ", ".join(f"{n} = {row[n]:.4g}" for n in (cfg["x"]["name"], cfg["y"]["name"]))
        return f"{at}, realization {int(row['index'])}"
    return f"{cfg['axis']['name']} = {row['value']:.4g}, initial condition {int(row['ic'])}"


def _replayed(job: tuple, check) -> tuple:
    """The fields of a job's row: its names, ``check(sweep, row, *args)`` and its seconds."""
    figure, sweep, row, *args = job
    t0 = time.perf_counter()
    with warnings.catch_warnings():  # the model's warnings came with the sweep's own run
        warnings.simplefilter("ignore", RuntimeWarning)
        found = check(sweep, row, *args)
    recorded = verdict_tag(row["label"], row["period"])
    return figure, _where(sweep.config, row), recorded, *found, time.perf_counter() - t0


def _half_step(sweep, row, extend_to) -> tuple[str, str, bool]:
    """(the replay's tag on the grid, at half the step, whether the check kept it)."""
    from ..sweep import replay
    from ..verdict import classify

    (v,) = classify(replay(sweep, row), check_step=True, extend_to=extend_to)
    check = v.settings.get("step_check", {})
    grid = verdict_tag(check.get("grid_label", v.label), check.get("grid_period", v.period))
    half = verdict_tag(check["label"], check["period"]) if "label" in check else "not re-run"
    return grid, half, v.label != "undetermined" and grid == half


def _audit_one(job: tuple) -> AuditRow:
    return AuditRow(*_replayed(job, _half_step))


def step_audit(sweeps, per_sweep: int, extend_to, workers=None, *, seed=AUDIT_SEED):
    """Audit ``per_sweep`` runs drawn with ``seed`` from each ``(figure name, sweep)``, verdicts
    extended up to ``extend_to`` s recorded, on ``workers`` threads."""
    jobs = list(_jobs(sweeps, audit_sample, per_sweep, seed, extend_to))
    return side_by_side(_audit_one, jobs, workers, prefix="chaoscam-audit")


def _count(n: int, one: str, many: str) -> str:
    return f"{n} {one if n == 1 else many}"


def audit_sentence(rows: list[AuditRow]) -> str:
    """The summary's sentence on the audit: how many runs were reproduced, kept their label
    at half the step, are undetermined there, or got another label (those two named)."""
    if not rows:
        return ""
    n = len(rows)
    figures = list(dict.fromkeys(r.figure for r in rows))
    same = [r for r in rows if r.reproduced]
    undecided = [r for r in same if not r.held and r.half.startswith("undetermined")]
    other = [r for r in same if not r.held and r not in undecided]
    lost = [r for r in rows if not r.reproduced]
    text = (
        f"Step audit: {n} run{'s' * (n != 1)} labelled periodic, quasiperiodic or chaotic, "
        f"drawn from {', '.join(figures)}, {'was' if n == 1 else 'were'} replayed alone and "
        f"classified again with the step halved ({sum(r.seconds for r in rows):.0f} s of "
        f"work): {_count(len(same), 'reproduces its', 'reproduce their')} label; "
        f"at half the step {_count(sum(r.held for r in same), 'keeps', 'keep')} it, "
        f"{_count(len(undecided), 'is', 'are')} undetermined and "
        f"{_count(len(other), 'gets', 'get')} another label"
    )
    for what, group in (("Undetermined at half the step", undecided), ("Another label", other)):
        if group:
            items = "; ".join(f"{r.figure} at {r.where}: {r.replayed} → {r.half}" for r in group)
            text += f". {what}: {items}"
    if lost:
        text += ". Not reproduced: " + "; ".join(
            f"{r.figure} at {r.where} (recorded {r.recorded}, replayed {r.replayed})" for r in lost
        )
    return text + ". The figures keep their labels: the audit samples them, it does not correct."


def _rungs(sweep, row, halvings, extend_to) -> tuple:
    """(the rungs,): a run that did not end normally is labelled by its status, as in a sweep."""
    from ..sweep import replay, verdict_fields
    from ..verdict import classify

    rungs = []
    for h in (0, *halvings):
        run = replay(sweep, row, refine=h)
        if not run.ok:
            rungs.append((h, run.status.label, math.nan))
            continue
        fields = verdict_fields(classify(run, extend_to=extend_to)[0])
        tag = verdict_tag(fields["label"], fields["period"])
        rungs.append((h, tag, fields["evidence"].get("exponent", math.nan)))
    return (tuple(rungs),)


def _ladder_one(job: tuple) -> LadderRow:
    return LadderRow(*_replayed(job, _rungs))


def step_ladder(sweeps, halvings, per_sweep: int, extend_to, workers=None, *, seed=AUDIT_SEED,
                label: str | None = None) -> list[LadderRow]:  # fmt: skip
    """``per_sweep`` runs (labelled ``label`` if given) of each sweep, each classified at its step
    and at ``dt / 2**h`` for each ``h`` in ``halvings``, as :func:`step_audit` runs them."""

    def sample(table, k, seed):
        return ladder_sample(table if label is None else table[table["label"] == label], k, seed)

    jobs = list(_jobs(sweeps, sample, per_sweep, seed, tuple(halvings), extend_to))
    return side_by_side(_ladder_one, jobs, workers, prefix="chaoscam-ladder")


def step_name(h: int) -> str:
    """The step after ``h`` halvings: "dt", "dt/2", "dt/4", ..."""
    return "dt" if h == 0 else f"dt/{2**h}"


def ladder_sentence(rows: list[LadderRow]) -> str:
    """Each rung against the finest: labels that agree, and the median and largest change of
    the exponent (runs with an exponent at both rungs)."""
    if not rows:
        return ""
    steps = [h for h, _, _ in rows[0].rungs]
    parts = []
    for i, h in enumerate(steps[:-1]):
        same = sum(r.rungs[i][1] == r.rungs[-1][1] for r in rows)
        moved = [abs(r.rungs[i][2] - r.rungs[-1][2]) for r in rows]
        moved = [m for m in moved if not math.isnan(m)]
        parts.append(f"at {step_name(h)} {same} of {len(rows)} labels agree")
        if moved:
            med, top = np.median(moved), max(moved)
            parts[-1] += f", the exponent by a median of {med:.3f} per iterate (largest {top:.3f})"
    figures = ", ".join(dict.fromkeys(r.figure for r in rows))
    text = (
        f"Step ladder: {len(rows)} runs of {figures} classified at "
        f"{', '.join(map(step_name, steps))} ({sum(r.seconds for r in rows):.0f} s of work). "
        f"Against {step_name(steps[-1])}: " + "; ".join(parts) + "."
    )
    if len(steps) < 2:
        return text
    found = Counter(t for t in map(settled, rows) if t is not None)  # in order of appearance
    counts = ", ".join(f"{t} {n}" for t, n in found.items())
    return text + (
        f" Settled (one decided label at {', '.join(map(step_name, steps[1:]))}): "
        f"{found.total()} of {len(rows)}" + (f" ({counts})" if found else "") + "."
    )


def settled(row: LadderRow) -> str | None:
    """The decided label ``row`` keeps at every halved step (every rung but the sweep's own);
    None when those rungs disagree, are undetermined, or there are none."""
    tags = {tag for h, tag, _ in row.rungs if h > 0}
    if len(tags) != 1:
        return None
    (tag,) = tags
    return None if tag == "undetermined" else tag


SWEEP_FILES = {
    4: ("Fig. 4", ["fig4.parquet"]),
    6: ("Fig. 6", [f"{fig6_tag(g)}.parquet" for g in G_FIG6]),
    7: ("Figs. 7–10", ["fig7-10.parquet"]),
}
"""The paper figures that are sweeps: number -> (name, their files in the data folder)."""

SENSITIVITY_KEY = "s"
"""``--figures`` names so every ``sensitivity-*.parquet`` of the folder, each by its file."""


def read_sweeps(folder: Path, figures) -> list[tuple[str, object]]:
    """``(name, sweep)`` for each of ``figures`` (:data:`SWEEP_FILES` keys, :data:`SENSITIVITY_KEY`)
    in ``folder``; FileNotFoundError naming a missing file and the command that writes it."""
    out = []
    for number in figures:
        if number == SENSITIVITY_KEY:
            paths = sorted(
                p
                for p in folder.glob("sensitivity-*.parquet")
                if not p.name.endswith((".verdicts.parquet", ".cells.parquet"))
            )
            if not paths:
                raise FileNotFoundError(f"{folder}: no sensitivity-*.parquet: write them with "
                                        f"{_how(folder, number)}")  # fmt: skip
            out += [(p.stem, _read_sweep(p)) for p in paths]
            continue
        name, files = SWEEP_FILES[number]
        for path in (folder / file for file in files):
            if not path.is_file():
                raise FileNotFoundError(f"{path} is missing: write it with {_how(folder, number)}")
        found = [_read_sweep(folder / file) for file in files]
        out += zip(sweep_names(name, found), found, strict=True)
    return out


def _how(folder: Path, number) -> str:
    """The command that writes figure ``number``'s data (or the sensitivity sweeps')."""
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


def audit_script(argv: list[str] | None = None) -> int:
    """The body of ``analyses/step_audit.py``. Bad arguments or a missing data file: exit 2
    with one line; Ctrl-C: exit 130 with one line. Returns 0 when it finishes."""
    from ..sweep import LABEL_ORDER, local_workers

    ap = argparse.ArgumentParser(
        prog="analyses/step_audit.py",
        description="Replay sampled runs of a report's figure sweeps and classify them again "
        "with the step halved (the full report's step audit, at any size).",
    )
    # fmt: off
    ap.add_argument("folder", nargs="?", default="reports/paper-data", metavar="DATA",
                    help="the report's data folder (default: reports/paper-data)")
    ap.add_argument("--figures", default=",".join(map(str, SWEEP_FILES)), metavar="N,N",
                    help="which figures' sweeps, comma-separated (default: 4,6,7; 7 stands for "
                    f"Figs. 7-10, {SENSITIVITY_KEY} for every sensitivity-*.parquet of the folder)")
    ap.add_argument("--per-sweep", type=int, default=PER_SWEEP[False], metavar="K",
                    help="runs drawn per sweep (decided ones; any with --ladder), K >= 1 (default "
                    f"{PER_SWEEP[False]}, the full report's; more than a sweep holds: all of them)")
    ap.add_argument("--seed", type=int, default=AUDIT_SEED, help="seed of the draw")
    ap.add_argument("--extend-to", type=float, default=FULL_EXTEND_TO, metavar="S",
                    help="longest recorded time of an extended verdict, S > 0 (default "
                    f"{FULL_EXTEND_TO:g} s, the full report's)")
    ap.add_argument("--ladder", default=None, metavar="K,K",
                    help="a step ladder instead: each drawn run (any label) classified at dt and "
                    "at dt/K for each K, powers of two >= 2 in increasing order (e.g. 2,4,8), and "
                    "compared with the finest")
    ap.add_argument("--label", default=None, choices=LABEL_ORDER,
                    help="with --ladder: follow only the runs the sweep labelled so (e.g. "
                    "undetermined)")
    ap.add_argument("--workers", type=int, default=None, help="cores (default: all)")
    # fmt: on
    args = ap.parse_args(sys.argv[1:] if argv is None else argv)
    figures, halvings = _checked(ap, args)
    try:
        if args.workers is not None:
            local_workers(args.workers)
        sweeps = read_sweeps(Path(args.folder), dict.fromkeys(figures))
    except (OSError, ValueError) as err:
        ap.error(str(err))  # exit 2
    kw = dict(workers=args.workers, seed=args.seed)
    try:
        if halvings:
            rows = step_ladder(sweeps, halvings, args.per_sweep, args.extend_to, **kw,
                               label=args.label)  # fmt: skip
        else:
            rows = step_audit(sweeps, args.per_sweep, args.extend_to, **kw)
    except KeyboardInterrupt:
        print(f"{ap.prog}: interrupted; nothing was written", file=sys.stderr)
        raise SystemExit(130) from None
    for r in rows:
        if halvings:
            steps = " | ".join(f"{step_name(h)}: {tag} ({lam:+.3f})" for h, tag, lam in r.rungs)
        else:
            steps = f"dt: {r.replayed} | dt/2: {r.half} | {'holds' if r.held else 'CHANGES'}"
        print(f"{r.figure} | {r.where} | recorded {r.recorded} | {steps} | {r.seconds:.1f} s")
    if halvings:
        print(ladder_sentence(rows) or "no run to follow")
    else:
        print(audit_sentence(rows) or "no decided run to audit")
    return 0


def _checked(ap, args) -> tuple[list, tuple[int, ...] | None]:
    """(the figures asked; the ladder's halvings or None), or exit 2 naming the argument."""
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
    halvings = None
    if args.ladder is not None:  # "2,4,8" -> (1, 2, 3)
        try:
            ks = [int(k) for k in args.ladder.split(",")]
        except ValueError:
            ks = []
        if not ks or any(k < 2 or k & (k - 1) for k in ks) or ks != sorted(set(ks)):
            ap.error(
                f"--ladder {args.ladder}: give powers of two >= 2 in increasing order, e.g. 2,4,8"
            )
        halvings = tuple(k.bit_length() - 1 for k in ks)
    if args.label is not None and halvings is None:
        ap.error(f"--label {args.label}: only with --ladder (the audit takes decided runs)")
    return [f if f == SENSITIVITY_KEY else int(f) for f in figures], halvings
