"""Time to classify a default 20 s trajectory from its evidence (budget: 2 s).

Run: python benchmarks/bench_classify_model.py

Simulates ``chaoscam.simulate()`` once (not timed), then times
``classify_trajectory(traj, tangent=False)`` — spectrum, 0–1 test and section evidence of the
theta_f(t) series and the stroboscopic section (the issue's budget excludes exponents): the
first call of the process (lazy imports included) and the median of 5 further calls. Further
lines time the default (tangent exponent re-simulated, orbit certificate, extension) and
``lyapunov=True``, for reference.
"""

from __future__ import annotations

import statistics
import time

BUDGET_S = 2.0


def main() -> None:
    from chaoscam import simulate

    traj = simulate()
    t0 = time.perf_counter()
    from chaoscam.classify import classify_trajectory

    v = classify_trajectory(traj, tangent=False)
    first = time.perf_counter() - t0
    times = []
    for _ in range(5):
        t1 = time.perf_counter()
        v = classify_trajectory(traj, tangent=False)
        times.append(time.perf_counter() - t1)
    med = statistics.median(times)
    print(
        f"classify_trajectory, default 20 s run ({len(traj.series)} samples, "
        f"{len(traj.section)} section points), budget {BUDGET_S:.1f} s"
    )
    print(f"  first call (imports included): {first:.3f} s = {first / BUDGET_S:.3f} of the budget")
    print(f"  median of 5:                   {med:.3f} s = {med / BUDGET_S:.3f} of the budget")
    print(f"  verdict: {v.label} (period {v.period}); {'; '.join(v.reasons) or 'no reasons'}")
    t1 = time.perf_counter()
    vt = classify_trajectory(traj)
    print(
        f"  default (tangent exponent, certificate, extension): "
        f"{time.perf_counter() - t1:.3f} s -> {vt.label} (period {vt.period})"
    )
    t1 = time.perf_counter()
    vl = classify_trajectory(traj, lyapunov=True)
    print(
        f"  with lyapunov=True (outside the budget): {time.perf_counter() - t1:.3f} s -> {vl.label}"
    )


if __name__ == "__main__":
    main()
