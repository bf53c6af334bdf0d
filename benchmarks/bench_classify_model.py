"""Time to classify a default 20 s trajectory from its evidence (budget: 2 s).

Run: python benchmarks/bench_classify_model.py

Simulates ``chaoscam.simulate(tangent=True)`` once (not timed: the run carries the section
map's Jacobians, so the verdict computes no exponent by simulation), then times
``chaoscam.classify(run, extend_to=None)`` — the section evidence, the tangent exponent from
the run's Jacobians (QR) and the model-level rules (with the periodic-orbit certificate where
they call for it), without extending an undetermined run: the first call of the process
(lazy imports included) and the median of 5 further calls. A last line times the default
``classify`` of a run made without the tangent (``chaoscam.simulate()``: the verdict solves
the realization again with the tangent and extends an undetermined one up to 120 s
recorded), for reference.
"""

from __future__ import annotations

import statistics
import time

BUDGET_S = 2.0


def main() -> None:
    import chaoscam

    run = chaoscam.simulate(tangent=True)
    t0 = time.perf_counter()
    (v,) = chaoscam.classify(run, extend_to=None)
    first = time.perf_counter() - t0
    times = []
    for _ in range(5):
        t1 = time.perf_counter()
        (v,) = chaoscam.classify(run, extend_to=None)
        times.append(time.perf_counter() - t1)
    med = statistics.median(times)
    print(
        f"chaoscam.classify(extend_to=None), default 20 s run with its Jacobians "
        f"({len(run.section)} section points), budget {BUDGET_S:.1f} s"
    )
    print(f"  first call (imports included): {first:.3f} s = {first / BUDGET_S:.3f} of the budget")
    print(f"  median of 5:                   {med:.3f} s = {med / BUDGET_S:.3f} of the budget")
    print(f"  verdict: {v.label} (period {v.period}); {'; '.join(v.reasons) or 'no reasons'}")
    plain = chaoscam.simulate()
    t1 = time.perf_counter()
    (vd,) = chaoscam.classify(plain)
    extended = vd.settings.get("extended", {}).get("recorded_s")
    print(
        f"  default classify of a run without the tangent (solved again with it, extended "
        f"to {extended or 'no'} s recorded; outside the budget): "
        f"{time.perf_counter() - t1:.3f} s -> {vd.label} (period {vd.period})"
    )


if __name__ == "__main__":
    main()
