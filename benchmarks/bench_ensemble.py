"""Ensemble scaling, measured in one run (issue 6): 2 threads against 1 on the same ensemble.

One ``chaoscam.solve`` call of 64 members x 20 s (l_lambda_sigma = 2 mm) on 1 and on 2 numba
threads. Prints trajectories per second for each thread count and the ratio (target >= 1.8x),
and the peak memory of a 10,000-member ensemble (target < 2 GB). Its members last
``--memory-duration`` seconds, 2 s by default to keep the run short (the arrays of a batch
grow with the duration only through the section rows: 40 B per cam period and member);
``--memory-duration 20`` measures the full case (about 7 minutes on 2 cores).
"""

from __future__ import annotations

import argparse
import resource
import time

import numba

import chaoscam
from chaoscam import Numerics, Params


def rate(p, num, members: int, threads: int) -> float:
    numba.set_num_threads(threads)
    t0 = time.perf_counter()
    chaoscam.solve(p, num, indices=range(members), seed=1, duration=20.0)
    return members / (time.perf_counter() - t0)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--memory-duration", type=float, default=2.0, help="member length [s]")
    ap.add_argument("--integrator", choices=("rk4", "adaptive"), default="rk4")
    args = ap.parse_args()
    p, num = Params(l_lambda_sigma=0.002), Numerics(integrator=args.integrator)
    chaoscam.solve(p, num, indices=range(2), seed=1, duration=0.1)  # compile or load from cache
    n = 64
    one = rate(p, num, n, 1)
    two = rate(p, num, n, min(2, numba.config.NUMBA_NUM_THREADS))
    print(
        f"ensemble of {n} x 20 s: 1 thread {one:.1f} traj/s, 2 threads {two:.1f} traj/s, "
        f"ratio {two / one:.2f}x (target >= 1.8x)"
    )
    t0 = time.perf_counter()
    dur = args.memory_duration
    ens = chaoscam.solve(p, num, indices=range(10_000), seed=1, duration=dur)
    wall = time.perf_counter() - t0
    peak = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024
    print(
        f"10,000 x {dur:g} s ({args.integrator}): {wall:.0f} s ({10_000 / wall:.0f} traj/s), "
        f"{len(ens.sections)} section points, peak RSS {peak:.0f} MiB (target < 2048 MiB)"
    )


if __name__ == "__main__":
    main()
