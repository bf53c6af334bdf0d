"""Escapes at half and a quarter of the step: is "left the cam's reach" the step's?

The sweeps step-check chaotic, periodic and quasiperiodic verdicts (``check_step``), but a run
that leaves the cam's reach is labelled by its status (``left_reach``) and not re-run. This
script re-runs every ``left_reach`` run of the full report's (omega, xi) map and xi sweep
(reports/paper-data, written by ``chaoscam paper``; not in the repository) alone
(:func:`chaoscam.sweep.replay_params`: the sweep's own parameters, seed and index) at dt,
dt/2 and dt/4 for 300 s (the report's fate horizon) and prints, per run, the time it left at
each step, then how many leave within the sweep's 20 s window and how many only later.

Usage: python analyses/escape_step.py   (about a minute on 2 cores)
"""

from __future__ import annotations

import sys
from pathlib import Path

from chaoscam import simulate
from chaoscam.sweep import read_bifurcation, read_regime_map, replay_params

DATA = Path(__file__).resolve().parent.parent / "reports" / "paper-data"
HORIZON = 300.0  # [s] the report's fate horizon
STEPS = (1, 2, 4)


def _rows():
    """(name, sweep, row) for every left_reach run of the report's map and xi sweep."""
    sweep = read_regime_map(DATA / "sensitivity-omega-xi.parquet")
    rows = sweep.realizations
    for _, row in rows[rows.label == "left_reach"].iterrows():
        yield f"(omega, xi) = ({row.omega:g}, {row.xi:.3g})", sweep, row
    sweep = read_bifurcation(DATA / "sensitivity-xi.parquet")
    rows = sweep.verdicts
    for _, row in rows[rows.label == "left_reach"].iterrows():
        yield f"xi = {row.value:.3g}", sweep, row


def main() -> None:
    for name in ("sensitivity-omega-xi.parquet", "sensitivity-xi.parquet"):
        if not (DATA / name).is_file():
            sys.exit(f"{DATA / name}: no such file; run `chaoscam paper` (the full report) first")
    print("| run | left at dt, dt/2, dt/4 [s] (stayed: -) |")
    print("|---|---|")
    window = later = stayed = total = 0
    for name, sweep, row in _rows():
        p, num = replay_params(sweep, row)
        cfg = sweep.config
        left = []
        for f in STEPS:
            tr = simulate(
                p,
                num.replace(dt=num.dt / f),
                duration=HORIZON,
                transient=cfg["transient"],
                seed=cfg["seed"],
                index=int(row.sim_index),
                series=False,
            )
            left.append(float(tr.final_state[0]) if tr.status.name == "LEFT_REACH" else None)
        total += 1
        half = left[1]
        if half is None:
            stayed += 1
        elif half <= cfg["duration"]:
            window += 1
        else:
            later += 1
        cells = ", ".join("-" if t is None else f"{t:.2f}" for t in left)
        print(f"| {name} | {cells} |")
    print(
        f"\nof {total} runs labelled left_reach at dt: at dt/2, {window} leave within the "
        f"window, {later} later (by {HORIZON:g} s), {stayed} stay"
    )


if __name__ == "__main__":
    main()
