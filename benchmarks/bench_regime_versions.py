"""One timed regime map with whichever chaoscam is installed: to compare versions.

Run: python benchmarks/bench_regime_versions.py ENGINE [TABLE.parquet]

The map of ``bench_regime_engine.py`` (3x3 cells of (l_lambda, l_lambda_sigma) x 6
realizations x 20 s, seed 1, 2 workers), warmed first like it, timed once. ENGINE is
"process" or "ensemble", or "default" for a version whose ``regime_map`` has no ``engine``
(before the ensemble engine: one process task per realization). Prints the time, the
trajectories per second, the CPU time (pool included) and the labels, and writes the
realizations' table if asked. To measure another commit, install it in its own virtual
environment and run this file with that environment's python, e.g.::

    git worktree add /tmp/filed ed91016 && python3 -m venv /tmp/filedenv
    /tmp/filedenv/bin/pip install -e /tmp/filed
    /tmp/filedenv/bin/python benchmarks/bench_regime_versions.py default

Alternate the versions on one idle machine and compare the best of each.
"""

from __future__ import annotations

import os
import resource
import sys
import time

from chaoscam.sweep import Axis, regime_map

ENGINES = ("process", "ensemble", "default")


def _cpu() -> float:
    """CPU seconds used so far by this process and its finished children (bench_regime_engine's
    own, not imported: that file needs modules an older version lacks)."""
    me = resource.getrusage(resource.RUSAGE_SELF)
    kids = resource.getrusage(resource.RUSAGE_CHILDREN)
    return me.ru_utime + me.ru_stime + kids.ru_utime + kids.ru_stime


def main() -> None:
    if len(sys.argv) not in (2, 3) or sys.argv[1] not in ENGINES:
        sys.exit(f"usage: {sys.argv[0]} {{{','.join(ENGINES)}}} [TABLE.parquet]")
    engine = sys.argv[1]
    extra = {} if engine == "default" else {"engine": engine}
    regime_map(  # warm: numba caches, imports
        Axis("l_lambda", (0.008,)),
        Axis("l_lambda_sigma", (0.001,)),
        realizations=2,
        duration=1.0,
        workers=2,
        **extra,
    )
    x = Axis.linspace("l_lambda", 0.008, 0.014, 3)
    y = Axis.linspace("l_lambda_sigma", 0.001, 0.002, 3)
    t0, c0 = time.perf_counter(), _cpu()
    runs = regime_map(x, y, realizations=6, seed=1, duration=20.0, workers=2, **extra)
    wall, cpu = time.perf_counter() - t0, _cpu() - c0
    table = runs.realizations
    if len(sys.argv) == 3:
        table.to_parquet(sys.argv[2])
    print(
        f"{engine}: {wall:.2f} s, {len(table) / wall:.2f} traj/s, CPU {cpu:.1f} s, "
        f"load {os.getloadavg()[0]:.2f}; labels {table['label'].value_counts().to_dict()}; "
        f"median impacts a run {table['n_impacts'].median():.0f}"
    )


if __name__ == "__main__":
    main()
