"""Kick audit of the report's periodic verdicts: do finite perturbations agree with Newton?

A periodic verdict of the deterministic model is certified by Newton's multipliers on the
grid and at dt/2 (``chaoscam.verdict.certify``); kicks (its ``_kicked``: kicks of 1e-7
and 1e-6 rad in ±θ_f, 30× that in rad/s in ±θ̇_f, followed for 40 orbit periods at dt and at
dt/2) are asked only where the multipliers leave the orbit open. This script asks the kicks
of every periodic verdict of the full report's deterministic sweeps (reports/paper-data,
written by ``chaoscam paper``; not in the repository): it runs each realization again alone
to the length it was classified at (``simulate`` with the sweep's parameters, numerics,
seed, index and transient, for the recorded seconds of the verdict: an extended run continues
bit for bit),
applies the kick certificate's own rule from its last section point, and prints one line per
verdict and the counts. A verdict the kicks refuse is one where the multipliers and finite
perturbations disagree: the line gives both.

With ``--deep``, each refused verdict is then settled on the model: its realization is run to
``--horizon`` seconds (default 300) at dt, dt/2 and dt/4, and for each step the script prints
the widest band of the last 100 orbit periods' section points (at most the run's second
half) at lag n and 2n, Newton's
|mu|max from the run's last point, and where kicks of 1e-7 to 1e-4 rad end (the largest
absolute distance over the four directions after 40 and 80 orbit periods: a slow contraction
goes on, a floor or another attractor stays). Fig. 6's steps (5e-8 and 9.6e-8 s) make this
dear: give it ``--horizon 60 --deep-steps 1,2 --deep-kicks 1e-7,1e-6`` there.
``--refused-from AUDIT.md`` deep-checks the rows an earlier run's printed table refused,
without asking the kicks of every verdict again.

Usage: python analyses/kick_audit.py [--stages fig4,fig6-G1e-09,...] [--data DIR] [--workers N]
       [--deep | --refused-from AUDIT.md] [--horizon S]
       [--deep-steps 1,2,4] [--deep-kicks 1e-7,1e-6,...]
       (all stages: about an hour on 2 cores, most of it Fig. 6's steps)
"""

from __future__ import annotations

import argparse
import time
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path
from typing import NamedTuple

import numpy as np
from _report_data import DATA, deterministic_rows

from chaoscam import Numerics, Params, simulate
from chaoscam.verdict import MODEL_ATOL, kick_test, periodic_orbit
from chaoscam.verdict._certificate import _kicked, _Run, _widest_band

DIAGRAMS = (
    "fig4",
    "fig6-G1e-09",
    "fig6-G1e-10",
    "sensitivity-J",
    "sensitivity-pivot",
    "sensitivity-stiffness",
    "sensitivity-xi",
)
MAPS = ("sensitivity-omega-xi", "fig7-10")  # regime maps (with a .cells.parquet)
DEEP_KICKS = (1e-7, 1e-6, 1e-5, 1e-4)  # [rad]
DEEP_PERIODS = 100  # orbit periods whose bands the deep check measures
KICK_PERIODS = 40  # orbit periods the kick certificate follows (kick_test's default)


class Job(NamedTuple):
    """One periodic verdict to ask: its realization, classified length and period."""

    stage: str
    what: str
    params: Params
    numerics: Numerics
    duration: float  # [s] the transient and the verdict's recorded seconds
    transient: float
    seed: int
    index: int
    period: int


def _jobs(data: Path, stages):
    """A :class:`Job` per periodic verdict of the deterministic model."""
    for stage, sweep, row, p, num, what in deterministic_rows(data, stages, ["periodic"]):
        transient = float(sweep.config["transient"])
        yield Job(
            stage,
            what,
            p,
            num,
            transient + float(row.recorded_s),
            transient,
            int(row.seed),
            int(row.sim_index),
            int(row.period),
        )


def _points(p, num, duration, transient, seed, index):
    tr = simulate(
        p, num, duration=duration, transient=transient, seed=seed, index=index, series=False
    )
    sec = tr.section
    return tr.status.name, sec.loc[sec["k"] > 0, ["theta_f", "omega_f"]].to_numpy(dtype=float)


def _audit(job: Job):
    """(certified, the kick records per step, the summary in words) of the kick certificate
    from the classified run's last section point."""
    _, points = _points(job.params, job.numerics, job.duration, job.transient, job.seed, job.index)
    extra: dict = {}
    ok, summary = _kicked(_Run(job.params, job.numerics, points, extra), job.period)
    return ok, extra["kick_test"], summary


def _deep(args):
    """The refused verdict's realization run long at dt / f: a line in words."""
    job, f, horizon, sizes = args
    n = job.period
    p, num = job.params, job.numerics.replace(dt=job.numerics.dt / f)
    t0 = time.perf_counter()
    status, points = _points(p, num, horizon, job.transient, job.seed, job.index)
    head = f"{job.stage} {job.what} (period {n}) at dt/{f}, {horizon:g} s: "
    periods = min(DEEP_PERIODS, len(points) // (2 * n))  # at most the run's second half
    if periods < 8:
        return head + f"{status} after {len(points)} section points"
    scale = np.array([1.0, p.cam_period])
    last = points[-periods * n :] * scale
    bands = [_widest_band(last, m) for m in (n, 2 * n)]
    orbit = periodic_orbit(p, points[-1], n, numerics=num)
    test = kick_test(p, points[-1], n, numerics=num, kicks=sizes, periods=2 * KICK_PERIODS)
    ends = [
        np.nanmax(test.growth[:, :, m], axis=1) * np.array(sizes)
        for m in (KICK_PERIODS, 2 * KICK_PERIODS)
    ]
    kicks = ", ".join(f"{k:g} -> {a:.2g} / {b:.2g}" for k, a, b in zip(sizes, *ends, strict=True))
    return head + (
        f"bands of the last {periods} orbit periods {bands[0]:.2g} rad at lag n, "
        f"{bands[1]:.2g} at 2n ({'within' if bands[0] <= MODEL_ATOL else 'above'} the "
        f"band tolerance {MODEL_ATOL:g}); Newton |mu|max {np.max(np.abs(orbit.multipliers)):.3g}"
        f" ({'certified' if orbit.certified else 'not certified'}); kicks end at [rad] "
        f"{kicks} ({time.perf_counter() - t0:.0f} s)"
    )


def _refused_in(path: Path) -> set:
    """(stage, run) of the rows an earlier audit's table marked refused ("NO")."""
    rows = (line.split("|") for line in path.read_text().splitlines() if line.startswith("| "))
    return {(c[1].strip(), c[2].strip()) for c in rows if len(c) > 6 and c[6].strip() == "NO"}


def _audit_all(jobs, workers: int) -> list:
    """Print the audit's table and counts; return the refused jobs."""
    print(f"{len(jobs)} periodic verdicts of the deterministic model\n")
    print(
        "| stage | run | period | dt [s] "
        "| kicks at dt, dt/2: largest end / kick, bands [rad] | agree |"
    )
    print("|---|---|---|---|---|---|")
    refused, refused_jobs, t0 = [], [], time.perf_counter()
    with ProcessPoolExecutor(workers) as pool:
        for job, (ok, records, summary) in zip(jobs, pool.map(_audit, jobs), strict=True):
            steps = "; ".join(f"{r['largest_final']:.2g}, {r['bands']:.2g}" for r in records)
            print(
                f"| {job.stage} | {job.what} | {job.period} | {job.numerics.dt:.3g} | {steps} "
                f"| {'yes' if ok else 'NO'} |",
                flush=True,
            )
            if not ok:
                refused.append((job.stage, job.what, job.period, summary))
                refused_jobs.append(job)
    print(
        f"\nkicks certify {len(jobs) - len(refused)} of {len(jobs)} periodic verdicts "
        f"({time.perf_counter() - t0:.0f} s)"
    )
    for stage, what, n, summary in refused:
        print(f"refused: {stage} {what} (period {n}): {summary}")
    return refused_jobs


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--stages", default=",".join(DIAGRAMS + MAPS))
    ap.add_argument("--data", type=Path, default=DATA, help="the report's data folder")
    ap.add_argument("--workers", type=int, default=2)
    ap.add_argument("--deep", action="store_true", help="settle each refused verdict")
    ap.add_argument(
        "--refused-from", type=Path, help="deep-check the refused rows of this earlier output"
    )
    ap.add_argument("--horizon", type=float, default=300.0, help="deep runs' end time [s]")
    ap.add_argument("--deep-steps", default="1,2,4", help="deep runs' step divisors")
    ap.add_argument("--deep-kicks", default=",".join(f"{k:g}" for k in DEEP_KICKS), help="[rad]")
    args = ap.parse_args()
    jobs = list(_jobs(args.data, args.stages.split(",")))
    # dearest first (steps of the period over dt), so the pool ends together
    jobs.sort(key=lambda j: -j.period * j.params.cam_period / j.numerics.dt)
    if args.refused_from:
        keep = _refused_in(args.refused_from)
        refused = [job for job in jobs if (job.stage, job.what) in keep]
    else:
        refused = _audit_all(jobs, args.workers)
    if (args.deep or args.refused_from) and refused:
        print(f"\nthe refused verdicts run to {args.horizon:g} s:")
        steps = [int(f) for f in args.deep_steps.split(",")]
        sizes = tuple(float(k) for k in args.deep_kicks.split(","))
        deep = [(job, f, args.horizon, sizes) for job in refused for f in steps]
        with ProcessPoolExecutor(args.workers) as pool:
            for line in pool.map(_deep, deep):
                print(line, flush=True)


if __name__ == "__main__":
    main()
