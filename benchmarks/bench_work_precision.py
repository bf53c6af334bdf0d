"""Work–precision: fixed-step RK4 against the adaptive path at equal accuracy (issue 6).

Two accuracy measures, each against a plain fixed-step RK4 run at dt = 2.5e-7 s (the
reference; its own error is estimated from the dt = 5e-7 run and printed):

- **impacts**: the first ten impacts faster than 0.01 m/s of a default run (2 s), to
  1e-6 s in time and 1e-6 rad in angle;
- **sections**: the stroboscopic section over 20 s of periodic responses (xi = 0.2, period
  1; omega = 45 rad/s, period 7, a third of the time in contact) to 1e-6 rad. A chaotic
  response cannot be compared point by point that far.

For each integrator the cheapest setting that meets a target is found on a ladder of steps
(RK4) or tolerances (adaptive), coarse to fine, and the cost ratio at equal accuracy is
printed. A setting counts only if it and every finer rung meet the target ("meets from here
on"): near the tolerance a chaotic run's error is not monotone in the setting (measured: the
impacts' error at rtol 1e-12 to 3e-14 was 2.8e-6 where 1e-10 and 1e-11 gave 1-3e-7), and a
rung that meets by chance is not the accuracy the setting buys. The ladders start coarse
enough that their first rung fails; where the coarsest rung counts, the ratio is printed as
a bound (a coarser setting might be cheaper still). Where the reference's own error (its
difference from dt = 5e-7) is not below a third of the target, no ratio is printed. Three
integrators are compared: plain fixed-step RK4 (``flight_merge=1``, the paper's method),
RK4 with merged flight steps (the package default), and adaptive Dormand–Prince. Target:
>= 10x over fixed-step RK4. Times are the best of a few repeats, single-threaded; this
machine is noisy, so read ratios, not absolute times.

Run: ``python benchmarks/bench_work_precision.py`` (about 2 minutes).
"""

from __future__ import annotations

import os
import time
import warnings

os.environ.setdefault("NUMBA_NUM_THREADS", "1")

import numpy as np  # noqa: E402

import chaoscam  # noqa: E402
from chaoscam import Numerics, Params  # noqa: E402

TOL = 1e-6
DT_LADDER = (4e-5, 2e-5, 1e-5, 8e-6, 6e-6, 5e-6, 4e-6, 2e-6, 1e-6, 7e-7, 5e-7)  # coarse to fine
RTOL_LADDER = (1e-4, 1e-5, 1e-6, 1e-7, 1e-8, 1e-9, 1e-10, 1e-11, 1e-12, 1e-13, 3e-14, 1e-14)


def timed(p: Params, num: Numerics, duration: float, repeat: int):
    best, tr = float("inf"), None
    for _ in range(repeat):
        t0 = time.perf_counter()
        tr = chaoscam.simulate(p, num, duration=duration, series=False)
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


def ladder(p: Params, duration: float, ref, error, repeat: int):
    """Rows (label, kind, setting, seconds, error) over the three integrators' ladders, on
    the model ``p`` from the default numerics."""
    base = Numerics()
    rows = []
    for dt in DT_LADDER:
        for kind, merge in (("rk4 fixed", 1), ("rk4 merged", base.flight_merge)):
            sec, tr = timed(p, base.replace(dt=dt, flight_merge=merge), duration, repeat)
            rows.append((kind, f"dt={dt:g}", sec, error(tr, ref)))
    for rtol in RTOL_LADDER:
        num = base.replace(integrator="adaptive", rtol=rtol, atol=rtol / 3)
        sec, tr = timed(p, num, duration, repeat)
        rows.append(("adaptive", f"rtol={rtol:g}", sec, error(tr, ref)))
    return rows


def settled(rows, kind: str):
    """The cheapest rung of ``kind`` from which every finer rung meets :data:`TOL`, as
    ``(setting, seconds, coarsest)``, ``coarsest`` telling whether it is the ladder's first
    rung (then a coarser setting might be cheaper still); None if the finest rung fails."""
    mine = [(setting, sec, err) for k, setting, sec, err in rows if k == kind]
    start = len(mine)
    while start > 0 and mine[start - 1][2] < TOL:
        start -= 1
    if start == len(mine):
        return None
    best = min(mine[start:], key=lambda r: r[1])
    return best[0], best[1], start == 0


QUALIFIED = {
    (True, False): ("at most ", ""),
    (False, True): ("at least ", ""),
    (True, True): ("", " (both at their ladders' coarsest rung: not settled)"),
}
"""How a ratio is read when (RK4's, the adaptive path's) cheapest setting is its ladder's
coarsest rung: a coarser RK4 step could lower the ratio, a coarser tolerance raise it."""


def report(title: str, rows, ref_error: float) -> None:
    print(f"\n{title}")
    for kind, setting, sec, err in rows:
        ok = "meets" if err < TOL else "     "
        print(f"  {kind:11s} {setting:12s} {sec * 1e3:9.1f} ms  error {err:9.2e}  {ok}")
    if not ref_error < TOL / 3:
        print(
            f"  no ratio: the reference's own error {ref_error:.1e} is not below a third of "
            f"{TOL:g}, so it cannot tell which setting meets it"
        )
        return
    best = {k: settled(rows, k) for k in ("rk4 fixed", "rk4 merged", "adaptive")}
    for kind, found in best.items():
        if found is None:
            print(f"  {kind}: its finest rung misses {TOL:g}")
            continue
        setting, sec, coarsest = found
        note = " (the ladder's coarsest rung: a coarser one might meet too)" if coarsest else ""
        print(
            f"  cheapest {kind:11s} meeting {TOL:g} from here on: {setting} in "
            f"{sec * 1e3:.1f} ms{note}"
        )
    if best["adaptive"] is None:
        return
    _, ad, ad_edge = best["adaptive"]
    for kind in ("rk4 fixed", "rk4 merged"):
        if best[kind] is None:
            continue
        _, rk, rk_edge = best[kind]
        before, after = QUALIFIED.get((rk_edge, ad_edge), ("", ""))
        print(
            f"  ratio {kind} / adaptive at equal accuracy: {before}{rk / ad:.1f}x{after}"
            + ("  (target >= 10x)" if kind == "rk4 fixed" else "")
        )


def main() -> None:
    # the coarse rungs resolve the contact with fewer than 40 steps, and say so each run
    warnings.simplefilter("ignore", RuntimeWarning)
    chaoscam.simulate(duration=0.01)
    chaoscam.simulate(numerics=Numerics(integrator="adaptive"), duration=0.01)
    fine = Numerics(dt=2.5e-7, flight_merge=1)

    p = Params()
    ref = chaoscam.simulate(p, fine, duration=2.0, series=False)
    half = chaoscam.simulate(p, fine.replace(dt=5e-7), duration=2.0, series=False)
    own = impact_error(half, ref)
    print(f"reference dt 2.5e-7; dt 5e-7 differs from it by {own:.1e} on the impacts")
    report(
        "first ten impacts > 0.01 m/s of the default run (2 s), to 1e-6 s and 1e-6 rad",
        ladder(p, 2.0, ref, impact_error, 3),
        own,
    )

    for changes in ({"xi": 0.2}, {"omega": 45.0}):
        p = Params(**changes)
        ref = chaoscam.simulate(p, fine, duration=20.0, series=False)
        half = chaoscam.simulate(p, fine.replace(dt=5e-7), duration=20.0, series=False)
        own = section_error(half, ref)
        print(f"\nreference dt 2.5e-7 for {changes}; dt 5e-7 differs by {own:.1e} rad")
        report(
            f"20 s stroboscopic section of {changes} (periodic), to 1e-6 rad",
            ladder(p, 20.0, ref, section_error, 2),
            own,
        )


if __name__ == "__main__":
    main()
