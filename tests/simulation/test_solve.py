"""solve(): a member of a batch equals the same realization solved alone, bit for bit,
through refills and with impacts kept; the request and the run window are checked."""

import numpy as np
import pytest

from chaoscam import Numerics, ParameterError, Params, classify, simulate, solve
from chaoscam.simulation import _batch, check_window


@pytest.mark.parametrize("integrator", ["rk4", "adaptive"])
def test_impacts_not_kept_are_counted_without_stopping(monkeypatch, integrator):
    """Without impacts kept the kernel counts the impacts in a buffer of no rows: the same
    sections and impact counts, bit for bit, as with rows kept, and a member stops for a
    refill only when its draws run out (each stop is a relaunch on a GPU)."""
    monkeypatch.setitem(_batch.ROOM, "cpu", (256, 64))  # rows run out long before draws
    stops = []
    drive = _batch.drive_members

    def counted(n, launch, refill, need=None):
        def refill_counted(members):
            stops.append(len(members))
            refill(members)

        return drive(n, launch, refill_counted, need)

    monkeypatch.setattr(_batch, "drive_members", counted)
    p, num = Params(l_lambda_sigma=0.002), Numerics(integrator=integrator)
    runs = {}
    for keep in (True, False):
        stops.clear()
        ens = solve(p, num, indices=[0, 1], seed=5, duration=1.0, impacts=keep)
        runs[keep] = (ens, sum(stops))
    (kept, kept_stops), (counted_only, counted_stops) = runs[True], runs[False]
    assert kept.sections.equals(counted_only.sections)
    assert kept.members.equals(counted_only.members)
    assert kept.members.n_impacts.min() > 10 * 64  # ~800 impacts in the first 0.05 s
    assert counted_stops < kept_stops / 4


def test_a_member_of_a_batch_equals_the_same_realization_solved_alone():
    """Each member of a batch is bit-identical to its (seed, index) solved alone."""
    p = Params(l_lambda_sigma=0.002, resample="interval")  # one draw per 0.01 s
    ens = solve(p, indices=[4, 9, 2], seed=3, duration=25.0)
    assert list(ens.members.status) == ["OK"] * 3
    for member, index in enumerate([4, 9, 2]):
        one = simulate(p, seed=3, index=index, duration=25.0, series=False)
        got = ens.sections[ens.sections.member == member].drop(columns="member")
        assert np.array_equal(got.to_numpy(), one.section.to_numpy())
        assert ens.members.n_impacts[member] == len(one.impacts)


@pytest.mark.parametrize("integrator", ["rk4", "adaptive"])
def test_members_that_refill_equal_the_same_realizations_solved_alone(integrator):
    """Members that use up their impact rows and draws (~2,500 impacts in 4 s, most of them
    micro-impacts of chattering) are refilled and resumed in parallel, and still equal
    their realizations solved alone bit for bit."""
    p, num = Params(l_lambda_sigma=0.002), Numerics(integrator=integrator)
    ens = solve(p, num, indices=[0, 1, 2], seed=5, duration=4.0, impacts=True)
    assert ens.members.n_impacts.min() > max(_batch.ROOM["cpu"])  # more than one launch holds
    for member in range(3):
        one = simulate(p, num, seed=5, index=member, duration=4.0, series=False)
        got = ens.sections[ens.sections.member == member].drop(columns="member")
        assert np.array_equal(got.to_numpy(), one.section.to_numpy())
        assert ens.members.n_impacts[member] == len(one.impacts)


def test_a_batch_keeps_impacts_and_its_members_are_labelled():
    """impacts=True returns each member's impacts as simulate() has them; classify labels
    each member from its section (a period-1 orbit: periodic, period 1)."""
    p = Params(l_lambda_sigma=0.002, v_min=0.0)  # ~900 impacts in 3 s: rows handed back
    ens = solve(p, indices=[3, 4], seed=1, duration=3.0, transient=1.0, impacts=True)
    for member, index in enumerate([3, 4]):
        one = simulate(p, seed=1, index=index, duration=3.0, transient=1.0, series=False)
        got = ens.impacts[ens.impacts.member == member].drop(columns="member")
        assert len(got) == ens.members.n_impacts[member] > 256
        assert np.array_equal(got.to_numpy(), one.impacts.drop(columns="member").to_numpy())
    assert solve(p, indices=[0], duration=0.5).impacts is None

    p = Params(omega=10.0)
    verdicts = classify(solve(p, indices=[0, 1], duration=20.0, transient=10.0, tangent=True))
    assert [v.label for v in verdicts] == ["periodic"] * 2
    assert [v.period for v in verdicts] == [1, 1]


@pytest.mark.parametrize(
    "kwargs, message",
    [
        (dict(indices=[0.5, 1.7]), r"index = 0.5 must be an integer"),
        (dict(indices=[-1]), r"index = -1 must be an integer >= 0"),
        (dict(indices=[0], seed=None), r"seed = None must be an integer"),
        (dict(indices=[0], seed=-1), r"seed = -1 must be an integer >= 0"),
    ],
)
def test_indices_and_seed_are_checked(kwargs, message):
    """Indices and seed are whole numbers >= 0, as for simulate: 0.5 was silently 0, and
    seed=None a TypeError from deep inside."""
    with pytest.raises(ParameterError, match=message):
        solve(Params(l_lambda_sigma=0.002), duration=0.01, **kwargs)


def test_params_as_a_dict_says_what_to_do():
    """A dict for params gets simulate's TypeError (use Params(**d)), not an AttributeError."""
    with pytest.raises(TypeError, match=r"use Params\(\*\*d\)"):
        solve({"omega": 30.0}, indices=[0], duration=0.01)


def test_a_batch_that_cannot_fit_in_memory_is_refused_at_once():
    """range(10**10) members is refused by its memory estimate before the index list is made
    (it hung building 1e10 ints), as `chaoscam ensemble` refuses it."""
    with pytest.raises(ParameterError, match=r"an ensemble of 10000000000 members needs about"):
        solve(Params(), indices=range(10**10), duration=20.0)


def test_equal_models_written_differently_are_the_same_models():
    """Params(omega=10) == Params(omega=10.0): one models fingerprint (a digest of their repr
    would differ), so a solution of either is recorded as the same models."""
    runs = [solve(Params(omega=w), indices=[0], duration=0.5) for w in (10, 10.0)]
    assert runs[0].settings["models"] == runs[1].settings["models"]
    assert runs[0].settings["models"] != solve(Params(omega=10.5), duration=0.5).settings["models"]


def test_a_batch_sizes_its_draws_once_not_once_a_member(monkeypatch):
    """The draws a batch starts with are a maximum over its models, asked once a batch, and
    its constants and initial states are made once a distinct model: asked once a member
    over every member it was quadratic, 137 s of host time before a full H200 wave's 5-s
    launch (33,792 members)."""
    asked = {"draws": 0, "constants": 0, "state": 0}

    def counted(name, real):
        def call(*args, **kwargs):
            asked[name] += 1
            return real(*args, **kwargs)

        return call

    monkeypatch.setattr(_batch, "_n_draws", counted("draws", _batch._n_draws))
    monkeypatch.setattr(_batch, "kernel_constants", counted("constants", _batch.kernel_constants))
    monkeypatch.setattr(_batch, "initial_state", counted("state", _batch.initial_state))
    p = Params(l_lambda_sigma=0.002)
    models = [p] * 300 + [Params(l_lambda_sigma=0.003)] * 300
    start = _batch.fresh(models, Numerics(), range(600), 1, 1.0, 0.0, tangent=False, stride=0,
                         room=(512, 256))  # fmt: skip
    assert asked == {"draws": 1, "constants": 2, "state": 2}  # one a batch, one a model
    assert len(_batch.models_of(models)) == 2
    assert start.lam.shape[0] == 600


_TWO_THREADS = """
import json, threading
from chaoscam import Params
from chaoscam import solve
p = Params(l_lambda_sigma=0.002)
alone = solve(p, indices=range(6), duration=1.0).sections
out = {}
def go(name):
    out[name] = [solve(p, indices=range(6), duration=1.0).sections.equals(alone)
                 for _ in range(3)]
threads = [threading.Thread(target=go, args=(n,)) for n in "ab"]
for t in threads:
    t.start()
for t in threads:
    t.join()
print(json.dumps(out))
"""


def test_ensembles_from_two_threads_take_turns_on_numbas_threads():
    """Two Python threads calling solve at once: numba's workqueue layer aborted the
    interpreter ("Concurrent access has been detected"); the launches now take turns
    (simulation._batch.PARALLEL_LOCK) and give the bits of a call alone. In a child process:
    an abort would end this one."""
    import json
    import subprocess
    import sys

    out = subprocess.run(
        [sys.executable, "-c", _TWO_THREADS], capture_output=True, text=True, timeout=600
    )
    assert out.returncode == 0, out.stderr[-2000:]
    assert json.loads(out.stdout.strip().splitlines()[-1]) == {"a": [True] * 3, "b": [True] * 3}


@pytest.mark.parametrize(
    ("duration", "transient", "field"),
    [
        (0.0, 0.0, "duration"),
        (float("nan"), 0.0, "duration"),
        (True, 0.0, "duration"),
        ("20", 0.0, "duration"),
        (20.0, 20.0, "transient"),
        (20.0, -1.0, "transient"),
        (20.0, None, "transient"),
    ],
)
def test_check_window_names_the_field_and_its_range(duration, transient, field):
    """Every entry point's run window is refused naming the field and its range."""
    with pytest.raises(ParameterError, match=rf"^{field} = .* must be"):
        check_window(duration, transient)


def test_check_window_refuses_a_run_shorter_than_one_step():
    """A duration shorter than one step dt would simulate nothing: refused."""
    with pytest.raises(ParameterError, match="shorter than one step"):
        check_window(1e-7, 0.0, dt=2e-6)
    assert check_window(20, 5) == (20.0, 5.0)
