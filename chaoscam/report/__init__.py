"""Reports: figures (seaborn/matplotlib) and HTML for simulations, regime maps, diagrams
and ensembles.

``chaoscam report INPUT... --out FILE.html`` drives this layer, and ``chaoscam paper``
(:mod:`chaoscam.experiments`) renders through it; it only renders. In Python::

    from chaoscam.report import build_report, load_inputs, write_report
    write_report(build_report(load_inputs(["run.parquet"])), "run.html", title="run")

matplotlib and jinja2 are imported only when a figure is drawn or a page rendered.
"""

from __future__ import annotations

from .._lazy import lazy_face

# Public names and the submodule that defines each: imported on first use (PEP 562),
# so that importing the package stays cheap.
_LAZY = {
    "Comparison": ("._html", "Comparison"),
    "FigureItem": ("._html", "FigureItem"),
    "InputError": ("._inputs", "InputError"),
    "ReportClassifier": ("._classify", "ReportClassifier"),
    "ReportParts": ("._html", "ReportParts"),
    "build_report": ("._html", "build_report"),
    "classify": ("._classify", "classify"),
    "load_inputs": ("._inputs", "load_inputs"),
    "load_trajectory": ("._inputs", "load_trajectory"),
    "write_report": ("._html", "write_report"),
}

__all__ = [
    "Comparison",
    "FigureItem",
    "InputError",
    "ReportClassifier",
    "ReportParts",
    "build_report",
    "classify",
    "load_inputs",
    "load_trajectory",
    "write_report",
]


__getattr__, __dir__ = lazy_face(__name__, _LAZY)
