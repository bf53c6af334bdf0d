"""The two tangents through located events: the flow's saltation matrix and the grid map's own.

Prints the tables behind docs/findings.md, "Tangent dynamics checked independently":

1. the largest Lyapunov exponent lambda_1 [1/s] from the tangent dynamics, per configuration,
   with the flow's tangent at events (``tangent_events="flow"``, the default) at dt, the grid
   map's (``"grid"``) at dt, dt/2 and dt/4, and the adaptive path (whose tangent is the
   flow's); each with its standard error from batch means;
2. the xi = 0.45 sticking period 6's dominant Floquet multiplier at dt from each of the last
   six section points of three runs (30, 31, 32 s), with either tangent;
3. the direct perturbation test (``chaoscam.tangent.kick_test``, no tangent) against the label
   of every deterministic settled configuration of the labelled and holdout sets
   (tests/data), and on three cases whose verdict the grid tangent changes ((26, 0.3) is in
   the holdout set, unsettled).

The check that the grid tangent is the derivative of what the kernel computes, chatter cycle
by chatter cycle against central differences of the grid map, is a test:
tests/tangent/test_event_time.py.

Usage: python analyses/tangent_events.py [--quick]
(--quick: 120 s runs and no dt/4 column, no third table. The full tables took 6 minutes
on 2 cores.)
"""

from __future__ import annotations

import json
import sys
import time
from pathlib import Path

import numpy as np

from chaoscam import Params, simulate
from chaoscam.tangent import kick_test, lyapunov_spectrum, stroboscopic_map

CONFIGS = {
    "default (Table 1)": {},
    "xi = 0.45 (sticking period 6)": {"xi": 0.45},
    "l_lambda = 15 mm": {"l_lambda": 0.015},
    "l_lambda = 12 mm": {"l_lambda": 0.012},
    "omega = 26, xi = 0.3 (7 bands)": {"omega": 26.0, "xi": 0.3},
}


def _exponent(p: Params, duration: float) -> str:
    spec = lyapunov_spectrum(p, duration=duration, transient=60.0)
    return f"{spec.exponents[0]:+.2f} ± {spec.stderr[0]:.2f}"


def exponent_table(duration: float, divisors: tuple[int, ...]) -> None:
    head = ["flow, dt"] + [f"grid, dt/{d}" if d > 1 else "grid, dt" for d in divisors]
    print("| configuration | " + " | ".join(head) + " | adaptive |")
    print("|---" * (len(head) + 2) + "|")
    for name, changes in CONFIGS.items():
        t0 = time.perf_counter()
        base = Params(**changes)
        cells = [_exponent(base, duration)]
        for d in divisors:
            cells.append(_exponent(base.replace(tangent_events="grid", dt=base.dt / d), duration))
        cells.append(_exponent(base.replace(integrator="adaptive"), duration))
        print(f"| {name} | " + " | ".join(cells) + f" |  ({time.perf_counter() - t0:.0f} s)")


def multiplier_table() -> None:
    print("\n| run | tangent | |mu|max at dt from each of its last 6 section points |")
    print("|---|---|---|")
    for duration in (30.0, 31.0, 32.0):
        tr = simulate(Params(xi=0.45), duration=duration, transient=25.0, series=False)
        points = tr.section[["theta_f", "omega_f"]].to_numpy()[-6:]
        for mode in ("flow", "grid"):
            p = Params(xi=0.45, tangent_events=mode)
            mu = [np.abs(np.linalg.eigvals(stroboscopic_map(p, x, 6)[1])).max() for x in points]
            print(f"| {duration:.0f} s | {mode} | {', '.join(f'{m:.3g}' for m in mu)} |")


DATA = Path(__file__).resolve().parent.parent / "tests" / "data"
KICK_CASES = {  # (changes, label from kicks and long runs at dt, period)
    # (32.5, 0.5) is periodic 6 at dt and periodic 12 at dt/2 (docs/classify-map-report.md,
    # "Fate of the motion": the 275-cell map at dt and dt/2); the kicks test the dt orbit.
    "(32.5, 0.5)": ({"omega": 32.5, "xi": 0.5}, "periodic", 6),
    "xi = 0.525": ({"xi": 0.525}, "periodic", 8),
    "(45, 0.4)": ({"omega": 45.0, "xi": 0.4}, "chaotic", None),
}


def kick_table() -> None:
    """kick_test from the last section point of a 130 s run (100 s transient), n the period
    (8 for chaos), against each configuration's label."""
    rows = {}
    for name in ("labelled_set", "holdout_set"):
        for key, row in json.loads((DATA / f"{name}.json").read_text()).items():
            if not row["params"].get("l_lambda_sigma"):  # the deterministic model only
                rows[key] = (row["params"], row["label"], row["period"])
    rows.update(KICK_CASES)
    print("\n| configuration | label | returns | largest final separation / kick (>= 1e-7) |")
    print("|---|---|---|---|")
    agree = total = 0
    for key, (changes, label, period) in rows.items():
        p = Params(**changes)
        sec = simulate(p, duration=130.0, transient=100.0, series=False).section
        if not len(sec):
            print(f"| {key} | {label} | (left the cam's reach) | |")
            continue
        x = sec[["theta_f", "omega_f"]].to_numpy()[-1]
        test = kick_test(p, x, period if label == "periodic" else 8)
        if label in ("periodic", "chaotic") and key not in KICK_CASES:
            total += 1
            agree += test.returns == (label == "periodic")
        print(f"| {key} | {label} | {test.returns} | {test.growth[1:, :, -1].max():.2g} |")
    print(f"\nkick_test agrees with {agree} of {total} settled labels")


def main() -> None:
    quick = "--quick" in sys.argv
    exponent_table(120.0 if quick else 360.0, (1, 2) if quick else (1, 2, 4))
    multiplier_table()
    if not quick:
        kick_table()


if __name__ == "__main__":
    main()
