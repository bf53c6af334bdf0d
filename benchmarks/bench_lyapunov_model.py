"""Cost of the model's Lyapunov exponent relative to one simulation (issue target: <= 3x).

Run: python benchmarks/bench_lyapunov_model.py [DURATION]

Times, in one process and after a warm-up (numba's cache loaded), the median of 3 calls of
``simulate()`` (the default, with its 1 ms series), ``simulate(series=False)`` and
``lyapunov_model()`` for the same duration (default 20 s, the paper's), and prints both
ratios; the target is checked against the cheaper simulation (series=False), the stricter
of the two.
"""

from __future__ import annotations

import statistics
import sys
import time

TARGET = 3.0


def median_time(fn, n: int = 3) -> float:
    times = []
    for _ in range(n):
        t0 = time.perf_counter()
        fn()
        times.append(time.perf_counter() - t0)
    return statistics.median(times)


def main() -> None:
    from chaoscam import simulate
    from chaoscam.lyapunov import lyapunov_model

    duration = float(sys.argv[1]) if len(sys.argv) > 1 else 20.0
    simulate(duration=1.0)
    lyapunov_model(duration=2.0)  # warm-up
    t_sim = median_time(lambda: simulate(duration=duration))
    t_bare = median_time(lambda: simulate(duration=duration, series=False))
    res = lyapunov_model(duration=duration)
    t_lyap = median_time(lambda: lyapunov_model(duration=duration))
    print(f"lyapunov_model vs simulate, default parameters, {duration:g} s (median of 3)")
    print(f"  simulate():                {t_sim:.3f} s")
    print(f"  simulate(series=False):    {t_bare:.3f} s")
    print(
        f"  lyapunov_model():          {t_lyap:.3f} s  (λ₁ = {res.exponent:.3f} ± "
        f"{res.stderr:.2g} 1/s, {res.n_intervals} intervals, {res.postponed} postponed)"
    )
    print(f"  ratio to simulate():             {t_lyap / t_sim:.2f}")
    ratio = t_lyap / t_bare
    verdict = "within" if ratio <= TARGET else "OVER"
    print(f"  ratio to simulate(series=False): {ratio:.2f}  ({verdict} the {TARGET:g}x target)")


if __name__ == "__main__":
    main()
