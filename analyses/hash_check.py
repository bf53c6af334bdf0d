"""Bit-identity check for refactors: hashes of sections and impacts for a fixed set of runs.

A restructuring of the kernels, drivers or sweeps must leave every result bit for bit as it
was. This script simulates a fixed set of realizations (both integrators, tangent on and
off, a random line length, a periodic orbit, an ensemble, a small regime map) and prints one
SHA-256 per run of its section and impact tables (and, for the map, its table and labels).

Usage:
    python analyses/hash_check.py --write    # before the change: store the hashes
    python analyses/hash_check.py            # after it: compare, exit 1 on any difference

The hashes live in ``reports/run_hashes.json``; a change that alters the physics on purpose
rewrites them (``--write``) and says so in its commit. Hashes are of this machine's floating
point: compare on one machine.
"""

from __future__ import annotations

import hashlib
import json
import sys
from pathlib import Path

import numpy as np
import pandas as pd

STORE = Path(__file__).resolve().parents[1] / "reports" / "run_hashes.json"

RUNS = {
    "default rk4": dict(),
    "default rk4, tangent": dict(tangent=True),
    "xi=0.2 rk4": dict(xi=0.2),
    "sigma=2mm rk4": dict(l_lambda_sigma=0.002, index=3),
    "sigma=2mm rk4, impact resampling": dict(l_lambda_sigma=0.002, resample="impact", index=3),
    "omega=45 rk4": dict(omega=45.0),
    "default adaptive": dict(integrator="adaptive"),
    "e=0.02 sticking": dict(e=0.02),
}


def _digest(*frames: pd.DataFrame) -> str:
    h = hashlib.sha256()
    for f in frames:
        h.update(",".join(map(str, f.columns)).encode())
        for col in f.columns:
            h.update(np.ascontiguousarray(f[col].to_numpy(dtype=float)).tobytes())
    return h.hexdigest()


def hashes() -> dict[str, str]:
    """The digest of every run of the fixed set."""
    from chaoscam import Numerics, Params, periodic_orbit, regime_map, simulate, solve

    steps = set(Numerics.field_names())
    out = {}
    for name, spec in RUNS.items():
        spec = dict(spec)
        index, tangent = spec.pop("index", 0), spec.pop("tangent", False)
        num = Numerics(**{k: v for k, v in spec.items() if k in steps})
        p = Params(**{k: v for k, v in spec.items() if k not in steps})
        tr = simulate(p, num, duration=6.0, transient=2.0, seed=1, index=index, series=False,
                      tangent=tangent)  # fmt: skip
        imp = tr.impacts.drop(columns="member")
        frames = [tr.section, imp.assign(kind=imp["kind"].cat.codes)]
        if tangent:
            frames.append(pd.DataFrame(tr.jacobians.reshape(len(tr.jacobians), 4)))
        out[name] = _digest(*frames)
    orbit = periodic_orbit(Params(xi=0.2), (0.0, 0.0), 1)
    out["periodic orbit xi=0.2"] = hashlib.sha256(
        np.concatenate([np.ravel(orbit.points), np.abs(orbit.multipliers)]).tobytes()
    ).hexdigest()
    ens = solve(Params(l_lambda_sigma=0.002), indices=range(4), seed=2, duration=4.0,
                transient=1.0)  # fmt: skip
    out["ensemble sigma=2mm x4"] = _digest(ens.sections, ens.members[["n_impacts"]])
    m = regime_map(
        "xi=0.2,0.45", "l_lambda_sigma=0,0.002", realizations=2, seed=3, duration=4.0,
        transient=2.0, workers=1, progress=False,
    )  # fmt: skip
    cols = ["cell", "index", "n_section", "n_impacts", "contact_fraction"]
    out["regime map"] = _digest(m.realizations[cols]) + " " + ",".join(m.realizations["label"])
    return out


def main(argv: list[str]) -> int:
    import argparse

    ap = argparse.ArgumentParser(prog="analyses/hash_check.py", description=__doc__.splitlines()[0])
    ap.add_argument("--write", action="store_true", help=f"store the hashes in {STORE.name}")
    args = ap.parse_args(argv)
    now = hashes()
    if args.write:
        STORE.write_text(json.dumps(now, indent=1) + "\n")
        print(f"wrote {len(now)} hashes to {STORE}")
        return 0
    if not STORE.exists():
        print(f"no stored hashes in {STORE}: run with --write first")
        return 1
    before = json.loads(STORE.read_text())
    bad = [k for k in before if before[k] != now.get(k)]
    for k in now:
        print(f"{'same' if before.get(k) == now[k] else 'DIFFERENT'}: {k}")
    print("bit-identical" if not bad else f"{len(bad)} of {len(before)} runs differ")
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
