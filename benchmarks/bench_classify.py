"""Time to classify a ~20 000-sample signal plus ~100 section points (budget: 2 s).

Run: python benchmarks/bench_classify.py

Data are generated first (Ueda oscillator: chaotic; two-torus: quasiperiodic; a forced
period-2 response), then `classify_signal` is timed on each: the first call of the
process (lazy imports included) and the median of 5 further calls. No Lyapunov exponent
from the equations is computed (the issue's budget excludes it); a last line times the
optional series estimate (nolds) separately.
"""

from __future__ import annotations

import math
import statistics
import time

import numpy as np

from chaoscam.testsystems import flow_trajectory, torus_section, torus_signal, ueda

BUDGET_S = 2.0
N_SAMPLES = 20_000
N_SECTION = 100


def cases():
    """(name, x, dt, forcing period, section) for the timed runs."""
    two_pi = 2.0 * math.pi
    _, s = flow_trajectory(
        ueda(),
        [2.5, 0.0, 0.0],
        dt=two_pi / 400,
        n_samples=N_SAMPLES,
        sample_every=4,
        transient_time=100 * two_pi,
    )
    yield "ueda (chaotic)", s[:, 0], two_pi / 100, two_pi, s[::100, :2][:N_SECTION]
    t = np.arange(N_SAMPLES) * 0.01
    yield "torus (quasiperiodic)", torus_signal(t), 0.01, 1.0, torus_section(N_SECTION)
    x = np.cos(2 * math.pi * t) + 0.1 * np.cos(math.pi * t + 0.3)
    k = np.arange(N_SECTION)
    sec = np.column_stack([1 + 0.1 * np.cos(math.pi * k + 0.3), np.zeros(N_SECTION)])
    yield "forced period 2", x, 0.01, 1.0, sec


def main() -> None:
    data = list(cases())
    t0 = time.perf_counter()
    from chaoscam.analysis import classify_signal

    first = None
    print(
        f"classify_signal, {N_SAMPLES} samples + {N_SECTION} section points, "
        f"budget {BUDGET_S:.1f} s"
    )
    for name, x, dt, period, sec in data:
        if first is None:
            classify_signal(x, dt, period, section=sec)
            first = time.perf_counter() - t0
            print(
                f"  first call of the process (imports included): {first:.3f} s "
                f"= {first / BUDGET_S:.3f} of the budget"
            )
        times = []
        for _ in range(5):
            t1 = time.perf_counter()
            verdict = classify_signal(x, dt, period, section=sec)
            times.append(time.perf_counter() - t1)
        med = statistics.median(times)
        print(
            f"  {name:22s} -> {verdict.label:13s} period={verdict.period}: "
            f"{med:.3f} s (median of 5) = {med / BUDGET_S:.3f} of the budget"
        )
    name, x, dt, period, sec = data[0]
    t1 = time.perf_counter()
    classify_signal(x, dt, period, section=sec, series_lyapunov=True)
    extra = time.perf_counter() - t1
    print(
        f"  {name} with series_lyapunov=True (nolds): {extra:.3f} s "
        f"= {extra / BUDGET_S:.3f} of the budget"
    )


if __name__ == "__main__":
    main()
