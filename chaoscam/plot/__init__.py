"""Drawings of results on matplotlib Axes: a run's series and section, bifurcation diagrams,
regime-map heatmaps (seaborn) and label shares; the ``.plot`` methods of the results and
:mod:`chaoscam.report` draw through them. matplotlib and seaborn load on the first drawing."""

from .._util import lazy_face

_LAZY = {
    "axes": ("._run", "axes"), "plot_section": ("._run", "plot_section"),
    "plot_series": ("._run", "plot_series"), "plot_shares": ("._run", "plot_shares"),
    "plot_branch": ("._branch", "plot_branch"), "plot_curves": ("._branch", "plot_curves"),
    "LABEL_COLORS": ("._sweep", "LABEL_COLORS"), "SETTLED_MARK": ("._sweep", "SETTLED_MARK"),
    "TRANSIENT_MARK": ("._sweep", "TRANSIENT_MARK"),
    "all_deterministic": ("._sweep", "all_deterministic"), "axis_label": ("._sweep", "axis_label"),
    "BAND_ZOOM": ("._sweep", "BAND_ZOOM"), "band_zoom": ("._sweep", "band_zoom"),
    "bifurcation_figure": ("._sweep", "bifurcation_figure"),
    "mark_without_points": ("._sweep", "mark_without_points"), "percent": ("._sweep", "percent"),
    "plot_bifurcation": ("._sweep", "plot_bifurcation"),
    "plot_diagram": ("._sweep", "plot_diagram"), "plot_dominant": ("._sweep", "plot_dominant"),
    "plot_interval_width": ("._sweep", "plot_interval_width"),
    "plot_probability": ("._sweep", "plot_probability"),
    "regime_map_figure": ("._sweep", "regime_map_figure"),
    "sweep_diagram": ("._sweep", "sweep_diagram"),
}  # fmt: skip

__all__ = sorted(_LAZY)

__getattr__, __dir__ = lazy_face(__name__, _LAZY)
