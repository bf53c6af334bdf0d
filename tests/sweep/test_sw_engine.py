"""The sweep engine: realizations in batches through chaoscam.solve, judged by the verdict.

Its records must be those of an independent path (``chaoscam.solve`` of the member alone,
then ``chaoscam.classify``), and independent of the thread count, the batch size and an
interruption.
"""

import inspect

import pandas as pd
import pytest

import chaoscam
from chaoscam import Numerics, Params
from chaoscam.sweep import Axis, SweepError, _engine, realization_index, regime_map

from ._helpers import SpreadClassifier, frames_equal

# xi = 0.2: a certified period 1 at sigma = 0; sigma = 2 mm: a random, chaotic response
XI = Axis("xi", (0.2, 0.3))
SIGMA = Axis("l_lambda_sigma", (0.0, 0.002))
KW = dict(realizations=3, seed=5, duration=6.0, transient=3.0, base=Params())


@pytest.fixture(scope="module")
def two_threads():
    return regime_map(XI, SIGMA, workers=2, **KW)


def test_labels_are_those_of_classify_on_the_member_alone(two_threads):
    """Each label is chaoscam.classify's verdict on chaoscam.solve of the same member alone;
    the deterministic cells run once, and every run has its tangent exponent."""
    rows = two_threads.realizations
    for _, row in rows.iterrows():
        p = Params().replace(xi=row["xi"], l_lambda_sigma=row["l_lambda_sigma"])
        alone = chaoscam.solve(
            p,
            indices=[realization_index(row["cell"], row["index"])],
            seed=5,
            duration=6.0,
            transient=3.0,
            tangent=True,
        )
        (verdict,) = chaoscam.classify(alone)
        period = None if pd.isna(row["period"]) else int(row["period"])
        assert (verdict.label, verdict.period) == (row["label"], period)
    det = rows[rows["l_lambda_sigma"] == 0.0]
    assert set(det["label"]) <= {"periodic", "chaotic"} and len(det) == 2  # one run a cell
    assert (det.loc[det["xi"] == 0.2, "period"] == 1).all()
    assert rows["ev_exponent"].notna().all()


def test_a_window_too_short_to_judge_is_extended():
    """Fewer than 2 section points after the transient (0.2 s recorded, under one cam period
    past the first section): the member is extended as chaoscam.classify extends it, not
    called undetermined, and the table says the extension's recorded time."""
    kw = dict(realizations=1, seed=3, duration=0.5, transient=0.3, workers=1)
    rows = regime_map(Axis("l_lambda", (0.008,)), SIGMA, **kw).realizations
    assert (rows["n_section"] < 2).all()
    assert "undetermined" not in set(rows["label"])
    assert (rows["recorded_s"] > 0.2 + 1e-9).all()  # the extension's time is what the table says


def test_threads_and_batches_do_not_change_the_table(two_threads, monkeypatch):
    """One thread and batches of one member give the two-thread table bit for bit."""
    monkeypatch.setattr(_engine, "batch_size", lambda *a, **k: 1)
    one = regime_map(XI, SIGMA, workers=1, **KW)
    frames_equal(one.realizations, two_threads.realizations)
    frames_equal(one.cells, two_threads.cells)


def test_few_tasks_are_spread_over_every_thread(two_threads, monkeypatch):
    """A sweep of fewer tasks than a batch holds runs them as several smaller batches, one
    a thread at once (guided: at most the tasks left over twice the threads), not as one
    batch on one thread while the other waits; the table is the same."""
    import threading

    monkeypatch.setattr(_engine, "batch_size", lambda *a, **k: 256)
    real, sizes, names = _engine.run_batch, [], set()

    def record(batch):
        sizes.append(len(batch.tasks))
        names.add(threading.current_thread().name)
        return real(batch)

    monkeypatch.setattr(_engine, "run_batch", record)
    spread = regime_map(XI, SIGMA, workers=2, **KW)
    total = len(two_threads.realizations)
    assert sum(sizes) == total and max(sizes) <= -(-total // 4) and len(names) == 2
    frames_equal(spread.realizations, two_threads.realizations)
    sizes.clear()
    regime_map(XI, SIGMA, workers=1, **KW)
    assert sizes == [total]  # one thread: nothing to spread, one batch


def test_an_interrupted_map_resumes_to_the_same_table(two_threads, tmp_path, monkeypatch):
    """Ctrl-C after the first batch saves it; --resume finishes to the whole table (one
    worker: the batches run one after another in this thread)."""
    from chaoscam.sweep import SweepInterrupted

    monkeypatch.setattr(_engine, "batch_size", lambda *a, **k: 2)
    real, calls = _engine.run_batch, []

    def interrupt_second(batch):
        calls.append(len(batch.tasks))
        if len(calls) == 2:
            raise KeyboardInterrupt
        return real(batch)

    out = tmp_path / "map.parquet"
    monkeypatch.setattr(_engine, "run_batch", interrupt_second)
    with pytest.raises(SweepInterrupted) as err:
        regime_map(XI, SIGMA, out=out, workers=1, **KW)
    assert "2 of" in str(err.value) and "--resume" in str(err.value)
    monkeypatch.setattr(_engine, "run_batch", real)
    done = regime_map(XI, SIGMA, out=out, resume=True, workers=1, **KW)
    frames_equal(done.realizations, two_threads.realizations)


def _noting_a_stop(run_batch, stopped: list, batch):
    """``run_batch``'s records; a batch stopped on request (StopRequested, raised again)
    has its size noted in ``stopped``."""
    from chaoscam.kernel import StopRequested

    try:
        return run_batch(batch)
    except StopRequested:
        stopped.append(len(batch.tasks))
        raise


def test_two_workers_run_batches_on_threads_and_a_ctrl_c_stops_them(
    two_threads, tmp_path, monkeypatch
):
    """With two workers the batches run on two threads at once, each member by member
    (no prange launch); a Ctrl-C in the waiting driver saves the finished batches, stops
    the running one at its next compiled call, leaves no thread behind, and --resume
    finishes to the table of one run."""
    import threading

    from chaoscam.simulation import _batch
    from chaoscam.sweep import SweepInterrupted, _backends

    monkeypatch.setattr(_engine, "batch_size", lambda *a, **k: 2)
    monkeypatch.setattr(_batch, "members_kernel", None)  # a prange launch would fail
    seen, stopped, waits, calls = set(), [], [], []
    interrupted = threading.Event()
    real_run, real_wait = _engine.run_batch, _backends.ThreadBackend.wait_any

    def on_thread(batch):
        seen.add(threading.current_thread().name)
        calls.append(1)
        if len(calls) == 2:  # the second batch is under way when Ctrl-C comes
            assert interrupted.wait(60)
        return _noting_a_stop(real_run, stopped, batch)

    def ctrl_c_on_second_wait(self, futures, timeout=None):
        waits.append(1)
        if len(waits) == 2:  # after the first finished batch was stored
            interrupted.set()
            raise KeyboardInterrupt
        return real_wait(self, futures, timeout)

    monkeypatch.setattr(_engine, "run_batch", on_thread)
    monkeypatch.setattr(_backends.ThreadBackend, "wait_any", ctrl_c_on_second_wait)
    before = threading.active_count()
    out = tmp_path / "map.parquet"
    with pytest.raises(SweepInterrupted) as err:
        regime_map(XI, SIGMA, out=out, workers=2, **KW)
    saved = int(str(err.value).split(" of ")[0].split()[-1])
    assert 2 <= saved < 8 and "--resume" in str(err.value)
    assert threading.active_count() == before  # the batch threads were joined
    assert len(seen) == 2 and all(n.startswith("chaoscam-batch") for n in seen)
    assert stopped  # a batch under way stopped between two compiled calls
    monkeypatch.setattr(_engine, "run_batch", real_run)
    monkeypatch.setattr(_backends.ThreadBackend, "wait_any", real_wait)
    done = regime_map(XI, SIGMA, out=out, resume=True, workers=2, **KW)
    frames_equal(done.realizations, two_threads.realizations)


def test_a_sweep_beside_an_interrupted_caller_stops_and_resumes(two_threads, tmp_path, monkeypatch):
    """A map on a thread beside its caller (paper._side_by_side.beside: the report's (ω, ξ)
    map) gets no Ctrl-C itself: when the caller is interrupted, the map's engine sees its
    thread's stop request while it waits (every STOP_POLL_S), saves the finished batch,
    stops the running one at its next compiled call, joins its threads, and --resume
    finishes to the table of one run."""
    import threading
    import time

    from chaoscam.paper._side_by_side import beside
    from chaoscam.sweep import SweepInterrupted

    monkeypatch.setattr(_engine, "batch_size", lambda *a, **k: 2)
    stored_one, interrupted = threading.Event(), threading.Event()
    stopped, waits = [], []
    real_run, real_finished = _engine.run_batch, _engine._finished

    def held_back(batch):
        if threading.current_thread().name.endswith("_1"):  # the second thread's batches
            assert interrupted.wait(60)
            time.sleep(10 * _engine.STOP_POLL_S)  # until the engine has seen the request
        return _noting_a_stop(real_run, stopped, batch)

    def finished(backend, futures):
        waits.append(1)
        if len(waits) > 1:  # the loop waits again once a batch was stored
            stored_one.set()
        return real_finished(backend, futures)

    monkeypatch.setattr(_engine, "run_batch", held_back)
    monkeypatch.setattr(_engine, "_finished", finished)
    before = threading.active_count()
    out = tmp_path / "map.parquet"
    with pytest.raises(KeyboardInterrupt):
        with beside(None, regime_map, XI, SIGMA, out=out, workers=2, **KW) as fut:
            assert stored_one.wait(60)
            interrupted.set()
            raise KeyboardInterrupt
    err = fut.exception()
    assert isinstance(err, SweepInterrupted) and "--resume" in str(err)
    saved = int(str(err).split(" of ")[0].split()[-1])
    assert 2 <= saved < 8
    assert stopped  # the batch under way stopped between two compiled calls
    assert threading.active_count() == before  # the map's and beside's threads joined
    monkeypatch.setattr(_engine, "run_batch", real_run)
    monkeypatch.setattr(_engine, "_finished", real_finished)
    done = regime_map(XI, SIGMA, out=out, resume=True, workers=2, **KW)
    frames_equal(done.realizations, two_threads.realizations)


@pytest.mark.parametrize(
    ("kw", "words"),
    [
        (dict(device="tpu"), "device = 'tpu'"),
        (dict(classify=SpreadClassifier(), check_step=True), "package's verdict only"),
        (dict(classify="chaoscam.classify"), "must be callable"),
    ],
)
def test_bad_engine_choices_are_refused_with_the_reason(kw, words):
    """A device the engine does not know, the step check (the package's verdict's) on a
    classifier of one's own, a classifier that cannot be called: refused before any run."""
    with pytest.raises(SweepError, match=words):
        regime_map(XI, SIGMA, duration=1.0, **kw)


def test_the_sweeps_default_extension_is_classifys():
    """The sweeps extend an undetermined verdict as far as chaoscam.classify does."""
    from chaoscam.sweep import bifurcation, ensemble
    from chaoscam.sweep._runs import Judge
    from chaoscam.verdict import EXTEND_TO

    want = inspect.signature(chaoscam.classify).parameters["extend_to"].default
    assert want == EXTEND_TO == Judge().extend_to
    for sweep in (regime_map, bifurcation, ensemble):
        assert inspect.signature(sweep).parameters["extend_to"].default == want, sweep


def test_a_capped_extension_is_recorded_and_honoured():
    """extend_to=None: never extended, and the configuration says so."""
    m = regime_map(
        Axis("xi", (0.3,)),
        Axis("omega", (26.0,)),
        duration=20.0,
        transient=10.0,
        extend_to=None,
    )  # 7 bands round an unstable orbit: undetermined on 10 s, chaotic on 40 s
    assert "extend_to=None" in m.config["classifier"]
    row = m.realizations.iloc[0]
    assert row["label"] == "undetermined" and "run longer" in row["reasons"]


def test_the_table_says_how_long_the_label_was_recorded():
    """recorded_s is the extended run's recorded time where the verdict extended an
    undetermined run (here from 3 s), else the run's own."""
    m = regime_map(
        Axis("xi", (0.3,)),
        Axis("l_lambda_sigma", (0.002,)),
        workers=1,
        **{**KW, "realizations": 1},
    )
    row = m.realizations.iloc[0]
    p = Params(xi=0.3, l_lambda_sigma=0.002)
    run = chaoscam.simulate(
        p, duration=6.0, transient=3.0, seed=5, index=int(row["sim_index"]), series=False
    )
    (v,) = chaoscam.classify(run)
    extended = v.settings.get("extended")
    assert extended is not None and row["recorded_s"] == extended["recorded_s"] > 3.0


def _gpu_here(monkeypatch, ready: bool, why: str) -> None:
    """gpu_status says (ready, why), wherever the sweep and solve ask."""
    import chaoscam.kernel
    from chaoscam.kernel import _gpu
    from chaoscam.simulation import _solve

    status = lambda: (ready, why)  # noqa: E731
    monkeypatch.setattr(_gpu, "gpu_status", status)
    monkeypatch.setattr(chaoscam.kernel, "gpu_status", status, raising=False)
    monkeypatch.setattr(_solve, "gpu_status", status)


@pytest.mark.parametrize("ready", [True, False])
def test_a_gpu_sweep_runs_large_batches_only_where_a_gpu_can_run(monkeypatch, ready):
    """A GPU thread runs one member, so GPU batches hold GPU_BATCH members, launched by
    the pipeline; where no GPU can run, device="gpu" falls back to the CPU's batches."""
    import contextlib

    from chaoscam.kernel import GPUFallbackWarning
    from chaoscam.sweep._runs import Judge

    _gpu_here(monkeypatch, ready, "test")
    said = contextlib.nullcontext() if ready else pytest.warns(GPUFallbackWarning)
    run = (Params(), Numerics(), (20.0, 0.0), 2, None)
    with said:
        eng = _engine.resolve_engine(Judge(), "gpu", *run)
    cpu = _engine.resolve_engine(Judge(), "cpu", *run)
    assert cpu.size < _engine.GPU_BATCH and not cpu.pipeline and cpu.device == "cpu"
    assert eng.size == (_engine.GPU_BATCH if ready else cpu.size)
    assert eng.pipeline is ready and eng.device == ("gpu" if ready else "cpu")


@pytest.mark.parametrize(("device", "large"), [("gpu", True), ("auto", False), ("cpu", False)])
def test_dask_workers_asked_for_their_gpus_get_batches_a_gpu_can_fill(device, large):
    """On Dask the driver cannot see the workers' devices: device="gpu" sends batches of
    GPU_BATCH (CPU-sized ones held a GPU for one member's run time each); "auto", settled
    on each worker by its batch's size, and "cpu" keep the CPU's batches."""
    from chaoscam.sweep._runs import Judge

    eng = _engine.resolve_engine(Judge(), device, Params(), Numerics(), (20.0, 0.0), None,
                                 "tcp://127.0.0.1:8786")  # fmt: skip
    assert (eng.size == _engine.GPU_BATCH) is large
    assert not eng.pipeline  # the workers run whole batches


def test_a_gpu_sweep_without_a_gpu_says_so_once(monkeypatch):
    """device="gpu" where no GPU can run: one GPUFallbackWarning for the sweep, and its
    records carry no fallback warning each (they ran on the CPU, as the config says)."""
    import warnings

    from chaoscam.kernel import GPUFallbackWarning

    _gpu_here(monkeypatch, False, "no CUDA device (test)")
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        m = regime_map(
            Axis("l_lambda", (0.008,)), Axis("l_lambda_sigma", (0.001,)), realizations=2,
            duration=1.0, device="gpu", workers=2,
        )  # fmt: skip
    fallback = [w for w in caught if issubclass(w.category, GPUFallbackWarning)]
    assert len(fallback) == 1 and "no CUDA device (test)" in str(fallback[0].message)
    assert m.config["device"] == "cpu"
    assert not m.realizations["warnings"].str.contains("GPU").any()


def test_auto_device_runs_a_small_sweep_on_the_cpu(monkeypatch):
    """device="auto" with a GPU here: a map of fewer than AUTO_GPU_MIN runs runs on the CPU
    (recorded so), without a notice; device="gpu" would have used the GPU."""
    import warnings

    from chaoscam.kernel import GPUFallbackWarning

    _gpu_here(monkeypatch, True, "Fake GPU")
    with warnings.catch_warnings():
        warnings.simplefilter("error", GPUFallbackWarning)
        m = regime_map(
            Axis("l_lambda", (0.008,)), Axis("l_lambda_sigma", (0.001,)), realizations=2,
            duration=1.0, device="auto", workers=2,
        )  # fmt: skip
    assert m.config["device"] == "cpu"


def test_a_batch_records_its_own_models_warnings_on_two_threads(monkeypatch):
    """Batches of 3 runs that mix two cells whose step warnings differ (each names its own
    contact period), on 2 batch threads: each record carries its own model's warnings only
    (not its batch neighbours'), and the process's warning state is as before
    (catch_warnings on two threads left a dead record list as its printer: every later
    warning vanished)."""
    import warnings

    from chaoscam.simulation import run_warnings

    monkeypatch.setattr(_engine, "batch_size", lambda *a, **k: 3)
    before = warnings.showwarning, warnings._showwarnmsg_impl, list(warnings.filters)
    num = Numerics(dt=8e-6)  # too coarse a step: each l_lambda's warning names its period
    m = regime_map(
        Axis("l_lambda", (0.008, 0.015)), Axis("l_lambda_sigma", (0.001,)), realizations=4,
        numerics=num, duration=2.0, transient=0.5, workers=2,
    )  # fmt: skip
    assert (warnings.showwarning, warnings._showwarnmsg_impl) == before[:2]
    assert list(warnings.filters) == before[2]
    for _, row in m.realizations.iterrows():
        own = run_warnings(Params(l_lambda=row["l_lambda"], l_lambda_sigma=0.001), num)
        assert own and row["warnings"] == " | ".join(own)


def test_a_custom_classifier_gets_one_run_with_its_realization():
    """A classifier of one's own is called on each run as a one-member Solution: that
    realization's model, index and section, the section chaoscam.simulate gives alone."""
    seen = []

    def spy(run):
        seen.append(run)
        return SpreadClassifier()(run)

    spy.needs_series = False
    m = regime_map(Axis("l_lambda", (0.008,)), SIGMA, realizations=2, seed=3, duration=1.0,
                   transient=0.5, classify=spy, workers=1)  # fmt: skip
    assert len(seen) == len(m.realizations) == 3
    for run, (_, row) in zip(seen, m.realizations.iterrows(), strict=True):
        assert isinstance(run, chaoscam.Solution) and len(run) == 1
        assert run.index == row["sim_index"] and run.series is None
        assert run.params == Params(l_lambda=0.008, l_lambda_sigma=row["l_lambda_sigma"])
        alone = chaoscam.simulate(run.params, duration=1.0, transient=0.5, seed=3,
                                  index=run.index, series=False)  # fmt: skip
        pd.testing.assert_frame_equal(run.section, alone.section, check_exact=True)
