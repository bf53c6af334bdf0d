"""Continued solutions: a member extended from its kept copy carries the bits of a run made
that long from t = 0, through refills, several rounds, ended members and interval draws;
the copy is kept at the last section's grid step, and only there is it exact."""

import numpy as np
import pandas as pd
import pytest

from chaoscam import Numerics, ParameterError, Params, extend, solve
from chaoscam.simulation import _batch

CHAOTIC = Params(l_lambda=0.011, l_lambda_sigma=0.0015)  # chattering: refills in every run
RUN = dict(seed=1, transient=1.0, tangent=True)


def _same(a, b) -> None:
    pd.testing.assert_frame_equal(a.sections, b.sections, check_exact=True)
    pd.testing.assert_frame_equal(a.members, b.members, check_exact=True)
    assert np.array_equal(a.jacobians, b.jacobians)


def test_a_resumable_run_is_the_same_run():
    """Keeping the copy (one more stop of the compiled call) changes no bit."""
    plain = solve(CHAOTIC, indices=range(4), duration=3.0, **RUN)
    kept = solve(CHAOTIC, indices=range(4), duration=3.0, resumable=True, **RUN)
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
    short = solve(params, indices=range(5), duration=3.0, resumable=True, **RUN)
    middle = extend(short, 5.0, members=[4, 1, 3], resumable=True)
    long = extend(middle, 9.0, members=[2, 0])
    made = solve(params, indices=[3, 4], duration=9.0, **RUN)
    _same(long, made)
    assert long.settings["duration"] == 9.0 and long.settings["continued_from"] > 0
    assert middle.settings["continued_from"] > 0  # continued, not run again
    # the first round equals its own long run too, members numbered in the order asked
    _same(middle, solve(params, indices=[4, 1, 3], duration=5.0, **RUN))
    refilled = (long.members.n_impacts > max(_batch.ROOM["cpu"])).all()
    assert refilled or params.l_lambda_sigma == 0.0  # the random ones refill on the way


def test_a_member_that_ended_stays_ended():
    """A member that left the cam's reach before the copy is not run on: its status, impacts
    and sections are those of the long run (which ended at the same moment)."""
    p = Params(xi=0.8, l_lambda_sigma=0.002)  # members 0-2 leave the cam's reach at 3.7-4.8 s
    short = solve(p, indices=range(3), duration=4.5, resumable=True, **RUN)
    ended = short.resume.status != 0  # before the copy, at the last section before 4.5 s
    assert ended.any() and not ended.all()
    long = extend(short, 6.0)
    _same(long, solve(p, indices=range(3), duration=6.0, **RUN))
    assert (long.members.status == "LEFT_REACH").all()  # the others leave on the way


def test_the_copy_is_exact_only_at_a_section_step(monkeypatch):
    """Why the copy sits at floor(k T / dt): a copy a few thousand steps later (inside a
    cam period, where a block of merged flight steps would be cut) gives other bits."""
    made = solve(CHAOTIC, indices=range(6), duration=6.0, **RUN)
    at_section = solve(CHAOTIC, indices=range(6), duration=3.0, resumable=True, **RUN)
    _same(extend(at_section, 6.0), made)
    step = _batch.snapshot_step
    monkeypatch.setattr(_batch, "snapshot_step", lambda num, p, n: step(num, p, n) + 5001)
    off = solve(CHAOTIC, indices=range(6), duration=3.0, resumable=True, **RUN)
    assert off.resume.step == at_section.resume.step + 5001
    moved = extend(off, 6.0)
    assert not moved.sections.equals(made.sections)


@pytest.mark.parametrize("dt", [2e-6, 1e-5, 3e-5])
@pytest.mark.parametrize("omega", [28.7, 10.0, 61.3])
def test_snapshot_step_is_the_grid_step_of_the_last_section(dt, omega):
    """N dt <= k T < (N + 1) dt for the last k T before the end (or 0), and N < n_stop."""
    p, num = Params(omega=omega), Numerics(dt=dt)
    for n_stop in (1, 7, int(0.5 * p.cam_period / dt), int(20.0 / dt), int(20.0 / dt) + 3):
        n = _batch.snapshot_step(num, p, n_stop)
        kk = int(n_stop * dt / p.cam_period)
        if kk * p.cam_period >= n_stop * dt:
            kk -= 1
        kk = max(kk, 0)
        assert n * dt <= kk * p.cam_period < (n + 1) * dt or kk == n == 0
        assert n < n_stop or n_stop == 0


def test_the_adaptive_integrator_keeps_no_copy():
    """The adaptive kernel lands its last step on the end time: it keeps no copy
    (snapshot_step is None), and its runs are run again from t = 0, to the same bits."""
    num = Numerics(integrator="adaptive")
    assert _batch.snapshot_step(num, Params(), 1000) is None
    ens = solve(Params(), num, indices=[0], duration=0.5, resumable=True)
    assert ens.resume is None
    longer = extend(ens, 1.0)
    assert longer.settings["continued_from"] is None
    _same(longer, solve(Params(), num, indices=[0], duration=1.0))


def test_bad_continuations_are_refused():
    """A shorter duration or a member the solution does not have: a clear error. A run
    without a copy is run again from t = 0 instead, to the same bits."""
    short = solve(CHAOTIC, indices=range(2), duration=2.0, resumable=True, **RUN)
    with pytest.raises(ParameterError, match=r"must be >= the run's duration, 2.0 s"):
        extend(short, 1.5)
    with pytest.raises(ParameterError, match=r"members = 2 must be an integer >= 0 and <= 1"):
        extend(short, 4.0, members=[0, 2])
    plain = solve(CHAOTIC, indices=range(2), duration=2.0, **RUN)
    again = extend(plain, 4.0)
    assert again.settings["continued_from"] is None
    _same(again, extend(short, 4.0))
