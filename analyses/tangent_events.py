"""The two tangents through located events: the flow's saltation matrix and the grid map's own.

Prints the tables behind README, "Tangent dynamics checked independently":

1. the largest Lyapunov exponent lambda_1 [1/s] from the tangent dynamics, per configuration,
   with the flow's tangent at events (``tangent_events="flow"``, the default) at dt, the grid
   map's (``"grid"``) at dt, dt/2 and dt/4, and the adaptive path (whose tangent is the
   flow's); each with its standard error from batch means;
2. the xi = 0.45 sticking period 6's dominant Floquet multiplier at dt from each of the last
   six section points of three runs (30, 31, 32 s), with either tangent.

The check that the grid tangent is the derivative of what the kernel computes, chatter cycle
by chatter cycle against central differences of the grid map, is a test:
tests/tangent/test_event_time.py.

Usage: python analyses/tangent_events.py [--quick]
(--quick: 120 s runs and no dt/4 column. The full tables took about 4 minutes on 2 cores.)
"""

from __future__ import annotations

import sys
import time

import numpy as np

from chaoscam import Params, simulate
from chaoscam.tangent import lyapunov_spectrum, stroboscopic_map

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


def main() -> None:
    quick = "--quick" in sys.argv
    exponent_table(120.0 if quick else 360.0, (1, 2) if quick else (1, 2, 4))
    multiplier_table()


if __name__ == "__main__":
    main()
