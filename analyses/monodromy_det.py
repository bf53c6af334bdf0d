"""|det| of the stroboscopic map's one-period Jacobians: the bound that excludes Neimark–Sacker.

With Hunt–Crossley damping the flow's divergence d theta''/d theta' is 0 in flight and <= 0
in contact while l_1 > mu_f a (a the friction arm), a restitution jump has det S = xi^2 and
the plastic closure ending a chattering det S = 0, so by Liouville each period's Jacobian has

    |det J_k| = exp(div_k) xi^(2 n_k)   (0 with a plastic closure)   <= 1,

div_k the divergence integrated over period k and n_k its restitution jumps, and a periodic
orbit with a jump has |mu_1 mu_2| <= xi^2 (docs/model.md, "What the model cannot do"). The
script checks, period by period, on every configuration of tests/data/labelled_set.json and
holdout_set.json (RECORD s after TRANSIENT s) and on the paper report's (omega, xi) axes
taken every second value (GRID_RECORD s after GRID_TRANSIENT s):

- div_k <= 0, |det J_k| <= 1 + tol_k, and |det J_k| <= xi^2 + tol_k when n_k > 0, with
  tol_k = N eps (|j11 j22| + |j12 j21|), N = T / dt: the round-off of det J_k if each step
  adds a relative eps to the entries, linearly (worst case);
- for the deterministic periodic configurations, |mu_1 mu_2| <= xi^2 (<= 1 without a jump)
  on the orbit shot from the run's last section point (``chaoscam.verdict.periodic_orbit``).

Columns: recorded periods, periods with a jump, the largest |det J_k|, the largest |det J_k| /
xi^2 over periods with a jump, the largest div_k, and "Liouville", the signed largest ln|det
J_k| - div_k - 2 n_k ln xi over resolved periods (tol_k < 1e-3 |det J_k|) without a plastic
closure: the tangent against its own divergence quadrature and saltation matrices. On
flight-and-impact periods it is round-off; in persistent contact RK4's own damping of the
Hertz oscillation, about -(h Omega)^6 / 72 a step (Omega = sqrt(K l_1^2 / J)). The literal
damping (``damping="paper_literal"``), outside the hypothesis, is shown for contrast and
never counted. Exit status 1 when a bound is violated.

Usage: python analyses/monodromy_det.py   (about two minutes of CPU)
"""

from __future__ import annotations

import json
import math
import sys
from pathlib import Path

import numpy as np

import chaoscam
from chaoscam import Params
from chaoscam.verdict import periodic_orbit

DATA = Path(__file__).parents[1] / "tests" / "data"
TRANSIENT, RECORD = 60.0, 60.0  # [s] the labelled configurations (as tests/test_labelled_set)
GRID_TRANSIENT, GRID_RECORD = 20.0, 20.0  # [s] the (omega, xi) cells
OMEGAS = np.linspace(10.0, 50.0, 17)[::2]  # chaoscam.paper's (omega, xi) map, every second
XIS = np.linspace(0.1, 0.7, 13)[::2]
CONTRAST_TRANSIENT, CONTRAST_RECORD = (
    5.0,
    5.0,
)  # [s] (the literal damping chatters: ~15,000 jumps/s)
CONTRAST = {
    "literal": {"damping": "paper_literal"},
    "literal,omega=15": {"damping": "paper_literal", "omega": 15.0},
}
EPS = np.finfo(float).eps


def periods(sol, i: int, transient: float) -> dict[str, np.ndarray]:
    """Member i's recorded periods whose start is after ``transient`` (their impacts are all
    listed): det J_k, its round-off tol_k, div_k, jumps n_k and plastic closures."""
    p = sol.models[i]
    sec = sol.sections
    rows = np.flatnonzero(sec["member"].to_numpy() == i)
    t = sec["t"].to_numpy()[rows]
    keep = t - p.cam_period >= transient
    rows, t = rows[keep], t[keep]
    j = sol.jacobians[rows]
    det = j[:, 0, 0] * j[:, 1, 1] - j[:, 0, 1] * j[:, 1, 0]
    steps = p.cam_period / sol.numerics.dt
    tol = steps * EPS * (np.abs(j[:, 0, 0] * j[:, 1, 1]) + np.abs(j[:, 0, 1] * j[:, 1, 0]))
    imp = sol.impacts[sol.impacts["member"] == i]
    ti, kind = imp["t"].to_numpy(), imp["kind"].to_numpy()

    def count(mask):
        c = np.searchsorted(ti[mask], t, side="right")
        return c - np.searchsorted(ti[mask], t - p.cam_period, side="right")

    return {
        "det": det,
        "tol": tol,
        "div": sol.divergence[rows],
        "jumps": count(kind != "chatter_end"),
        "plastic": count(kind == "chatter_end"),
    }


def check(per: dict[str, np.ndarray], xi: float) -> dict:
    """The bounds on one member's periods: counts, extremes and the violations found."""
    det, tol, n = np.abs(per["det"]), per["tol"], per["jumps"]
    jump = n > 0
    bad = [f"div_k > 0 in {int(np.sum(per['div'] > 0))} periods"] if np.any(per["div"] > 0) else []
    if np.any(det > 1 + tol):
        bad.append(f"|det| > 1 in {int(np.sum(det > 1 + tol))} periods")
    if np.any(det[jump] > xi**2 + tol[jump]):
        bad.append(f"|det| > xi^2 in {int(np.sum(det[jump] > xi**2 + tol[jump]))} jump periods")
    resolved = (tol < 1e-3 * det) & (det > 0)
    ok = resolved & (per["plastic"] == 0)
    gap = np.log(det[ok]) - per["div"][ok] - 2 * n[ok] * math.log(xi) if xi > 0 else np.array([])
    return {
        "periods": len(det),
        "jump_periods": int(jump.sum()),
        "resolved": int(resolved.sum()),
        "blurred": int((~resolved & (per["plastic"] == 0)).sum()),
        "max_det": float(det.max()) if len(det) else math.nan,
        "max_det_xi2": float((det[jump] / xi**2).max()) if jump.any() else math.nan,
        "max_div": float(per["div"].max()) if len(det) else math.nan,
        "liouville": float(gap[np.argmax(np.abs(gap))]) if len(gap) else math.nan,
        "bad": bad,
    }


def orbit(p: Params, sol, period: int, per: dict[str, np.ndarray]) -> tuple[str, float, list]:
    """Shooting from the run's last section point: its text (|mu_1 mu_2|, complex or real, and
    the product of the run's last ``period`` dets), |mu_1 mu_2| / xi^2 when the orbit has a
    jump (else NaN) and the violation of |mu_1 mu_2| <= xi^2 (<= 1 without a jump; relative
    slack 1e-9, far above the ~N eps = 2e-11 round-off of a period's det)."""
    x0 = sol.sections[["theta_f", "omega_f"]].to_numpy()[-1]
    orb = periodic_orbit(p, x0, period)
    mu = abs(complex(np.prod(orb.multipliers)))
    kind = "complex" if abs(orb.multipliers[0].imag) > 0 else "real"
    text = f"|mu1 mu2| = {mu:.4g} ({kind}; run {abs(np.prod(per['det'][-period:])):.3g})"
    if not orb.converged:
        return text + ", not converged", math.nan, []
    jumps = per["jumps"][-period:].sum() > 0
    bound = p.xi**2 if jumps else 1.0
    bad = [f"|mu1 mu2| = {mu:.4g} > {bound:.4g}"] if mu > bound * (1 + 1e-9) else []
    return text, mu / bound if jumps else math.nan, bad


def configurations() -> list[tuple[str, dict, str, int | None, float, float]]:
    """(name, overrides, label, period, transient, recorded) of the labelled sets, then the
    literal-damping contrast."""
    rows = []
    for name in ("labelled_set.json", "holdout_set.json"):
        for key, row in json.loads((DATA / name).read_text()).items():
            rows.append((key, row["params"], row["label"], row["period"], TRANSIENT, RECORD))
    return rows + [
        (key, ov, "contrast", None, CONTRAST_TRANSIENT, CONTRAST_RECORD)
        for key, ov in CONTRAST.items()
    ]


def line(name: str, label: str, status: str, r: dict | None, extra: str) -> str:
    if r is None:
        return f"{name:<24} {label:<13} {status:<10}"
    return (
        f"{name:<24} {label:<13} {status:<10} {r['periods']:>5} {r['jump_periods']:>5} "
        f"{r['max_det']:>10.4g} {r['max_det_xi2']:>9.4g} {r['max_div']:>8.3g} "
        f"{r['liouville']:>10.2g}  {extra}"
    )


class Tally:
    """Periods checked, the largest |det J_k| and |det J_k| / xi^2, the violations."""

    def __init__(self):
        self.periods, self.det, self.ratio, self.orbit, self.bad = 0, 0.0, 0.0, 0.0, []
        self.resolved = self.blurred = 0

    def add(self, name: str, r: dict, bad: list[str]) -> None:
        self.periods += r["periods"]
        self.resolved += r["resolved"]
        self.blurred += r["blurred"]
        self.det = max(self.det, r["max_det"])
        self.ratio = np.nanmax([self.ratio, r["max_det_xi2"]])
        self.bad += [f"{name}: {b}" for b in bad]


def labelled_table(tally: Tally) -> None:
    print(
        f"{'configuration':<24} {'label':<13} {'status':<10} {'per':>5} {'jump':>5} "
        f"{'max|det|':>10} {'max/xi^2':>9} {'max div':>8} {'Liouville':>10}"
    )
    for name, ov, label, period, transient, record in configurations():
        p = Params(**ov)
        sol = chaoscam.solve(
            p, duration=transient + record, transient=transient, tangent=True, impacts=True
        )
        per = periods(sol, 0, transient)
        r = check(per, p.xi) if len(per["det"]) else None
        extra, bad = "", [] if r is None else list(r["bad"])
        if label == "periodic" and p.l_lambda_sigma == 0 and r is not None:
            extra, ratio, more = orbit(p, sol, period, per)
            tally.orbit = np.nanmax([tally.orbit, ratio])
            bad += more
        if label == "contrast":
            extra, bad = "; ".join(bad), []
        elif bad:
            extra += "  VIOLATION: " + "; ".join(bad)
        print(line(name, f"{label} {period}" if period else label, sol.status.name, r, extra))
        if r is not None and label != "contrast":
            tally.add(name, r, bad)


def grid_table(tally: Tally) -> None:
    print("\n(omega, xi) cells: largest |det J_k| / largest |det J_k| / xi^2 over jump periods")
    for w in OMEGAS:
        models = [Params(omega=float(w), xi=float(x)) for x in XIS]
        sol = chaoscam.solve(
            models,
            duration=GRID_TRANSIENT + GRID_RECORD,
            transient=GRID_TRANSIENT,
            indices=range(len(models)),
            tangent=True,
            impacts=True,
        )
        cells = []
        for i, x in enumerate(XIS):
            per, status = periods(sol, i, GRID_TRANSIENT), sol.members["status"].iat[i]
            if not len(per["det"]):
                cells.append(f"xi={x:.1f}: {status}")
                continue
            r = check(per, float(x))
            tally.add(f"omega={w:g}, xi={x:.1f}", r, r["bad"])
            tail = "" if status == "OK" else f" {status}"
            cells.append(f"xi={x:.1f}: {r['max_det']:.3g}/{r['max_det_xi2']:.2g}{tail}")
        print(f"omega={w:>4g}  " + "  ".join(cells))


def main() -> int:
    tally = Tally()
    labelled_table(tally)
    grid_table(tally)
    print(
        f"\n{tally.periods} periods checked (Hunt–Crossley): {tally.resolved} with det J_k "
        f"resolved (tol_k < 1e-3 |det J_k|), {tally.blurred} unresolved without a plastic "
        "closure, the rest with one (det J_k = 0 in exact arithmetic)"
    )
    print(
        f"largest |det J_k| = {tally.det:.17g}; largest |det J_k| / xi^2 with a jump = "
        f"{tally.ratio:.17g}; largest |mu1 mu2| / xi^2 of a shot orbit with a jump = "
        f"{tally.orbit:.17g}; {len(tally.bad)} violations"
    )
    for v in tally.bad:
        print("  " + v)
    return 1 if tally.bad else 0


if __name__ == "__main__":
    sys.exit(main())
