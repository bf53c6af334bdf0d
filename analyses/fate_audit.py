"""Fate audit of a report's chaotic verdicts: does the chaos last, or settle, or leave?

A label describes the recorded window, and chaos can be transient. The full report continues
its (omega, xi) map and xi sweep to a fate horizon (``fate=300``: README "Fate of the
motion"), but not its figure diagrams and its other sensitivity sweeps. This script does the
same for those: every chaotic (and undetermined) verdict of the deterministic model in the
stages named (reports/paper-data, written by ``chaoscam paper``; not in the repository) is
simulated again alone to ``--horizon`` seconds with the tangent (the sweep's parameters, seed
and index: the same motion, bit for bit) and judged as a sweep's fate is
(``chaoscam.sweep._tasks.fate_fields``: the status at the horizon, and for a run that stayed
the model's verdict on the run's last half, certificate included, at the run's own step).
Prints one line per run and the counts: still chaotic, settled on a period, left the cam's
reach, other. Writes nothing.

Usage: python analyses/fate_audit.py [--stages fig4,...] [--horizon S] [--labels chaotic]
       [--data DIR] [--workers N]
       (the default stages at 300 s: about 20 minutes on 2 cores, most of it Fig. 4's step)
"""

from __future__ import annotations

import argparse
import time
import warnings
from collections import Counter
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path

from _report_data import DATA, sweep_rows

from chaoscam import simulate
from chaoscam.sweep import replay_params
from chaoscam.sweep._tasks import fate_fields

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


def _jobs(data: Path, stages, labels, horizon: float):
    """(stage, what, label, params, seed, index, horizon) per verdict asked."""
    for stage in stages:
        sweep, rows, names = sweep_rows(data, stage)
        for _, row in rows[rows.label.isin(labels)].iterrows():
            p = replay_params(sweep, row)
            if p.l_lambda_sigma > 0:
                continue  # the deterministic model only
            what = ", ".join(f"{n} = {row[n]:.4g}" for n in names)
            if "ic" in row:
                what += f", ic {row.ic}"
            yield stage, what, row.label, p, int(row.seed), int(row.sim_index), horizon


def _fate(job):
    stage, what, label, p, seed, index, horizon = job
    t0 = time.perf_counter()
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # the model's warnings came with the sweep's run
        long = simulate(
            p,
            duration=horizon,
            transient=0.0,
            seed=seed,
            index=index,
            series=False,
            tangent=p.integrator == "rk4",
        )
    fate = fate_fields(long.status.name, long.section, long.jacobians, p)
    return stage, what, label, fate, time.perf_counter() - t0


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
    jobs = list(_jobs(args.data, args.stages.split(","), labels, args.horizon))
    jobs.sort(key=lambda j: j[3].dt)  # dearest first, so the pool ends together
    print(f"{len(jobs)} verdicts ({', '.join(labels)}) continued to {args.horizon:g} s\n")
    print("| stage | run | label | at the horizon | left at [s] |")
    print("|---|---|---|---|---|")
    counts: dict = {}
    t0 = time.perf_counter()
    with ProcessPoolExecutor(args.workers) as pool:
        for stage, what, label, fate, _ in pool.map(_fate, jobs):
            outcome = _outcome(fate)
            left = "" if fate["left_at"] != fate["left_at"] else f"{fate['left_at']:.1f}"
            print(f"| {stage} | {what} | {label} | {outcome} | {left} |", flush=True)
            counts.setdefault(label, Counter())[outcome.split(":")[0]] += 1
    print(f"\n({time.perf_counter() - t0:.0f} s)")
    for label, c in counts.items():
        print(f"{label}: " + ", ".join(f"{k} {v}" for k, v in c.most_common()))


if __name__ == "__main__":
    main()
