"""A lost Dask scheduler, or no Dask worker: the finished runs saved, one line saying how to
resume (no FuturesCancelledError traceback, no silent wait), and --resume on local
threads ends with the table of an uninterrupted run."""

import json
import os
import re
import signal
import subprocess
import sys
import time
from contextlib import contextmanager

import pandas as pd
import pytest

from chaoscam.cli import main
from chaoscam.sweep import checkpoint_dir
from chaoscam.sweep._store import decode_part

from ._helpers import frames_equal
from .test_sw_cli import CLS, MAP, ROOT, SLOW, _start, _wait_for_parts, uninterrupted  # noqa: F401

distributed = pytest.importorskip("distributed")


def _spawn(module: str, *args: str) -> subprocess.Popen:
    return subprocess.Popen(
        [sys.executable, "-m", module, *args],
        cwd=ROOT,
        env=dict(os.environ, PYTHONPATH=str(ROOT)),  # the scheduler unpickles the tasks too
        start_new_session=True,
        stdout=subprocess.DEVNULL,
        stderr=subprocess.DEVNULL,
    )


def _stop(proc: subprocess.Popen) -> None:
    if proc.poll() is None:
        os.killpg(proc.pid, signal.SIGKILL)
    proc.wait(timeout=30)


@contextmanager
def _dask_cluster(tmp_path, workers: int):
    """A scheduler process on 127.0.0.1 and ``workers`` worker processes; yields
    (scheduler process, address)."""
    file = tmp_path / "scheduler.json"
    sched = _spawn(
        "distributed.cli.dask_scheduler",
        "--host", "127.0.0.1", "--port", "0", "--no-dashboard", "--scheduler-file", str(file),
    )  # fmt: skip
    procs = [sched]
    try:
        t0 = time.monotonic()
        while not file.exists() or not file.read_text().strip():
            assert sched.poll() is None and time.monotonic() - t0 < 60, "no scheduler"
            time.sleep(0.05)
        address = json.loads(file.read_text())["address"]
        for _ in range(workers):
            procs.append(
                _spawn(
                    "distributed.cli.dask_worker",
                    address,
                    "--nthreads",
                    "1",
                    "--no-nanny",
                    "--no-dashboard",
                )  # fmt: skip
            )
        yield sched, address
    finally:
        for proc in procs:
            _stop(proc)


def test_scheduler_killed_mid_run_saves_and_resumes_locally(tmp_path, uninterrupted):  # noqa: F811
    """SIGKILL of the Dask scheduler mid-map: exit 1 with one line naming the lost scheduler
    and --resume, no traceback; the checkpoint holds the finished runs, and --resume on
    local threads ends with the uninterrupted table."""
    out = tmp_path / "m.parquet"
    args = [*MAP, "--checkpoint-interval", "0", "--out", str(out)]
    args[args.index(CLS)] = SLOW
    with _dask_cluster(tmp_path, workers=1) as (sched, address):
        proc = _start([*args, "--scheduler", address], batch=1)  # a part per run
        try:
            _wait_for_parts(out, 2, proc)
            t_kill = time.monotonic()
            os.killpg(sched.pid, signal.SIGKILL)
            _, err = proc.communicate(timeout=60)
        finally:
            _stop(proc)
    lines = [line for line in err.splitlines() if line.strip()]
    assert proc.returncode == 1, err
    assert "Traceback" not in err and "Error:" not in err, err
    assert len(lines) == 1 and "the Dask scheduler at" in lines[0], err
    assert "was lost" in lines[0] and "--resume" in lines[0], err
    assert time.monotonic() - t_kill < 30  # stopped, not waiting for the dead scheduler
    saved = int(re.search(r"(\d+) of 33 runs are saved", lines[0]).group(1))
    parts = checkpoint_dir(out).glob("part-*.jsonl")
    assert 2 <= saved == sum(len(decode_part(p.read_bytes())) for p in parts) < 33
    assert not out.exists()
    proc = _start([*args, "--workers", "1", "--resume"])
    _, err = proc.communicate(timeout=120)
    assert proc.returncode == 0, err
    frames_equal(pd.read_parquet(out), uninterrupted.realizations)
    frames_equal(pd.read_parquet(tmp_path / "m.cells.parquet"), uninterrupted.cells)


def test_closed_connection_logs_dropped_from_the_first_connection():
    """Once a Dask backend is connected, distributed's records of a closed comm (the
    background sender's "Batched Comm Closed" traceback, which CI once printed before the
    one-line message) and of a failed reconnection reach no handler; other records do."""
    import logging

    from distributed.comm.core import CommClosedError

    from chaoscam.sweep._backends import _CLIENT_CONNECTION_LOGGERS, DaskBackend

    class Keep(logging.Handler):
        def __init__(self):
            super().__init__(logging.DEBUG)
            self.records = []

        def emit(self, record):
            self.records.append(record)

    with distributed.LocalCluster(
        n_workers=0, host="127.0.0.1", dashboard_address="127.0.0.1:0"
    ) as cluster:
        backend = DaskBackend(cluster.scheduler_address)
        backend.close()
    for name in _CLIENT_CONNECTION_LOGGERS:
        logger, keep = logging.getLogger(name), Keep()
        logger.addHandler(keep)
        try:
            try:
                raise CommClosedError("in <TCP (closed) Client->Scheduler>")
            except CommClosedError:
                logger.error("Batched Comm Closed %r", "comm", exc_info=True)
            logger.error("Failed to reconnect to scheduler after 30.00 seconds, closing client")
            logger.error("an unrelated record")
        finally:
            logger.removeHandler(keep)
        assert [r.getMessage() for r in keep.records] == ["an unrelated record"], name


def test_no_worker_says_so_and_stops(tmp_path, monkeypatch, capsys):
    """A scheduler with no worker: the driver says it is waiting (even with --quiet), then
    stops after the bounded wait with exit 1 and the resume hint, the checkpoint kept."""
    from chaoscam.sweep import _backends

    monkeypatch.setattr(_backends, "_DASK_POLL_S", 0.2)
    monkeypatch.setattr(_backends, "_DASK_NOTICE_S", 0.5)
    monkeypatch.setattr(_backends, "DASK_NO_WORKER_S", 2.0)
    out = tmp_path / "m.parquet"
    with distributed.LocalCluster(
        n_workers=0, host="127.0.0.1", dashboard_address="127.0.0.1:0"
    ) as cluster:
        t0 = time.monotonic()
        code = main([*MAP, "--scheduler", cluster.scheduler_address, "--out", str(out)])
        waited = time.monotonic() - t0
    err = capsys.readouterr().err
    assert code == 1, err
    assert "waiting: no Dask worker is connected" in err
    assert "no Dask worker was connected" in err and "--resume" in err
    assert "Traceback" not in err
    assert 2.0 <= waited < 30
    assert (checkpoint_dir(out) / "manifest.json").exists() and not out.exists()
