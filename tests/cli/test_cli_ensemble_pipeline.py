"""``chaoscam ensemble`` on a GPU (the sweep engine's PipelineBackend): the next batch is
launched while the last is labelled, with the CPU's outputs, and a Ctrl-C stops both.

A stand-in device runs the CPU's kernel (so its outputs equal a CPU run's bit for bit);
events, not timings, show that a launch and a labelling overlap.
"""

import threading

import numpy as np
import pandas as pd
import pytest

from chaoscam.cli import main
from chaoscam.sweep import _engine, checkpoint_dir
from chaoscam.sweep._runs import Batch
from chaoscam.sweep._store import decode_part

from .test_cli_ensemble import ARGS

CLASSIFY = [*ARGS, "--classify"]


def _gpu_status(monkeypatch, ready: bool, why: str) -> None:
    import chaoscam.kernel
    from chaoscam.kernel import _gpu
    from chaoscam.simulation import _solve

    status = lambda: (ready, why)  # noqa: E731
    for module in (_gpu, _solve, chaoscam.kernel):
        monkeypatch.setattr(module, "gpu_status", status, raising=False)


@pytest.fixture
def device(monkeypatch):
    """A stand-in GPU that runs its launches on the CPU's kernel; batches of 2 members."""
    from chaoscam.kernel import layout as k
    from chaoscam.simulation import _batch

    def on_cpu(y, cnt, c, to, lam, section, impacts, status, hand_back, keep_impacts=False):
        series = np.empty((y.shape[0], 1, k.SERIES_COLS))  # a GPU keeps no series
        _batch.run_on_cpu(y, cnt, c, to, lam, series, section, impacts, status, hand_back)

    _gpu_status(monkeypatch, True, "Stand-in GPU")
    monkeypatch.setattr(_batch, "run_on_gpu", on_cpu)
    monkeypatch.setattr(_engine, "GPU_BATCH", 2)


@pytest.fixture(scope="module")
def cpu_run(tmp_path_factory):
    """The same command on the CPU: (members, sections)."""
    out = tmp_path_factory.mktemp("cpu") / "ens.parquet"
    assert main([*CLASSIFY, "--device", "cpu", "--out", str(out)]) == 0
    return pd.read_parquet(out), pd.read_parquet(out.with_suffix(".sections.parquet"))


def _same_as(out, cpu_run) -> None:
    members, sections = cpu_run
    pd.testing.assert_frame_equal(pd.read_parquet(out), members)
    pd.testing.assert_frame_equal(pd.read_parquet(out.with_suffix(".sections.parquet")), sections)


def test_the_next_batch_is_launched_while_the_last_is_labelled(
    device, monkeypatch, tmp_path, cpu_run
):
    """The first batch's labels wait (up to 60 s) for the second batch's launch to begin:
    with launches and labels one after another they would wait in vain. Launches run in the
    command's thread, labels on the labelling thread; the outputs are the CPU run's."""
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
    out = tmp_path / "ens.parquet"
    assert main([*CLASSIFY, "--device", "gpu", "--out", str(out)]) == 0
    assert overlapped == [True]
    assert set(launches) == {threading.main_thread().name} and len(launches) == 3
    assert labellers and all(n.startswith("chaoscam-labels") for n in labellers)
    _same_as(out, cpu_run)


def test_the_cpu_runs_its_batches_one_after_another(monkeypatch, tmp_path):
    """Without a GPU (--device gpu falling back, or cpu) and one worker, no labelling thread
    is started: every batch is labelled in the command's thread."""
    _gpu_status(monkeypatch, False, "no CUDA device (test)")
    real, labellers = Batch.label, set()

    def label(self, launched):
        labellers.add(threading.current_thread().name)
        return real(self, launched)

    monkeypatch.setattr(Batch, "label", label)
    assert main([*CLASSIFY, "--device", "gpu", "--out", str(tmp_path / "e.parquet")]) == 0
    assert labellers == {threading.main_thread().name}


def _saved(out) -> int:
    return sum(len(decode_part(p.read_bytes())) for p in checkpoint_dir(out).glob("part-*"))


def test_a_ctrl_c_in_a_launch_stops_the_labels_and_resumes(
    device, monkeypatch, tmp_path, capsys, cpu_run
):
    """Ctrl-C during the third launch: the labels of the second batch stop or finish, the one
    message counts the runs kept, no thread is left, and --resume gives the CPU's outputs."""
    real, calls = Batch.launch, []

    def launch(self):
        calls.append(1)
        if len(calls) == 3:
            raise KeyboardInterrupt
        return real(self)

    monkeypatch.setattr(Batch, "launch", launch)
    before = threading.active_count()
    out = tmp_path / "ens.parquet"
    assert main([*CLASSIFY, "--device", "gpu", "--out", str(out)]) == 130
    assert threading.active_count() == before
    said = [line for line in capsys.readouterr().err.splitlines() if "interrupted" in line]
    saved = _saved(out)
    assert len(said) == 1 and "--resume" in said[0]
    assert saved in (2, 4)  # the first batch; the second's labels stopped or finished
    assert f"{saved} of 5 runs are saved" in said[0]
    monkeypatch.setattr(Batch, "launch", real)
    assert main([*CLASSIFY, "--device", "gpu", "--resume", "--out", str(out)]) == 0
    _same_as(out, cpu_run)


def test_a_stop_reaches_the_labels_under_way(device, monkeypatch, tmp_path, capsys):
    """Ctrl-C while the labelling thread is in a batch's first verdict: the labelling stops
    before the next member (StopRequested), not at the batch's end, so nothing is kept; a
    second Ctrl-C while it stops is ignored, and the one message still counts what is kept."""
    import os
    import signal

    from chaoscam.sweep._backends import PipelineBackend
    from chaoscam.verdict import _classify

    real_launch, real_verdict = Batch.launch, _classify.judge_member
    real_cancel = PipelineBackend.cancel
    labelling, cancelled, verdicts, calls = threading.Event(), threading.Event(), [], []

    def verdict(*args, **kw):
        verdicts.append(threading.current_thread().name)
        labelling.set()
        assert cancelled.wait(60)  # the stop is asked while this member is labelled
        os.kill(os.getpid(), signal.SIGINT)  # a second Ctrl-C while the labels stop
        return real_verdict(*args, **kw)

    def launch(self):
        calls.append(1)
        if len(calls) == 2:  # the first batch's labels are under way on the other thread
            assert labelling.wait(60)
            raise KeyboardInterrupt
        return real_launch(self)

    def cancel(self, futures):
        real_cancel(self, futures)
        cancelled.set()

    monkeypatch.setattr(_classify, "judge_member", verdict)
    monkeypatch.setattr(Batch, "launch", launch)
    monkeypatch.setattr(PipelineBackend, "cancel", cancel)
    out = tmp_path / "ens.parquet"
    assert main([*CLASSIFY, "--device", "gpu", "--out", str(out)]) == 130
    assert verdicts == ["chaoscam-labels_0"]  # one member of the batch's two, then the stop
    err = capsys.readouterr().err
    assert "0 of 5 runs are saved" in err and err.count("interrupted") == 1
    assert _saved(out) == 0
