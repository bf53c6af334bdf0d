"""The RK4 step of the paper's bifurcation figures: steps per contact period, measured.

The model's default ``dt`` (2e-6 s) resolves the Hertz contact oscillation with 46 RK4 steps
at l_λ = 8 mm and 30 at 18 mm. Followed down a ladder of steps (``analyses/step_audit.py
--ladder``, docs/findings.md, "The figures' step"), that is enough for most labels but not
for all, and not for the exponent:

* Fig. 4 (18 values of l_λ, one initial condition): at dt the three period-8 windows at
  8.75, 13.5 and 15.25 mm read chaotic; at dt/4 and dt/8 all three are certified period 8,
  and 16 of 18 labels at dt/4 equal dt/8's. The exponent at dt is about twice dt/8's
  (0.61 against 0.30 per iterate at 8 mm).
* Fig. 6 (fractal stiffness, 42 runs): at 40 steps per contact period at D = 1.56, 20 of 42
  labels differ from dt/8's and the exponent is overstated up to 5x; at 160 steps, 9 of 42.
* Figs. 7-10: every label holds at dt/2 (100 of 100) and at dt/4 (39 of 39), though the
  exponent at dt is about 2.5x dt/4's; they keep the default step.

So the full report runs Figs. 4 and 6 at :data:`FULL_STEPS` steps per contact period at the
figure's stiffest point; the quick report keeps the default step for Fig. 4 and 40 steps for
Fig. 6, and says its labels are not converged there.
"""

from __future__ import annotations

from ..model import Params, contact_period
from ..numerics import Numerics

__all__ = [
    "FIG4_STEPS",
    "FIG6_STEPS",
    "FIGS7_10_STEP_NOTE",
    "FULL_STEPS",
    "fig4_step_note",
    "fig6_step_note",
    "figure_dt",
    "steps_per_period",
]

FULL_STEPS = 160
"""RK4 steps per contact period at the stiffest point of a bifurcation figure, full report."""

FIG4_STEPS = {True: None, False: FULL_STEPS}
"""Fig. 4's steps per contact period at its largest l_λ, 0.018 m, quick and full (None: the
model's default dt, 30 steps there): dt = 3.8e-7 s in the full report."""

FIG6_STEPS = {True: 40, False: FULL_STEPS}
"""Fig. 6's steps per contact period at its largest D, 1.56, quick and full: dt = 9.6e-8 and
5e-8 s (G = 1e-9, 1e-10 m) in the full report."""

FIGS7_10_STEP_NOTE = (
    "; the model's default dt, whose labels hold when it is refined (measured: 100 of 100 runs "
    "at dt/2, 39 of 39 at dt/4: docs/findings.md), though its exponent is about 2.5x dt/4's"
)
"""Figs. 7-10's comparison, on their step (the default)."""


def figure_dt(stiffest: Params, steps: int | None) -> float:
    """The step giving ``steps`` RK4 steps per contact period of ``stiffest`` (the figure's
    stiffest point, :func:`chaoscam.contact_period`), rounded to two significant digits;
    the default ``Numerics().dt`` when ``steps`` is None.

    Examples: Fig. 4 at l_λ = 0.018 m and 160 steps, 3.8e-7 s; Fig. 6 at D = 1.56,
    G = 1e-9 m and 160 steps, 9.6e-8 s.
    """
    if steps is None:
        return Numerics().dt
    return float(f"{contact_period(stiffest) / steps:.1e}")


def steps_per_period(p: Params, dt: float) -> float:
    """How many steps of ``dt`` [s] one contact period of ``p`` spans."""
    return contact_period(p) / dt


def fig4_step_note(stiffest: Params, dt: float) -> str:
    """Fig. 4's comparison, on its step ``dt`` [s] (``stiffest``: its largest l_λ)."""
    steps = steps_per_period(stiffest, dt)
    at = f"at l_λ = {stiffest.l_lambda:g} m"
    here = f"; dt = {dt:g} s ({steps:.0f} RK4 steps per contact period {at}"
    measured = (
        "measured at the default 2e-6 s (30 steps), the period-8 windows at 8.75, 13.5 and "
        "15.25 mm read chaotic and the exponent is about twice dt/8's (docs/findings.md)"
    )
    if steps < FULL_STEPS * 0.9:
        coarse = "a step at which labels are not converged"
        return f"{here}, {coarse}: {measured}; the full report takes {FULL_STEPS})"
    return f"{here}; {measured})"


def fig6_step_note(stiffest: Params, quick: bool) -> str:
    """Fig. 6's comparison, on its step, quick or full (``stiffest``: its largest D)."""
    here = f"; {FIG6_STEPS[quick]} RK4 steps per contact period at D = {stiffest.D:g}"
    measured = (
        "measured: at 40 the exponent is overstated up to 5x and 20 of 42 labels differ from "
        "dt/8's, at 160 9 of 42 (docs/findings.md)"
    )
    if quick:
        coarse = "a step at which labels are not converged"
        return f"{here}, {coarse} ({measured}; the full report takes {FIG6_STEPS[False]})"
    return f"{here} ({measured})"
