"""Ensembles: every member equals simulate() of the same (seed, index) bit for bit, through
refills, with impacts kept, and labelled by classify_ensemble."""

import numpy as np
import pytest

from chaoscam import Params, classify_ensemble, simulate


def test_ensemble_members_equal_single_runs():
    """Each ensemble member is bit-identical to simulate() of the same (seed, index)."""
    from chaoscam.integrate import simulate_ensemble

    p = Params(l_lambda_sigma=0.002, resample="interval")  # one draw per 0.01 s
    ens = simulate_ensemble(p, [4, 9, 2], seed=3, duration=25.0)
    assert list(ens.members.status) == ["OK"] * 3
    for member, index in enumerate([4, 9, 2]):
        one = simulate(p, seed=3, index=index, duration=25.0, series=False)
        got = ens.sections[ens.sections.member == member].drop(columns="member")
        assert np.array_equal(got.to_numpy(), one.section.to_numpy())
        assert ens.members.n_impacts[member] == len(one.impacts)


@pytest.mark.parametrize("integrator", ["rk4", "adaptive"])
def test_ensemble_members_that_refill_equal_single_runs(integrator):
    """Members that use up their impact rows and draws (~2,500 impacts in 4 s, most of them
    micro-impacts of chattering) are refilled and resumed in parallel, and still equal
    simulate() bit for bit."""
    from chaoscam.integrate import _ensemble, simulate_ensemble

    p = Params(l_lambda_sigma=0.002, integrator=integrator)
    ens = simulate_ensemble(p, [0, 1, 2], seed=5, duration=4.0)
    assert ens.members.n_impacts.min() > max(_ensemble._ROOM["cpu"])  # more than one launch holds
    for member in range(3):
        one = simulate(p, seed=5, index=member, duration=4.0, series=False)
        got = ens.sections[ens.sections.member == member].drop(columns="member")
        assert np.array_equal(got.to_numpy(), one.section.to_numpy())
        assert ens.members.n_impacts[member] == len(one.impacts)


def test_ensemble_keeps_impacts_and_labels_members():
    """keep_impacts returns each member's impacts as simulate() has them; classify labels
    each member from its section (a period-1 orbit: periodic, period 1)."""
    from chaoscam.integrate import simulate_ensemble

    p = Params(l_lambda_sigma=0.002, v_min=0.0)  # ~900 impacts in 3 s: rows handed back
    ens = simulate_ensemble(p, [3, 4], seed=1, duration=3.0, transient=1.0, keep_impacts=True)
    for member, index in enumerate([3, 4]):
        one = simulate(p, seed=1, index=index, duration=3.0, transient=1.0, series=False)
        got = ens.impacts[ens.impacts.member == member].drop(columns="member")
        assert len(got) == ens.members.n_impacts[member] > 256
        assert np.array_equal(got.to_numpy(), one.impacts.to_numpy())
    assert simulate_ensemble(p, [0], duration=0.5).impacts is None

    p = Params(omega=10.0)
    ens = classify_ensemble(
        simulate_ensemble(p, [0, 1], duration=20.0, transient=10.0, tangent=True), p
    )
    assert list(ens.members.label) == ["periodic"] * 2 and list(ens.members.period) == [1, 1]
