"""The step check of a verdict (``classify(..., check_step=True)``; shared/MODEL.md: a result
must not change when the step is halved): what the verdict at :meth:`Numerics.refined` (dt / 2;
the adaptive tolerances / 32) makes of the grid's. An undetermined verdict is not re-run: no
half-step verdict can change it."""

from __future__ import annotations

import dataclasses

from ..analysis import Evidence, Verdict
from ..numerics import Numerics

__all__ = ["compared", "skipped"]


def skipped(verdict: Verdict, fine: Numerics) -> Verdict:
    """An undetermined ``verdict`` with evidence ``step_check`` (no value) saying why the
    realization was not re-run at ``fine``'s step."""
    why = (f"not re-run at {fine.describe_step()}: the verdict is undetermined already, "
           "which a half step cannot change")  # fmt: skip
    evidence = (*verdict.evidence, Evidence("step_check", None, None, why))
    record = dict(
        dt_half=fine.dt, skipped=True, grid_label=verdict.label, grid_period=verdict.period
    )
    settings = {**verdict.settings, "step_check": record}
    return dataclasses.replace(verdict, evidence=evidence, settings=settings)


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
    realization's at ``fine``'s (on ``half_recorded_s`` seconds recorded): kept with evidence
    ``step_check`` = 1 when label and period agree, else "undetermined" with the reason and
    ``step_check`` = 0; ``settings["step_check"]`` records both verdicts."""
    same = half.label == verdict.label and half.period == verdict.period
    what = (
        f"{coarse.describe_step()}: {_describe(verdict)}; {fine.describe_step()}: {_describe(half)}"
    )
    changed = f"{'unchanged' if same else 'changed'} when the step is halved ({what})"
    evidence = (*verdict.evidence, Evidence("step_check", int(same), None, changed))
    record = {"dt_half": fine.dt, "refined": fine.describe_step(), "label": half.label,
              "period": half.period, "reasons": list(half.reasons), "recorded_s": half_recorded_s,
              "grid_label": verdict.label, "grid_period": verdict.period}  # fmt: skip
    settings = {**verdict.settings, "step_check": record}
    if same:
        return dataclasses.replace(verdict, evidence=evidence, settings=settings)
    why = f"halving the step changes the verdict ({what})"
    return Verdict("undetermined", None, evidence, (*verdict.reasons, why), settings)
