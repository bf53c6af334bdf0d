"""Ensembles: every member equals simulate() of the same (seed, index) bit for bit, through
refills, with impacts kept, and labelled by classify_ensemble."""

import numpy as np
import pytest

from chaoscam import ParameterError, Params, classify_ensemble, simulate
from chaoscam.integrate import simulate_ensemble


@pytest.mark.parametrize("integrator", ["rk4", "adaptive"])
def test_impacts_not_kept_are_counted_without_stopping(monkeypatch, integrator):
    """Without keep_impacts the kernel counts the impacts in a buffer of no rows: the same
    sections and impact counts, bit for bit, as with rows kept, and a member stops for a
    refill only when its draws run out (each stop is a relaunch on a GPU)."""
    from chaoscam.integrate import _ensemble, _members

    monkeypatch.setitem(_ensemble._ROOM, "cpu", (256, 64))  # rows run out long before draws
    stops = []
    drive = _members.drive_members

    def counted(n, launch, refill, need=None):
        def refill_counted(members):
            stops.append(len(members))
            refill(members)

        return drive(n, launch, refill_counted, need)

    monkeypatch.setattr(_members, "drive_members", counted)
    p = Params(l_lambda_sigma=0.002, integrator=integrator)
    runs = {}
    for keep in (True, False):
        stops.clear()
        ens = simulate_ensemble(p, [0, 1], seed=5, duration=1.0, keep_impacts=keep)
        runs[keep] = (ens, sum(stops))
    (kept, kept_stops), (counted_only, counted_stops) = runs[True], runs[False]
    assert kept.sections.equals(counted_only.sections)
    assert kept.members.equals(counted_only.members)
    assert kept.members.n_impacts.min() > 10 * 64  # ~800 impacts in the first 0.05 s
    assert counted_stops < kept_stops / 4


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
    ens = simulate_ensemble(p, [0, 1, 2], seed=5, duration=4.0, keep_impacts=True)
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


def test_classify_ensemble_refuses_other_models():
    """The verdicts judge each member with the params given (the certificate runs the model
    again), so params that are not the run's, a list of the wrong length or not Params are
    refused; the same models, as one Params or a list of equal ones, are taken."""
    p = Params(omega=10.0)
    ens = simulate_ensemble(p, [0, 1], duration=2.0, transient=1.0, tangent=True)
    with pytest.raises(ValueError, match="not the models this ensemble was run with"):
        classify_ensemble(ens, Params(omega=10.0, xi=0.3))
    with pytest.raises(ValueError, match="not the models"):
        classify_ensemble(ens, [p, Params(omega=10.0, l_lambda=0.009)])
    with pytest.raises(ValueError, match="params: 3 parameter sets for an ensemble of 2"):
        classify_ensemble(ens, [p] * 3)
    with pytest.raises(ValueError, match="params: expected chaoscam.Params, got dict"):
        classify_ensemble(ens, [p, {"omega": 10.0}])
    for same in (Params(omega=10.0), [Params(omega=10.0), Params(omega=10.0)]):
        labelled = classify_ensemble(ens, same, extend_to=None)
        assert len(labelled.members["label"]) == 2


@pytest.mark.parametrize(
    "kwargs, message",
    [
        (dict(indices=[0.5, 1.7]), r"index = 0.5 must be an integer"),
        (dict(indices=[-1]), r"index = -1 must be an integer >= 0"),
        (dict(indices=[0], seed=None), r"seed = None must be an integer"),
        (dict(indices=[0], seed=-1), r"seed = -1 must be an integer >= 0"),
    ],
)
def test_ensemble_indices_and_seed_are_checked(kwargs, message):
    """Indices and seed are whole numbers >= 0, as for simulate: 0.5 was silently 0, and
    seed=None a TypeError from deep inside."""
    with pytest.raises(ParameterError, match=message):
        simulate_ensemble(Params(l_lambda_sigma=0.002), duration=0.01, **kwargs)


def test_ensemble_params_as_a_dict_says_what_to_do():
    """A dict for params gets simulate's TypeError (use Params(**d)), not an AttributeError."""
    with pytest.raises(TypeError, match=r"use Params\(\*\*d\)"):
        simulate_ensemble({"omega": 30.0}, [0], duration=0.01)


def test_an_ensemble_that_cannot_fit_in_memory_is_refused_at_once():
    """range(10**10) members is refused by its memory estimate before the index list is made
    (it hung building 1e10 ints), as `chaoscam ensemble` refuses it."""
    with pytest.raises(ParameterError, match=r"an ensemble of 10000000000 members needs about"):
        simulate_ensemble(Params(), range(10**10), duration=20.0)


def test_equal_models_written_differently_are_the_same_models():
    """Params(omega=10) == Params(omega=10.0): classify_ensemble takes either (the
    fingerprint hashed their repr, which differs)."""
    ens = simulate_ensemble(Params(omega=10), [0], duration=1.0, transient=0.5, tangent=True)
    assert len(classify_ensemble(ens, Params(omega=10.0), extend_to=None).members) == 1


def test_a_batch_sizes_its_draws_once_not_once_a_member(monkeypatch):
    """The draws a batch starts with are a maximum over its models, asked once a batch: asked
    once a member over every member it was quadratic, 137 s of host time before a full
    H200 wave's 5-s launch (33,792 members)."""
    from chaoscam.integrate import _members

    asked = []
    draws = _members._draws

    def counted(p, duration, room):
        asked.append(p)
        return draws(p, duration, room)

    monkeypatch.setattr(_members, "_draws", counted)
    p = Params(l_lambda_sigma=0.002)
    models = [p] * 300 + [Params(l_lambda_sigma=0.003)] * 300
    start = _members.fresh(models, range(600), 1, 1.0, 0.0, False, (512, 256))
    assert len(asked) == 2  # one a distinct model
    assert start.lam.shape[0] == 600


_TWO_THREADS = """
import json, threading
from chaoscam import Params
from chaoscam.integrate import simulate_ensemble
p = Params(l_lambda_sigma=0.002)
alone = simulate_ensemble(p, range(6), duration=1.0).sections
out = {}
def go(name):
    out[name] = [simulate_ensemble(p, range(6), duration=1.0).sections.equals(alone)
                 for _ in range(3)]
threads = [threading.Thread(target=go, args=(n,)) for n in "ab"]
for t in threads:
    t.start()
for t in threads:
    t.join()
print(json.dumps(out))
"""


def test_ensembles_from_two_threads_take_turns_on_numbas_threads():
    """Two Python threads calling simulate_ensemble at once: numba's workqueue layer aborted
    the interpreter ("Concurrent access has been detected"); the launches now take turns
    (_members.PARALLEL_LOCK) and give the bits of a call alone. In a child process: an
    abort would end this one."""
    import json
    import subprocess
    import sys

    out = subprocess.run(
        [sys.executable, "-c", _TWO_THREADS], capture_output=True, text=True, timeout=600
    )
    assert out.returncode == 0, out.stderr[-2000:]
    assert json.loads(out.stdout.strip().splitlines()[-1]) == {"a": [True] * 3, "b": [True] * 3}
