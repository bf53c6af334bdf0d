"""The step ladder: runs of a figure's sweep classified again at dt / 2, dt / 4, ...

The step audit (:mod:`._step_audit`) asks whether a decided label holds when the step is
halved once. The ladder follows each drawn run (any label, undetermined too) down several
halvings, each rung the same realization (:func:`chaoscam.sweep.replay` with ``refine``)
classified as the sweeps classify (``classify_trajectory``, undetermined verdicts extended),
and compares every rung with the finest: how many labels agree and how far the tangent
exponent moves. Measured with it (docs/findings.md, "The figures' step"): Fig. 6 at 40 RK4 steps per
contact period, 20 of its 42 labels differ from dt/8's; at 160 steps, 9.

``python analyses/step_audit.py --ladder 2,4,8`` runs it on a report's data folder.
"""

from __future__ import annotations

import math
import time
import warnings
from dataclasses import dataclass
from typing import Any

import numpy as np

from ._sensitivity import verdict_tag
from ._step_audit import AUDIT_SEED, _where, draw_rows, run_jobs, sampled_rows

__all__ = ["LadderRow", "ladder_sample", "ladder_sentence", "step_ladder", "step_name"]


@dataclass(frozen=True)
class LadderRow:
    """One run down the ladder: ``figure`` and ``where`` name it, ``recorded`` is its
    verdict in the figure; ``rungs`` holds ``(halvings, verdict, exponent)`` per rung, from
    the sweep's step (0 halvings) down, the verdict as "label" or "period N", the exponent
    λ₁ per iterate of the forcing (NaN without one); ``seconds`` the work it took."""

    figure: str
    where: str
    recorded: str
    rungs: tuple[tuple[int, str, float], ...]
    seconds: float


ladder_sample = draw_rows
"""Up to ``k`` rows of a sweep's table, whatever their label (:func:`._step_audit.draw_rows`)."""


def _exponent(verdict) -> float:
    """The tangent exponent as a sweep's table keeps it (``ev_exponent``; NaN without one)."""
    from ..sweep._tasks import verdict_fields

    return verdict_fields(verdict)["evidence"].get("exponent", math.nan)


def _ladder_one(job: tuple) -> LadderRow:
    """Classify one run at each rung (a pool task: plain arguments)."""
    from ..classify import classify_trajectory
    from ..sweep import replay

    figure, settings, row, halvings, extend_to = job
    t0 = time.perf_counter()
    rungs = []
    with warnings.catch_warnings():  # the model's warnings came with the sweep's own run
        warnings.simplefilter("ignore", RuntimeWarning)
        for h in (0, *halvings):
            v = classify_trajectory(replay(settings, row, refine=h), extend_to=extend_to)
            rungs.append((h, verdict_tag(v.label, v.period), _exponent(v)))
    return LadderRow(
        figure,
        _where(settings.config, row),
        verdict_tag(row["label"], row["period"]),
        tuple(rungs),
        time.perf_counter() - t0,
    )


def step_ladder(
    sweeps: list[tuple[str, Any]],
    halvings: tuple[int, ...],
    per_sweep: int,
    extend_to: float | None,
    workers=None,
    *,
    seed: int = AUDIT_SEED,
) -> list[LadderRow]:
    """``per_sweep`` runs of each ``(figure name, sweep)`` drawn with ``seed``
    (:func:`ladder_sample`), each classified at the sweep's step and at ``dt / 2**h`` for
    each ``h`` in ``halvings`` (increasing, >= 1), an undetermined verdict extended up to
    ``extend_to`` seconds recorded, on ``workers`` local processes."""
    jobs = [
        (*job, tuple(halvings), extend_to)
        for job in sampled_rows(sweeps, ladder_sample, per_sweep, seed)
    ]
    return run_jobs(_ladder_one, jobs, workers)


def step_name(h: int) -> str:
    """The step after ``h`` halvings: "dt", "dt/2", "dt/4", ..."""
    return "dt" if h == 0 else f"dt/{2**h}"


def ladder_sentence(rows: list[LadderRow]) -> str:
    """Each rung against the finest, over ``rows``: labels that agree, and the median and
    largest change of the exponent (runs with an exponent at both rungs)."""
    if not rows:
        return ""
    steps = [h for h, _, _ in rows[0].rungs]
    finest = steps[-1]
    parts = []
    for i, h in enumerate(steps[:-1]):
        same = sum(r.rungs[i][1] == r.rungs[-1][1] for r in rows)
        moved = [abs(r.rungs[i][2] - r.rungs[-1][2]) for r in rows]
        moved = [m for m in moved if not math.isnan(m)]
        size = (
            f", the exponent by a median of {np.median(moved):.3f} per iterate (largest "
            f"{max(moved):.3f})"
            if moved
            else ""
        )
        parts.append(f"at {step_name(h)} {same} of {len(rows)} labels agree{size}")
    figures = ", ".join(dict.fromkeys(r.figure for r in rows))
    work = sum(r.seconds for r in rows)
    return (
        f"Step ladder: {len(rows)} runs of {figures} classified at "
        f"{', '.join(map(step_name, steps))} ({work:.0f} s of work). Against {step_name(finest)}: "
        + "; ".join(parts)
        + "."
    )
