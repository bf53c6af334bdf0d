"""Verdict machinery on the model, measured in one run (verdicts issue).

Prints, each as measured here:
- the tangent exponent's cost against one simulation of the same run (target <= 1.5x);
- the time to certify a periodic orbit: Newton shooting, and the whole certificate with its
  step halving (target <= 1 s for period <= 8);
- the default 20 s run with chattering handled (v_min = 0, plastic hand-over below
  v_chatter) against the same run with the withdrawn v_min = 1e-3 m/s decision, the closest
  thing to the old default that this build still runs (target <= 2x).
"""

from __future__ import annotations

import os
import time

os.environ.setdefault("NUMBA_NUM_THREADS", "1")

from bench_simulate import best_of  # noqa: E402 (benchmarks/ is on the path of a script)

import chaoscam  # noqa: E402
from chaoscam import Numerics, Params  # noqa: E402
from chaoscam.verdict import certify, lyapunov_spectrum, periodic_orbit  # noqa: E402


def main() -> None:
    p = Params()
    chaoscam.simulate(p, duration=0.01, tangent=True)  # compile or load from cache
    plain = best_of(lambda: chaoscam.simulate(p, duration=120.0, transient=60.0, series=False), 3)
    tangent = best_of(lambda: lyapunov_spectrum(p, duration=120.0, transient=60.0), 3)
    print(
        f"default 120 s run: simulation {plain:.3f} s, with the tangent exponent {tangent:.3f} s, "
        f"ratio {tangent / plain:.2f}x (target <= 1.5x)"
    )
    cases = (
        ("xi = 0.2, period 1", Params(xi=0.2), 1),
        ("omega = 45, period 7", Params(omega=45.0), 7),
        ("e = 0.03, period 8", Params(e=0.03), 8),
    )
    for label, q, n in cases:
        tr = chaoscam.simulate(q, duration=80.0, transient=60.0, series=False)
        x0 = tr.section[["theta_f", "omega_f"]].to_numpy()[-1]
        t0 = time.perf_counter()
        orbit = periodic_orbit(q, x0, n)
        wall = time.perf_counter() - t0
        points = tr.section[["theta_f", "omega_f"]].to_numpy()
        t0 = time.perf_counter()
        cert = certify(q, Numerics(), points, n, {})
        whole = time.perf_counter() - t0
        print(
            f"certified orbit ({label}): shooting {wall:.3f} s, converged {orbit.converged}, "
            f"period {orbit.period}, |mu|max {abs(orbit.multipliers).max():.3g}, "
            f"{orbit.settings['map_calls']} map calls; the whole certificate (the run on it, "
            f"step halving, settling at dt/2) {whole:.3f} s, {cert.status} (target <= 1 s)"
        )
    now = best_of(lambda: chaoscam.simulate(p, duration=20.0, series=False), 3)
    old = best_of(lambda: chaoscam.simulate(p.replace(v_min=1e-3), duration=20.0, series=False), 3)
    print(
        f"default 20 s run: chattering handled {now:.3f} s, v_min = 1e-3 {old:.3f} s, "
        f"ratio {now / old:.2f}x (target <= 2x)"
    )


if __name__ == "__main__":
    main()
