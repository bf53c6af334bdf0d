"""Sweep figures: the sweep layer's (``_sweep_figures``) when present, else plain ones."""

from __future__ import annotations

import importlib

__all__ = ["bifurcation_figure", "regime_map_figure"]


def _module():
    try:
        return importlib.import_module("chaoscam.report._sweep_figures")
    except ModuleNotFoundError as err:
        if err.name != "chaoscam.report._sweep_figures":
            raise
        return None


def bifurcation_figure(points):
    """θ_f of the section points over the swept value."""
    mod = _module()
    if mod is not None:
        return mod.bifurcation_figure(points)
    from matplotlib.figure import Figure

    fig = Figure(figsize=(9, 5), layout="constrained")
    ax = fig.subplots()
    ax.scatter(points["value"], points["theta_f"], s=1, color="k", rasterized=True)
    param = str(points["param"].iloc[0]) if len(points) else "value"
    ax.set(xlabel=f"{param} [SI unit of {param}]", ylabel="θ_f [rad]")
    return fig


def regime_map_figure(cells, *, x: str, y: str):
    """Dominant label and P(chaotic) per cell."""
    mod = _module()
    if mod is not None:
        return mod.regime_map_figure(cells, x=x, y=y)
    from matplotlib.figure import Figure

    fig = Figure(figsize=(7, 5), layout="constrained")
    ax = fig.subplots()
    sc = ax.scatter(cells[x], cells[y], c=cells["p_chaotic"], vmin=0, vmax=1, s=80)
    fig.colorbar(sc, ax=ax, label="P(chaotic)")
    ax.set(xlabel=f"{x} [m]", ylabel=f"{y} [m]")
    return fig
