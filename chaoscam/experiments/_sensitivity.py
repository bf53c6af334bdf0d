"""Why our reconstruction differs from the paper: the response against K_n, ξ and (ω, ξ).

``sensitivity(quick, outdir) -> FigureResult`` runs three sweeps of the deterministic model
(Table 1 otherwise) on the package's default classifier and states what they show:

* the contact stiffness K_n over more than eight decades (through the follower's Young's
  modulus Y_f: K_n = (pi/4) E l_lambda with 1/E = (1 - nu_f^2)/Y_f + (1 - nu_c^2)/Y_c), to see
  whether the paper's Hertz range can explain the difference (it cannot when the label is
  flat there);
* the restitution coefficient ξ, sampled densely around Table 1's value, to compare how many
  regimes its neighbourhood holds with how many the paper's stiffness range holds;
* a regime map over (ω, ξ): periodic windows, sticking, chaos and escape from the cam's reach.

Every sentence of the findings is computed from the sweeps; nothing is written in advance.
The full run checks every verdict at half the step (:data:`CHECK_STEP`).
"""

from __future__ import annotations

import dataclasses
from pathlib import Path

import numpy as np
import pandas as pd

from ..report._html import FigureItem

__all__ = ["PAPER_K_N", "sensitivity", "label_runs"]

PAPER_K_N = (8.9e7, 1.6e9)
"""The paper's Hertz line stiffness range [N/m] (its l_λ range with Table 1's materials)."""


def verdict_tag(label, period) -> str:
    """A verdict in a finding's words: "period 8" for a periodic one with its period, else the
    label ("chaotic", "undetermined", "left_reach", ...)."""
    ok = label == "periodic" and period is not None and pd.notna(period)
    return f"period {int(period)}" if ok else str(label)


def label_runs(values, labels, periods) -> list[tuple[str, float, float]]:
    """Consecutive equal (label, period) along sorted values: [(text, first, last), ...]."""
    out: list[tuple[str, float, float]] = []
    for v, lab, per in zip(values, labels, periods, strict=True):
        t = verdict_tag(lab, per)
        if out and out[-1][0] == t:
            out[-1] = (t, out[-1][1], float(v))
        else:
            out.append((t, float(v), float(v)))
    return out


def _runs_text(runs, fmt="{:.3g}") -> str:
    parts = []
    for t, a, b in runs:
        span = fmt.format(a) if a == b else f"{fmt.format(a)}–{fmt.format(b)}"
        parts.append(f"{t} ({span})")
    return " → ".join(parts)


FATE_S = {True: 100.0, False: 300.0}
"""The fate horizon [s] of the restitution sweep and the (omega, xi) map, quick and full:
runs labelled chaotic, quasiperiodic or undetermined go on to it, to see whether they stay in
the cam's reach (the full one covers (42.5 rad/s, 0.40), chaotic for 229 s and then out of
reach)."""

CHECK_STEP = {True: False, False: True}
"""Whether the sweeps re-run each periodic, quasiperiodic or chaotic verdict at half the step
and call it undetermined when it changes there (``check_step``; quick, full). The full run
does: one period certificate halves the step already, but a chaotic label had no such check,
and (ω, ξ) maps hold cells whose label is the step's (measured at ξ = 0.375, Table 1
otherwise: chaotic at dt = 2e-6 s, period 32 at dt/2, chaotic at dt/4). The quick run does
not: it would take its sweeps from 24 to 56 s, and the quick report past its 90 s."""


def step_checked(classify, quick: bool):
    """The sweeps' classifier (a ``DefaultClassifier``) with :data:`CHECK_STEP`'s choice."""
    return dataclasses.replace(classify, check_step=CHECK_STEP[quick])


def step_finding(rows: pd.DataFrame, where) -> str:
    """The sentence on the step check of one sweep's runs (``rows`` with ``ev_step_check``:
    1 kept, 0 changed, empty when not checked): how many verdicts were checked, and where
    they changed (``where(row)`` names a run). Empty when no run was checked."""
    if "ev_step_check" not in rows or not rows["ev_step_check"].notna().any():
        return ""
    checked = rows[rows["ev_step_check"].notna()]
    changed = checked[checked["ev_step_check"] == 0]
    held = len(checked) - len(changed)
    head = f" Checked at half the step, {held} of {len(checked)} " + (
        "verdict holds" if len(checked) == 1 else "verdicts hold"
    )
    if not len(changed):
        return head + "."
    one = len(changed) == 1
    runs = ", ".join(map(where, changed.itertuples()))
    return head + (
        f"; {len(changed)} change{'s' * one} there and {'is' if one else 'are'} undetermined "
        f"({runs})."
    )


XI_WINDOW = 0.05
"""Half-width of the neighbourhood of Table 1's ξ that the restitution finding looks at."""


def xi_values(quick: bool) -> list[float]:
    """The restitution sweep: a coarse grid over [0.1, 0.7] plus Table 1's ξ and ξ ± 0.025,
    ± 0.05, so that the neighbourhood the finding speaks of is sampled whatever the grid."""
    from ..model import Params

    xi0 = Params().xi
    coarse = np.linspace(0.1, 0.7, 9 if quick else 25)
    near = xi0 + np.array([-2, -1, 0, 1, 2]) * XI_WINDOW / 2
    return sorted({round(float(v), 10) for v in (*coarse, *near)})


def restitution_finding(v: pd.DataFrame, xi0: float, stiffness_tags: list[str]) -> str:
    """The restitution sentence of the findings, from the ξ sweep's verdicts ``v`` (columns
    value, label, period; sorted by value) and the labels the stiffness sweep found around
    the paper's Hertz range. It calls the restitution the more sensitive parameter only when
    the neighbourhood of Table 1's ξ holds more regimes than that stiffness range."""
    near = v[(v["value"] - xi0).abs() <= XI_WINDOW + 1e-9]
    tags = list(
        dict.fromkeys(verdict_tag(a, b) for a, b in zip(near["label"], near["period"], strict=True))
    )
    head = (
        f"Restitution ξ (Table 1: {xi0:g}): "
        + _runs_text(label_runs(v["value"], v["label"], v["period"]), "{:.3g}")
        + f". Within ±{XI_WINDOW:g} of Table 1's value ({len(near)} values sampled) "
    )
    if len(tags) > max(len(stiffness_tags), 1):
        return head + (
            f"the label takes {len(tags)} different values ({', '.join(tags)}), against "
            f"{len(stiffness_tags)} across the paper's stiffness range: the regime is more "
            "sensitive to the restitution (and so to how the restitution law is applied at the "
            "oblique impact) than to the stiffness, a plausible source of the difference."
        )
    return head + (
        f"the label takes {len(tags)} value{'s' if len(tags) != 1 else ''} "
        f"({', '.join(tags) or 'none'}), no more than across the paper's stiffness range "
        f"({len(stiffness_tags)}): this sweep does not single the restitution out as the "
        "source of the difference."
    )


def transient_finding(rows: pd.DataFrame, horizon: float, what: str) -> str:
    """The sentence on transient motion: of the runs labelled chaotic, quasiperiodic or
    undetermined (continued to the fate ``horizon``), how many stop before it, when, and how
    many of those were labelled chaotic over the recorded window; from ``rows`` with columns
    label, fate and left_at.
    ``what`` names one run ("cell", "value"). Empty when no run was continued."""
    from ..sweep._stats import continued_labels, fate_split

    checked, left = fate_split(rows)
    if not len(checked):
        return ""
    n = len(checked)
    head = (
        f" Continued to {horizon:g} s, the {n} {what}{'s' * (n != 1)} {continued_labels(checked)}"
    )
    if not len(left):
        return head + (" all stay" if n != 1 else " stays") + " in the cam's reach."
    verb = {"LEFT_REACH": ("leaves the cam's reach", "leave the cam's reach")}
    how = ", ".join(
        f"{k} {verb.get(st, (st.lower(), st.lower()))[k != 1]}"
        for st, k in left["fate"].value_counts().sort_index().items()
    )
    t0, t1 = left["left_at"].min(), left["left_at"].max()
    when = f"{t0:.3g} s" if f"{t0:.3g}" == f"{t1:.3g}" else f"{t0:.3g}–{t1:.3g} s"
    chaotic = int((left["label"] == "chaotic").sum())
    if chaotic == 0:
        return head + f": {how} before it (last section at {when}), none labelled chaotic."
    return head + (
        f": {how} before it (last section at {when}), {chaotic} labelled chaotic over the "
        "recorded window: transient chaos, which that label cannot see."
    )


def _first_ic(bif) -> pd.DataFrame:
    return bif.verdicts[bif.verdicts["ic"] == 0].sort_values("value")


def _stiffness(quick: bool, outdir: Path, workers, classify):
    from ..model import Params
    from ..sweep import bifurcation

    step = 1.0 if quick else 0.5
    y_f = [float(f"{v:.3g}") for v in 10 ** np.arange(2.0, 11.01, step)] + [2.07e11]
    bif = bifurcation("Y_f", y_f, duration=20.0, transient=10.0, classify=classify, workers=workers)
    path = outdir / "sensitivity-stiffness.parquet"
    bif.to_parquet(path)
    base = Params()
    k_n = {v: base.replace(Y_f=v).stiffness_at(base.l_lambda) for v in y_f}
    return bif, path, k_n


def _stiffness_figure(bif, k_n: dict):
    from matplotlib.figure import Figure

    from ..report._sweep_figures import LABEL_COLORS

    pts = bif.points.assign(K_n=bif.points["value"].map(k_n))
    fig = Figure(figsize=(10, 5.5), layout="constrained")
    ax = fig.subplots()
    for lab, g in pts.groupby("label"):
        ax.scatter(
            g["K_n"],
            g["theta_f"],
            s=4,
            color=LABEL_COLORS.get(lab, "#E69F00"),
            label=lab,
            rasterized=True,
        )
    ax.axvspan(*PAPER_K_N, color="#999999", alpha=0.25, lw=0, label="the paper's Hertz range")
    ax.set_xscale("log")
    ax.set(
        xlabel="contact stiffness K_n [N/m] (through Y_f)",
        ylabel="θ_f at the section [rad]",
        title="Section points against the contact stiffness (the rest as in Table 1)",
    )
    ax.legend(frameon=False, fontsize="medium", markerscale=3)
    return fig


def sensitivity(quick: bool, outdir: Path, workers=None, classify=None):
    """The three sweeps, their figures and the findings (a FigureResult titled
    "Sensitivity"); ``classify`` as for the sweeps (the report's quick run caps the
    extension of undetermined runs)."""
    from ..model import Params
    from ..report._figures import png_uri
    from ..report._sweep_figures import TRANSIENT_MARK, bifurcation_figure, regime_map_figure
    from ..sweep import Axis, bifurcation, regime_map
    from ._paper import FigureResult, _save

    res = FigureResult(0, title="Sensitivity (why the paper differs)")
    # 1. stiffness
    bif_k, path_k, k_n = _stiffness(quick, outdir, workers, classify)
    fig = _stiffness_figure(bif_k, k_n)
    png_k = _save(fig, outdir, "sensitivity-stiffness")
    v = _first_ic(bif_k)
    kv = v["value"].map(k_n).to_numpy()
    runs = label_runs(kv, v["label"], v["period"])
    inside = v[(kv >= PAPER_K_N[0] / 10) & (kv <= PAPER_K_N[1])]
    flat = sorted(
        {verdict_tag(a, b) for a, b in zip(inside["label"], inside["period"], strict=True)}
    )
    decades = np.log10(kv.max() / kv.min())
    res.why.append(
        f"Contact stiffness: K_n from {kv.min():.3g} to {kv.max():.3g} N/m ({decades:.1f} "
        f"decades, through Y_f): {_runs_text(runs)}. Around and below the paper's Hertz range "
        f"{PAPER_K_N[0]:.2g}–{PAPER_K_N[1]:.2g} N/m (from a tenth of its low end) the labels "
        f"are {', '.join(flat) or 'none'}: "
        + (
            "the response does not change there, so the paper's stiffness model cannot "
            "explain why its regimes differ from ours."
            if len(flat) == 1
            else "the response changes inside that range, so the stiffness model matters."
        )
        + step_finding(v, lambda r: f"K_n = {k_n[r.value]:.3g} N/m")
    )
    res.why_figures.append(
        FigureItem(
            "sensitivity-stiffness",
            "Sensitivity to the contact stiffness",
            png_uri(png_k),
            "Section angle against contact stiffness on a log axis, coloured by verdict, "
            "with the paper's stiffness range shaded.",
            f"{len(v)} stiffnesses, 20 s runs (10 s transient), one initial condition; "
            f"labels from the default classifier"
            + (", each checked at half the step" if getattr(classify, "check_step", False) else "")
            + f". Data: {path_k.name}.",
        )
    )
    res.bifurcations.append((str(path_k), bif_k, png_k))
    # 2. restitution
    bif_x = bifurcation(
        "xi",
        xi_values(quick),
        duration=20.0,
        transient=10.0,
        classify=classify,
        workers=workers,
        fate=FATE_S[quick],
    )
    path_x = outdir / "sensitivity-xi.parquet"
    bif_x.to_parquet(path_x)
    png_x = _save(bifurcation_figure(bif_x.points), outdir, "sensitivity-xi")
    res.bifurcations.append((str(path_x), bif_x, png_x))
    res.why.append(
        restitution_finding(_first_ic(bif_x), Params().xi, flat)
        + transient_finding(_first_ic(bif_x), FATE_S[quick], "value")
        + step_finding(_first_ic(bif_x), lambda r: f"ξ = {r.value:.3g}")
    )
    # 3. (omega, xi) map
    omegas = (20.0, 50.0, 6) if quick else (10.0, 50.0, 17)
    xis = (0.1, 0.7, 6) if quick else (0.1, 0.7, 13)
    rm = regime_map(
        Axis.linspace("omega", *omegas),
        Axis.linspace("xi", *xis),
        realizations=1,
        duration=20.0,
        transient=10.0,
        classify=classify,
        workers=workers,
        fate=FATE_S[quick],
    )
    path_m = outdir / "sensitivity-omega-xi.parquet"
    rm.to_parquet(path_m)
    png_m = _save(regime_map_figure(rm.cells, x="omega", y="xi"), outdir, "sensitivity-omega-xi")
    res.regime_maps.append((str(path_m), rm, png_m))
    cells = rm.cells
    tags = pd.Series(
        [verdict_tag(a, b) for a, b in zip(cells["dominant"], cells["period"], strict=True)]
    )
    periods = sorted({int(p) for p in cells["period"].dropna()})
    escape = cells[cells["dominant"] == "left_reach"]
    row_xi = float(cells["xi"].iloc[(cells["xi"] - Params().xi).abs().argmin()])
    row = cells[cells["xi"] == row_xi].sort_values("omega")
    row_tags = [verdict_tag(a, b) for a, b in zip(row["dominant"], row["period"], strict=True)]
    changes = sum(a != b for a, b in zip(row_tags, row_tags[1:], strict=False))
    res.why.append(
        f"(ω, ξ) map, {len(cells)} deterministic cells (one run each): "
        + ", ".join(f"{k} {n}" for k, n in tags.value_counts().sort_index().items())
        + f"; periods found: {', '.join(map(str, periods)) or 'none'}"
        + (
            f"; the follower leaves the cam's reach for ξ ≥ {escape['xi'].min():.3g} (at some ω)"
            if len(escape)
            else ""
        )
        + f". Along ω at ξ = {row_xi:.3g} the label changes {changes} times over "
        f"{len(row)} values"
        + (
            ": periodic windows and chaos alternate, so the regime at one parameter point is "
            "fragile, which makes a point-by-point comparison with the paper uncertain."
            if changes
            else "."
        )
        + transient_finding(rm.realizations, FATE_S[quick], "cell").replace(
            "transient chaos,", f"transient chaos (marked {TRANSIENT_MARK}),"
        )
        + step_finding(rm.realizations, lambda r: f"(ω, ξ) = ({r.omega:.3g}, {r.xi:.3g})")
    )
    return res
