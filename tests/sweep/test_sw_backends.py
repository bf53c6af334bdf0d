"""Backends: the same table for any thread count, local threads or Dask, lost Dask workers."""

import os

import pytest

from chaoscam.sweep import Axis, bifurcation, realization_index, regime_map

from ._helpers import (
    InterruptOnce,
    KillOnceClassifier,
    ParityClassifier,
    SpreadClassifier,
    frames_equal,
)

MU = Axis("l_lambda", (0.006, 0.010))
SIGMA = Axis("l_lambda_sigma", (0.0, 0.002))
KW = dict(realizations=3, seed=11, duration=1.5, transient=0.5, classify=SpreadClassifier())
ADAPTIVE = dict(
    KW, realizations=2, classify=ParityClassifier(), target_halfwidth=0.3, max_realizations=6
)


def _assert_dead(marker):
    """The worker that wrote ``marker`` (its pid) no longer runs."""
    pid = int(marker.read_text())
    with pytest.raises(ProcessLookupError):
        os.kill(pid, 0)


@pytest.fixture(scope="module")
def serial():
    return regime_map(MU, SIGMA, **KW, workers=1)


@pytest.fixture(scope="module")
def serial_adaptive():
    return regime_map(MU, SIGMA, **ADAPTIVE, workers=1)


def test_two_threads_equal_one(serial, serial_adaptive):
    """Two batch threads give the one-thread table bit for bit, adaptive cells too."""
    frames_equal(regime_map(MU, SIGMA, **KW, workers=2).realizations, serial.realizations)
    two = regime_map(MU, SIGMA, **ADAPTIVE, workers=2)
    frames_equal(two.realizations, serial_adaptive.realizations)
    frames_equal(two.cells, serial_adaptive.cells)


def test_adaptive_resume_replays_the_decisions(tmp_path, serial_adaptive):
    """Interrupted inside a cell's third batch, an adaptive map resumes to the same table."""
    out = tmp_path / "a.parquet"
    cls = InterruptOnce(str(tmp_path / "m"), realization_index(1, 4), ParityClassifier())
    with pytest.raises(KeyboardInterrupt):
        regime_map(MU, SIGMA, **{**ADAPTIVE, "classify": cls}, workers=1, out=out, flush_interval=0)
    res = regime_map(MU, SIGMA, **{**ADAPTIVE, "classify": cls}, workers=1, out=out, resume=True)
    frames_equal(res.realizations, serial_adaptive.realizations)


@pytest.fixture(scope="module")
def dask_client():
    distributed = pytest.importorskip("distributed")
    with (
        distributed.LocalCluster(
            n_workers=2,
            threads_per_worker=1,
            processes=True,
            host="127.0.0.1",
            dashboard_address="127.0.0.1:0",
        ) as cluster,
        distributed.Client(cluster) as client,
    ):
        yield client


def test_dask_equals_local_threads(dask_client, serial, serial_adaptive):
    """A Dask LocalCluster on loopback gives the local table bit for bit."""
    frames_equal(
        regime_map(MU, SIGMA, **KW, scheduler=dask_client).realizations, serial.realizations
    )
    frames_equal(
        regime_map(MU, SIGMA, **ADAPTIVE, scheduler=dask_client).cells, serial_adaptive.cells
    )


def test_dask_runs_the_package_verdicts_batches_bit_for_bit(dask_client):
    """Batches judged by the package's verdict (chaoscam.classify) on Dask workers give the
    in-process table."""
    kw = dict(realizations=2, seed=3, duration=3.0, transient=1.5)
    local = regime_map(MU, SIGMA, **kw, workers=1)
    frames_equal(
        regime_map(MU, SIGMA, **kw, scheduler=dask_client).realizations, local.realizations
    )


def test_dask_worker_lost_loses_nothing(dask_client, tmp_path, serial):
    """A Dask worker killed mid-task (SIGKILL): its task is rescheduled, nothing lost."""
    cls = KillOnceClassifier(str(tmp_path / "killed"), victim=realization_index(2, 0))
    res = regime_map(
        MU,
        SIGMA,
        **{**KW, "classify": cls},
        scheduler=dask_client,
        out=tmp_path / "d.parquet",
        flush_interval=0,
    )
    _assert_dead(tmp_path / "killed")
    frames_equal(res.realizations, serial.realizations)


def test_dask_continuation_diagram_equals_serial(dask_client):
    """Continuation chains on Dask give the in-process diagram."""
    kw = dict(
        duration=1.5,
        transient=0.5,
        classify=SpreadClassifier(),
        initial_conditions=2,
        continuation=True,
    )
    a = bifurcation("l_lambda", "0.004:0.012:3", workers=1, **kw)
    b = bifurcation("l_lambda", "0.004:0.012:3", scheduler=dask_client, **kw)
    frames_equal(a.points, b.points)
    frames_equal(a.verdicts, b.verdicts)


def test_dask_local_cluster_started_by_the_sweep(serial):
    """scheduler="local" starts (and closes) its own LocalCluster on 127.0.0.1."""
    res = regime_map(MU, SIGMA, **KW, scheduler="local", workers=2)
    frames_equal(res.realizations, serial.realizations)
