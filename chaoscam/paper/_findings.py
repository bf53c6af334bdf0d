"""The findings' sentences, computed from the sweeps' verdict tables (nothing is written in
advance), and the tags and runs of verdicts they quote."""

from __future__ import annotations

from itertools import groupby

import numpy as np
import pandas as pd

from ..model import Params
from ..report import SETTLED_MARK, TRANSIENT_MARK, band_counts, band_number, frame_tags, verdict_tag

PAPER_K_N = (8.9e7, 1.6e9)
"""The paper's Hertz line stiffness range [N/m] (its l_λ range with Table 1's materials)."""

PAPER_L_LAMBDA = (0.001, 0.018)  # the paper's l_λ range [m] (Fig. 4), which spans PAPER_K_N

XI_WINDOW = 0.05
"""Half-width of the neighbourhood of Table 1's ξ that the restitution finding looks at."""


def along(v: pd.DataFrame, key: str = "value") -> str:
    """The runs of equal tags along ``v[key]`` (sorted): "period 1 (0.1–0.3) → chaotic (0.4)"."""
    parts = []
    for tag, group in groupby(zip(frame_tags(v), v[key], strict=True), key=lambda t: t[0]):
        xs = [float(x) for _, x in group]
        span = f"{xs[0]:.3g}" if xs[0] == xs[-1] else f"{xs[0]:.3g}–{xs[-1]:.3g}"
        parts.append(f"{tag} ({span})")
    return " → ".join(parts)


def regimes(tags) -> list[str]:
    """The distinct tags, in order, without "undetermined" (no regime: nothing decided)."""
    return [t for t in dict.fromkeys(tags) if t != "undetermined"]


def _regimes_text(found: list[str]) -> str:
    return f"{len(found)} regime{'s' * (len(found) != 1)} ({', '.join(found) or 'none'})"


def paper_regimes(found: list[str], where: str) -> str:
    """The clause on whether the paper's period 2 or a quasiperiodic motion is ``found``."""
    paper = [t for t in ("period 2", "quasiperiodic") if t in found]
    if not paper:
        return f"; neither the paper's period 2 nor a quasiperiodic motion appears {where}."
    return f"; the paper's {' and '.join(paper)} appear{'s' * (len(paper) == 1)} {where}."


def step_finding(rows: pd.DataFrame, where) -> str:
    """The sentence on the step check of a sweep's runs (``ev_step_check``: 1 kept, 0
    changed): how many held, and where (``where(row)``) they changed; empty if none checked."""
    checked = rows[rows["ev_step_check"].notna()] if "ev_step_check" in rows else rows.iloc[:0]
    if not len(checked):
        return ""
    changed = checked[checked["ev_step_check"] == 0]
    n, k = len(checked), len(changed)
    text = f" Checked at half the step, {n - k} of {n} verdict{'s' * (n != 1)} hold{'s' * (n == 1)}"
    if not k:
        return text + "."
    runs = ", ".join(map(where, changed.itertuples()))
    verb = "changes there and is" if k == 1 else "change there and are"
    return text + f"; {k} {verb} undetermined ({runs})."


def first_ic(bif) -> pd.DataFrame:
    return bif.verdicts[bif.verdicts["ic"] == 0].sort_values("value")


def choices_finding(inertia, pivot, arm, damping, hertz_tags: list[str]) -> str:
    """The sentence on J, y_O, the friction arm and the literal damping against the Hertz range."""
    p = Params()
    tags = sum((frame_tags(v) for v in (inertia, pivot, arm, damping)), [])
    found, hertz = regimes(tags), regimes(hertz_tags)
    text = (
        f"What the paper leaves open, at Table 1 otherwise: the rod's inertia J from "
        f"{inertia['value'].min():.3g} to {inertia['value'].max():.3g} kg m² (the solid rod's "
        f"{p.inertia:.3g}): {along(inertia)}; the pivot height y_O from "
        f"{pivot['value'].min():.3g} to {pivot['value'].max():.3g} m (default {p.pivot[1]:g}): "
        f"{along(pivot)}; the friction torque's arm from {arm['value'].min():.3g} to "
        f"{arm['value'].max():.3g} m (default r = {p.arm:g}): {along(arm)}; "
        f"the paper's literal damping signs: {', '.join(frame_tags(damping))}. "
        f"Together {_regimes_text(found)}, against {len(hertz)} across the paper's Hertz range: "
    )
    if len(found) > max(len(hertz), 1):
        text += "these unreported choices move the motion more than the paper's stiffness does"
    else:
        text += "these choices move the motion no more than the paper's stiffness does"
    return (
        text
        + paper_regimes(found, "among them")
        + (
            f" Not swept: the chattering limit (v_min = {p.v_min:g}, v_chatter = "
            f"{p.v_chatter:g} m/s; numerical, its convergence measured on the documentation's "
            f"verdicts page) and, "
            f"for a random line length (σ > 0, not Table 1's), when a length is drawn "
            f"(resample = {p.resample})."
        )
    )


def restitution_finding(v: pd.DataFrame, xi0: float, hertz_tags: list[str]) -> str:
    """The restitution sentence: more sensitive only when more regimes lie within :data:`XI_WINDOW`
    of ``xi0`` than across the paper's Hertz range (undetermined on neither side)."""
    near = v[(v["value"] - xi0).abs() <= XI_WINDOW + 1e-9]
    tags, hertz = regimes(frame_tags(near)), regimes(hertz_tags)
    n_und = int((near["label"] == "undetermined").sum())
    text = (
        f"Restitution ξ (Table 1: {xi0:g}): {along(v)}. Within ±{XI_WINDOW:g} of Table 1's "
        f"value ({len(near)} values sampled"
        + (f", {n_und} undetermined" if n_und else "")
        + f") the motion takes {_regimes_text(tags)}, "
    )
    across = f"{len(hertz)} across the paper's Hertz range ({', '.join(hertz) or 'none'})"
    if len(tags) > max(len(hertz), 1):
        return text + (
            f"against {across}: the regime is more sensitive to the restitution (and so to how "
            "the restitution law is applied at the oblique impact) than to the stiffness, a "
            "plausible source of the difference."
        )
    return text + (
        f"no more than the {across}: this sweep does not single the restitution out as the "
        "source of the difference."
    )


def stiffness_finding(yf: pd.DataFrame, hertz: pd.DataFrame) -> tuple[str, list[str]]:
    """The stiffness sentence and the tags across the paper's Hertz range (the l_λ runs and the Y_f
    runs inside :data:`PAPER_K_N`); period n and n-band chaos of one n are the same motion."""
    kv = yf["K_n"].to_numpy()
    in_yf = yf[(yf["K_n"] >= PAPER_K_N[0]) & (yf["K_n"] <= PAPER_K_N[1])]
    inside = pd.concat([hertz, in_yf]).sort_values("K_n")
    tags = frame_tags(inside)
    found = regimes(tags)
    text = (
        f"Contact stiffness: K_n from {kv.min():.3g} to {kv.max():.3g} N/m "
        f"({np.log10(kv.max() / kv.min()):.1f} decades, through Y_f): {along(yf, 'K_n')}. "
        f"Across the paper's Hertz range {PAPER_K_N[0]:.2g}–{PAPER_K_N[1]:.2g} N/m, sampled "
        f"through l_λ = {PAPER_L_LAMBDA[0] * 1e3:g}–{PAPER_L_LAMBDA[1] * 1e3:g} mm as the paper "
        f"does ({len(hertz)} values) and by {len(in_yf)} of the Y_f values: "
        f"{along(inside, 'K_n')}: "
    )
    decided = inside[inside["label"] != "undetermined"]
    rows = zip(decided["label"], decided["period"], band_counts(decided), strict=True)
    bands = {band_number(*r) for r in rows}
    if len(found) <= 1:
        text += (
            "one regime there, so the paper's stiffness model cannot explain why its regimes "
            "differ from ours"
        )
    elif len(bands) == 1 and None not in bands:  # period n and n-band chaos of one n
        text += (
            f"the label moves between {' and '.join(found)}, the same motion on {bands.pop()} "
            "narrow bands: the stiffness decides which label, not the kind of motion, so it "
            "cannot explain why the paper's regimes differ from ours"
        )
    else:
        text += "the response changes inside that range, so the stiffness model matters"
    return text + paper_regimes(found, "there"), tags


def transient_finding(rows: pd.DataFrame, horizon: float, what: str, where=None, name=None) -> str:
    """The sentence on the runs continued to the fate ``horizon``: how many stop before it, when,
    how many of those were labelled chaotic (named by ``where(row)``), and how many are periodic
    on the continued run's last half (``name(row)``); ``what`` names one run. Empty if none."""
    from ..sweep import fate_settled

    text, settled = _left_finding(rows, horizon, what, where), fate_settled(rows)
    if not len(settled):
        return text
    k, chaotic = len(settled), int((settled["label"] == "chaotic").sum())
    named = f" ({'; '.join(map(name, settled.itertuples()))})" if name else ""
    periods = ", ".join(str(p) for p in sorted(set(settled["fate_period"].dropna().astype(int))))
    why = [f"{chaotic} labelled chaotic settle{'s' * (chaotic == 1)} later"] if chaotic else []
    if k > chaotic:
        why.append(f"{k - chaotic} labelled otherwise needed the longer window for a verdict")
    return text + (
        f" {k} of them {'is' if k == 1 else 'are'} periodic on the continued run's last half "
        f"(period {periods}; the classifier's verdict there, at the run's step){named}: "
        + " and ".join(why)
        + "."
    )


def _left_finding(rows: pd.DataFrame, horizon: float, what: str, where=None) -> str:
    from ..sweep import continued_labels, fate_split

    checked, left = fate_split(rows)
    if not len(checked):
        return ""
    n, labels = len(checked), continued_labels(checked)
    head = f" Continued to {horizon:g} s, the {n} {what}{'s' * (n != 1)} {labels}"
    if not len(left):
        return head + (" all stay" if n != 1 else " stays") + " in the cam's reach."
    verb = {"LEFT_REACH": ("leaves the cam's reach", "leave the cam's reach")}
    how = ", ".join(
        f"{k} {verb.get(st, (st.lower(), st.lower()))[k != 1]}"
        for st, k in left["fate"].value_counts().sort_index().items()
    )
    t0, t1 = left["left_at"].min(), left["left_at"].max()
    when = f"{t0:.3g} s" if f"{t0:.3g}" == f"{t1:.3g}" else f"{t0:.3g}–{t1:.3g} s"
    head += f": {how} before it (last section at {when}), "
    gone = left[left["label"] == "chaotic"]
    if not len(gone):
        return head + "none labelled chaotic."
    named = f", at {'; '.join(map(where, gone.itertuples()))}" if where else ""
    return head + (
        f"{len(gone)} labelled chaotic over the recorded window{named}: transient chaos, which "
        "that label cannot see."
    )


def omega_xi_finding(rm, horizon: float) -> str:
    """The (ω, ξ) map's sentence: its regimes and periods, where the follower escapes, how
    often the label changes along ω at Table 1's ξ, and its transient motion."""
    cells = rm.cells
    tags = pd.Series(
        [verdict_tag(*t) for t in zip(cells["dominant"], cells["period"], strict=True)]
    )
    periods = ", ".join(map(str, sorted({int(p) for p in cells["period"].dropna()})))
    escape = cells[cells["dominant"] == "left_reach"]
    row_xi = float(cells["xi"].iloc[(cells["xi"] - Params().xi).abs().argmin()])
    row = cells[cells["xi"] == row_xi].sort_values("omega")
    row_tags = [verdict_tag(*t) for t in zip(row["dominant"], row["period"], strict=True)]
    changes = sum(a != b for a, b in zip(row_tags, row_tags[1:], strict=False))
    text = f"(ω, ξ) map, {len(cells)} deterministic cells (one run each): "
    text += ", ".join(f"{k} {n}" for k, n in tags.value_counts().sort_index().items())
    text += f"; periods found: {periods or 'none'}"
    if len(escape):
        text += (
            f"; the follower leaves the cam's reach for ξ ≥ {escape['xi'].min():.3g} (at some ω)"
        )
    text += (
        f". Along ω at ξ = {row_xi:.3g} the label changes {changes} times over {len(row)} values"
    )
    text += (
        ": periodic windows and chaos alternate, so the regime at one parameter point is "
        "fragile, which makes a point-by-point comparison with the paper uncertain."
        if changes
        else "."
    )

    def cell_name(r) -> str:
        return f"({r.omega:.3g}, {r.xi:.3g})"

    moved = transient_finding(rm.realizations, horizon, "cell", cell_name, cell_name)
    moved = moved.replace("transient chaos,", f"transient chaos (marked {TRANSIENT_MARK}),")
    moved = moved.replace("continued run's last half (",
                          f"continued run's last half (marked {SETTLED_MARK}Pn; ")  # fmt: skip
    return text + moved + step_finding(rm.realizations, lambda r: f"(ω, ξ) = {cell_name(r)}")
