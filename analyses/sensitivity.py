"""Why our reconstruction differs from the paper: the response against stiffness and restitution.

Sweeps the contact stiffness K_n over many decades (through the follower's Young's modulus
Y_f, K_n = (pi/4) E l_lambda with 1/E = (1 - nu_f^2)/Y_f + (1 - nu_c^2)/Y_c) and the
coefficient of restitution xi, classifying each deterministic run with the package's
default classifier (tangent exponent, orbit certificate, extension when undetermined).
Prints a table and writes it as CSV.

Usage: python analyses/sensitivity.py [OUT.csv]   (default reports/sensitivity.csv)
"""

from __future__ import annotations

import sys
import time
from pathlib import Path

import numpy as np
import pandas as pd

import chaoscam
from chaoscam import Params
from chaoscam._simulate import contact_period
from chaoscam.classify import classify_trajectory

DURATION, TRANSIENT = 60.0, 30.0


def row(what: str, value: float, p: Params) -> dict:
    t0 = time.perf_counter()
    tr = chaoscam.simulate(p, duration=DURATION, transient=TRANSIENT, series=False, tangent=True)
    out = {
        "sweep": what,
        "value": value,
        "K_n": p.stiffness_at(p.l_lambda),
        "dt": p.dt,
        "status": tr.status.name,
    }
    if tr.ok:
        v = classify_trajectory(tr)
        tang = v.settings.get("tangent", {})
        out.update(
            label=v.label,
            period=v.period,
            lambda1=(tang.get("exponents") or [np.nan])[0],
            extended=v.settings.get("extended", {}).get("recorded_s"),
        )
    else:
        out.update(label=tr.status.label, period=None, lambda1=np.nan, extended=None)
    out["wall_s"] = time.perf_counter() - t0
    return out


def main(argv: list[str]) -> None:
    out = Path(argv[0]) if argv else Path(__file__).parents[1] / "reports/sensitivity.csv"
    rows = []
    base = Params()
    k0 = base.stiffness_at(base.l_lambda)
    for y_f in (1e2, 1e3, 1e4, 1e5, 1e6, 1e7, 1e8, 1e9, 1e10, 2.07e11):
        p = base.replace(Y_f=y_f)
        # resolve the contact period with >= 40 steps
        dt = min(base.dt, contact_period(p) / 40.0)
        rows.append(row("Y_f", y_f, p.replace(dt=float(f"{dt:.2g}"))))
        print(rows[-1], flush=True)
    for xi in np.round(np.arange(0.1, 0.71, 0.05), 3):
        rows.append(row("xi", float(xi), base.replace(xi=float(xi))))
        print(rows[-1], flush=True)
    table = pd.DataFrame(rows)
    out.parent.mkdir(parents=True, exist_ok=True)
    table.to_csv(out, index=False)
    print(table.to_string())
    print(f"wrote {out} (K_n of the default: {k0:.3g} N/m)")


if __name__ == "__main__":
    main(sys.argv[1:])
