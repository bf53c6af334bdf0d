"""Continued ensembles: a member extended from its kept copy carries the bits of a run made
that long from t = 0, through refills, several rounds, ended members and interval draws;
the copy is kept at the last section's grid step, and only there is it exact."""

import numpy as np
import pandas as pd
import pytest

from chaoscam import Params
from chaoscam.integrate import _ensemble, _members, _resume, extend_ensemble, simulate_ensemble

CHAOTIC = Params(l_lambda=0.011, l_lambda_sigma=0.0015)  # chattering: refills in every run
RUN = dict(seed=1, transient=1.0, tangent=True)


def _same(a, b) -> None:
    pd.testing.assert_frame_equal(a.sections, b.sections, check_exact=True)
    pd.testing.assert_frame_equal(a.members, b.members, check_exact=True)
    assert np.array_equal(a.jacobians, b.jacobians)


def test_a_resumable_run_is_the_same_run():
    """Keeping the copy (one more stop of the compiled call) changes no bit."""
    plain = simulate_ensemble(CHAOTIC, range(4), duration=3.0, **RUN)
    kept = simulate_ensemble(CHAOTIC, range(4), duration=3.0, resumable=True, **RUN)
    _same(plain, kept)
    assert plain.resume is None and len(kept.resume) == 4


@pytest.mark.parametrize(
    "params",
    [
        CHAOTIC,
        Params(l_lambda_sigma=0.002, resample="interval"),  # draws on a clock, not per impact
        Params(xi=0.2),  # deterministic, periodic
        Params(xi=0.45),  # chattering to sticking
    ],
    ids=["chaotic", "interval-draws", "periodic", "sticking"],
)
def test_extended_members_equal_runs_made_long(params):
    """Two rounds of continuation (3 -> 5 -> 9 s), a subset in a new order, equal runs made
    9 s long from t = 0: sections, Jacobians, impact counts, contact fractions, statuses."""
    short = simulate_ensemble(params, range(5), duration=3.0, resumable=True, **RUN)
    middle = extend_ensemble(short, params, 5.0, members=[4, 1, 3], resumable=True)
    long = extend_ensemble(middle, params, 9.0, members=[2, 0])
    made = simulate_ensemble(params, [3, 4], duration=9.0, **RUN)
    _same(long, made)
    assert long.settings["duration"] == 9.0 and long.settings["continued_from"] > 0
    # the first round equals its own long run too, members numbered in the order asked
    _same(middle, simulate_ensemble(params, [4, 1, 3], duration=5.0, **RUN))
    refilled = (long.members.n_impacts > max(_ensemble._ROOM["cpu"])).all()
    assert refilled or params.l_lambda_sigma == 0.0  # the random ones refill on the way


def test_a_member_that_ended_stays_ended():
    """A member that left the cam's reach before the copy is not run on: its status, impacts
    and sections are those of the long run (which ended at the same moment)."""
    p = Params(xi=0.8, l_lambda_sigma=0.002)  # members 0-2 leave the cam's reach at 3.7-4.8 s
    short = simulate_ensemble(p, range(3), duration=4.5, resumable=True, **RUN)
    ended = short.resume.status != 0  # before the copy, at the last section before 4.5 s
    assert ended.any() and not ended.all()
    long = extend_ensemble(short, p, 6.0)
    _same(long, simulate_ensemble(p, range(3), duration=6.0, **RUN))
    assert (long.members.status == "LEFT_REACH").all()  # the others leave on the way


def test_the_copy_is_exact_only_at_a_section_step(monkeypatch):
    """Why the copy sits at floor(k T / dt): a copy a few thousand steps later (inside a
    cam period, where a block of merged flight steps would be cut) gives other bits."""
    made = simulate_ensemble(CHAOTIC, range(6), duration=6.0, **RUN)
    at_section = simulate_ensemble(CHAOTIC, range(6), duration=3.0, resumable=True, **RUN)
    _same(extend_ensemble(at_section, CHAOTIC, 6.0), made)
    step = _resume.snapshot_step
    monkeypatch.setattr(_members, "snapshot_step", lambda p, n: step(p, n) + 5001)
    off = simulate_ensemble(CHAOTIC, range(6), duration=3.0, resumable=True, **RUN)
    moved = extend_ensemble(off, CHAOTIC, 6.0)
    assert not moved.sections.equals(made.sections)


@pytest.mark.parametrize("dt", [2e-6, 1e-5, 3e-5])
@pytest.mark.parametrize("omega", [28.7, 10.0, 61.3])
def test_snapshot_step_is_the_grid_step_of_the_last_section(dt, omega):
    """N dt <= k T < (N + 1) dt for the last k T before the end (or 0), and N < n_stop."""
    p = Params(dt=dt, omega=omega)
    for n_stop in (1, 7, int(0.5 * p.cam_period / dt), int(20.0 / dt), int(20.0 / dt) + 3):
        n = _resume.snapshot_step(p, n_stop)
        kk = int(n_stop * dt / p.cam_period)
        if kk * p.cam_period >= n_stop * dt:
            kk -= 1
        kk = max(kk, 0)
        assert n * dt <= kk * p.cam_period < (n + 1) * dt or kk == n == 0
        assert n < n_stop or n_stop == 0


def test_the_adaptive_integrator_keeps_no_copy():
    """The adaptive kernel lands its last step on the end time: its runs are re-run."""
    ens = simulate_ensemble(Params(integrator="adaptive"), [0], duration=0.5, resumable=True)
    assert ens.resume is None
    with pytest.raises(ValueError, match="resumable=True"):
        extend_ensemble(ens, Params(integrator="adaptive"), 1.0)


def test_bad_continuations_are_refused():
    """A shorter duration, the wrong model or a run without a copy: a clear error."""
    short = simulate_ensemble(CHAOTIC, range(2), duration=2.0, resumable=True, **RUN)
    with pytest.raises(ValueError, match="shorter than the run's 2.0 s"):
        extend_ensemble(short, CHAOTIC, 1.5)
    with pytest.raises(ValueError, match=r"params\[0\] is not the model member 0 ran with"):
        extend_ensemble(short, CHAOTIC.replace(xi=0.3), 4.0)
    with pytest.raises(ValueError, match="2 parameter sets for 2 members|3 parameter sets"):
        extend_ensemble(short, [CHAOTIC] * 3, 4.0)
    plain = simulate_ensemble(CHAOTIC, range(2), duration=2.0, **RUN)
    with pytest.raises(ValueError, match="cannot be continued"):
        extend_ensemble(plain, CHAOTIC, 4.0)
