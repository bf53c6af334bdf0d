"""What the paper leaves open, swept: does a choice this model had to make move the motion
more than the paper's whole stiffness range does?

At Table 1 otherwise: the rod's inertia J over 0.5–2 times the solid steel rod's (the paper
gives the mass, not J), the pivot height y_O over R + r ± 1 cm (the paper draws the rod but
gives no pivot), the friction torque's arm over 0–16 r (equation (1) writes a force where a
torque belongs; the default arm is the rod radius r), and one run with the paper's literal
damping signs (``damping = "paper_literal"``; docs/model.md and the README's decisions table
give the reasons for the defaults). The sentence is computed from the verdicts, on the
sensitivity sweeps' step and classifier; the choices not swept are named with the values the
runs used.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd

from ._findings import (
    band_counts,
    first_ic,
    frame_tags,
    label_runs,
    paper_regimes,
    regimes,
    runs_text,
    step_finding,
)
from ._stage import SWEEP_FATE_S, save
from ._store import stored

__all__ = ["ARM_FACTORS", "J_FACTORS", "PIVOT_SPAN", "choices_finding", "open_choices"]

J_FACTORS = {True: (0.5, 0.75, 1.0, 1.5, 2.0), False: tuple(np.linspace(0.5, 2.0, 13))}
"""The inertias swept, as factors of the solid rod's m (l²/3 + r²/4) (quick, full)."""

ARM_FACTORS = {True: (0.0, 1.0, 4.0), False: (0.0, 0.5, 1.0, 2.0, 4.0, 8.0, 16.0)}
"""The friction arms swept, as factors of the rod radius r (quick, full)."""

PIVOT_SPAN = 0.01
"""Half-width [m] of the pivot heights swept around the default R + r."""


def _pivots(quick: bool) -> list[float]:
    from ..model import Params

    y0 = Params().pivot[1]
    return np.linspace(y0 - PIVOT_SPAN, y0 + PIVOT_SPAN, 5 if quick else 11).round(6).tolist()


def choices_finding(
    inertia: pd.DataFrame,
    pivot: pd.DataFrame,
    arm: pd.DataFrame,
    damping: pd.DataFrame,
    hertz_tags: list[str],
) -> str:
    """The sentence: the labels along J, y_O and the friction arm (verdict tables with value,
    label, period and optionally ev_banded_chaos, sorted), the literal damping's label, and
    how many regimes they hold together against the paper's Hertz range (undetermined counts
    on neither side)."""
    from ..model import Params

    p = Params()
    tags = sum((frame_tags(v) for v in (inertia, pivot, arm, damping)), [])
    found, hertz = regimes(tags), regimes(hertz_tags)

    def along(v):
        return runs_text(label_runs(v["value"], v["label"], v["period"], band_counts(v)))

    text = (
        f"What the paper leaves open, at Table 1 otherwise: the rod's inertia J from "
        f"{inertia['value'].min():.3g} to {inertia['value'].max():.3g} kg m² (the solid rod's "
        f"{p.inertia:.3g}): {along(inertia)}; the pivot height y_O from "
        f"{pivot['value'].min():.3g} to {pivot['value'].max():.3g} m (default {p.pivot[1]:g}): "
        f"{along(pivot)}; the friction torque's arm from {arm['value'].min():.3g} to "
        f"{arm['value'].max():.3g} m (default r = {p.arm:g}): {along(arm)}; "
        f"the paper's literal damping signs: {', '.join(frame_tags(damping))}. "
        f"Together {len(found)} regime{'s' * (len(found) != 1)} ({', '.join(found) or 'none'}), "
        f"against {len(hertz)} across the paper's Hertz range: "
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
            f"{p.v_chatter:g} m/s; numerical, its convergence measured in docs/verdicts.md) and, "
            f"for a random line length (σ > 0, not Table 1's), when a length is drawn "
            f"(resample = {p.resample})."
        )
    )


def open_choices(quick: bool, outdir: Path, workers, judge: dict, hertz_tags: list[str]):
    """Run the sweeps (``judge``: their verdict keywords); returns (the sentence, [(data
    file, bifurcation, its figure)] for the J, y_O and friction-arm diagrams). The
    literal-damping run is kept as data only."""
    from ..model import Params
    from ..report import sweep_diagram
    from ..sweep import bifurcation

    p = Params()
    runs, figures = {}, []
    plan = (
        ("J", [round(p.inertia * f, 8) for f in J_FACTORS[quick]], p, "sensitivity-J"),
        ("y_O", _pivots(quick), p, "sensitivity-pivot"),
        ("friction_arm", [round(p.r * f, 8) for f in ARM_FACTORS[quick]], p, "sensitivity-arm"),
        ("xi", [p.xi], p.replace(damping="paper_literal"), "sensitivity-damping"),
    )
    for name, values, base, stem in plan:
        path = outdir / f"{stem}.parquet"
        bif = bifurcation(
            name, values, base=base, duration=20.0, transient=10.0, workers=workers,
            fate=SWEEP_FATE_S[quick], **judge, **stored(path),
        )  # fmt: skip
        runs[name] = first_ic(bif)
        if name != "xi":
            figures.append((str(path), bif, save(outdir, stem, sweep_diagram, bif)))
    text = choices_finding(runs["J"], runs["y_O"], runs["friction_arm"], runs["xi"], hertz_tags)
    rows = pd.concat([runs[name].assign(what=name) for name in ("J", "y_O", "friction_arm")])
    return text + step_finding(rows, lambda r: f"{r.what} = {r.value:.3g}"), figures
