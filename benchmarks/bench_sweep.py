"""Sweep speed and memory, measured in one run (issue 4's budgets).

Run: python benchmarks/bench_sweep.py [--quick]

1. Fig. 4's bifurcation diagram: l_lambda over 0.001:0.018:69, 20 s each (10 s transient),
   every core; budget 60 s on the 2-core machine.
2. The same regime map with one and with two workers (``workers=1`` / ``workers=2``: one
   batch of realizations per thread, each member through the compiled call without the
   GIL): speed-up (goal >= 1.8), the map sized to ~15 s on one worker, best of two
   alternated runs each, with the CPU time per run, how busy the workers kept their cores
   (CPU time over wall time x workers) and the load average printed beside it.
3. Memory as the grid grows: the driver's peak traced allocation (tracemalloc, which sees
   numpy buffers) for 4, 16 and 64 cells.

The runs are labelled by the package's verdict (``chaoscam.classify``, the sweeps' default).
All timings are in this process, warm (imports and numba cache loads done by a first map).
"""

from __future__ import annotations

import argparse
import os
import resource
import sys
import time
import tracemalloc

import numpy as np

from chaoscam.sweep import Axis, bifurcation, regime_map

FIG4_BUDGET_S = 60.0
SPEEDUP_GOAL = 1.8


def classifier():
    return None, "chaoscam.classify"


def bench_fig4(classify, workers) -> float:
    t0 = time.perf_counter()
    b = bifurcation(
        "l_lambda",
        "0.001:0.018:69",
        duration=20.0,
        transient=10.0,
        classify=classify,
        workers=workers,
    )
    wall = time.perf_counter() - t0
    counts = b.verdicts["label"].value_counts().to_dict()
    print(
        f"Fig. 4 diagram: 69 values x 20 s, {len(b.points)} section points, "
        f"{workers or os.cpu_count()} workers: {wall:.1f} s "
        f"(budget {FIG4_BUDGET_S:.0f} s, {wall / FIG4_BUDGET_S:.2f} of it); labels {counts}"
    )
    return wall


def _load() -> str:
    one, five, _ = os.getloadavg()
    return f"load average {one:.2f} (1 min), {five:.2f} (5 min)"


def _cpu() -> float:
    """CPU seconds used so far by this process (every thread)."""
    me = resource.getrusage(resource.RUSAGE_SELF)
    return me.ru_utime + me.ru_stime


def _one_run_s(classify, duration: float) -> float:
    """Seconds for one realization (solve + classify) on one worker, warm."""
    x, y = Axis("l_lambda", (0.008,)), Axis("l_lambda_sigma", (0.001,))
    kw = dict(duration=duration, classify=classify, workers=1)
    regime_map(x, y, realizations=1, **kw)
    t0 = time.perf_counter()
    regime_map(x, y, realizations=4, **kw)
    return (time.perf_counter() - t0) / 4


def bench_speedup(classify, cells: int, serial_s: float, duration: float, repeats: int) -> float:
    """The map is sized to take about ``serial_s`` on one worker, so that start-up does not
    dominate; best of ``repeats`` alternated runs of each, so that transient load from
    other users of the machine is less likely to hit both."""
    n = int(round(np.sqrt(cells)))
    per_run = _one_run_s(classify, duration)
    realizations = max(1, int(np.ceil(serial_s / (n * n * per_run))))
    kw = dict(realizations=realizations, seed=1, duration=duration, classify=classify)
    x = Axis.linspace("l_lambda", 0.006, 0.012, n)
    y = Axis.linspace("l_lambda_sigma", 0.0, 0.002, n)
    print(
        f"one {duration:g} s realization {per_run * 1e3:.0f} ms on one worker; "
        f"{realizations} per cell"
    )
    times: dict[int, list[float]] = {1: [], 2: []}
    cpu: dict[int, list[float]] = {1: [], 2: []}
    tables = {}
    print(f"  before: {_load()}")
    for _ in range(repeats):
        for w in (1, 2):
            t0, c0 = time.perf_counter(), _cpu()
            tables[w] = regime_map(x, y, workers=w, **kw).realizations
            times[w].append(time.perf_counter() - t0)
            cpu[w].append(_cpu() - c0)
    t1, t2 = min(times[1]), min(times[2])
    same = tables[1].equals(tables[2])
    runs = len(tables[1])
    busy = {}
    for w in (1, 2):
        i = times[w].index(min(times[w]))
        busy[w] = f"{cpu[w][i] / runs:.3f} CPU s a run, {cpu[w][i] / (times[w][i] * w):.0%} busy"
    print(
        f"regime map {n}x{n} cells x {realizations} x {duration:g} s ({runs} runs): "
        f"1 worker {t1:.1f} s ({busy[1]}), 2 workers {t2:.1f} s ({busy[2]}; best of "
        f"{repeats}), speed-up {t1 / t2:.2f} (goal >= {SPEEDUP_GOAL}); tables identical: "
        f"{same}; after: {_load()}"
    )
    return t1 / t2


def bench_memory(classify, duration: float) -> None:
    print("memory as the grid grows (1 realization per cell, 2 workers):")
    for n in (2, 4, 8):
        tracemalloc.start()
        m = regime_map(
            Axis.linspace("l_lambda", 0.006, 0.012, n),
            Axis.linspace("l_lambda_sigma", 0.0, 0.002, n),
            realizations=1,
            duration=duration,
            classify=classify,
            workers=2,
        )
        _, peak = tracemalloc.get_traced_memory()
        tracemalloc.stop()
        rows = len(m.realizations)
        table = m.realizations.memory_usage(deep=True).sum()
        print(
            f"  {n * n:3d} cells: driver peak {peak / 2**20:6.2f} MiB traced, final table "
            f"{table / max(rows, 1):.0f} B/row"
        )


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true", help="smaller runs (a smoke test)")
    args = ap.parse_args()
    classify, name = classifier()
    print(f"classifier: {name}; cores: {os.cpu_count()}; python {sys.version.split()[0]}")
    print(f"machine: {_load()} (the 2 cores are shared: a load above ~0.5 skews the ratios)")
    if not args.quick:
        bench_fig4(classify, workers=None)
    if args.quick:
        bench_speedup(classify, 4, serial_s=2.0, duration=2.0, repeats=1)
        bench_memory(classify, duration=1.0)
    else:
        bench_speedup(classify, 16, serial_s=15.0, duration=10.0, repeats=2)
        bench_memory(classify, duration=2.0)


if __name__ == "__main__":
    main()
