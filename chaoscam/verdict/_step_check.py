"""The step check of a verdict (``classify(..., check_step=True)``).

MODEL.md: a result must not change when the step is halved. The realization is solved again
with dt / 2 (:meth:`Numerics.refined`; the adaptive integrator's tolerances / 32) and judged
the same way (:func:`~._classify.classify` does that); here, what the comparison makes of the
two verdicts: the grid verdict with evidence ``step_check`` (1: unchanged), or "undetermined"
with the reason (0: changed). An undetermined verdict is not re-run, since no half-step
verdict can change it (``step_check`` without a value).
"""

from __future__ import annotations

import dataclasses

from ..analysis import Evidence, Verdict
from ..numerics import Numerics

__all__ = ["compared", "skipped"]


def skipped(verdict: Verdict, fine: Numerics) -> Verdict:
    """An undetermined ``verdict`` with evidence ``step_check`` (no value) saying why the
    realization was not re-run at ``fine``'s step."""
    check = Evidence(
        "step_check",
        None,
        None,
        f"not re-run at {fine.describe_step()}: the verdict is undetermined already, "
        "which a half step cannot change",
    )
    return dataclasses.replace(
        verdict,
        evidence=verdict.evidence + (check,),
        settings={
            **verdict.settings,
            "step_check": {
                "dt_half": fine.dt,
                "skipped": True,
                "grid_label": verdict.label,
                "grid_period": verdict.period,
            },
        },
    )


def _describe(v: Verdict) -> str:
    return f"{v.label}" + (f" (period {v.period})" if v.period is not None else "")


def compared(
    verdict: Verdict,
    half: Verdict,
    coarse: Numerics,
    fine: Numerics,
    *,
    half_recorded_s: float | None = None,
) -> Verdict:
    """The grid ``verdict`` (at ``coarse``'s step) checked against ``half``, the same
    realization's at ``fine``'s (made on ``half_recorded_s`` seconds of recording):
    unchanged (label and period), it is kept with evidence ``step_check`` = 1; else
    "undetermined" with the reason, ``step_check`` = 0. ``settings["step_check"]`` records
    both verdicts."""
    same = half.label == verdict.label and half.period == verdict.period
    what = (
        f"{coarse.describe_step()}: {_describe(verdict)}; {fine.describe_step()}: {_describe(half)}"
    )
    check = Evidence(
        "step_check",
        int(same),
        None,
        f"{'unchanged' if same else 'changed'} when the step is halved ({what})",
    )
    settings = {
        **verdict.settings,
        "step_check": {
            "dt_half": fine.dt,
            "refined": fine.describe_step(),
            "label": half.label,
            "period": half.period,
            "reasons": list(half.reasons),
            "recorded_s": half_recorded_s,
            "grid_label": verdict.label,
            "grid_period": verdict.period,
        },
    }
    if same:
        return dataclasses.replace(verdict, evidence=verdict.evidence + (check,), settings=settings)
    return Verdict(
        "undetermined",
        None,
        verdict.evidence + (check,),
        verdict.reasons + (f"halving the step changes the verdict ({what})",),
        settings,
    )
