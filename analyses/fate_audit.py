"""Fate audit of a report's chaotic verdicts: does the chaos last, or settle, or leave?

A label describes the recorded window, and chaos can be transient. The full report continues
its (omega, xi) map and xi sweep to a fate horizon (``fate=300``:
docs/classify-map-report.md, "Fate of the motion"), but not its figure diagrams and its other
sensitivity sweeps. This script does the same for those: every chaotic (and undetermined) verdict of
the deterministic model in the stages named (reports/paper-data, written by ``chaoscam paper``; not
in the repository) is simulated again alone to ``--horizon`` seconds with the tangent (the sweep's
parameters, seed and index: the same motion, bit for bit) by the sweeps' own fate run
(``chaoscam.sweep._tasks._fate``: the status at the horizon, and for a run that stayed the
model's verdict on the run's last half, certificate included, at the run's own step).
Prints one line per run and the counts: still chaotic, settled on a period, left the cam's
reach, other. Writes nothing.

Usage: python analyses/fate_audit.py [--stages fig4,...] [--horizon S] [--labels chaotic]
       [--data DIR] [--workers N]
       (the default stages at 300 s: about 20 minutes on 2 cores, most of it Fig. 4's step)
"""

from __future__ import annotations

import argparse
import time
from collections import Counter
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path
from typing import NamedTuple

from _report_data import DATA, deterministic_rows

from chaoscam import Params
from chaoscam.sweep._tasks import _fate as run_fate

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
    seed: int
    sim_index: int
    fate: float  # [s] the horizon


def _tasks(data: Path, stages, labels, horizon: float):
    """A :class:`Task` per verdict of the deterministic model labelled one of ``labels``."""
    for stage, _, row, p, what in deterministic_rows(data, stages, labels):
        yield Task(stage, what, row.label, p, int(row.seed), int(row.sim_index), horizon)


def _fate(task: Task) -> dict:
    """The sweeps' own fate run (``sweep._tasks._fate``): the realization again to the
    horizon with the tangent, its status and the verdict on its last half."""
    return run_fate(task.params, task)


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
    tasks.sort(key=lambda t: t.params.dt)  # dearest first, so the pool ends together
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
