"""The step ladder: runs of a figure's sweep classified again at dt / 2, dt / 4, ...

The step audit (:mod:`._step_audit`) asks whether a decided label holds when the step is
halved once. The ladder follows each drawn run (any label, undetermined too) down several
halvings, each rung the same realization (:func:`chaoscam.sweep.replay` with ``refine``)
classified as the sweeps classify (:func:`chaoscam.classify`, undetermined verdicts
extended; a run that leaves the cam's reach or diverges labelled by its status, as the
sweeps label it), and compares every rung with the finest: how many labels agree and how far
the tangent exponent moves (docs/findings.md, "The figures' step": Fig. 6 at 40 RK4 steps
per contact period, 20 of its 42 labels differ from dt/8's; at 160 steps, 9).

``python analyses/step_audit.py --ladder 2,4,8`` runs it on a report's data folder.
"""

from __future__ import annotations

import math
import time
import warnings
from collections import Counter
from dataclasses import dataclass
from typing import Any

import numpy as np

from ._findings import verdict_tag
from ._side_by_side import side_by_side
from ._step_audit import AUDIT_SEED, _where, draw_rows, sampled_rows

__all__ = [
    "LadderRow",
    "ladder_sample",
    "ladder_sentence",
    "settled",
    "step_ladder",
    "step_name",
]


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


def _ladder_one(job: tuple) -> LadderRow:
    """Classify one run at each rung, into the fields a sweep's table keeps: the tag (the
    status's label for a run that did not end normally) and the tangent exponent
    (``ev_exponent``; NaN without one)."""
    from ..sweep import replay, verdict_fields
    from ..verdict import classify

    figure, sweep, row, halvings, extend_to = job
    t0 = time.perf_counter()
    rungs = []
    with warnings.catch_warnings():  # the model's warnings came with the sweep's own run
        warnings.simplefilter("ignore", RuntimeWarning)
        for h in (0, *halvings):
            run = replay(sweep, row, refine=h)
            if not run.ok:
                rungs.append((h, run.status.label, math.nan))
                continue
            fields = verdict_fields(classify(run, extend_to=extend_to)[0])
            tag = verdict_tag(fields["label"], fields["period"])
            rungs.append((h, tag, fields["evidence"].get("exponent", math.nan)))
    return LadderRow(
        figure,
        _where(sweep.config, row),
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
    label: str | None = None,
) -> list[LadderRow]:
    """``per_sweep`` runs of each ``(figure name, sweep)`` drawn with ``seed``
    (:func:`ladder_sample`; only those the sweep labelled ``label`` when given, e.g.
    "undetermined"), each classified at the sweep's step and at ``dt / 2**h`` for each ``h``
    in ``halvings`` (increasing, >= 1), an undetermined verdict extended up to ``extend_to``
    seconds recorded, on ``workers`` local threads."""

    def sample(table, k, seed):
        return ladder_sample(table if label is None else table[table["label"] == label], k, seed)

    jobs = [
        (*job, tuple(halvings), extend_to) for job in sampled_rows(sweeps, sample, per_sweep, seed)
    ]
    return side_by_side(_ladder_one, jobs, workers, prefix="chaoscam-ladder")


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
        + _settled_sentence(rows, steps)
    )


def settled(row: LadderRow) -> str | None:
    """The label ``row`` keeps at every halved step (every rung but the sweep's own), when
    that label is a decision (not "undetermined"); None when the halved rungs disagree or
    the ladder has none. A run settled so has an answer that the step no longer moves; one
    that is not sits where the step decides (a window's edge, an escape time)."""
    tags = {tag for h, tag, _ in row.rungs if h > 0}
    if len(tags) != 1:
        return None
    (tag,) = tags
    return None if tag == "undetermined" else tag


def _settled_sentence(rows: list[LadderRow], steps: list[int]) -> str:
    """ " Settled at dt/2 ... dt/8: k of n (chaotic 6, period 12 2)." ("" with no halving)."""
    if len(steps) < 2:
        return ""
    found = Counter(t for t in map(settled, rows) if t is not None)  # in order of appearance
    counts = ", ".join(f"{t} {n}" for t, n in found.items())
    halved = ", ".join(map(step_name, steps[1:]))
    return (
        f" Settled (one decided label at {halved}): {found.total()} of {len(rows)}"
        + (f" ({counts})" if found else "")
        + "."
    )
