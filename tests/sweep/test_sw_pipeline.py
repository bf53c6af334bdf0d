"""A GPU sweep's pipeline (sweep._backends.PipelineBackend): the next batch is launched while
the last is labelled, with the serial backend's records, and a Ctrl-C stops both.

A stand-in device runs the CPU's kernel (so its records equal the CPU engine's bit for bit);
events, not timings, show that a launch and a labelling overlap.
"""

import threading

import numpy as np
import pytest

import chaoscam
from chaoscam import Params
from chaoscam.sweep import Axis, SweepInterrupted, _engine, regime_map
from chaoscam.sweep._runs import Batch

from ._helpers import frames_equal

XI = Axis("xi", (0.2, 0.3))
SIGMA = Axis("l_lambda_sigma", (0.0, 0.002))
KW = dict(realizations=3, seed=5, duration=6.0, transient=3.0, base=Params())


@pytest.fixture
def device(monkeypatch):
    """A stand-in GPU that runs its launches on the CPU's kernel; batches of 2 members."""
    import chaoscam.kernel
    from chaoscam.kernel import _gpu
    from chaoscam.kernel import layout as k
    from chaoscam.simulation import _batch, _solve

    def on_cpu(y, cnt, c, to, lam, section, impacts, status, hand_back, keep_impacts=False):
        series = np.empty((y.shape[0], 1, k.SERIES_COLS))  # a GPU keeps no series
        _batch.run_on_cpu(y, cnt, c, to, lam, series, section, impacts, status, hand_back)

    status = lambda: (True, "Stand-in GPU")  # noqa: E731
    for module in (_gpu, _solve, chaoscam.kernel):
        monkeypatch.setattr(module, "gpu_status", status, raising=False)
    monkeypatch.setattr(_batch, "run_on_gpu", on_cpu)
    monkeypatch.setattr(_engine, "GPU_BATCH", 2)


@pytest.fixture(scope="module")
def cpu_map():
    return regime_map(XI, SIGMA, device="cpu", workers=1, **KW)


def test_the_next_batch_is_launched_while_the_last_is_labelled(device, monkeypatch, cpu_map):
    """The first batch's labels wait (up to 60 s) for the second batch's launch to begin:
    with launches and labels one after another they would wait in vain. Launches run in the
    driver's thread, labels on the labelling thread; the table is the CPU engine's."""
    second_launch = threading.Event()
    launches, labellers, overlapped = [], set(), []
    real_launch, real_label = Batch.launch, Batch.label

    def launch(self):
        launches.append(threading.current_thread().name)
        if len(launches) == 2:
            second_launch.set()
        return real_launch(self)

    def label(self, launched):
        labellers.add(threading.current_thread().name)
        if not overlapped:
            overlapped.append(second_launch.wait(60))
        return real_label(self, launched)

    monkeypatch.setattr(Batch, "launch", launch)
    monkeypatch.setattr(Batch, "label", label)
    m = regime_map(XI, SIGMA, device="gpu", workers=1, **KW)
    assert overlapped == [True]
    assert set(launches) == {threading.main_thread().name} and len(launches) >= 3
    assert labellers and all(n.startswith("chaoscam-labels") for n in labellers)
    assert m.config["device"] == "gpu"
    frames_equal(m.realizations, cpu_map.realizations)
    frames_equal(m.cells, cpu_map.cells)


def test_a_ctrl_c_in_a_launch_stops_the_labels_and_resumes(device, monkeypatch, tmp_path, cpu_map):
    """Ctrl-C during the third launch: the labels under way stop, the finished batches are
    saved, no thread is left, and --resume finishes to the CPU engine's table."""
    real_launch, calls = Batch.launch, []

    def launch(self):
        calls.append(1)
        if len(calls) == 3:
            raise KeyboardInterrupt
        return real_launch(self)

    monkeypatch.setattr(Batch, "launch", launch)
    before = threading.active_count()
    out = tmp_path / "map.parquet"
    with pytest.raises(SweepInterrupted) as err:
        regime_map(XI, SIGMA, device="gpu", workers=1, out=out, **KW)
    assert "--resume" in str(err.value)
    assert threading.active_count() == before  # the labelling thread was joined
    monkeypatch.setattr(Batch, "launch", real_launch)
    done = regime_map(XI, SIGMA, device="gpu", workers=1, out=out, resume=True, **KW)
    frames_equal(done.realizations, cpu_map.realizations)


def test_a_labelling_thread_asked_to_stop_stops_at_its_next_compiled_call():
    """stop_on: a thread whose stop event is set raises StopRequested before its next
    solve on numba's threads, as a batch thread does between members."""
    from chaoscam.kernel import StopRequested, stop_on

    stop = threading.Event()
    stop.set()
    with stop_on(stop), pytest.raises(StopRequested):
        chaoscam.solve(Params(), indices=range(2), duration=0.1)
    chaoscam.solve(Params(), indices=range(2), duration=0.1)  # outside: no stop


def test_an_inner_stop_context_does_not_hide_the_threads_stop():
    """stop_on nests: inside a second context (a serial sweep's batch on a thread run
    beside another sweep) the first context's stop request still stops the thread."""
    from chaoscam.kernel import StopRequested, check_stop, stop_on, stops_here

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
    from chaoscam.kernel import StopRequested, stop_on
    from chaoscam.verdict import _classify

    p = Params(l_lambda_sigma=0.002)
    sol = chaoscam.solve(p, indices=range(2), duration=1.0, tangent=True)
    judged = []
    real = _classify.judge_member
    monkeypatch.setattr(_classify, "judge_member", lambda *a: judged.append(1) or real(*a))
    stop = threading.Event()
    stop.set()
    with stop_on(stop), pytest.raises(StopRequested):
        chaoscam.classify(sol)
    assert judged == []


def test_a_continued_diagram_on_the_pipeline_is_the_cpus(device):
    """A bifurcation diagram with continuation (each value's start is the last value's end,
    so its tasks exist only after the records before them): the same points on the
    pipeline as on the CPU."""
    from chaoscam.sweep import bifurcation

    kw = dict(duration=4.0, transient=2.0, initial_conditions=2, continuation=True, workers=1)
    a = bifurcation("xi", "0.2:0.3:3", device="gpu", **kw)
    b = bifurcation("xi", "0.2:0.3:3", device="cpu", **kw)
    assert a.config["device"] == "gpu" and b.config["device"] == "cpu"
    frames_equal(a.points, b.points)
