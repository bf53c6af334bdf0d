"""Why our reconstruction differs from the paper: sweeps of the deterministic model (Table 1
otherwise) and their figures (the sentences: :mod:`._findings`): the contact stiffness over
nine decades through Y_f and across the paper's Hertz range through l_λ, the restitution ξ,
an (ω, ξ) map, and what the paper leaves open: the inertia J, the pivot height y_O, the
friction torque's arm and its literal damping signs (docs/model.md gives the defaults)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd

from ..model import Params
from ..report import LABEL_COLORS, FigureItem, mark_without_points
from ._continued import continued_part
from ._findings import (
    PAPER_K_N,
    PAPER_L_LAMBDA,
    XI_WINDOW,
    choices_finding,
    first_ic,
    omega_xi_finding,
    restitution_finding,
    step_finding,
    stiffness_finding,
    transient_finding,
)
from ._side_by_side import beside
from ._stage import FATE_S, RUN, SWEEP_FATE_S, FigureResult, draw, swept, uri_of

HERTZ_VALUES = {True: 6, False: 18}
"""How many l_λ the stiffness finding samples across :data:`PAPER_L_LAMBDA` (quick, full)."""

J_FACTORS = {True: (0.5, 0.75, 1.0, 1.5, 2.0), False: tuple(np.linspace(0.5, 2.0, 13))}
"""The inertias swept, as factors of the solid rod's m (l²/3 + r²/4) (quick, full)."""

ARM_FACTORS = {True: (0.0, 1.0, 4.0), False: (0.0, 0.5, 1.0, 2.0, 4.0, 8.0, 16.0)}
"""The friction arms swept, as factors of the rod radius r (quick, full)."""

PIVOT_SPAN = 0.01  # half-width [m] of the pivot heights swept around the default R + r


def xi_values(quick: bool) -> list[float]:
    """A coarse grid over [0.1, 0.7] plus Table 1's ξ and ξ ± 0.025, ± 0.05."""
    near = Params().xi + np.array([-2, -1, 0, 1, 2]) * XI_WINDOW / 2
    coarse = np.linspace(0.1, 0.7, 9 if quick else 25)
    return sorted({round(float(v), 10) for v in (*coarse, *near)})


def _stiffness_figure(sweeps):
    """Section points of ``[(sweep, {value: K_n}), ...]`` against K_n, coloured by verdict."""
    from matplotlib.figure import Figure

    fig = Figure(figsize=(10, 5.5), layout="constrained")
    ax = fig.subplots()
    pts = pd.concat([b.points.assign(K_n=b.points["value"].map(k)) for b, k in sweeps])
    for lab, g in pts.groupby("label"):
        color = LABEL_COLORS.get(lab, "#E69F00")
        ax.scatter(g["K_n"], g["theta_f"], s=9, color=color, label=lab, rasterized=True)
    ax.axvspan(*PAPER_K_N, color="#999999", alpha=0.25, lw=0, label="the paper's Hertz range")
    runs = pd.concat([b.verdicts.assign(K_n=b.verdicts["value"].map(k)) for b, k in sweeps])
    mark_without_points(ax, pts, runs, x="K_n")
    ax.set_xscale("log")
    ax.set(
        xlabel="contact stiffness K_n [N/m] (through Y_f, and through l_λ in the shaded range)",
        ylabel="θ_f at the section [rad]",
        title="Section points against the contact stiffness (the rest as in Table 1)",
    )
    ax.legend(frameon=False, fontsize="medium", markerscale=2.5)
    return fig


def _omega_xi_map(sweep, quick: bool):
    """The (ω, ξ) regime map, one deterministic run a cell continued to the fate horizon."""
    from ..sweep import Axis

    omegas, xis = ((20.0, 50.0, 6), (0.1, 0.7, 6)) if quick else ((10.0, 50.0, 17), (0.1, 0.7, 13))
    x, y = Axis.linspace("omega", *omegas), Axis.linspace("xi", *xis)
    return sweep(
        "sensitivity-omega-xi", x, y, kind="regime_map", realizations=1, fate=FATE_S[quick]
    )


def sensitivity(quick: bool, outdir: Path, workers=None, judge: dict | None = None):
    """The sweeps, their figures and findings (``judge``: their verdict keywords, as
    :func:`._stage.judging`); the (ω, ξ) map, the longest, runs beside the others."""
    judge = dict(judge or {})
    res = FigureResult(0, title="Sensitivity (why the paper differs)")

    def sweep(stem: str, *args, fate=SWEEP_FATE_S[quick], **kw):
        return swept(res, outdir, stem, *args, workers=workers, fate=fate, **RUN, **judge, **kw)

    with beside(workers, _omega_xi_map, sweep, quick) as omega_xi:
        hertz_tags = _stiffness_part(res, sweep, quick, outdir, judge.get("check_step"))
        _restitution_part(res, sweep, quick, hertz_tags)
        choices = open_choices(sweep, quick, hertz_tags)
        rm = omega_xi.result()
    res.why += [omega_xi_finding(rm, FATE_S[quick]), choices]
    continued_part(res, sweep, quick, outdir, rm)
    return res


def _stiffness_part(res, sweep, quick: bool, outdir: Path, checked) -> list[str]:
    """The stiffness sweeps, their figures and sentence into ``res``; returns the tags across
    the paper's Hertz range, which the other findings compare with."""
    base = Params()
    y_f = [float(f"{v:.3g}") for v in 10 ** np.arange(2.0, 11.01, 1.0 if quick else 0.5)]
    y_f += [2.07e11]
    l_lambda = np.linspace(*PAPER_L_LAMBDA, HERTZ_VALUES[quick]).round(6).tolist()
    sweeps = [
        (sweep("sensitivity-stiffness", "Y_f", y_f, png="sensitivity-yf"),
         {v: base.replace(Y_f=v).stiffness_at(base.l_lambda) for v in y_f}),
        (sweep("sensitivity-hertz", "l_lambda", l_lambda),
         {v: base.stiffness_at(v) for v in l_lambda}),
    ]  # fmt: skip
    png_k = draw(outdir / "sensitivity-stiffness.png", _stiffness_figure, sweeps)
    yf, hertz = (first_ic(b).assign(K_n=lambda f, k=k: f["value"].map(k)).sort_values("K_n")
                 for b, k in sweeps)  # fmt: skip
    text, hertz_tags = stiffness_finding(yf, hertz)
    res.why.append(text + step_finding(pd.concat([yf, hertz]), lambda r: f"K_n = {r.K_n:.3g} N/m"))
    res.why_figures.append(FigureItem(
        "sensitivity-stiffness", "Sensitivity to the contact stiffness", uri_of(png_k),
        "Section angle against contact stiffness on a log axis, coloured by verdict, "
        "with the paper's stiffness range shaded.",
        f"{len(yf)} stiffnesses through Y_f and {len(hertz)} through l_λ across the "
        "paper's range, 20 s runs (10 s transient), one initial condition; labels from "
        "the default classifier" + (", each checked at half the step" if checked else "")
        + ". Data: sensitivity-stiffness.parquet, sensitivity-hertz.parquet.",
    ))  # fmt: skip
    return hertz_tags


def _restitution_part(res, sweep, quick: bool, hertz_tags) -> None:
    """The restitution sweep and its sentence into ``res``."""
    v = first_ic(sweep("sensitivity-xi", "xi", xi_values(quick), fate=FATE_S[quick]))
    left = lambda r: f"ξ = {r.value:.3g} (left at {r.left_at:.3g} s)"  # noqa: E731
    named = lambda r: f"ξ = {r.value:.3g}"  # noqa: E731
    res.why.append(
        restitution_finding(v, Params().xi, hertz_tags)
        + transient_finding(v, FATE_S[quick], "value", left, named)
        + step_finding(v, named)
    )


def open_choices(sweep, quick: bool, hertz_tags) -> str:
    """The sweeps of what the paper leaves open (the literal damping's run as data only, no
    diagram); returns their sentence."""
    p = Params()
    y0 = p.pivot[1]
    pivots = np.linspace(y0 - PIVOT_SPAN, y0 + PIVOT_SPAN, 5 if quick else 11).round(6).tolist()
    runs = {
        "J": sweep("sensitivity-J", "J", [round(p.inertia * f, 8) for f in J_FACTORS[quick]]),
        "y_O": sweep("sensitivity-pivot", "y_O", pivots),
        "friction_arm": sweep("sensitivity-arm", "friction_arm",
                              [round(p.r * f, 8) for f in ARM_FACTORS[quick]]),
        "xi": sweep("sensitivity-damping", "xi", [p.xi], base=p.replace(damping="paper_literal"),
                    png=None),
    }  # fmt: skip
    runs = {name: first_ic(bif) for name, bif in runs.items()}
    text = choices_finding(runs["J"], runs["y_O"], runs["friction_arm"], runs["xi"], hertz_tags)
    rows = pd.concat([runs[name].assign(what=name) for name in ("J", "y_O", "friction_arm")])
    return text + step_finding(rows, lambda r: f"{r.what} = {r.value:.3g}")
