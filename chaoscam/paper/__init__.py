"""The paper: its figures reproduced (:mod:`._paper`), the sweeps that explain the
differences (:mod:`._sensitivity`), the step audit (:mod:`._step_audit`), and
:func:`run_paper`, which renders them through :mod:`chaoscam.report`::

    from chaoscam.paper import run_paper
    run_paper(quick=True, out="out/paper.html")
"""

from __future__ import annotations

from .._util import lazy_face

_LAZY = {
    "FIGURES": ("._paper", "FIGURES"),
    "RESUME_HINT": ("._run", "RESUME_HINT"),
    "SENSITIVITY": ("._paper", "SENSITIVITY"),
    "FigureResult": ("._stage", "FigureResult"),
    "PaperRun": ("._run", "PaperRun"),
    "audit_script": ("._step_audit", "audit_script"),
    "check_paper_outputs": ("._run", "check_paper_outputs"),
    "data_files": ("._paper", "data_files"),
    "figure_script": ("._run", "figure_script"),
    "run_paper": ("._run", "run_paper"),
    "sensitivity": ("._sensitivity", "sensitivity"),
}

__all__ = sorted(_LAZY)

__getattr__, __dir__ = lazy_face(__name__, _LAZY)
