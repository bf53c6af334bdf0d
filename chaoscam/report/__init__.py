"""Reports: figures (seaborn/matplotlib) and HTML for simulations, regime maps and diagrams.

``chaoscam report INPUT... --out FILE.html`` and ``chaoscam paper [--quick]`` drive this
layer; in Python::

    from chaoscam.report import build_report, load_inputs, write_report
    write_report(build_report(load_inputs(["run.parquet"])), "run.html", title="run")

matplotlib and jinja2 are imported only when a figure is drawn or a page rendered.
"""

from ._classify import ReportClassifier as ReportClassifier
from ._classify import classify as classify
from ._html import Comparison as Comparison
from ._html import FigureItem as FigureItem
from ._html import ReportParts as ReportParts
from ._html import build_report as build_report
from ._html import write_report as write_report
from ._inputs import InputError as InputError
from ._inputs import load_inputs as load_inputs
from ._inputs import load_trajectory as load_trajectory
from ._paper import FIGURES as FIGURES
from ._paper import run_paper as run_paper

__all__ = [
    "FIGURES",
    "Comparison",
    "FigureItem",
    "InputError",
    "ReportClassifier",
    "ReportParts",
    "build_report",
    "classify",
    "load_inputs",
    "load_trajectory",
    "run_paper",
    "write_report",
]
