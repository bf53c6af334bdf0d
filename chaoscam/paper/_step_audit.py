"""A step audit of the paper figures' verdicts: do a sample of them hold at half the step?

The paper's figures hold over a thousand runs; checking each one at dt / 2 would double the
full report's time, and its sensitivity sweeps do check every one (``CHECK_STEP``). Here, from
each of the figures' sweeps, :data:`PER_SWEEP` runs labelled periodic, quasiperiodic or
chaotic are drawn (seeded, without replacement) and each is

1. replayed alone (:func:`chaoscam.sweep.replay`): its label must come back, which checks
   that the audit looks at the run the figure shows;
2. classified with ``check_step=True`` and the report's ``extend_to``: an undetermined verdict,
   on the grid or at half the step, is extended as the sweeps extend it (the grid verdict
   comes back as the figure has it; the half-step run may need longer to settle: measured on
   Fig. 4's and Figs. 7-10's runs, chaotic on 10 s recorded at dt, undetermined on 10 s at
   dt / 2, chaotic on 40 s).

The summary says how many were reproduced, how many keep their label at half the step, how
many are undetermined there and how many get another label, naming the last two. A run that
changes is not relabelled in the figure: the audit samples, it does not correct.
"""

from __future__ import annotations

import time
import warnings
from dataclasses import dataclass
from typing import Any

import numpy as np
import pandas as pd

from ._findings import verdict_tag
from ._side_by_side import side_by_side

__all__ = [
    "PER_SWEEP",
    "AuditRow",
    "audit_sample",
    "audit_sentence",
    "draw_rows",
    "sampled_rows",
    "step_audit",
    "sweep_names",
]

PER_SWEEP = {True: 0, False: 5}
"""Runs audited per sweep of the paper's figures (quick, full): the full report's four sweeps
(Fig. 4, Fig. 6's two, Figs. 7-10's map) give 20 runs; the quick report audits none."""

AUDIT_SEED = 20261126
"""Seed of the draw of audited runs (fixed: the same report audits the same runs). Every
sweep is drawn with it, so sweeps with as many decided runs are audited at the same rows:
Fig. 6's two diagrams (one D grid) at the same values of D, a paired comparison of the two
roughnesses."""

LABELS = ("periodic", "quasiperiodic", "chaotic")
"""Labels the audit draws from (undetermined ones have nothing a half step could change)."""


@dataclass(frozen=True)
class AuditRow:
    """One audited run: ``figure`` and ``where`` name it; ``recorded`` is its verdict as the
    figure has it, ``replayed`` the replay's on the grid, ``half`` the one at dt / 2 ("not
    re-run" when the replay came back undetermined), each "label" or "periodic N"; ``held``
    whether the check kept the verdict; ``seconds`` the work it took."""

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


def sweep_names(name: str, sweeps: list) -> list[str]:
    """``name`` for each of a figure's sweeps, with the base parameters in which they differ
    and numerics when there are several (Fig. 6: "Fig. 6 (G = 1e-09, dt = 3.9e-07)") and
    with their step when it is not the default (Fig. 4: "Fig. 4 (dt = 3.8e-07)"): what the
    audit halves is that step."""
    from ..numerics import Numerics

    if not sweeps:  # Figs. 3 and 5 have no sweep
        return []
    default_dt = Numerics().dt
    bases = [{**s.config["base"], **s.config.get("numerics", {})} for s in sweeps]
    keys = [k for k in bases[0] if len({repr(b.get(k)) for b in bases}) > 1]
    if "dt" not in keys and bases[0].get("dt", default_dt) != default_dt:
        keys.append("dt")  # the same step for all, not the default

    def text(v) -> str:
        return f"{v:g}" if isinstance(v, float) else str(v)

    same_base = len(sweeps) > 1 and len({repr(b) for b in bases}) == 1  # axes or windows differ
    names = []
    for i, base in enumerate(bases, start=1):
        parts = [f"{k} = {text(base.get(k, default_dt if k == 'dt' else None))}" for k in keys]
        parts += [f"sweep {i}"] if same_base else []
        names.append(f"{name} ({', '.join(parts)})" if parts else name)
    return names


def draw_rows(table: pd.DataFrame, k: int, seed: int = AUDIT_SEED) -> pd.DataFrame:
    """Up to ``k`` rows of ``table``, drawn without replacement with ``seed`` (all of them
    when there are fewer), in table order."""
    if len(table) <= k:
        return table
    pick = np.random.default_rng(seed).choice(len(table), size=k, replace=False)
    return table.iloc[np.sort(pick)]


def audit_sample(table: pd.DataFrame, k: int, seed: int = AUDIT_SEED) -> pd.DataFrame:
    """Up to ``k`` rows of a sweep's table labelled as in :data:`LABELS`, drawn with
    :func:`draw_rows`."""
    return draw_rows(table[table["label"].isin(LABELS)], k, seed)


def sampled_rows(sweeps: list[tuple[str, Any]], sample, k: int, seed: int):
    """``(figure name, sweep, row)`` for the rows ``sample(table, k, seed)`` draws from each
    ``(figure name, sweep)``'s table (a map's realizations, a diagram's verdicts): what a job
    of the audit or the ladder starts from."""
    for figure, sweep in sweeps:
        table = sweep.realizations if sweep.config["kind"] == "regime_map" else sweep.verdicts
        for row in sample(table, k, seed).to_dict("records"):
            yield figure, sweep, row


def _where(cfg: dict, row: dict) -> str:
    if cfg["kind"] == "regime_map":
        names = (cfg["x"]["name"], cfg["y"]["name"])
        at = ", ".join(f"{n} = {row[n]:.4g}" for n in names)
        return f"{at}, realization {int(row['index'])}"
    return f"{cfg['axis']['name']} = {row['value']:.4g}, initial condition {int(row['ic'])}"


def _audit_one(job: tuple) -> AuditRow:
    """Replay one run and check it at half the step."""
    from ..sweep import replay
    from ..verdict import classify

    figure, sweep, row, extend_to = job
    t0 = time.perf_counter()
    with warnings.catch_warnings():  # the model's warnings came with the sweep's own run
        warnings.simplefilter("ignore", RuntimeWarning)
        (v,) = classify(replay(sweep, row), check_step=True, extend_to=extend_to)
    check = v.settings.get("step_check", {})
    grid = verdict_tag(check.get("grid_label", v.label), check.get("grid_period", v.period))
    half = verdict_tag(check["label"], check["period"]) if "label" in check else "not re-run"
    return AuditRow(
        figure,
        _where(sweep.config, row),
        verdict_tag(row["label"], row["period"]),
        grid,
        half,
        v.label != "undetermined" and grid == half,
        time.perf_counter() - t0,
    )


def step_audit(
    sweeps: list[tuple[str, Any]],
    per_sweep: int,
    extend_to: float | None,
    workers=None,
    *,
    seed: int = AUDIT_SEED,
) -> list[AuditRow]:
    """Audit ``per_sweep`` runs (the report: :data:`PER_SWEEP`) of each ``(figure name,
    sweep)`` (a RegimeMap or a Bifurcation), drawn with ``seed``: each replayed and checked at
    half the step, an undetermined verdict extended up to ``extend_to`` seconds recorded (the
    sweeps' own cap), on ``workers`` local threads (:func:`chaoscam.sweep.local_workers`)."""
    jobs = [(*job, extend_to) for job in sampled_rows(sweeps, audit_sample, per_sweep, seed)]
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
        "drawn from "
        f"{', '.join(figures)}, {'was' if n == 1 else 'were'} replayed alone and classified "
        "again with the step halved "
        f"({sum(r.seconds for r in rows):.0f} s of work): "
        f"{_count(len(same), 'reproduces its', 'reproduce their')} label; "
        f"at half the step {_count(sum(r.held for r in same), 'keeps', 'keep')} it, "
        f"{_count(len(undecided), 'is', 'are')} undetermined and "
        f"{_count(len(other), 'gets', 'get')} another label"
    )

    def named(what: str, group: list[AuditRow]) -> str:
        items = "; ".join(f"{r.figure} at {r.where}: {r.replayed} → {r.half}" for r in group)
        return f". {what}: {items}" if group else ""

    text += named("Undetermined at half the step", undecided)
    text += named("Another label", other)
    if lost:
        text += ". Not reproduced: " + "; ".join(
            f"{r.figure} at {r.where} (recorded {r.recorded}, replayed {r.replayed})" for r in lost
        )
    return text + ". The figures keep their labels: the audit samples them, it does not correct."
