"""Reports: figures (seaborn/matplotlib) and HTML of runs, regime maps, bifurcation diagrams
and ensembles; ``chaoscam report`` and :mod:`chaoscam.paper` render through it. In Python::

    from chaoscam.report import build_report, write_report
    parts = build_report(["run.parquet", regime_map])  # files, results in memory, or both
    write_report(parts, "run.html", title="run")

matplotlib and jinja2 are imported only when a figure is drawn or a page rendered.
"""

from __future__ import annotations

from .._util import lazy_face

_LAZY = {
    "LABEL_COLORS": ("._figures", "LABEL_COLORS"),
    "SETTLED_MARK": ("._figures", "SETTLED_MARK"),
    "TRANSIENT_MARK": ("._figures", "TRANSIENT_MARK"),
    "Comparison": ("._html", "Comparison"),
    "FigureItem": ("._html", "FigureItem"),
    "InputError": ("._inputs", "InputError"),
    "Inputs": ("._inputs", "Inputs"),
    "ReportParts": ("._html", "ReportParts"),
    "add_bifurcation": ("._html", "add_bifurcation"),
    "add_ensemble": ("._html", "add_ensemble"),
    "add_regime_map": ("._html", "add_regime_map"),
    "add_trajectory": ("._html", "add_trajectory"),
    "band_counts": ("._headline", "band_counts"),
    "band_number": ("._headline", "band_number"),
    "fold": ("._headline", "fold"),
    "frame_tags": ("._headline", "frame_tags"),
    "headline": ("._headline", "headline"),
    "in_words": ("._headline", "in_words"),
    "lead_figure": ("._html", "lead_figure"),
    "mostly": ("._headline", "mostly"),
    "as_inputs": ("._inputs", "as_inputs"),
    "bifurcation_figure": ("._figures", "bifurcation_figure"),
    "build_report": ("._html", "build_report"),
    "ensemble_figure": ("._ensemble", "ensemble_figure"),
    "load_inputs": ("._inputs", "load_inputs"),
    "mark_without_points": ("._figures", "mark_without_points"),
    "png_bytes": ("._figures", "png_bytes"),
    "png_uri": ("._figures", "png_uri"),
    "regime_map_figure": ("._figures", "regime_map_figure"),
    "response_figure": ("._figures", "response_figure"),
    "sweep_diagram": ("._figures", "sweep_diagram"),
    "verdict_tag": ("._headline", "verdict_tag"),
    "write_report": ("._html", "write_report"),
}

__all__ = sorted(_LAZY)

__getattr__, __dir__ = lazy_face(__name__, _LAZY)
