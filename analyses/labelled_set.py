"""Settle the truth of a set of model configurations, independently of the classifier.

Each configuration is settled by measurements the classifier never sees:

1. a long run (300 s recorded after a 100 s transient) and the same run with dt halved;
2. the band structure of each run's stroboscopic section: the least n for which every one of
   the n sub-sequences x_{r + k n} is narrower than BAND_RTOL of the attractor's extent (or
   than BAND_ATOL) — in both runs, with the same n;
3. the tangent exponent λ₁ ± stderr of each run (QR on its section map's Jacobians);
4. for a candidate period of the deterministic model, Newton shooting (converged,
   |μ| < 1, the run on the orbit);
5. a direct perturbation test: two runs from the long run's end state, one moved by
   PERTURBATION rad in θ_f, followed for 100 s; the largest and the last distance between
   their section points;
6. the other integrator: a run on the adaptive DOP853 path (CROSS_TRANSIENT + CROSS_RECORDED
   s), its band structure and λ₁ ± stderr.

The rules (written out in :func:`settle`): *periodic n* when both runs show n bands no wider
than BAND_ATOL-ish jitter, shooting certifies an attracting orbit and the perturbation decays;
*chaotic* when λ₁ − 3σ > 0 at both steps and the perturbation grows at least 100-fold;
either only if the adaptive run agrees (n bands and λ₁ not positive beyond 3σ for periodic,
λ₁ − 3σ > 0 for chaotic) — the step-halving pair alone once called a period-6 orbit chaotic
(ξ = 0.45: λ₁ = +0.56 at dt, −1.67 at dt/2, −2.85 on the adaptive path);
*quasiperiodic* when no period exists, λ₁ is zero within 3σ at both steps and the
perturbation neither decays nor grows 100-fold; anything else is *unsettled* and left out of
the labelled set (reported, never forced).

Usage: python analyses/labelled_set.py [OUT.json]   (default tests/data/labelled_set.json)
       python analyses/labelled_set.py --holdout [OUT.json]   (default tests/data/holdout_set.json)
"""

from __future__ import annotations

import json
import math
import sys
import time
from pathlib import Path

import numpy as np

import chaoscam
from chaoscam import Numerics, Params
from chaoscam.analysis import spectrum_from_jacobians
from chaoscam.verdict import periodic_orbit

CONFIGS: dict[str, dict] = {
    "xi=0.2": {"xi": 0.2},
    "xi=0.25": {"xi": 0.25},
    "xi=0.5": {"xi": 0.5},
    "e=0.02": {"e": 0.02},
    "e=0.03": {"e": 0.03},
    "omega=10": {"omega": 10.0},
    "omega=20": {"omega": 20.0},
    "omega=22": {"omega": 22.0},
    "omega=31": {"omega": 31.0},
    "omega=45": {"omega": 45.0},
    "default": {},
    "l_lambda=0.015": {"l_lambda": 0.015},
    "x_O=-0.45": {"x_O": -0.45},
    "mu_f=0.1": {"mu_f": 0.1},
    "sigma=0.002": {"l_lambda_sigma": 0.002},
    "xi=0.2,sigma=0.002": {"xi": 0.2, "l_lambda_sigma": 0.002},
}
# A second set, settled by the same rules after the classifier was built and never used to
# tune it: configurations it had not seen (``--holdout``).
HOLDOUT: dict[str, dict] = {
    "omega=15": {"omega": 15.0},
    "omega=26": {"omega": 26.0},
    "omega=38": {"omega": 38.0},
    "omega=50": {"omega": 50.0},
    "xi=0.3": {"xi": 0.3},
    "xi=0.35": {"xi": 0.35},
    "xi=0.45": {"xi": 0.45},
    "e=0.01": {"e": 0.01},
    "e=0.025": {"e": 0.025},
    "l_lambda=0.004": {"l_lambda": 0.004},
    "l_lambda=0.012": {"l_lambda": 0.012},
    "x_O=-0.40": {"x_O": -0.40},
    "mu_f=0.2": {"mu_f": 0.2},
    "sigma=0.001": {"l_lambda_sigma": 0.001},
    "xi=0.3,sigma=0.001": {"xi": 0.3, "l_lambda_sigma": 0.001},
    "omega=26,xi=0.3": {"omega": 26.0, "xi": 0.3},
}
TRANSIENT, RECORDED = 100.0, 300.0
BAND_RTOL = 1e-3  # bands narrower than this fraction of the extent ...
BAND_ATOL = 1e-5  # ... or than this [rad, θ_f and θ̇_f T] count as one point
PERTURBATION = 1e-8  # [rad]
CROSS_TRANSIENT, CROSS_RECORDED = 60.0, 100.0  # the adaptive run [s]
MAX_PERIOD = 16


def bands(points: np.ndarray, period_s: float) -> tuple[int | None, float, float]:
    """(least n with n narrow bands or None, widest band at that n [rad], extent [rad])."""
    z = points * np.array([1.0, period_s])
    extent = float(np.ptp(z, axis=0).max())
    for n in range(1, MAX_PERIOD + 1):
        width = max(float(np.ptp(z[r::n], axis=0).max()) for r in range(n))
        if width <= max(BAND_ATOL, BAND_RTOL * extent):
            return n, width, extent
    return None, math.nan, extent


def exponent(tr) -> tuple[float, float]:
    keep = tr.section["k"].to_numpy() > 0
    spec = spectrum_from_jacobians(tr.jacobians[keep], tr.params.cam_period)
    return float(spec.exponents[0]), float(spec.stderr[0])


def perturbation(p: Params, tr) -> tuple[float, float]:
    """(largest, last) section distance [rad] of two runs 1e-8 rad apart, over 100 s."""
    t_end, th, om = tr.final_state
    base = p.replace(theta_c0=(p.theta_c0 + p.omega * t_end) % (2 * math.pi))
    kw = dict(duration=100.0, series=False, seed=tr.settings["seed"], index=tr.index)
    a = chaoscam.simulate(base.replace(theta_f0=th, omega_f0=om), **kw)
    b = chaoscam.simulate(base.replace(theta_f0=th + PERTURBATION, omega_f0=om), **kw)
    n = min(len(a.section), len(b.section))
    w = np.array([1.0, p.cam_period])
    d = np.linalg.norm(
        (
            a.section[["theta_f", "omega_f"]].to_numpy()[:n]
            - b.section[["theta_f", "omega_f"]].to_numpy()[:n]
        )
        * w,
        axis=1,
    )
    return float(d.max()), float(d[-10:].max())


def measure(overrides: dict) -> dict:
    p, num = Params(**overrides), Numerics()
    out: dict = {"params": overrides}
    runs = {}
    for name, q in (("dt", num), ("dt/2", num.refined())):
        tr = chaoscam.simulate(
            p, q, duration=TRANSIENT + RECORDED, transient=TRANSIENT, series=False, tangent=True
        )
        runs[name] = tr
        m = {"status": tr.status.name}
        if tr.ok:
            pts = tr.section[["theta_f", "omega_f"]].to_numpy()
            n, width, extent = bands(pts, p.cam_period)
            lam, se = exponent(tr)
            m.update(bands=n, band_width=width, extent=extent, lambda1=lam, stderr=se)
        out[name] = m
    tr = chaoscam.simulate(
        p,
        Numerics(integrator="adaptive"),
        duration=CROSS_TRANSIENT + CROSS_RECORDED,
        transient=CROSS_TRANSIENT,
        series=False,
        tangent=True,
    )
    out["adaptive"] = {"status": tr.status.name}
    if tr.ok:
        n, width, _ = bands(tr.section[["theta_f", "omega_f"]].to_numpy(), p.cam_period)
        lam, se = exponent(tr)
        out["adaptive"].update(bands=n, band_width=width, lambda1=lam, stderr=se)
    tr = runs["dt"]
    if tr.ok:
        out["perturbation_max"], out["perturbation_last"] = perturbation(p, tr)
        n = out["dt"]["bands"]
        if n is not None and p.l_lambda_sigma == 0.0:
            pts = tr.section[["theta_f", "omega_f"]].to_numpy()
            orbit = periodic_orbit(p, pts[-1], n, numerics=num)
            out["orbit"] = {
                "period": orbit.period,
                "converged": orbit.converged,
                "mu_abs": [float(abs(m)) for m in orbit.multipliers],
                "distance": orbit.distance(pts[-4 * n :]),
            }
    return out


def settle(m: dict) -> tuple[str, int | None, str]:
    """(label, period, why) from the measurements; label 'unsettled' when the rules disagree."""
    label, period, why = _settle(m)
    cross = m.get("adaptive")
    grid = _settle({k: v for k, v in m.items() if k != "adaptive"})
    if cross is not None and label == "unsettled" and grid[0] != "unsettled":
        why = (
            f"{grid[0]} {grid[1] or ''} on the RK4 grid ({grid[2]}), but the adaptive run "
            f"disagrees: {cross.get('bands') or 'no'} bands, lambda1 = "
            f"{cross.get('lambda1', math.nan):.3g} +- {cross.get('stderr', math.nan):.2g}"
        )
    if label != "unsettled" and cross is not None:
        why += (
            f"; adaptive run: {cross['bands'] or 'no'} bands, lambda1 = "
            f"{cross['lambda1']:.3g} +- {cross['stderr']:.2g}"
        )
    return label, period, why


def _settle(m: dict) -> tuple[str, int | None, str]:
    a, b = m["dt"], m["dt/2"]
    if a["status"] != "OK" or b["status"] != "OK":
        return "unsettled", None, f"status {a['status']} / {b['status']}"
    grow = m["perturbation_max"] / PERTURBATION
    # decayed: back below the perturbation, or into the run's own jitter (its band width)
    jitter = a["band_width"] if a["bands"] is not None else 0.0
    decays = m["perturbation_last"] <= max(PERTURBATION, 2.0 * jitter)
    neg = all(r["lambda1"] + 3 * r["stderr"] < 0 for r in (a, b))
    pos = all(r["lambda1"] - 3 * r["stderr"] > 0 for r in (a, b))
    zero = all(abs(r["lambda1"]) <= 3 * r["stderr"] for r in (a, b))
    orbit = m.get("orbit")
    cross = m.get("adaptive")  # the other integrator (absent in tables measured before it)
    if cross is not None and cross["status"] != "OK":
        return "unsettled", None, f"adaptive run {cross['status']}"
    cross_periodic = cross is None or (
        cross["bands"] == a["bands"] and cross["lambda1"] - 3 * cross["stderr"] <= 0
    )
    cross_chaotic = cross is None or cross["lambda1"] - 3 * cross["stderr"] > 0
    if a["bands"] is not None and a["bands"] == b["bands"] and orbit is not None:
        ok = (
            orbit["converged"]
            and max(orbit["mu_abs"]) < 1
            and orbit["distance"] <= max(BAND_ATOL, BAND_RTOL * a["extent"])
        )
        if ok and decays and orbit["period"] == a["bands"] and cross_periodic:
            return (
                "periodic",
                a["bands"],
                (
                    f"{a['bands']} bands at dt and dt/2 (widest {a['band_width']:.2g} rad), "
                    f"certified orbit |mu|max {max(orbit['mu_abs']):.3g}, perturbation decays "
                    f"to {m['perturbation_last']:.2g} rad"
                ),
            )
    if (
        a["bands"] is not None
        and a["bands"] == b["bands"]
        and orbit is None
        and neg
        and decays
        and m["params"].get("l_lambda_sigma", 0.0) > 0
        and cross_periodic
    ):
        return (
            "periodic",
            a["bands"],
            (
                f"random model: {a['bands']} bands at dt and dt/2 (widest {a['band_width']:.2g} "
                f"rad), lambda1 + 3 sigma < 0 at both, perturbation decays to "
                f"{m['perturbation_last']:.2g} rad"
            ),
        )
    if pos and grow >= 100 and cross_chaotic:
        return (
            "chaotic",
            None,
            (
                f"lambda1 = {a['lambda1']:.3g} +- {a['stderr']:.2g} (dt), {b['lambda1']:.3g} +- "
                f"{b['stderr']:.2g} (dt/2); a 1e-8 rad perturbation grows {grow:.3g}-fold"
            ),
        )
    if a["bands"] is None and b["bands"] is None and zero and not decays and grow < 100:
        return "quasiperiodic", None, "no period, lambda1 zero within 3 sigma, neutral perturbation"
    return "unsettled", None, "the rules disagree (see the measurements)"


def main(argv: list[str]) -> None:
    """``[OUT.json]`` measures and settles; ``--from IN.json [OUT.json]`` only re-applies the
    rules to measurements made before. OUT is checked before the hours of measurement: an
    existing file (the default is the tests' truth, ``tests/data/``) is replaced only with
    ``--force``, and it is written whole or not at all."""
    import argparse

    from chaoscam.io import OutputError, atomic_write_bytes, check_output

    ap = argparse.ArgumentParser(
        prog="analyses/labelled_set.py", description=__doc__.splitlines()[0]
    )
    ap.add_argument("out", nargs="?", metavar="OUT.json", help="default: tests/data/NAME.json")
    ap.add_argument("--holdout", action="store_true", help="the holdout configurations")
    ap.add_argument("--from", dest="source", metavar="IN.json", help="re-settle these")
    ap.add_argument("--force", action="store_true", help="replace an existing OUT.json")
    args = ap.parse_args(argv)
    configs, default = (
        (HOLDOUT, "holdout_set.json") if args.holdout else (CONFIGS, "labelled_set.json")
    )
    out = Path(args.out) if args.out else Path(__file__).parents[1] / "tests/data" / default
    try:
        check_output(out, flag="OUT.json", force=args.force, suffixes=(".json",))
        old = json.loads(Path(args.source).read_text()) if args.source else {}
    except (OutputError, OSError, ValueError) as err:
        ap.error(str(err))
    table = {}
    for name, overrides in configs.items():
        t0 = time.perf_counter()
        if name in old:
            m = {k: v for k, v in old[name].items() if k not in ("label", "period", "why")}
        else:
            m = measure(overrides)
        label, period, why = settle(m)
        m.setdefault("wall_time_s", time.perf_counter() - t0)
        m.update(label=label, period=period, why=why)
        table[name] = m
        print(
            f"{name:>22}: {label:<13} {period or '':>3}  {why}  ({m['wall_time_s']:.0f} s)",
            flush=True,
        )
    text = json.dumps(table, indent=1, default=float) + "\n"
    try:
        atomic_write_bytes(out, text.encode(), replace=args.force)
    except OutputError as err:  # OUT.json appeared meanwhile: the table went beside it
        raise SystemExit(f"{ap.prog}: {err}") from None
    print(f"wrote {out}")


if __name__ == "__main__":
    main(sys.argv[1:])
