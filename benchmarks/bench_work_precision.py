"""Work–precision: fixed-step RK4 against the adaptive path at equal accuracy (issue 6).

Two accuracy measures, each against a plain fixed-step RK4 run at dt = 2.5e-7 s (the
reference; its own error is estimated from the dt = 5e-7 run and printed):

- **impacts**: the first ten impacts faster than 0.01 m/s of a default run (2 s), to
  1e-6 s in time and 1e-6 rad in angle;
- **sections**: the stroboscopic section over 20 s of periodic responses (xi = 0.2, period
  1; omega = 45 rad/s, period 7, a third of the time in contact) to 1e-6 rad. A chaotic
  response cannot be compared point by point that far.

For each integrator the cheapest setting that meets a target is found on a ladder of steps
(RK4) or tolerances (adaptive), and the cost ratio at equal accuracy is printed. Three
integrators are compared: plain fixed-step RK4 (``flight_merge=1``, the paper's method),
RK4 with merged flight steps (the package default), and adaptive Dormand–Prince. Target:
>= 10x over fixed-step RK4. Times are the best of a few repeats, single-threaded; this
machine is noisy, so read ratios, not absolute times.

Run: ``python benchmarks/bench_work_precision.py`` (about 2 minutes).
"""

from __future__ import annotations

import os
import time

os.environ.setdefault("NUMBA_NUM_THREADS", "1")

import numpy as np  # noqa: E402

import chaoscam  # noqa: E402
from chaoscam import Params  # noqa: E402

TOL = 1e-6
DT_LADDER = (4e-6, 2e-6, 1e-6, 7e-7, 5e-7)
RTOL_LADDER = (1e-9, 1e-10, 1e-11, 1e-12, 1e-13, 3e-14, 1e-14)


def timed(p: Params, duration: float, repeat: int):
    best, tr = float("inf"), None
    for _ in range(repeat):
        t0 = time.perf_counter()
        tr = chaoscam.simulate(p, duration=duration, series=False)
        best = min(best, time.perf_counter() - t0)
    return best, tr


def fast_impacts(tr, n: int = 10) -> np.ndarray:
    imp = tr.impacts[-tr.impacts.gap_rate_before > 0.01]
    return imp[["t", "theta_f"]].to_numpy()[:n]


def impact_error(tr, ref) -> float:
    a, b = fast_impacts(tr), fast_impacts(ref)
    if len(a) < 10 or len(b) < 10:
        return float("inf")
    return float(np.max(np.abs(a - b)))  # max over time [s] and angle [rad]


def section_error(tr, ref) -> float:
    a, b = tr.section, ref.section
    if len(a) != len(b) or not np.array_equal(a.k.values, b.k.values):
        return float("inf")
    return float(np.max(np.abs(a.theta_f.values - b.theta_f.values)))


def ladder(base: Params, duration: float, ref, error, repeat: int):
    """Rows (label, kind, setting, seconds, error) over the three integrators' ladders."""
    rows = []
    for dt in DT_LADDER:
        for kind, merge in (("rk4 fixed", 1), ("rk4 merged", base.flight_merge)):
            sec, tr = timed(base.replace(dt=dt, flight_merge=merge), duration, repeat)
            rows.append((kind, f"dt={dt:g}", sec, error(tr, ref)))
    for rtol in RTOL_LADDER:
        p = base.replace(integrator="adaptive", rtol=rtol, atol=rtol / 3)
        sec, tr = timed(p, duration, repeat)
        rows.append(("adaptive", f"rtol={rtol:g}", sec, error(tr, ref)))
    return rows


def report(title: str, rows) -> None:
    print(f"\n{title}")
    for kind, setting, sec, err in rows:
        ok = "meets" if err < TOL else "     "
        print(f"  {kind:11s} {setting:12s} {sec * 1e3:9.1f} ms  error {err:9.2e}  {ok}")
    best = {}
    for kind, setting, sec, err in rows:
        if err < TOL and (kind not in best or sec < best[kind][1]):
            best[kind] = (setting, sec)
    for kind, (setting, sec) in best.items():
        print(f"  cheapest {kind:11s} at {TOL:g}: {setting} in {sec * 1e3:.1f} ms")
    if "adaptive" in best:
        ad = best["adaptive"][1]
        for kind in ("rk4 fixed", "rk4 merged"):
            if kind in best:
                print(
                    f"  ratio {kind} / adaptive at equal accuracy: {best[kind][1] / ad:.1f}x"
                    + ("  (target >= 10x)" if kind == "rk4 fixed" else "")
                )
            else:
                print(f"  {kind}: no step on the ladder meets {TOL:g}")
    else:
        print("  adaptive: no tolerance on the ladder meets the target")


def main() -> None:
    chaoscam.simulate(duration=0.01)
    chaoscam.simulate(Params(integrator="adaptive"), duration=0.01)
    fine = Params(dt=2.5e-7, flight_merge=1)

    p = Params()
    ref = chaoscam.simulate(fine, duration=2.0, series=False)
    half = chaoscam.simulate(fine.replace(dt=5e-7), duration=2.0, series=False)
    print(
        f"reference dt 2.5e-7; dt 5e-7 differs from it by {impact_error(half, ref):.1e} "
        "on the impacts"
    )
    report(
        "first ten impacts > 0.01 m/s of the default run (2 s), to 1e-6 s and 1e-6 rad",
        ladder(p, 2.0, ref, impact_error, 3),
    )

    for changes in ({"xi": 0.2}, {"omega": 45.0}):
        p = Params(**changes)
        ref = chaoscam.simulate(fine.replace(**changes), duration=20.0, series=False)
        half = chaoscam.simulate(fine.replace(dt=5e-7, **changes), duration=20.0, series=False)
        print(
            f"\nreference dt 2.5e-7 for {changes}; dt 5e-7 differs by "
            f"{section_error(half, ref):.1e} rad"
        )
        report(
            f"20 s stroboscopic section of {changes} (periodic), to 1e-6 rad",
            ladder(p, 20.0, ref, section_error, 2),
        )


if __name__ == "__main__":
    main()
