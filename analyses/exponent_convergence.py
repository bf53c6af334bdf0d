"""Convergence of the tangent exponent and of a sticking orbit's Floquet multipliers.

Prints two tables (docs/verdicts.md, "Tangent exponent and multipliers under step halving"):

1. the largest Lyapunov exponent of the default model (Table 1, chaotic, 8 narrow bands) from
   the tangent dynamics, per step ``dt`` and integrator: the mean of runs from two initial
   conditions, with a standard error from the runs' batch means, the impacts per second by
   kind, the closings left without a jump (approach speed not > v_min: none should be, with
   v_min = 0) and the wall time;
2. the same exponent against ``v_chatter`` (the approach speed below which a closing ends a
   complete chattering sequence), on both integrators: the model is the limit v_chatter -> 0;
3. the period-1 sticking orbit at e = 0.02 m (labelled set): its dominant Floquet multiplier
   from Newton shooting with the tangent's monodromy matrix, per ``dt``, and the impacts
   applied over one period (macro / micro / chatter ends).

Usage: python analyses/exponent_convergence.py [--quick]
(--quick: 120 s runs, dt down to 5e-7 s. The full tables took 5 minutes on 2 cores.)
"""

from __future__ import annotations

import sys
import time

import numpy as np

from chaoscam import Numerics, Params, simulate
from chaoscam.verdict import lyapunov_spectrum, periodic_orbit

STICKING = {"e": 0.02}  # the labelled set's sticking period 1
STICKING_SEED = (-3.7812e-09, 1.1038714)  # its section point (theta_f [rad], theta_f' [rad/s])


def _kinds(tr) -> np.ndarray:
    """Impacts applied by kind: (macro, micro, chatter_end)."""
    kind = tr.impacts["kind"].astype(str)
    return np.array([(kind == name).sum() for name in ("macro", "micro", "chatter_end")])


def exponent_row(
    p: Params, num: Numerics, duration: float
) -> tuple[float, float, np.ndarray, float, float]:
    """(lambda_1 mean, its standard error, impacts per second by kind, closings per second
    left without a jump, wall seconds)."""
    t0 = time.perf_counter()
    lam, var, kinds, slow = [], [], np.zeros(3), 0
    for omega_f0 in (None, 0.05):  # two initial conditions on the same attractor
        q = p.replace(omega_f0=omega_f0)
        tr = simulate(q, num, duration=duration, transient=60.0, series=False, tangent=True)
        s = lyapunov_spectrum(tr)
        lam.append(s.exponents[0])
        var.append(s.stderr[0] ** 2)
        kinds += _kinds(tr)
        slow += tr.stats["slow_closings"]
    se = float(np.sqrt(np.sum(var))) / len(lam)
    span = 2 * (duration - 60.0)
    return float(np.mean(lam)), se, kinds / span, slow / span, time.perf_counter() - t0


def _table(runs: list[tuple[Params, Numerics, str]], duration: float) -> None:
    print("| run | lambda_1 [1/s] (+- se) | macro / micro / chatter ends per s", end="")
    print(" | closings without a jump per s | wall [s] |")
    print("|---|---|---|---|---|")
    for p, num, label in runs:
        lam, se, kinds, slow, wall = exponent_row(p, num, duration)
        rate = " / ".join(f"{v:.0f}" for v in kinds)
        row = f"| {label} | {lam:+.2f} +- {se:.2f} | {rate} | {slow:.2f} | {wall:.1f} |"
        print(row, flush=True)


def main(quick: bool) -> None:
    duration = 180.0 if quick else 360.0
    dts = (2e-6, 1e-6, 5e-7) if quick else (2e-6, 1e-6, 5e-7, 2.5e-7, 1.25e-7)
    print(f"Default model, lambda_1 from the tangent dynamics ({duration - 60:.0f} s x 2 runs)")
    p = Params()
    runs = [(p, Numerics(dt=dt), f"rk4, dt = {dt:g}") for dt in dts]
    runs += [
        (p, Numerics(dt=dt, integrator="adaptive"), f"adaptive, dt = {dt:g}") for dt in dts[:3]
    ]
    _table(runs, duration)

    print(f"\nAgainst v_chatter ({duration - 60:.0f} s x 2 runs; rk4 at dt = 5e-7 s)")
    runs = []
    for v in (1e-5, 1e-6, 1e-7):
        q = Params(v_chatter=v)
        runs.append((q, Numerics(dt=5e-7), f"rk4, v_chatter = {v:g}"))
        runs.append((q, Numerics(integrator="adaptive"), f"adaptive, v_chatter = {v:g}"))
    _table(runs, duration)

    print("\nSticking period 1 (e = 0.02 m): dominant Floquet multiplier")
    print(
        "| dt [s] | converged | abs(mu)max | impacts per period (macro/micro/chatter end)", end=""
    )
    print(" | wall [s] |")
    print("|---|---|---|---|---|")
    for dt in (4e-6, 2e-6, 1e-6, 5e-7, 2.5e-7):
        p, num = Params(**STICKING), Numerics(dt=dt)
        t0 = time.perf_counter()
        orbit = periodic_orbit(p, STICKING_SEED, 1, numerics=num, tol=1e-9)
        wall = time.perf_counter() - t0
        q = p.replace(theta_f0=float(orbit.points[0][0]), omega_f0=float(orbit.points[0][1]))
        tr = simulate(q, num, duration=p.cam_period, series=False)
        kinds = _kinds(tr)
        mu = float(np.abs(orbit.multipliers).max())
        counts = "/".join(str(int(v)) for v in kinds)
        print(f"| {dt:g} | {orbit.converged} | {mu:.4f} | {counts} | {wall:.1f} |")


if __name__ == "__main__":
    import argparse

    ap = argparse.ArgumentParser(
        prog="analyses/exponent_convergence.py", description=__doc__.splitlines()[0]
    )
    ap.add_argument("--quick", action="store_true", help="fewer steps and shorter runs")
    main(ap.parse_args(sys.argv[1:]).quick)
