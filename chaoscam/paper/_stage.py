"""What a stage of ``chaoscam paper`` returns, how it saves its files, and the sweep settings
the stages share (how long undetermined runs are extended, the fate horizons, the step
check)."""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from ._drawing import draw

__all__ = [
    "CHECK_STEP",
    "FATE_S",
    "FULL_EXTEND_TO",
    "QUICK_EXTEND_TO",
    "SWEEP_FATE_S",
    "FigureResult",
    "judging",
    "save",
    "write_file",
]

QUICK_EXTEND_TO, FULL_EXTEND_TO = 40.0, 120.0
"""Recorded time [s] the quick and the full report extend an undetermined run to (the full
one's Fig. 6 included; the quick one's Fig. 6 extends none)."""

FATE_S = {True: 100.0, False: 300.0}
"""The fate horizon [s] of the restitution sweep and the (omega, xi) map, quick and full:
runs labelled chaotic, quasiperiodic or undetermined go on to it, to see whether they stay in
the cam's reach (the full one covers (42.5 rad/s, 0.40), chaotic for 229 s and then out of
reach)."""

SWEEP_FATE_S = {True: None, False: FATE_S[False]}
"""The fate horizon [s] of Fig. 4 and the other sensitivity diagrams (J, y_O, friction arm,
literal damping, both stiffness sweeps), quick and full: the full report only. Of 245 chaotic
verdicts of these sweeps, 4 of Fig. 4's settle on a period 8 by 300 s and one (J = 0.08823)
leaves the cam's reach at 102 s (analyses/fate_audit.py); the horizon costs the full report
about 14 minutes. Figs. 6 and 7-10 keep none (their steps and realizations would cost
hours)."""

CHECK_STEP = {True: False, False: True}
"""Whether the sensitivity sweeps re-run each periodic, quasiperiodic or chaotic verdict at
half the step and call it undetermined when it changes there (``check_step``; quick, full).
One period certificate halves the step already, but a chaotic label has no such check, and
(ω, ξ) maps hold cells whose label is the step's (at ξ = 0.375, Table 1 otherwise: chaotic at
dt = 2e-6 s, period 32 at dt/2, chaotic at dt/4). The quick run does not: it would more than
double the time of its sweeps."""


def judging(quick: bool, *, check_step: bool = False) -> dict[str, Any]:
    """The sweeps' verdict keywords (``extend_to``, ``check_step``): the package's verdict,
    an undetermined run extended to :data:`QUICK_EXTEND_TO` or :data:`FULL_EXTEND_TO`
    seconds recorded (the report says which)."""
    return {"extend_to": QUICK_EXTEND_TO if quick else FULL_EXTEND_TO, "check_step": check_step}


@dataclass
class FigureResult:
    """What one stage (a paper figure, or the sensitivity sweeps) produced."""

    number: int
    title: str = ""
    figures: list[Any] = field(default_factory=list)  # chaoscam.report.FigureItem
    comparisons: list[Any] = field(default_factory=list)  # chaoscam.report.Comparison
    # (data file, result, its figure rendered by save) for the report to embed
    bifurcations: list[tuple[str, Any, bytes]] = field(default_factory=list)
    regime_maps: list[tuple[str, Any, bytes]] = field(default_factory=list)
    # (data file, run, its figure, its verdict)
    trajectories: list[tuple[str, Any, bytes, Any]] = field(default_factory=list)
    notes: list[str] = field(default_factory=list)
    why: list[str] = field(default_factory=list)
    why_figures: list[Any] = field(default_factory=list)
    seconds: float = 0.0

    @property
    def name(self) -> str:
        return self.title or f"Fig. {self.number}"


def save(outdir: Path, name: str, build, *args, **kwargs):
    """The figure ``build(*args, **kwargs)`` rendered once to ``outdir/name.png``
    (:func:`._drawing.draw`: its PNG, which the report embeds as it is, or within
    ``chaoscam paper`` a drawing on the drawing thread that :func:`._drawing.settle`
    collects once every stage has run)."""
    return draw(outdir / f"{name}.png", build, *args, **kwargs)


def write_file(path: Path, write) -> None:
    """``write(tmp)`` to a temporary name, then moved into place (whole or absent)."""
    from ..io import atomic_path

    with atomic_path(path) as tmp:
        write(tmp)
