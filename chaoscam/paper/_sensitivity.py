"""Why our reconstruction differs from the paper: the response against K_n, ξ and (ω, ξ).

``sensitivity(quick, outdir) -> FigureResult`` runs sweeps of the deterministic model
(Table 1 otherwise) on the package's default classifier and states what they show:

* the contact stiffness K_n over more than eight decades (through the follower's Young's
  modulus Y_f: K_n = (pi/4) E l_lambda with 1/E = (1 - nu_f^2)/Y_f + (1 - nu_c^2)/Y_c), and
  across the paper's Hertz range itself through l_lambda (:data:`PAPER_L_LAMBDA`, as the paper
  varies it), to see whether that range can explain the difference (it cannot when the motion
  keeps one regime there);
* the restitution coefficient ξ, sampled densely around Table 1's value, to compare how many
  regimes its neighbourhood holds with how many the paper's stiffness range holds;
* a regime map over (ω, ξ): periodic windows, sticking, chaos and escape from the cam's reach;
* what the paper leaves open and this model decided (:mod:`._choices`: the inertia J, the
  pivot height, the damping signs), against the same Hertz range.

Every sentence of the findings is computed from the sweeps; nothing is written in advance.
The full run checks every verdict at half the step (:data:`._stage.CHECK_STEP`).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd

from ..report import FigureItem
from ._choices import open_choices
from ._findings import (
    band_counts,
    band_number,
    first_ic,
    frame_tags,
    label_runs,
    paper_regimes,
    regimes,
    runs_text,
    step_finding,
    verdict_tag,
)
from ._stage import FATE_S, SWEEP_FATE_S, FigureResult, save
from ._store import stored

__all__ = ["PAPER_K_N", "PAPER_L_LAMBDA", "label_runs", "sensitivity", "stiffness_finding"]

PAPER_K_N = (8.9e7, 1.6e9)
"""The paper's Hertz line stiffness range [N/m] (its l_λ range with Table 1's materials)."""

PAPER_L_LAMBDA = (0.001, 0.018)
"""The paper's l_λ range [m] (Fig. 4): through K_n = (π/4) E l_λ it spans :data:`PAPER_K_N`."""

HERTZ_VALUES = {True: 6, False: 18}
"""How many l_λ the stiffness finding samples across :data:`PAPER_L_LAMBDA` (quick, full), at
the ξ sweep's step and classifier, so that the two ranges are compared on equal terms (Fig. 4
samples the same range at a finer step)."""


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


def restitution_finding(v: pd.DataFrame, xi0: float, hertz_tags: list[str]) -> str:
    """The restitution sentence of the findings, from the ξ sweep's verdicts ``v`` (columns
    value, label, period, optionally ev_banded_chaos; sorted by value) and the tags of the
    runs across the paper's Hertz range (:func:`stiffness_finding`). It calls the restitution
    the more sensitive parameter only when the neighbourhood of Table 1's ξ holds more regimes
    than that range; undetermined runs count on neither side."""
    near = v[(v["value"] - xi0).abs() <= XI_WINDOW + 1e-9]
    tags, hertz = regimes(frame_tags(near)), regimes(hertz_tags)
    n_und = int((near["label"] == "undetermined").sum())
    head = (
        f"Restitution ξ (Table 1: {xi0:g}): "
        + runs_text(label_runs(v["value"], v["label"], v["period"], band_counts(v)), "{:.3g}")
        + f". Within ±{XI_WINDOW:g} of Table 1's value ({len(near)} values sampled"
        + (f", {n_und} undetermined" if n_und else "")
        + ") "
    )
    across = f"across the paper's Hertz range ({', '.join(hertz) or 'none'})"
    if len(tags) > max(len(hertz), 1):
        return head + (
            f"the motion takes {len(tags)} regimes ({', '.join(tags)}), against {len(hertz)} "
            f"{across}: the regime is more sensitive to the restitution (and so to how the "
            "restitution law is applied at the oblique impact) than to the stiffness, a "
            "plausible source of the difference."
        )
    return head + (
        f"the motion takes {len(tags)} regime{'s' if len(tags) != 1 else ''} "
        f"({', '.join(tags) or 'none'}), no more than the {len(hertz)} {across}: this sweep "
        "does not single the restitution out as the source of the difference."
    )


def stiffness_finding(yf: pd.DataFrame, hertz: pd.DataFrame) -> tuple[str, list[str]]:
    """The stiffness sentence of the findings and the tags across the paper's Hertz range.

    ``yf``: the Y_f sweep's verdicts, ``hertz``: the l_λ sweep's (:data:`PAPER_L_LAMBDA`),
    each with a ``K_n`` column [N/m] and sorted by it. The range is judged from the l_λ runs
    and the Y_f runs inside :data:`PAPER_K_N`: one regime there (undetermined aside) means
    the paper's stiffness model cannot explain the difference; periods n and n-band chaos of
    one n are the same motion on n narrow bands, where the stiffness decides the label only.
    """
    kv = yf["K_n"].to_numpy()
    runs = label_runs(kv, yf["label"], yf["period"], band_counts(yf))
    in_yf = yf[(yf["K_n"] >= PAPER_K_N[0]) & (yf["K_n"] <= PAPER_K_N[1])]
    inside = pd.concat([hertz, in_yf]).sort_values("K_n")
    tags = frame_tags(inside)
    found = regimes(tags)
    text = (
        f"Contact stiffness: K_n from {kv.min():.3g} to {kv.max():.3g} N/m "
        f"({np.log10(kv.max() / kv.min()):.1f} decades, through Y_f): {runs_text(runs)}. "
        f"Across the paper's Hertz range {PAPER_K_N[0]:.2g}–{PAPER_K_N[1]:.2g} N/m, sampled "
        f"through l_λ = {PAPER_L_LAMBDA[0] * 1e3:g}–{PAPER_L_LAMBDA[1] * 1e3:g} mm as the paper "
        f"does ({len(hertz)} values) and by {len(in_yf)} of the Y_f values: "
        + runs_text(
            label_runs(inside["K_n"], inside["label"], inside["period"], band_counts(inside))
        )
        + ": "
    )
    decided = inside[inside["label"] != "undetermined"]
    rows = zip(decided["label"], decided["period"], band_counts(decided), strict=True)
    bands = {band_number(*r) for r in rows}
    family = len(bands) == 1 and None not in bands  # period n and n-band chaos of one n
    if len(found) <= 1:
        text += (
            "one regime there, so the paper's stiffness model cannot explain why its regimes "
            "differ from ours"
        )
    elif family:
        text += (
            f"the label moves between {' and '.join(found)}, the same motion on {bands.pop()} "
            "narrow bands: the stiffness decides which label, not the kind of motion, so it "
            "cannot explain why the paper's regimes differ from ours"
        )
    else:
        text += "the response changes inside that range, so the stiffness model matters"
    return text + paper_regimes(found, "there"), tags


def transient_finding(rows: pd.DataFrame, horizon: float, what: str, where=None, name=None) -> str:
    """The sentence on transient motion: of the runs labelled chaotic, quasiperiodic or
    undetermined (continued to the fate ``horizon``), how many stop before it, when, and how
    many of those were labelled chaotic over the recorded window, then how many are periodic
    on the continued run's last half (:func:`_settled_finding`); from ``rows`` with columns
    label, fate, left_at, fate_label and fate_period.
    ``what`` names one run ("cell", "value"); ``where(row)``, when given, names the runs
    labelled chaotic that left, ``name(row)`` those periodic later. Empty when no run was
    continued."""
    return _left_finding(rows, horizon, what, where) + _settled_finding(rows, name)


def _settled_finding(rows: pd.DataFrame, name=None) -> str:
    """The clause on the continued runs that are periodic on the fate run's last half: the
    chaotic ones settle after the recorded window (transient chaos); the undetermined ones
    needed the longer window for a verdict."""
    from ..sweep import fate_settled

    settled = fate_settled(rows)
    if not len(settled):
        return ""
    k = len(settled)
    named = f" ({'; '.join(map(name, settled.itertuples()))})" if name else ""
    periods = ", ".join(str(p) for p in sorted(set(settled["fate_period"].dropna().astype(int))))
    chaotic = int((settled["label"] == "chaotic").sum())
    why = []
    if chaotic:
        why.append(f"{chaotic} labelled chaotic settle{'s' * (chaotic == 1)} later")
    if k > chaotic:
        why.append(f"{k - chaotic} labelled otherwise needed the longer window for a verdict")
    return (
        f" {k} of them {'is' if k == 1 else 'are'} periodic on the continued run's last half "
        f"(period {periods}; the classifier's verdict there, at the run's step){named}: "
        + " and ".join(why)
        + "."
    )


def _left_finding(rows: pd.DataFrame, horizon: float, what: str, where=None) -> str:
    """The sentence's part on the continued runs that stop before the horizon."""
    from ..sweep import continued_labels, fate_split

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
    gone = left[left["label"] == "chaotic"]
    if not len(gone):
        return head + f": {how} before it (last section at {when}), none labelled chaotic."
    named = f", at {'; '.join(map(where, gone.itertuples()))}" if where else ""
    return head + (
        f": {how} before it (last section at {when}), {len(gone)} labelled chaotic over the "
        f"recorded window{named}: transient chaos, which that label cannot see."
    )


def _stiffness(quick: bool, outdir: Path, workers, judge: dict):
    """The two stiffness sweeps: Y_f over nine decades and l_λ across the paper's range;
    each returns (bifurcation, path, {value: K_n})."""
    from ..model import Params
    from ..sweep import bifurcation

    base = Params()
    step = 1.0 if quick else 0.5
    y_f = [float(f"{v:.3g}") for v in 10 ** np.arange(2.0, 11.01, step)] + [2.07e11]
    l_lambda = np.linspace(*PAPER_L_LAMBDA, HERTZ_VALUES[quick]).round(6).tolist()
    out = []
    for name, values, k_of in (
        ("Y_f", y_f, lambda v: base.replace(Y_f=v).stiffness_at(base.l_lambda)),
        ("l_lambda", l_lambda, base.stiffness_at),
    ):
        path = outdir / f"sensitivity-{'stiffness' if name == 'Y_f' else 'hertz'}.parquet"
        bif = bifurcation(
            name, values, duration=20.0, transient=10.0, workers=workers,
            fate=SWEEP_FATE_S[quick], **judge, **stored(path),
        )  # fmt: skip
        out.append((bif, path, {v: k_of(v) for v in values}))
    return out


def _stiffness_figure(sweeps):
    """Section points of both stiffness sweeps against K_n, coloured by verdict; a run that
    left no section point (diverged, out of reach) is an x on the top edge."""
    from matplotlib.figure import Figure

    from ..report import LABEL_COLORS, mark_without_points

    fig = Figure(figsize=(10, 5.5), layout="constrained")
    ax = fig.subplots()
    pts = pd.concat([b.points.assign(K_n=b.points["value"].map(k)) for b, _, k in sweeps])
    for lab, g in pts.groupby("label"):
        color = LABEL_COLORS.get(lab, "#E69F00")
        ax.scatter(g["K_n"], g["theta_f"], s=9, color=color, label=lab, rasterized=True)
    ax.axvspan(*PAPER_K_N, color="#999999", alpha=0.25, lw=0, label="the paper's Hertz range")
    runs = pd.concat([b.verdicts.assign(K_n=b.verdicts["value"].map(k)) for b, _, k in sweeps])
    mark_without_points(ax, pts, runs, x="K_n")
    ax.set_xscale("log")
    ax.set(
        xlabel="contact stiffness K_n [N/m] (through Y_f, and through l_λ in the shaded range)",
        ylabel="θ_f at the section [rad]",
        title="Section points against the contact stiffness (the rest as in Table 1)",
    )
    ax.legend(frameon=False, fontsize="medium", markerscale=2.5)
    return fig


def _omega_xi_map(quick: bool, outdir: Path, workers, judge: dict):
    """The (ω, ξ) regime map, one deterministic run a cell continued to the fate horizon;
    returns (the map, its data file)."""
    from ..sweep import Axis, regime_map

    omegas = (20.0, 50.0, 6) if quick else (10.0, 50.0, 17)
    xis = (0.1, 0.7, 6) if quick else (0.1, 0.7, 13)
    rm = regime_map(
        Axis.linspace("omega", *omegas),
        Axis.linspace("xi", *xis),
        realizations=1,
        duration=20.0,
        transient=10.0,
        workers=workers,
        fate=FATE_S[quick],
        **judge,
        **stored(path := outdir / "sensitivity-omega-xi.parquet"),
    )
    return rm, path


def sensitivity(quick: bool, outdir: Path, workers=None, judge: dict | None = None):
    """The sweeps, their figures and the findings (a FigureResult titled "Sensitivity").

    ``judge``: the sweeps' verdict keywords (``extend_to``, ``check_step``; the report's
    :func:`._stage.judging`), None for the sweeps' defaults. The (ω, ξ) map, the longest
    sweep, runs beside the others (:func:`._side_by_side.beside`, where ``workers`` is every
    core), so no sweep's last runs leave a core idle."""
    from ._side_by_side import beside

    judge = dict(judge or {})
    with beside(workers, _omega_xi_map, quick, outdir, workers, judge) as omega_xi:
        res = FigureResult(0, title="Sensitivity (why the paper differs)")
        hertz_tags = _stiffness_part(res, quick, outdir, workers, judge)
        _restitution_part(res, quick, outdir, workers, judge, hertz_tags)
        # the last sweeps first, then the (ω, ξ) map, under way since the stage began
        choices, bifs = open_choices(quick, outdir, workers, judge, hertz_tags)
        rm, path_m = omega_xi.result()
    png_m = _save_map(outdir, rm)
    res.regime_maps.append((str(path_m), rm, png_m))
    res.why += [omega_xi_finding(rm, FATE_S[quick]), choices]
    res.bifurcations.extend(bifs)
    return res


def _save_map(outdir: Path, rm):
    from ..report import regime_map_figure

    return save(outdir, "sensitivity-omega-xi", regime_map_figure, rm.cells, x="omega", y="xi")


def _stiffness_part(res, quick: bool, outdir: Path, workers, judge: dict) -> list[str]:
    """The stiffness sweeps, their figures and sentence into ``res``; returns the tags across
    the paper's Hertz range, which the other findings compare with."""
    from ..report import sweep_diagram
    from ._drawing import uri_of

    sweeps = _stiffness(quick, outdir, workers, judge)
    png_k = save(outdir, "sensitivity-stiffness", _stiffness_figure, sweeps)
    (bif_k, path_k, _), (bif_h, path_h, _) = sweeps
    yf, hertz = (
        first_ic(b).assign(K_n=lambda f, k=k: f["value"].map(k)).sort_values("K_n")
        for b, _, k in sweeps
    )
    text, hertz_tags = stiffness_finding(yf, hertz)
    res.why.append(text + step_finding(pd.concat([yf, hertz]), lambda r: f"K_n = {r.K_n:.3g} N/m"))
    res.why_figures.append(
        FigureItem(
            "sensitivity-stiffness",
            "Sensitivity to the contact stiffness",
            uri_of(png_k),
            "Section angle against contact stiffness on a log axis, coloured by verdict, "
            "with the paper's stiffness range shaded.",
            f"{len(yf)} stiffnesses through Y_f and {len(hertz)} through l_λ across the "
            "paper's range, 20 s runs (10 s transient), one initial condition; labels from "
            "the default classifier"
            + (", each checked at half the step" if judge.get("check_step") else "")
            + f". Data: {path_k.name}, {path_h.name}.",
        )
    )
    res.bifurcations.append(
        (str(path_k), bif_k, save(outdir, "sensitivity-yf", sweep_diagram, bif_k))
    )
    png_h = save(outdir, "sensitivity-hertz", sweep_diagram, bif_h)
    res.bifurcations.append((str(path_h), bif_h, png_h))
    return hertz_tags


def _restitution_part(res, quick, outdir: Path, workers, judge: dict, hertz_tags) -> None:
    """The restitution sweep, its figure and sentence into ``res``."""
    from ..model import Params
    from ..report import sweep_diagram
    from ..sweep import bifurcation

    bif_x = bifurcation(
        "xi",
        xi_values(quick),
        duration=20.0,
        transient=10.0,
        workers=workers,
        fate=FATE_S[quick],
        **judge,
        **stored(path_x := outdir / "sensitivity-xi.parquet"),
    )
    png_x = save(outdir, "sensitivity-xi", sweep_diagram, bif_x)
    res.bifurcations.append((str(path_x), bif_x, png_x))
    v_x = first_ic(bif_x)
    res.why.append(
        restitution_finding(v_x, Params().xi, hertz_tags)
        + transient_finding(
            v_x,
            FATE_S[quick],
            "value",
            lambda r: f"ξ = {r.value:.3g} (left at {r.left_at:.3g} s)",
            lambda r: f"ξ = {r.value:.3g}",
        )
        + step_finding(v_x, lambda r: f"ξ = {r.value:.3g}")
    )


def omega_xi_finding(rm, horizon: float) -> str:
    """The (ω, ξ) map's sentence: its regimes and periods, where the follower escapes, how
    often the label changes along ω at Table 1's ξ, and its transient motion."""
    from ..model import Params
    from ..report import SETTLED_MARK, TRANSIENT_MARK

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

    def cell_name(r) -> str:
        return f"({r.omega:.3g}, {r.xi:.3g})"

    return (
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
        + transient_finding(rm.realizations, horizon, "cell", cell_name, cell_name)
        .replace("transient chaos,", f"transient chaos (marked {TRANSIENT_MARK}),")
        .replace(
            "continued run's last half (", f"continued run's last half (marked {SETTLED_MARK}Pn; "
        )
        + step_finding(rm.realizations, lambda r: f"(ω, ξ) = ({r.omega:.3g}, {r.xi:.3g})")
    )
