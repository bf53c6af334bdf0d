"""A GPU sweep's pipeline (sweep._pipeline.PipelineBackend): the next batch is launched while
the last is labelled, with the serial backend's records, and a Ctrl-C stops both.

A stand-in device runs the CPU's kernel (so its records equal the CPU engine's bit for bit);
events, not timings, show that a launch and a labelling overlap.
"""

import threading

import pytest

from chaoscam import Params, _ensemble_verdicts
from chaoscam.integrate import _gpu, _members
from chaoscam.sweep import Axis, SweepInterrupted, _batch, regime_map

from ._helpers import frames_equal

XI = Axis("xi", (0.2, 0.3))
SIGMA = Axis("l_lambda_sigma", (0.0, 0.002))
KW = dict(realizations=3, seed=5, duration=6.0, transient=3.0, base=Params())


@pytest.fixture
def device(monkeypatch):
    """A stand-in GPU that runs its launches on the CPU; batches of 2 members."""
    monkeypatch.setattr(_gpu, "gpu_status", lambda: (True, "Stand-in GPU"))
    monkeypatch.setattr(_gpu, "run_on_gpu", lambda *args, **kw: _members.run_on_cpu(*args))
    monkeypatch.setattr(_batch, "GPU_MAP_BATCH", 2)


@pytest.fixture(scope="module")
def cpu_map():
    return regime_map(XI, SIGMA, engine="ensemble", device="cpu", workers=1, **KW)


def test_the_next_batch_is_launched_while_the_last_is_labelled(device, monkeypatch, cpu_map):
    """The first batch's labels wait (up to 60 s) for the second batch's launch to begin:
    with launches and labels one after another they would wait in vain. Launches run in the
    driver's thread, labels on the labelling thread; the table is the CPU engine's."""
    second_launch = threading.Event()
    launches, labellers, overlapped = [], set(), []
    real_launch, real_verdicts = _batch.launch_batch, _ensemble_verdicts.member_verdicts

    def launch(tasks, backend="cpu", extend_to=None):
        launches.append(threading.current_thread().name)
        if len(launches) == 2:
            second_launch.set()
        return real_launch(tasks, backend, extend_to)

    def verdicts(*args, **kw):
        labellers.add(threading.current_thread().name)
        if not overlapped:
            overlapped.append(second_launch.wait(60))
        return real_verdicts(*args, **kw)

    monkeypatch.setattr(_batch, "launch_batch", launch)
    monkeypatch.setattr(_ensemble_verdicts, "member_verdicts", verdicts)
    m = regime_map(XI, SIGMA, engine="ensemble", device="gpu", workers=1, **KW)
    assert overlapped == [True]
    assert set(launches) == {threading.main_thread().name} and len(launches) >= 3
    assert labellers and all(n.startswith("chaoscam-labels") for n in labellers)
    assert m.config["device"] == "gpu"
    frames_equal(m.realizations, cpu_map.realizations)
    frames_equal(m.cells, cpu_map.cells)


def test_a_ctrl_c_in_a_launch_stops_the_labels_and_resumes(device, monkeypatch, tmp_path, cpu_map):
    """Ctrl-C during the third launch: the labels under way stop, the finished batches are
    saved, no thread is left, and --resume finishes to the CPU engine's table."""
    real_launch, calls = _batch.launch_batch, []

    def launch(tasks, backend="cpu", extend_to=None):
        calls.append(1)
        if len(calls) == 3:
            raise KeyboardInterrupt
        return real_launch(tasks, backend, extend_to)

    monkeypatch.setattr(_batch, "launch_batch", launch)
    before = threading.active_count()
    out = tmp_path / "map.parquet"
    with pytest.raises(SweepInterrupted) as err:
        regime_map(XI, SIGMA, engine="ensemble", device="gpu", workers=1, out=out, **KW)
    assert "--resume" in str(err.value)
    assert threading.active_count() == before  # the labelling thread was joined
    monkeypatch.setattr(_batch, "launch_batch", real_launch)
    done = regime_map(
        XI, SIGMA, engine="ensemble", device="gpu", workers=1, out=out, resume=True, **KW
    )
    frames_equal(done.realizations, cpu_map.realizations)


def test_a_labelling_thread_asked_to_stop_stops_at_its_next_compiled_call():
    """stop_on: a thread whose stop event is set raises StopRequested before its next
    ensemble launch on numba's threads, as a batch thread does between members."""
    from chaoscam.integrate import simulate_ensemble
    from chaoscam.integrate._driver import StopRequested, stop_on

    stop = threading.Event()
    stop.set()
    with stop_on(stop), pytest.raises(StopRequested):
        simulate_ensemble(Params(), range(2), duration=0.1)
    simulate_ensemble(Params(), range(2), duration=0.1)  # outside: no stop


def test_an_inner_stop_context_does_not_hide_the_threads_stop():
    """stop_on nests: inside a second context (a serial sweep's batch on a thread run
    beside another sweep) the first context's stop request still stops the thread."""
    from chaoscam.integrate._driver import StopRequested, check_stop, stop_on, stops_here

    outer, inner = threading.Event(), threading.Event()
    with stop_on(outer):
        with stop_on(inner), stop_on(None):
            assert stops_here() == (outer, inner)
            check_stop()  # neither set
            outer.set()
            with pytest.raises(StopRequested):
                check_stop()
        assert stops_here() == (outer,)
    assert stops_here() == ()
    check_stop()  # outside: nothing watched


def test_labels_asked_to_stop_stop_before_the_next_member(monkeypatch):
    """A random member's verdict runs no compiled call, so the verdicts check the stop
    request before each member: a cancelled labelling of 8,192 members (about 27 s of
    verdicts) stops within one."""
    from chaoscam.integrate import simulate_ensemble
    from chaoscam.integrate._driver import StopRequested, stop_on

    p = Params(l_lambda_sigma=0.002)
    ens = simulate_ensemble(p, range(2), duration=1.0, tangent=True)
    judged = []
    real = _ensemble_verdicts._member
    monkeypatch.setattr(_ensemble_verdicts, "_member", lambda *a: judged.append(1) or real(*a))
    stop = threading.Event()
    stop.set()
    with stop_on(stop), pytest.raises(StopRequested):
        _ensemble_verdicts.member_verdicts(ens, p)
    assert judged == []


def test_a_continued_diagram_on_the_pipeline_is_the_cpus(device):
    """A bifurcation diagram with continuation (each value's start is the last value's end,
    so its tasks exist only after the records before them): the same points on the
    pipeline as on the CPU."""
    from chaoscam.sweep import bifurcation

    kw = dict(duration=4.0, transient=2.0, initial_conditions=2, continuation=True, workers=1)
    a = bifurcation("xi", "0.2:0.3:3", engine="ensemble", device="gpu", **kw)
    b = bifurcation("xi", "0.2:0.3:3", engine="ensemble", device="cpu", **kw)
    assert a.config["device"] == "gpu" and b.config["device"] == "cpu"
    frames_equal(a.points, b.points)
