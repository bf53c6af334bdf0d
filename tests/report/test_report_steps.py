"""The step of the paper's bifurcation figures: steps per contact period at the stiffest point."""

import math

import pytest

from chaoscam import contact_period
from chaoscam.model import Params
from chaoscam.numerics import Numerics
from chaoscam.paper import _paper

FIG4_STIFFEST = Params(l_lambda=0.018)
FIG6_STIFFEST = Params(stiffness="fractal", D=1.56, G=1e-9)


@pytest.mark.parametrize("stiffest", [FIG4_STIFFEST, FIG6_STIFFEST])
@pytest.mark.parametrize("steps", [40, 160])
def test_the_step_resolves_the_stiffest_contact_with_the_asked_steps(stiffest, steps):
    """dt spans 1/steps of the stiffest point's contact period, to two significant digits
    (so within 5 % of the asked count)."""
    dt = _paper.figure_dt(stiffest, steps)
    assert dt == float(f"{dt:.1e}")
    assert math.isclose(dt, contact_period(stiffest) / steps, rel_tol=0.05)


class _Stop(Exception):
    pass


@pytest.mark.parametrize("quick", [True, False])
@pytest.mark.parametrize("number", [4, 6])
def test_the_figures_run_their_sweeps_at_the_rule_s_step(number, quick, monkeypatch, tmp_path):
    """Figs. 4 and 6 hand their bifurcation sweep numerics whose dt is the rule's at the
    sweep's largest value (l_λ = 0.018 m, D = 1.56): caught at the call, before any run."""
    import chaoscam.sweep

    seen = []

    def caught(param, values, *, numerics=None, **kwargs):
        seen.append((param, numerics))
        raise _Stop

    monkeypatch.setattr(chaoscam.sweep, "bifurcation", caught)
    with pytest.raises(_Stop):
        _paper.FIGURES[number](quick, tmp_path)
    param, numerics = seen[0]
    if number == 4:
        steps, stiffest = _paper.FIG4_STEPS[quick], FIG4_STIFFEST
    else:
        steps, stiffest = _paper.FIG6_STEPS[quick], FIG6_STIFFEST
    assert numerics.dt == _paper.figure_dt(stiffest, steps)
    assert param == ("l_lambda" if number == 4 else "D")


def test_the_full_report_refines_both_figures_and_the_quick_one_keeps_its_step():
    """Full: 160 steps for Figs. 4 and 6 (Fig. 4's dt 3.8e-7 s, about 5x finer than the
    default); quick: the model's default dt for Fig. 4 and 40 steps for Fig. 6."""
    assert _paper.FIG4_STEPS[False] == _paper.FIG6_STEPS[False] == _paper.FULL_STEPS == 160
    assert _paper.figure_dt(FIG4_STIFFEST, _paper.FIG4_STEPS[True]) == Numerics().dt
    assert _paper.figure_dt(FIG4_STIFFEST, _paper.FIG4_STEPS[False]) == 3.8e-7
    assert _paper.FIG6_STEPS[True] == 40


def test_the_notes_state_the_step_the_figure_ran_at():
    """Fig. 4's note counts the steps of the dt it ran at (30 at the default, 160 refined)
    and says the coarse one misses the period-8 windows; Fig. 6's names its step count."""
    coarse = _paper.fig4_step_note(FIG4_STIFFEST, Numerics().dt)
    fine = _paper.fig4_step_note(FIG4_STIFFEST, 3.8e-7)
    assert "(30 RK4 steps per contact period at l_λ = 0.018 m, a step at which" in coarse
    assert coarse.endswith("the full report takes 160)")
    assert "(160 RK4 steps per contact period at l_λ = 0.018 m; measured at" in fine
    assert "not converged" not in fine
    quick, full = (_paper.fig6_step_note(FIG6_STIFFEST, q) for q in (True, False))
    assert "; 40 RK4 steps per contact period at D = 1.56, a step at which" in quick
    assert "not converged" in quick and "not converged" not in full
    assert full.startswith("; 160 RK4 steps per contact period at D = 1.56 (measured")
