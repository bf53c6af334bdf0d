"""Simulator speed, measured in one run (issue 2).

Prints the wall time of a default 20 s trajectory on the compiled path (after compilation),
and the ratio compiled / solve_ivp on the same short run. Targets: <= 1 s, >= 300x.
"""

from __future__ import annotations

import os
import time

os.environ.setdefault("NUMBA_NUM_THREADS", "1")

import chaoscam  # noqa: E402
from chaoscam import Numerics, Params  # noqa: E402


def best_of(fn, repeat: int) -> float:
    times = []
    for _ in range(repeat):
        t0 = time.perf_counter()
        fn()
        times.append(time.perf_counter() - t0)
    return min(times)


def main() -> None:
    p = Params()
    chaoscam.simulate(p, duration=0.01)  # compile or load from cache
    full = best_of(lambda: chaoscam.simulate(p, duration=20.0, series=False), 3)
    print(f"default 20 s trajectory, compiled path: {full:.3f} s (target <= 1 s)")
    plain = Numerics(flight_merge=1)
    fixed = best_of(lambda: chaoscam.simulate(p, plain, duration=20.0, series=False), 3)
    print(f"same with plain fixed-step RK4 everywhere (flight_merge=1): {fixed:.3f} s")
    short = 0.7
    kernel = best_of(lambda: chaoscam.simulate(p, duration=short, series=False), 5)
    ref = best_of(lambda: chaoscam.simulate_reference(p, short), 1)
    print(
        f"{short} s run: compiled {kernel * 1e3:.1f} ms, solve_ivp {ref:.2f} s, "
        f"ratio {ref / kernel:.0f}x (target >= 300x)"
    )


if __name__ == "__main__":
    main()
