"""The default classify of a 120-s run (60 s transient) of the random model, with and without the
common-noise twins (the rule ``common_noise_twins``): the ratio of the two, measured in one run.

Run: python benchmarks/bench_classify_random.py [--repeats N]

Each configuration is simulated once as ``chaoscam simulate`` stores it (no Jacobians, so the
verdict re-solves the tangent as a user's classify does), then classified alternately with and
without the rule, ``--repeats`` times; the medians and their ratio are printed (target: <= 2).
"""

from __future__ import annotations

import argparse
import statistics
import time

import chaoscam
from chaoscam.verdict import _rules

CONFIGS = {
    "sigma = 2 mm (Table 1, chaotic)": {"l_lambda_sigma": 0.002},
    "xi = 0.525, sigma = 2 mm (synchronised, 8 clusters)": {"xi": 0.525, "l_lambda_sigma": 0.002},
    "omega = 31, sigma = 2 mm (synchronised, 5 clusters)": {"omega": 31.0, "l_lambda_sigma": 0.002},
    "xi = 0.2, sigma = 2 mm (synchronised, 1 cluster)": {"xi": 0.2, "l_lambda_sigma": 0.002},
}


def _timed(run, rules) -> tuple[float, str]:
    _rules.RULES = rules
    t0 = time.perf_counter()
    (v,) = chaoscam.classify(run)
    return time.perf_counter() - t0, f"{v.label} {v.period or ''}".strip()


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeats", type=int, default=3)
    args = ap.parse_args()
    full = _rules.RULES
    without = tuple(r for r in full if r.name != "common_noise_twins")
    runs = {k: chaoscam.simulate(duration=120.0, transient=60.0, series=False, **v)
            for k, v in CONFIGS.items()}  # fmt: skip
    _timed(runs[next(iter(runs))], full)  # compile and warm
    total_new = total_old = 0.0
    for name, run in runs.items():
        new, old = [], []
        for _ in range(args.repeats):
            t, label_new = _timed(run, full)
            new.append(t)
            t, label_old = _timed(run, without)
            old.append(t)
        a, b = statistics.median(new), statistics.median(old)
        total_new, total_old = total_new + a, total_old + b
        print(f"{name:<52} with twins {a:6.2f} s ({label_new}), without {b:6.2f} s "
              f"({label_old}): ratio {a / b:.2f}")  # fmt: skip
    _rules.RULES = full
    print(f"all configurations: ratio {total_new / total_old:.2f} (target <= 2)")


if __name__ == "__main__":
    main()
