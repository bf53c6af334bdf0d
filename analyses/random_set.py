"""Settle the truth of random-line-length configurations (sigma > 0) by common-noise twins.

For a random dynamical system the question is the sign of the top Lyapunov exponent of the
cocycle (L. Arnold, Random Dynamical Systems, 1998): negative, trajectories driven by the same
draws converge (synchronised); positive, they separate (random chaos). Each configuration is
settled at dt and at dt/2 (chaoscam.Numerics().refined()), independently of the classifier:

1. a run of TRANSIENT + RECORDED s with the tangent; its section's clusters (the least n whose n
   interleaved sub-sequences are each narrower than CLUSTER_RTOL of the extent) and lambda_1;
2. twin runs from three section points of that run (a quarter, half and all of the record),
   each with a twin moved by SYNC_DELTA rad (theta_f, theta_f' T, theta_f in turn) and one moved
   by CHAOS_DELTA rad, sharing the draws (same seed and index), for TWIN_S s; the distance over
   the last quarter of each pair, in units of its start, and whether the pair's draws stayed
   shared (the section's line length equal in both) until the pair first grew 100-fold.

*periodic n* (synchronised): at dt/2 every SYNC_DELTA pair ends at most 1e-2 of its start and
no CHAOS_DELTA pair grows; at dt no pair ends above SYNC_DELTA (the coarser step may keep a floor
of its own below it: at xi = 0.525, sigma = 2 mm, 1e-8 pairs grow to ~6e-7 rad at dt and shrink
at dt/2); the draws shared, and the same n clusters at both steps. *chaotic*: at both steps every
CHAOS_DELTA pair ends at least 100x its start and no SYNC_DELTA pair shrinks, with the draws
shared, and lambda_1 - 3 stderr > 0.
Anything else is *unsettled*, reported and left out of the tests.

Usage: python analyses/random_set.py [OUT.json] [--force] [--only NAME ...] [--from IN.json]
(default tests/data/random_set.json, with --holdout tests/data/random_holdout.json; --from
re-applies the rules to measurements made before, --remeasure NAME ... measures those anew)
"""

from __future__ import annotations

import json
import sys
import time
from pathlib import Path

import numpy as np

import chaoscam
from chaoscam import Numerics, Params
from chaoscam.analysis import spectrum_from_jacobians

CONFIGS: dict[str, dict] = {
    "xi=0.2,sigma=2mm": {"xi": 0.2, "l_lambda_sigma": 0.002},
    "xi=0.525,sigma=2mm": {"xi": 0.525, "l_lambda_sigma": 0.002},
    "e=0.02,sigma=2mm": {"e": 0.02, "l_lambda_sigma": 0.002},
    "omega=22,sigma=2mm": {"omega": 22.0, "l_lambda_sigma": 0.002},
    "omega=31,sigma=2mm": {"omega": 31.0, "l_lambda_sigma": 0.002},
    "omega=45,sigma=2mm": {"omega": 45.0, "l_lambda_sigma": 0.002},
    "xi=0.35,sigma=2mm": {"xi": 0.35, "l_lambda_sigma": 0.002},
    "xi=0.5,sigma=2mm": {"xi": 0.5, "l_lambda_sigma": 0.002},
    "J=0.0331,sigma=4mm": {"J": 0.0331, "l_lambda_sigma": 0.004},
    "sigma=2mm": {"l_lambda_sigma": 0.002},
    "l_lambda=0.015,sigma=2mm": {"l_lambda": 0.015, "l_lambda_sigma": 0.002},
    "omega=38,sigma=2mm": {"omega": 38.0, "l_lambda_sigma": 0.002},
    "omega=26,sigma=2mm": {"omega": 26.0, "l_lambda_sigma": 0.002},
    "xi=0.3,sigma=1mm": {"xi": 0.3, "l_lambda_sigma": 0.001},
    "xi=0.45,sigma=2mm": {"xi": 0.45, "l_lambda_sigma": 0.002},
    "x_O=-0.45,sigma=2mm": {"x_O": -0.45, "l_lambda_sigma": 0.002},
}
# A second set, settled by the same rules after the twin rule was built and never used to tune
# it: configurations it had not seen (``--holdout``).
HOLDOUT: dict[str, dict] = {
    "omega=20,sigma=2mm": {"omega": 20.0, "l_lambda_sigma": 0.002},
    "e=0.025,sigma=2mm": {"e": 0.025, "l_lambda_sigma": 0.002},
    "xi=0.25,sigma=3mm": {"xi": 0.25, "l_lambda_sigma": 0.003},
    "omega=29.25,xi=0.1,sigma=2mm": {"omega": 29.25, "xi": 0.1, "l_lambda_sigma": 0.002},
    "sigma=1mm": {"l_lambda_sigma": 0.001},
    "mu_f=0.1,sigma=2mm": {"mu_f": 0.1, "l_lambda_sigma": 0.002},
    "omega=50,xi=0.3,sigma=2mm": {"omega": 50.0, "xi": 0.3, "l_lambda_sigma": 0.002},
    "e=0.03,sigma=2mm": {"e": 0.03, "l_lambda_sigma": 0.002},
}
TRANSIENT, RECORDED, TWIN_S = 60.0, 120.0, 100.0  # [s]
SYNC_DELTA, CHAOS_DELTA = 1e-6, 1e-8  # [rad]
CLUSTER_RTOL, MAX_CLUSTERS = 0.2, 16


def clusters(points: np.ndarray, period_s: float) -> tuple[int, float]:
    """(least n of clusters visited in turn, each within CLUSTER_RTOL of the extent (1 when
    none), the widest one's width [rad])."""
    z = points * np.array([1.0, period_s])
    extent = float(np.ptp(z, axis=0).max())
    for n in range(1, MAX_CLUSTERS + 1):
        width = max(float(np.ptp(z[r::n], axis=0).max()) for r in range(n))
        if width <= max(1e-5, CLUSTER_RTOL * extent):
            return n, width
    return 1, extent


def twins(p: Params, num: Numerics, run, delta: float) -> list[dict]:
    """Each pair's tail distance / delta and whether its draws stayed shared."""
    pts = run.section[["theta_f", "omega_f"]].to_numpy()
    starts = pts[[len(pts) // 4, len(pts) // 2, -1]]
    models = []
    for i, (th, om) in enumerate(starts):
        moved = (th, om + delta / p.cam_period) if i == 1 else (th + delta, om)
        models.append(p.replace(theta_f0=th, omega_f0=om))
        models.append(p.replace(theta_f0=moved[0], omega_f0=moved[1]))
    sol = chaoscam.solve(models, num, indices=[run.index] * len(models), duration=TWIN_S)
    sec, out = sol.sections, []
    for i in range(len(starts)):
        a, b = (sec[sec["member"] == m] for m in (2 * i, 2 * i + 1))
        n = min(len(a), len(b))
        d = np.hypot(
            a["theta_f"].to_numpy()[:n] - b["theta_f"].to_numpy()[:n],
            (a["omega_f"].to_numpy()[:n] - b["omega_f"].to_numpy()[:n]) * p.cam_period,
        )
        tail = d[int(0.75 * n) :]
        ratio = 0.0 if (tail == 0).any() else float(np.exp(np.log(tail).mean())) / delta
        # shared: the same draws up to where the pair first grew 100-fold (or throughout)
        differ = np.flatnonzero(a["l_lambda"].to_numpy()[:n] != b["l_lambda"].to_numpy()[:n])
        grown = np.flatnonzero(d > 100 * delta)
        shared = not len(differ) or (len(grown) > 0 and differ[0] > grown[0])
        out.append(
            {"ratio": ratio, "shared": bool(shared), "status": sol.members["status"].iat[2 * i]}
        )
    return out


def measure(overrides: dict) -> dict:
    p, out = Params(**overrides), {"params": overrides}
    for name, num in (("dt", Numerics()), ("dt/2", Numerics().refined())):
        run = chaoscam.simulate(p, num, duration=TRANSIENT + RECORDED, transient=TRANSIENT,
                                series=False, tangent=True)  # fmt: skip
        m = {"status": run.status.name}
        if run.ok:
            keep = run.section["k"].to_numpy() > 0
            spec = spectrum_from_jacobians(run.jacobians[keep], p.cam_period)
            n, width = clusters(run.section[["theta_f", "omega_f"]].to_numpy(), p.cam_period)
            m.update(clusters=n, width=width, lambda1=float(spec.exponents[0]),
                     stderr=float(spec.stderr[0]), sync=twins(p, num, run, SYNC_DELTA),
                     chaos=twins(p, num, run, CHAOS_DELTA))  # fmt: skip
        out[name] = m
    return out


def settle(m: dict) -> tuple[str, int | None, str]:
    a, b = m["dt"], m["dt/2"]
    if a["status"] != "OK" or b["status"] != "OK":
        return "unsettled", None, f"status {a['status']} / {b['status']}"
    ok = all(t["status"] == "OK" and t["shared"] for r in (a, b) for t in r["sync"] + r["chaos"])
    # synchronised at dt/2 at both amplitudes; at dt no pair grows past SYNC_DELTA (a coarse
    # step may keep a floor of its own below it)
    sync = all(t["ratio"] <= 1e-2 for t in b["sync"]) and all(t["ratio"] <= 1 for t in b["chaos"])
    sync &= all(t["ratio"] <= 1 for t in a["sync"])
    sync &= all(t["ratio"] <= SYNC_DELTA / CHAOS_DELTA for t in a["chaos"])
    chaos = all(t["ratio"] >= 100 for r in (a, b) for t in r["chaos"])
    chaos &= all(t["ratio"] >= 1 for r in (a, b) for t in r["sync"])
    pos = all(r["lambda1"] - 3 * r["stderr"] > 0 for r in (a, b))
    shown = "; ".join(f"{k}: {_shown(r)}" for k, r in (("dt", a), ("dt/2", b)))
    if ok and sync and not chaos and a["clusters"] == b["clusters"]:
        return "periodic", a["clusters"], f"synchronised at dt and dt/2 ({shown})"
    if ok and chaos and pos and not sync:
        return "chaotic", None, f"twins separate at dt and dt/2 ({shown})"
    why = "draws not shared by every pair" if not ok else "the twins do not settle it"
    return "unsettled", None, f"{why} ({shown})"


def _shown(r: dict) -> str:
    sync = ", ".join(f"{t['ratio']:.2g}" for t in r["sync"])
    chaos = ", ".join(f"{t['ratio']:.2g}" for t in r["chaos"])
    return (f"sync {sync}, chaos {chaos}, lambda1 {r['lambda1']:.3g} +- {r['stderr']:.2g}, "
            f"{r['clusters']} cluster(s) of {r['width']:.2g} rad")  # fmt: skip


def main(argv: list[str]) -> None:
    """``[OUT.json] [--force]``: measure, settle, and write the table (whole or not at all)."""
    import argparse

    from chaoscam.io import OutputError, atomic_write_bytes, check_output

    ap = argparse.ArgumentParser(prog="analyses/random_set.py", description=__doc__.splitlines()[0])
    ap.add_argument("out", nargs="?", metavar="OUT.json")
    ap.add_argument("--force", action="store_true", help="replace an existing OUT.json")
    ap.add_argument("--holdout", action="store_true", help="the holdout configurations")
    ap.add_argument("--only", nargs="*", help="these configurations only")
    ap.add_argument("--remeasure", nargs="*", default=[], help="measure these anew (--from)")
    ap.add_argument("--from", dest="source", metavar="IN.json", help="re-settle these")
    args = ap.parse_args(argv)
    configs, default = (
        (HOLDOUT, "random_holdout.json") if args.holdout else (CONFIGS, "random_set.json")
    )
    out = Path(args.out or Path(__file__).parents[1] / "tests/data" / default)
    try:
        check_output(out, flag="OUT.json", force=args.force, suffixes=(".json",))
    except OutputError as err:
        ap.error(str(err))
    old = json.loads(Path(args.source).read_text()) if args.source else {}
    table = {}
    for name, overrides in configs.items():
        if args.only and name not in args.only:
            continue
        t0 = time.perf_counter()
        fresh = name not in old or name in args.remeasure
        m = measure(overrides) if fresh else old[name]
        label, period, why = settle(m)
        m.setdefault("wall_time_s", time.perf_counter() - t0)
        m.update(label=label, period=period, why=why)
        table[name] = m
        print(f"{name:>26}: {label:<10} {period or '':>3}  {why}  ({m['wall_time_s']:.0f} s)",
              flush=True)  # fmt: skip
    text = json.dumps(table, indent=1, default=float) + "\n"
    atomic_write_bytes(out, text.encode(), replace=args.force)
    print(f"wrote {out}")


if __name__ == "__main__":
    main(sys.argv[1:])
