"""The period-1 window at ξ = 0.1 by continuation: the branch over a brute-force diagram in ω,
its fold and period doubling continued over the (ω, ξ) map, and the sentence that names the
bifurcations ending the window (:mod:`chaoscam.continuation`; docs/continuation.md)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd

from ..continuation import Branch, Curve, continuation, curve
from ..model import Params
from ..report import FigureItem
from ._stage import draw, uri_of

XI_BRANCH, OMEGA_START = 0.1, 30.0
"""The branch's ξ and its start ω [rad/s], inside the period-1 window."""

OMEGA_RANGE = (28.9, 33.0)
"""The ω interval [rad/s] the branch is followed over, both ways from the start."""

BRUTE_OMEGAS = {True: 11, False: 41}
"""How many ω of the brute-force diagram over :data:`OMEGA_RANGE` (quick, full)."""

COEXISTING = (29.0, 29.25)
"""ω [rad/s] the brute-force diagram always samples: near the fold, where the run from the
model's initial state finds another attractor than the period-1 orbit (P4 at 29.25)."""

CONTINUED_FILES = [*(f"continuation-{n}{e}" for n in ("p1", "curves")
                     for e in (".parquet", ".events.parquet")),
                   "continuation-omega.parquet", "continuation-omega.verdicts.parquet",
                   "continuation.png"]  # fmt: skip
"""The files :func:`continued_part` writes into the data folder."""


def follow_window(to_xi: float) -> tuple[Branch, Curve]:
    """The period-1 branch at ξ = :data:`XI_BRANCH` from ω = :data:`OMEGA_START` both ways
    over :data:`OMEGA_RANGE` (one Branch, the downward half's points numbered negative) and
    its folds and period doublings continued in ξ up to ``to_xi`` (one Curve)."""
    p = Params(xi=XI_BRANCH, omega=OMEGA_START)
    halves = [continuation(p, param="omega", to=to, ds_max=0.05) for to in OMEGA_RANGE]
    down, up = halves
    points = pd.concat([down.points.assign(point=-down.points.point), up.points])
    branch = Branch(points, pd.concat([down.events, up.events], ignore_index=True),
                    {"halves": [h.settings for h in halves]})  # fmt: skip
    starts = branch.events[branch.events.kind.isin(["fold", "period_doubling"])]
    found = [curve(p, row, second="xi", to=to_xi, ds_max=0.05) for _, row in starts.iterrows()]
    curves = Curve(pd.concat([c.points.assign(curve=i) for i, c in enumerate(found)]),
                   pd.concat([c.events.assign(curve=i) for i, c in enumerate(found)]),
                   {"curves": [c.settings for c in found]})  # fmt: skip
    return branch, curves


def crossings(points: pd.DataFrame, cells: pd.DataFrame, x: str = "omega", y: str = "xi"):
    """Where each curve of ``points`` (``Curve.points``) crosses a row of a regime map's
    ``cells`` between two neighbouring cells: one row per crossing, ``kind``, the row's y,
    the curve's x there (linear between its points), and the two cells' x, ``dominant``
    label and ``period`` (``_lo`` left, ``_hi`` right)."""
    rows, xs = [], np.sort(cells[x].unique())
    for (c, kind), g in points.groupby(["curve", "kind"]):
        v, v2 = g.sort_values("point")[["value", "value2"]].to_numpy().T
        for yv in np.sort(cells[y].unique()):
            for k in np.flatnonzero((v2[:-1] - yv) * (v2[1:] - yv) <= 0):
                if v2[k + 1] == v2[k]:
                    continue
                at = v[k] + (yv - v2[k]) * (v[k + 1] - v[k]) / (v2[k + 1] - v2[k])
                i = np.searchsorted(xs, at)
                if not 0 < i < len(xs):
                    continue
                row = {"curve": c, "kind": kind, y: yv, x: at}
                for side, xv in (("lo", xs[i - 1]), ("hi", xs[i])):
                    cell = cells[(cells[x] == xv) & (cells[y] == yv)].iloc[0]
                    row.update({f"{x}_{side}": xv, f"dominant_{side}": cell["dominant"],
                                f"period_{side}": cell.get("period", np.nan)})  # fmt: skip
                rows.append(row)
    return pd.DataFrame(rows)


def sides_differ(cross: pd.DataFrame) -> pd.Series:
    """Whether the two cells of each of :func:`crossings`' rows differ in label or period."""
    per = [pd.to_numeric(cross[f"period_{side}"]).fillna(-1) for side in ("lo", "hi")]
    return (cross.dominant_lo != cross.dominant_hi) | (per[0] != per[1])


def _figure(rm, branch, curves, bif):
    """The (ω, ξ) map with the curves, and the brute-force diagram with the branch."""
    from matplotlib.figure import Figure

    from ..plot import plot_bifurcation, plot_branch, plot_curves, plot_dominant

    fig = Figure(figsize=(15, 6), layout="constrained")
    a, b = fig.subplots(1, 2, width_ratios=(1.1, 1))
    plot_dominant(rm.cells, "omega", "xi", a)
    plot_curves(curves.points, a, grid=(rm.cells["omega"], rm.cells["xi"]))
    a.set_title("(ω, ξ) map with the continued fold and period-doubling curves")
    plot_bifurcation(bif.points, b)
    plot_branch(branch.points, branch.events, ax=b)
    b.set_title(f"ξ = {XI_BRANCH}: brute force (dots) and the continued period-1 orbit")
    return fig


def _sentence(branch: Branch, curves: Curve, cross: pd.DataFrame, bif) -> str:
    """What ends the period-1 window at ξ = 0.1 and where its curves go."""
    ev = branch.events.groupby("kind")["value"].first()
    fold, flip = float(ev["fold"]), float(ev["period_doubling"])
    at = curves.points.groupby("kind").apply(
        lambda g: g.loc[g.value2.idxmax()], include_groups=False
    )
    v = bif.verdicts
    inside = v[(v.value >= fold) & (v.value <= flip)]
    tags = inside.apply(lambda r: f"P{int(r.period)}" if r.label == "periodic" and
                        pd.notna(r.period) else str(r.label), axis=1)  # fmt: skip
    text = (f"Continued from ω = {OMEGA_START:g} rad/s at ξ = {XI_BRANCH:g} (chaoscam continue), "
            f"the period-1 window ends below at a fold (a saddle-node, multiplier +1) at "
            f"ω = {fold:.4f} rad/s and above at a period doubling (multiplier −1) at "
            f"ω = {flip:.4f} rad/s, where the period-2 orbit takes over")  # fmt: skip
    if "grazing" in ev:
        text += (f"; the unstable period-1 orbit born at the fold ends at a grazing (a flight "
                 f"touching the cam, no period-1 orbit past it) at ω = "
                 f"{float(ev['grazing']):.4f} rad/s")  # fmt: skip
    if len(tags):
        counts = ", ".join(f"{n} {tag}" for tag, n in tags.value_counts().sort_index().items())
        text += (f"; the {len(tags)} brute-force runs (from the model's initial state) inside "
                 f"the window are {counts}: where they are not P1, another attractor "
                 "coexists with the period-1 orbit")  # fmt: skip
    text += ". Continued in ξ, both move to lower ω: " + ", ".join(
        f"the {k.replace('_', ' ')} to ω = {r.value:.2f} rad/s at ξ = {r.value2:.2f}"
        for k, r in at.iterrows())  # fmt: skip
    if len(cross):
        differ = sides_differ(cross)
        text += (f"; of the {len(cross)} places where they cross a row of the map between two "
                 f"cells, the two differ in label or period at {int(differ.sum())}")  # fmt: skip
    return text + "."


def continued_part(res, sweep, quick: bool, outdir: Path, rm) -> None:
    """The continuation's files, figure and sentence into ``res`` (``rm``: the (ω, ξ) map)."""
    branch, curves = follow_window(float(rm.cells["xi"].max()))
    branch.to_parquet(outdir / "continuation-p1.parquet", replace=True)
    curves.to_parquet(outdir / "continuation-curves.parquet", replace=True)
    grid = np.linspace(*OMEGA_RANGE, BRUTE_OMEGAS[quick]).round(6).tolist()
    omegas = sorted({*grid, *COEXISTING})
    bif = sweep("continuation-omega", "omega", omegas, base=Params(xi=XI_BRANCH), png=None)
    cross = crossings(curves.points, rm.cells)
    png = draw(outdir / "continuation.png", _figure, rm, branch, curves, bif)
    res.why.append(_sentence(branch, curves, cross, bif))
    res.why_figures.append(FigureItem(
        "continuation", "The period-1 window by continuation", uri_of(png),
        "Left: the (omega, xi) regime map with the fold and period-doubling curves; right: "
        "a brute-force bifurcation diagram in omega at xi = 0.1 with the continued orbit.",
        "Pseudo-arclength continuation of the period-1 orbit (stable solid, unstable dashed) "
        "and of its fold and period doubling in (ω, ξ) (docs/continuation.md). Data: "
        + ", ".join(CONTINUED_FILES[:6]) + "."))  # fmt: skip
