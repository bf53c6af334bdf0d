"""The warnings a run gets before it starts: :func:`chaoscam.solve` raises them as
``RuntimeWarning``, the sweeps keep them in each realization's ``warnings`` column."""

from __future__ import annotations

from ..model import Params, contact_period
from ..numerics import Numerics


def resolution_warning(p: Params, num: Numerics) -> str | None:
    """The warning for a fixed step too coarse for the contact oscillation (fewer than 20
    steps per contact period), or None. The adaptive path's steps follow the contact."""
    period = contact_period(p)
    steps = period / num.dt
    if steps >= 20 or num.integrator != "rk4":
        return None
    few = f"only {steps:.1f} steps" if steps >= 1 else f"a step {1 / steps:.3g}x the period"
    finest = Numerics.field_docs()["dt"]["range"][0]
    if period / 40 < finest:
        return (
            f"dt = {num.dt:g} s resolves the contact oscillation (period {period:.3g} s) with "
            f"{few}, and no allowed dt (>= {finest:g} s) resolves it in 40 steps: soften the "
            "contact (Y_f, Y_c, l_lambda) or make the follower heavier (m, J)"
        )
    return (
        f"dt = {num.dt:g} s resolves the contact oscillation (period {period:.3g} s) with "
        f"{few}; use dt <= {period / 40:.2g} s (40 steps), and check the verdict "
        "at half the step (classify(..., check_step=True)): where chattering "
        "dominates, 40 steps can still overstate the exponent"
    )


def ignored_sigma_warning(p: Params) -> str | None:
    """The warning for a line-length spread that cannot act, or None: the fractal joint's K_n
    (MODEL.md (15)/(17)) does not depend on the line length, so its ``l_lambda_sigma`` is idle."""
    if p.stiffness != "fractal" or p.l_lambda_sigma == 0.0:
        return None
    return (
        f"l_lambda_sigma = {p.l_lambda_sigma:g} m has no effect with stiffness = 'fractal' "
        "(its K_n does not depend on the line length); use stiffness = 'hertz' for a random "
        "contact stiffness"
    )


def run_warnings(p: Params, num: Numerics) -> list[str]:
    """The warnings of :func:`resolution_warning` and :func:`ignored_sigma_warning` for ``p``."""
    return [w for w in (resolution_warning(p, num), ignored_sigma_warning(p)) if w]
