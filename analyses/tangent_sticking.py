"""The tangent exponent where chattering ends in sticking, against twins and step halving.

Prints a Markdown table from the shipped settled sets (tests/data/labelled_set.json,
holdout_set.json, random_set.json, random_holdout.json): for each deterministic configuration
with sticking (a plastic closure makes twins coincide: a perturbation distance of exactly 0) and
each synchronised random one (twin distances of exactly 0 where it sticks), lambda_1
of the tangent (QR through the impacts, per second) at dt and at dt/2, the adaptive run's where
measured, what the twins did, and the settled label.

Usage: python analyses/tangent_sticking.py
"""

from __future__ import annotations

import json
from pathlib import Path

DATA = Path(__file__).resolve().parents[1] / "tests" / "data"


def _lam(m: dict) -> str:
    return f"{m['lambda1']:+.2f} ± {m['stderr']:.2f}" if "lambda1" in m else "–"


def rows():
    for name in ("labelled_set", "holdout_set"):
        for key, r in json.loads((DATA / f"{name}.json").read_text()).items():
            if r.get("perturbation_last") == 0.0 and "lambda1" in r["dt"]:
                twins = (
                    f"1e-8 rad perturbation → 0 (grows at most {r['perturbation_max'] / 1e-8:.3g}x)"
                )
                yield (
                    key,
                    "σ = 0",
                    _lam(r["dt"]),
                    _lam(r["dt/2"]),
                    _lam(r.get("adaptive", {})),
                    twins,
                    _label(r),
                )
    for name in ("random_set", "random_holdout"):
        for key, r in json.loads((DATA / f"{name}.json").read_text()).items():
            a, b = r["dt"], r["dt/2"]
            if "sync" not in a or r["label"] != "periodic":
                continue
            sync = max(t["ratio"] for t in a["sync"] + b["sync"])
            stuck = any(t["ratio"] == 0 for t in a["sync"] + b["sync"])
            twins = f"1e-6 rad twins end at ≤ {sync:.2g}x" + (" (some exactly 0)" if stuck else "")
            yield key, "σ > 0", _lam(a), _lam(b), "–", twins, _label(r)


def _label(r: dict) -> str:
    return r["label"] + (f" {r['period']}" if r.get("period") else "")


def main() -> None:
    print("| configuration | model | λ₁ at dt [1/s] | λ₁ at dt/2 | λ₁ adaptive | twins | settled |")
    print("|---|---|---|---|---|---|---|")
    for row in rows():
        print("| " + " | ".join(row) + " |")


if __name__ == "__main__":
    main()
