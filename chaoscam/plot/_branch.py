"""Continuation drawn on a matplotlib Axes: a branch (the parameter against the section's θ_f)
and bifurcation curves in two parameters."""

from __future__ import annotations

import numpy as np

from ._run import axes
from ._sweep import axis_label

__all__ = ["plot_branch", "plot_curves"]

EVENT_MARKS = {"fold": ("o", "#D55E00"), "period_doubling": ("s", "#0072B2"),
               "neimark_sacker": ("D", "#009E73"), "impact_change": ("^", "#CC79A7"),
               "sticking": ("v", "#E69F00"), "grazing": ("x", "#000000")}  # fmt: skip


def plot_branch(points, events=None, ax=None):
    """The branch diagram of ``Branch.points`` (one row per section point of each orbit):
    ``value`` against ``theta_f``, each section point j of each branch a line, solid where
    the orbit is stable and dashed where not; the ``events`` (``Branch.events``, ``end``
    and ``section`` left out) marked with their kind in the legend. Returns the Axes."""
    ax = axes(ax)
    for (b, _), g in points.groupby(["branch", "j"], sort=True):
        g = g.sort_values("point")
        x, y = g["value"].to_numpy(), g["theta_f"].to_numpy()
        stable = g["stable"].to_numpy(dtype=bool)
        color = "#000000" if b == 0 else f"C{int(b) % 10}"
        for mask, ls in ((stable, "-"), (~stable, "--")):
            keep = mask | np.r_[mask[1:], False] | np.r_[False, mask[:-1]]  # join the pieces
            ax.plot(x, np.where(keep, y, np.nan), ls=ls, lw=1.0, color=color)
    if events is not None and len(events):
        for kind, g in events[~events["kind"].isin(["end", "section"])].groupby("kind"):
            marker, color = EVENT_MARKS.get(kind, ("*", "#000000"))
            ax.scatter(g["value"], g["theta_f"], marker=marker, color=color, zorder=3,
                       label=kind.replace("_", " "))  # fmt: skip
        ax.legend(frameon=False, fontsize="small")
    name = str(points["param"].iloc[0]) if len(points) else "value"
    ax.set(xlabel=axis_label(name), ylabel=axis_label("theta_f"),
           title="continuation: stable solid, unstable dashed")  # fmt: skip
    return ax


CURVE_STYLES = {"fold": ("-", "#D55E00"), "period_doubling": ("--", "#0072B2"),
                "grazing": (":", "#000000")}  # fmt: skip


def _cell_coordinate(v, values, flip: bool):
    """Heatmap coordinates of data values v over a grid's ``values`` (cell i centred at
    i + 0.5, rows from the largest down when ``flip``): piecewise linear, NaN outside."""
    values = np.sort(np.unique(values))
    i = np.interp(v, values, np.arange(len(values)), left=np.nan, right=np.nan)
    return (len(values) - 1 - i if flip else i) + 0.5


def plot_curves(points, ax=None, *, swap: bool = False, grid=None):
    """Bifurcation curves (``Curve.points``) on ``ax``: ``value`` (λ1) on x and ``value2``
    (λ2) on y (``swap``: the other way round), one line per ``curve``, styled by ``kind``
    (fold solid vermilion, period doubling dashed blue). ``grid`` = (x values, y values)
    of a heatmap drawn on ``ax`` (:func:`plot_dominant`): the curves in its cell
    coordinates, cut at its outer cells' centres. Returns the Axes."""
    from matplotlib.patheffects import withStroke

    ax, seen, stroke = axes(ax), set(), withStroke(linewidth=4.5, foreground="white")
    for (_, kind), g in points.groupby(["curve", "kind"], sort=True):
        g = g.sort_values("point")
        ls, color = CURVE_STYLES.get(kind, ("-.", "#000000"))
        xy = (g["value2"], g["value"]) if swap else (g["value"], g["value2"])
        if grid is not None:
            xy = (_cell_coordinate(xy[0], grid[0], False), _cell_coordinate(xy[1], grid[1], True))
        ax.plot(*xy, ls=ls, lw=2.5, color=color, path_effects=[stroke],
                label=None if kind in seen else kind.replace("_", " "))  # fmt: skip
        seen.add(kind)
    if len(points) and grid is None:
        names = [axis_label(str(points[c].iloc[0])) for c in ("param", "param2")]
        ax.set(xlabel=names[swap], ylabel=names[not swap])
    if len(points):
        old, lines = ax.get_legend(), ax.get_legend_handles_labels()
        if old is not None:  # a heatmap's legend of labels: the curves join it
            handles = [*old.legend_handles, *lines[0]]
            labels = [*(t.get_text() for t in old.get_texts()), *lines[1]]
            ax.legend(handles, labels, loc="upper left", bbox_to_anchor=(1.01, 1.0),
                      frameon=False, fontsize="small")  # fmt: skip
        else:
            ax.legend(frameon=False, fontsize="small")
    return ax
