"""Fate audit of a report's chaotic verdicts: does the chaos last, or settle, or leave?

A label describes the recorded window, and chaos can be transient. The full report continues
its (omega, xi) map and xi sweep to a fate horizon (``fate=300``:
docs/classify-map-report.md, "Fate of the motion"), but not its figure diagrams and its other
sensitivity sweeps. This script does the same for those: every chaotic (and undetermined) verdict of
the deterministic model in the stages named (reports/paper-data, written by ``chaoscam paper``; not
in the repository) is solved again alone to ``--horizon`` seconds with the tangent (the sweep's
parameters, numerics, seed and index: the same motion, bit for bit) as the sweeps' own fate run
does it (:func:`chaoscam.solve`, then the status at the horizon and, for a run that stayed, the
model's verdict on the run's last half by :func:`chaoscam.verdict.judge_points`, certificate
included, at the run's own step).
Prints one line per run and the counts: still chaotic, settled on a period, left the cam's
reach, other. Writes nothing.

Usage: python analyses/fate_audit.py [--stages fig4,...] [--horizon S] [--labels chaotic]
       [--data DIR] [--workers N]
       (the default stages at 300 s: about 20 minutes on 2 cores, most of it Fig. 4's step)
"""

from __future__ import annotations

import argparse
import math
import time
import warnings
from collections import Counter
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path
from typing import NamedTuple

from _report_data import DATA, deterministic_rows

from chaoscam import Numerics, Params, Status, solve
from chaoscam.sweep._runs import FATE_LATE  # the share of the fate run the sweeps judge
from chaoscam.verdict import judge_points

STAGES = (  # the report's sweeps without a fate horizon of their own
    "fig4",
    "sensitivity-J",
    "sensitivity-arm",
    "sensitivity-damping",
    "sensitivity-hertz",
    "sensitivity-pivot",
    "sensitivity-stiffness",
    "fig7-10",
)


class Task(NamedTuple):
    """One verdict to continue; the fields a sweep's fate run reads (seed, sim_index, fate)."""

    stage: str
    what: str
    label: str
    params: Params
    numerics: Numerics
    seed: int
    sim_index: int
    fate: float  # [s] the horizon


def _tasks(data: Path, stages, labels, horizon: float):
    """A :class:`Task` per verdict of the deterministic model labelled one of ``labels``."""
    for stage, _, row, p, num, what in deterministic_rows(data, stages, labels):
        yield Task(stage, what, row.label, p, num, int(row.seed), int(row.sim_index), horizon)


def _fate(task: Task) -> dict:
    """The sweeps' fate run: the realization again from t = 0 to the horizon with the
    tangent (on RK4), its status (``fate``), the last section time of a run that stopped
    (``left_at``) and, for one that stayed, the model's verdict on the run's last
    :data:`FATE_LATE` (``fate_label``, ``fate_period``)."""
    p, num = task.params, task.numerics
    with warnings.catch_warnings():  # the model's warnings came with the sweep's own run
        warnings.simplefilter("ignore", RuntimeWarning)
        run = solve(p, num, indices=[task.sim_index], seed=task.seed, duration=task.fate,
                    transient=0.0, tangent=num.integrator == "rk4")  # fmt: skip
        t, k = run.section["t"].to_numpy(), run.section["k"].to_numpy()
        stopped = run.status is not Status.OK
        out = {"fate": run.status.name, "left_at": float(t[-1]) if stopped and len(t) else math.nan,
               "fate_label": None, "fate_period": None}  # fmt: skip
        if stopped or run.jacobians is None or not len(t):
            return out
        late = (t >= (1.0 - FATE_LATE) * t[-1]) & (k > 0)
        if not late.any():  # a horizon within a cam period or so: nothing to judge
            return out
        xy = run.section[["theta_f", "omega_f"]].to_numpy(dtype=float)[late]
        v = judge_points(xy, run.jacobians[late], p, num, {})
    return {**out, "fate_label": v.label, "fate_period": v.period}


def _outcome(fate: dict) -> str:
    if fate["fate"] != "OK":
        return "left the cam's reach" if fate["fate"] == "LEFT_REACH" else fate["fate"]
    if fate["fate_label"] == "periodic":
        return f"settled: periodic {fate['fate_period']}"
    return str(fate["fate_label"])


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--stages", default=",".join(STAGES))
    ap.add_argument("--data", type=Path, default=DATA, help="the report's data folder")
    ap.add_argument("--horizon", type=float, default=300.0, help="end time [s]")
    ap.add_argument("--labels", default="chaotic,undetermined")
    ap.add_argument("--workers", type=int, default=2)
    args = ap.parse_args()
    labels = args.labels.split(",")
    tasks = list(_tasks(args.data, args.stages.split(","), labels, args.horizon))
    tasks.sort(key=lambda t: t.numerics.dt)  # dearest first, so the pool ends together
    print(f"{len(tasks)} verdicts ({', '.join(labels)}) continued to {args.horizon:g} s\n")
    print("| stage | run | label | at the horizon | left at [s] |")
    print("|---|---|---|---|---|")
    counts: dict = {}
    t0 = time.perf_counter()
    with ProcessPoolExecutor(args.workers) as pool:
        for task, fate in zip(tasks, pool.map(_fate, tasks), strict=True):
            outcome = _outcome(fate)
            left = "" if fate["left_at"] != fate["left_at"] else f"{fate['left_at']:.1f}"
            print(f"| {task.stage} | {task.what} | {task.label} | {outcome} | {left} |", flush=True)
            counts.setdefault(task.label, Counter())[outcome.split(":")[0]] += 1
    print(f"\n({time.perf_counter() - t0:.0f} s)")
    for label, c in counts.items():
        print(f"{label}: " + ", ".join(f"{k} {v}" for k, v in c.most_common()))


if __name__ == "__main__":
    main()
