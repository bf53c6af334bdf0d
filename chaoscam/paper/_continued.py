"""Continuation in the paper report (:mod:`chaoscam.continuation`; docs/continuation.md): the
period-1 window at ξ = 0.1, its branch over a brute-force diagram in ω, its fold and period
doubling continued over the (ω, ξ) map, and the sentence that names the bifurcations ending
the window; and Table 1's periodic orbits continued over Fig. 4's l_λ diagram."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd

from ..continuation import Branch, Curve, NoOrbitError, continuation, curve, find_start
from ..model import Params
from ..numerics import Numerics
from ..report import FigureItem
from ..verdict import kick_test
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


LAMBDA_PERIODS = (1, 2, 4, 8)
"""Periods of the orbits looked for at Table 1 (Newton from a 20-s run's last section point)
and continued over Fig. 4's l_λ range; one with no impact (the follower off the cam) is
left out."""

LAMBDA_FILES = [f"fig4-continued{e}" for e in (".parquet", ".events.parquet", ".png")]
"""The files :func:`lambda_part` writes into the data folder."""


def follow_lambda(num: Numerics, lo: float, hi: float) -> Branch:
    """Each orbit of :data:`LAMBDA_PERIODS` found at Table 1 followed in l_λ from Table 1's
    value both ways over [lo, hi] (one Branch, an orbit a ``branch``, the lower half's points
    numbered negative)."""
    p, points, events, found = Params(), [], [], []
    for n in LAMBDA_PERIODS:
        try:
            x0 = find_start(p, None, n, num).points[0]
        except NoOrbitError:
            continue
        halves = [continuation(p, x0, param="l_lambda", to=to, period=n, numerics=num,
                               ds_max=0.05) for to in (lo, hi)]  # fmt: skip
        if (halves[0].points.n_macro_impacts == 0).all():
            continue
        b, (down, up) = len(found), halves
        points += [down.points.assign(branch=b, point=-down.points.point),
                   up.points.assign(branch=b)]  # fmt: skip
        events += [h.events.assign(branch=b) for h in halves]
        found.append(n)
    if not found:
        return Branch(pd.DataFrame(), pd.DataFrame(), {"periods": []})
    points = pd.concat(points, ignore_index=True)
    kicks = {b: _kicks(g, num) for b, g in points.groupby("branch") if g.sticks.any()}
    return Branch(points, pd.concat(events, ignore_index=True),
                  {"periods": found, "kicks": kicks})  # fmt: skip


def _kicks(g: pd.DataFrame, num: Numerics) -> list[tuple[float, bool]]:
    """(l_λ, whether kicks return) at a sticking branch's ends and nearest Table 1: where
    chattering ends in sticking the tangent's multipliers do not decide stability, and
    kicks do (docs/verdicts.md)."""
    first = g[g.j == 0]
    rows = {first.value.idxmin(), first.value.idxmax(),
            (first.value - Params().l_lambda).abs().idxmin()}  # fmt: skip
    out = []
    for i in sorted(rows, key=lambda i: first.value[i]):
        r = first.loc[i]
        test = kick_test(Params(l_lambda=float(r.value)), (r.theta_f, r.omega_f), int(r.period),
                         numerics=num)  # fmt: skip
        out.append((float(r.value), bool(test.returns)))
    return out


def _lambda_sentence(branch: Branch) -> str:
    """What the orbits continued over l_λ show."""
    if not len(branch.points):
        return ("Continued over Fig. 4's l_λ range: Newton finds no periodic orbit with an "
                "impact at Table 1 from the start run (periods "
                f"{', '.join(map(str, LAMBDA_PERIODS))}), so none is drawn.")  # fmt: skip
    parts = []
    for _, g in branch.points.groupby("branch"):
        n, lo, hi = int(g.period.iloc[0]), g.value.min(), g.value.max()
        mu, spread = g.abs_mu, float(g.groupby("j").theta_f.agg(np.ptp).max())
        how = "sticking" if g.sticks.any() else "no contact phase"
        stable = g[g.stable].value
        text = (f"the period-{n} orbit ({int(g.n_macro_impacts.max())} impacts over its {n} "
                f"cam period{'s' if n > 1 else ''}, {how}) has "
                + (f"|μ1| = {mu.min():.4g}" if mu.max() - mu.min() < 1e-6 * mu.max()
                   else f"|μ1| from {mu.min():.3g} to {mu.max():.3g}")
                + f" over l_λ ∈ [{lo:.4g}, {hi:.4g}] m: "
                + (f"stable for l_λ in [{stable.min():.4g}, {stable.max():.4g}] m" if len(stable)
                   else "unstable throughout"))  # fmt: skip
        kicks = branch.settings.get("kicks", {}).get(g.branch.iloc[0])
        if kicks:
            back = [f"{v:.4g} m" for v, r in kicks if r]
            text += (" by its tangent multipliers, which do not decide stability where it sticks; "
                     f"kicks of 1e-7 to 1e-6 rad return at {len(back)} of {len(kicks)} of its "
                     f"points checked (l_λ = {', '.join(f'{v:.4g}' for v, _ in kicks)} m)"
                     + (f": it attracts at {', '.join(back)}" if back else ""))  # fmt: skip
        if spread < 1e-9 and not g.sticks.any() and (g.contact_fraction == 0).all():
            text += (", and its θ_f does not move (by less than 1e-9 rad): with no contact "
                     "phase, where alone the line length acts, it is the same orbit at every "
                     "l_λ")  # fmt: skip
        parts.append(text)
    text = ("Continued over Fig. 4's l_λ range from Table 1 (chaoscam continue --param "
            "l_lambda), " + "; ".join(parts))  # fmt: skip
    if not branch.points.stable.any() and not any(
        r for ks in branch.settings.get("kicks", {}).values() for _, r in ks
    ):
        one = branch.points.branch.nunique() == 1
        who = ("It is not", "it") if one else ("None of them is", "them")
        text += (f". {who[0]} stable anywhere on the range, so no periodic window over l_λ "
                 f"comes from {who[1]}")  # fmt: skip
        if 2 in branch.settings["periods"]:
            text += ": the paper's period-2 window is not this period-2 orbit"
    return text + "."


def _lambda_figure(bif, branch):
    """Fig. 4's brute-force diagram with the continued orbits."""
    from matplotlib.figure import Figure

    from ..plot import plot_bifurcation, plot_branch

    fig = Figure(figsize=(9, 5.5), layout="constrained")
    ax = fig.subplots()
    plot_bifurcation(bif.points, ax)
    if len(branch.points):
        plot_branch(branch.points, branch.events, ax=ax)
    ax.set_title("Fig. 4: brute force (dots) and the continued periodic orbits (dashed: unstable)")
    return fig


def lambda_part(res, outdir: Path, bif, num: Numerics, lo: float, hi: float) -> None:
    """Table 1's orbits continued over Fig. 4's l_λ range into ``res``: the files, the figure
    over the brute-force diagram ``bif`` and the sentence."""
    branch = follow_lambda(num, lo, hi)
    if len(branch.points):
        branch.to_parquet(outdir / LAMBDA_FILES[0], replace=True)
    png = draw(outdir / LAMBDA_FILES[2], _lambda_figure, bif, branch)
    res.why.append(_lambda_sentence(branch))
    res.why_figures.append(FigureItem(
        "fig4-continued", "Fig. 4's periodic orbits by continuation", uri_of(png),
        "Fig. 4's bifurcation diagram over l_λ with Table 1's periodic orbits continued over it.",
        "Pseudo-arclength continuation in l_λ (stable solid, unstable dashed) of the periodic "
        "orbits Newton finds at Table 1 (docs/continuation.md). Data: "
        + ", ".join(LAMBDA_FILES[:2]) + "."))  # fmt: skip
