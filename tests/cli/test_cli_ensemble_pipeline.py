"""``chaoscam ensemble`` on a GPU (cli._ensemble_run): the next part is launched while the
last is labelled and written, with the CPU's outputs, and a Ctrl-C stops both.

A stand-in device runs the CPU's kernel (so its outputs equal a CPU run's bit for bit);
events, not timings, show that a launch and a labelling overlap.
"""

import threading

import pandas as pd
import pytest

from chaoscam import _ensemble_verdicts
from chaoscam.cli import main
from chaoscam.integrate import _gpu, _members

from .test_cli_ensemble import ARGS

CLASSIFY = [*ARGS, "--classify"]


@pytest.fixture
def device(monkeypatch):
    """A stand-in GPU that runs its launches on the CPU."""
    monkeypatch.setattr(_gpu, "gpu_status", lambda: (True, "Stand-in GPU"))
    monkeypatch.setattr(_gpu, "run_on_gpu", lambda *args, **kw: _members.run_on_cpu(*args))


@pytest.fixture(scope="module")
def cpu_run(tmp_path_factory):
    """The same command on the CPU: (members, sections)."""
    out = tmp_path_factory.mktemp("cpu") / "ens.parquet"
    assert main([*CLASSIFY, "--backend", "cpu", "--out", str(out)]) == 0
    return pd.read_parquet(out), pd.read_parquet(out.with_suffix(".sections.parquet"))


def _same_as(out, cpu_run) -> None:
    members, sections = cpu_run
    got = pd.read_parquet(out)
    # the settled backend is recorded per member where the table has it; labels and numbers
    # are the CPU's
    keep = [c for c in members.columns if c != "backend"]
    pd.testing.assert_frame_equal(got[keep], members[keep])
    pd.testing.assert_frame_equal(pd.read_parquet(out.with_suffix(".sections.parquet")), sections)


def test_the_next_part_is_launched_while_the_last_is_labelled(
    device, monkeypatch, tmp_path, cpu_run
):
    """The first part's labels wait (up to 60 s) for the second part's launch to begin: with
    launches and labels one after another they would wait in vain. Launches run in the
    command's thread, labels on the labelling thread; the outputs are the CPU run's."""
    import chaoscam.integrate as integrate

    second_launch = threading.Event()
    launches, labellers, overlapped = [], set(), []
    real_simulate, real_classify = integrate.simulate_ensemble, _ensemble_verdicts.classify_ensemble

    def simulate(*args, **kw):
        launches.append(threading.current_thread().name)
        if len(launches) == 2:
            second_launch.set()
        return real_simulate(*args, **kw)

    def classify(*args, **kw):
        labellers.add(threading.current_thread().name)
        if not overlapped:
            overlapped.append(second_launch.wait(60))
        return real_classify(*args, **kw)

    monkeypatch.setattr(integrate, "simulate_ensemble", simulate)
    monkeypatch.setattr(_ensemble_verdicts, "classify_ensemble", classify)
    out = tmp_path / "ens.parquet"
    assert main([*CLASSIFY, "--backend", "gpu", "--out", str(out)]) == 0
    assert overlapped == [True]
    assert set(launches) == {threading.main_thread().name} and len(launches) == 3
    assert labellers and all(n.startswith("chaoscam-labels") for n in labellers)
    _same_as(out, cpu_run)


def test_the_cpu_runs_its_parts_one_after_another(monkeypatch, tmp_path):
    """Without a GPU (--backend gpu falling back, or cpu) no labelling thread is started:
    every part is labelled in the command's thread."""
    monkeypatch.setattr(_gpu, "gpu_status", lambda: (False, "no CUDA device (test)"))
    real, labellers = _ensemble_verdicts.classify_ensemble, set()

    def classify(*args, **kw):
        labellers.add(threading.current_thread().name)
        return real(*args, **kw)

    monkeypatch.setattr(_ensemble_verdicts, "classify_ensemble", classify)
    assert main([*CLASSIFY, "--backend", "gpu", "--out", str(tmp_path / "e.parquet")]) == 0
    assert labellers == {threading.main_thread().name}


def test_a_ctrl_c_in_a_launch_stops_the_labels_and_resumes(
    device, monkeypatch, tmp_path, capsys, cpu_run
):
    """Ctrl-C during the third launch: the labels of the second part stop or finish, the one
    message counts the parts kept, no thread is left, and --resume gives the CPU's outputs."""
    import chaoscam.integrate as integrate

    real, calls = integrate.simulate_ensemble, []

    def simulate(*args, **kw):
        calls.append(1)
        if len(calls) == 3:
            raise KeyboardInterrupt
        return real(*args, **kw)

    monkeypatch.setattr(integrate, "simulate_ensemble", simulate)
    before = threading.active_count()
    out = tmp_path / "ens.parquet"
    assert main([*CLASSIFY, "--backend", "gpu", "--out", str(out)]) == 130
    assert threading.active_count() == before
    said = [line for line in capsys.readouterr().err.splitlines() if "interrupted" in line]
    done = sorted((tmp_path / "ens.parts").glob("*.done"))
    assert len(said) == 1 and "--resume" in said[0]
    assert 1 <= len(done) <= 2  # the first part; the second's labels stopped or finished
    assert f"{2 * len(done)} of 5 members are finished" in said[0]
    monkeypatch.setattr(integrate, "simulate_ensemble", real)
    assert main([*CLASSIFY, "--backend", "gpu", "--resume", "--out", str(out)]) == 0
    _same_as(out, cpu_run)


def test_a_stop_reaches_the_labels_under_way(device, monkeypatch, tmp_path, capsys):
    """Ctrl-C while the labelling thread is in a part's first verdict: the labelling stops
    before the next member (StopRequested), not at the part's end, so nothing is kept; a
    second Ctrl-C while it stops is ignored, and the one message still counts what is kept."""
    import os
    import signal

    import chaoscam.integrate as integrate
    from chaoscam.sweep._pipeline import PipelineBackend

    real_simulate, real_verdicts = integrate.simulate_ensemble, _ensemble_verdicts._member
    real_cancel = PipelineBackend.cancel
    labelling, cancelled, verdicts, calls = threading.Event(), threading.Event(), [], []

    def verdict(*args, **kw):
        verdicts.append(threading.current_thread().name)
        labelling.set()
        assert cancelled.wait(60)  # the stop is asked while this member is labelled
        os.kill(os.getpid(), signal.SIGINT)  # a second Ctrl-C while the labels stop
        return real_verdicts(*args, **kw)

    def simulate(*args, **kw):
        calls.append(1)
        if len(calls) == 2:  # the first part's labels are under way on the other thread
            assert labelling.wait(60)
            raise KeyboardInterrupt
        return real_simulate(*args, **kw)

    def cancel(self, futures):
        real_cancel(self, futures)
        cancelled.set()

    monkeypatch.setattr(_ensemble_verdicts, "_member", verdict)
    monkeypatch.setattr(integrate, "simulate_ensemble", simulate)
    monkeypatch.setattr(PipelineBackend, "cancel", cancel)
    out = tmp_path / "ens.parquet"
    assert main([*CLASSIFY, "--backend", "gpu", "--out", str(out)]) == 130
    assert verdicts == ["chaoscam-labels_0"]  # one member of the part's two, then the stop
    err = capsys.readouterr().err
    assert "0 of 5 members are finished" in err and err.count("interrupted") == 1
    assert not list((tmp_path / "ens.parts").glob("*.done"))
