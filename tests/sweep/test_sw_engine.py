"""The ensemble engine: sweeps in batches through the compiled ensemble call.

Its realizations must be the process engine's bit for bit, its labels the ones
``classify_ensemble`` gives those realizations, and its records independent of the thread
count, the batch size and an interruption.
"""

import pandas as pd
import pytest

from chaoscam import Params, classify_ensemble
from chaoscam.integrate import simulate_ensemble
from chaoscam.sweep import Axis, SweepError, _batch, bifurcation, realization_index, regime_map

from ._helpers import SpreadClassifier, frames_equal

# xi = 0.2: a certified period 1 at sigma = 0; sigma = 2 mm: a random, chaotic response
XI = Axis("xi", (0.2, 0.3))
SIGMA = Axis("l_lambda_sigma", (0.0, 0.002))
KW = dict(realizations=3, seed=5, duration=6.0, transient=3.0, base=Params())
SAME = [
    "cell",
    "index",
    "seed",
    "sim_index",
    "status",
    "n_section",
    "n_impacts",
    "contact_fraction",
    "truncated_mass",
]


@pytest.fixture(scope="module")
def maps():
    return {e: regime_map(XI, SIGMA, engine=e, workers=2, **KW) for e in ("ensemble", "process")}


def test_the_engines_simulate_the_same_realizations(maps):
    """Same runs on both engines; the configuration says which engine ran."""
    a, b = maps["ensemble"], maps["process"]
    frames_equal(a.realizations[SAME], b.realizations[SAME])
    assert a.config["engine"] == "ensemble" and b.config["engine"] == "process"
    assert a.config["classifier"] != b.config["classifier"]


def test_ensemble_labels_are_those_of_classify_ensemble(maps):
    """Each label is classify_ensemble's verdict on simulate_ensemble of the same member."""
    rows = maps["ensemble"].realizations
    for _, row in rows.iterrows():
        p = Params().replace(xi=row["xi"], l_lambda_sigma=row["l_lambda_sigma"])
        ens = simulate_ensemble(
            p,
            [realization_index(row["cell"], row["index"])],
            seed=5,
            duration=6.0,
            transient=3.0,
            tangent=True,
        )
        member = classify_ensemble(ens, p).members.iloc[0]
        assert (member["label"], member["period"]) == (row["label"], row["period"])
    det = rows[rows["l_lambda_sigma"] == 0.0]
    assert set(det["label"]) <= {"periodic", "chaotic"} and len(det) == 2  # one run a cell
    assert (det.loc[det["xi"] == 0.2, "period"] == 1).all()
    assert rows["ev_exponent"].notna().all()


def test_a_window_too_short_to_judge_is_extended_on_both_engines():
    """Fewer than 2 section points after the transient (0.2 s recorded, under one cam period
    past the first section): the ensemble engine extended no such member and called it
    undetermined, while the process engine extends it as classify_trajectory does."""
    kw = dict(realizations=1, seed=3, duration=0.5, transient=0.3, workers=1)
    x, y = Axis("l_lambda", (0.008,)), SIGMA
    a, b = (regime_map(x, y, engine=e, **kw).realizations for e in ("ensemble", "process"))
    assert (a["n_section"] < 2).all()
    same = [*SAME, "label", "period", "recorded_s"]
    frames_equal(a[same], b[same])
    assert "undetermined" not in set(a["label"])
    assert (a["recorded_s"] > 0.2 + 1e-9).all()  # the extension's time is what the table says


def test_threads_and_batches_do_not_change_the_table(maps, monkeypatch):
    """One thread and batches of one member give the two-thread table bit for bit."""
    monkeypatch.setattr(_batch, "batch_size", lambda *a, **k: 1)
    one = regime_map(XI, SIGMA, engine="ensemble", workers=1, **KW)
    frames_equal(one.realizations, maps["ensemble"].realizations)
    frames_equal(one.cells, maps["ensemble"].cells)


def test_few_tasks_are_spread_over_every_thread(maps, monkeypatch):
    """A sweep of fewer tasks than a batch holds runs them as several smaller batches, one
    a thread at once (guided: at most the tasks left over twice the threads), not as one
    batch on one thread while the other waits; the table is the same."""
    import threading

    monkeypatch.setattr(_batch, "batch_size", lambda *a, **k: 256)
    real, sizes, names = _batch.run_batch, [], set()

    def record(tasks, backend="cpu", extend_to=None):
        sizes.append(len(tasks))
        names.add(threading.current_thread().name)
        return real(tasks, backend, extend_to)

    monkeypatch.setattr(_batch, "run_batch", record)
    spread = regime_map(XI, SIGMA, engine="ensemble", workers=2, **KW)
    total = len(maps["ensemble"].realizations)
    assert sum(sizes) == total and max(sizes) <= -(-total // 4) and len(names) == 2
    frames_equal(spread.realizations, maps["ensemble"].realizations)
    sizes.clear()
    regime_map(XI, SIGMA, engine="ensemble", workers=1, **KW)
    assert sizes == [total]  # one thread: nothing to spread, one batch


def test_an_interrupted_ensemble_map_resumes_to_the_same_table(maps, tmp_path, monkeypatch):
    """Ctrl-C after the first batch saves it; --resume finishes to the whole table (one
    worker: the batches run one after another in this thread)."""
    from chaoscam.sweep import SweepInterrupted

    monkeypatch.setattr(_batch, "batch_size", lambda *a, **k: 2)
    real, calls = _batch.run_batch, []

    def interrupt_second(tasks, backend="cpu", extend_to=None):
        calls.append(len(tasks))
        if len(calls) == 2:
            raise KeyboardInterrupt
        return real(tasks, backend, extend_to)

    out = tmp_path / "map.parquet"
    monkeypatch.setattr(_batch, "run_batch", interrupt_second)
    with pytest.raises(SweepInterrupted) as err:
        regime_map(XI, SIGMA, engine="ensemble", out=out, workers=1, **KW)
    assert "2 of" in str(err.value) and "--resume" in str(err.value)
    monkeypatch.setattr(_batch, "run_batch", real)
    done = regime_map(XI, SIGMA, engine="ensemble", out=out, resume=True, workers=1, **KW)
    frames_equal(done.realizations, maps["ensemble"].realizations)


def _noting_a_stop(run_batch, stopped: list, tasks, backend, extend_to):
    """``run_batch``'s records; a batch stopped on request (StopRequested, raised again)
    has its size noted in ``stopped``."""
    from chaoscam.integrate._driver import StopRequested

    try:
        return run_batch(tasks, backend, extend_to)
    except StopRequested:
        stopped.append(len(tasks))
        raise


def test_two_workers_run_batches_on_threads_and_a_ctrl_c_stops_them(maps, tmp_path, monkeypatch):
    """With two workers the batches run on two threads at once, each member by member
    (no prange launch); a Ctrl-C in the waiting driver saves the finished batches, stops
    the running one at its next compiled call, leaves no thread behind, and --resume
    finishes to the table of one thread."""
    import threading

    from chaoscam.integrate import _members
    from chaoscam.sweep import SweepInterrupted, _backends

    monkeypatch.setattr(_batch, "batch_size", lambda *a, **k: 2)
    monkeypatch.setattr(_members, "members_kernel", None)  # a prange launch would fail
    seen, stopped, waits, calls = set(), [], [], []
    interrupted = threading.Event()
    real_run, real_wait = _batch.run_batch, _backends.ThreadBackend.wait_any

    def on_thread(tasks, backend="cpu", extend_to=None):
        seen.add(threading.current_thread().name)
        calls.append(1)
        if len(calls) == 2:  # the second batch is under way when Ctrl-C comes
            assert interrupted.wait(60)
        return _noting_a_stop(real_run, stopped, tasks, backend, extend_to)

    def ctrl_c_on_second_wait(self, futures):
        waits.append(1)
        if len(waits) == 2:  # after the first finished batch was stored
            interrupted.set()
            raise KeyboardInterrupt
        return real_wait(self, futures)

    monkeypatch.setattr(_batch, "run_batch", on_thread)
    monkeypatch.setattr(_backends.ThreadBackend, "wait_any", ctrl_c_on_second_wait)
    before = threading.active_count()
    out = tmp_path / "map.parquet"
    with pytest.raises(SweepInterrupted) as err:
        regime_map(XI, SIGMA, engine="ensemble", out=out, workers=2, **KW)
    saved = int(str(err.value).split(" of ")[0].split()[-1])
    assert 2 <= saved < 8 and "--resume" in str(err.value)
    assert threading.active_count() == before  # the batch threads were joined
    assert len(seen) == 2 and all(n.startswith("chaoscam-batch") for n in seen)
    assert stopped  # a batch under way stopped between two compiled calls
    monkeypatch.setattr(_batch, "run_batch", real_run)
    monkeypatch.setattr(_backends.ThreadBackend, "wait_any", real_wait)
    done = regime_map(XI, SIGMA, engine="ensemble", out=out, resume=True, workers=2, **KW)
    frames_equal(done.realizations, maps["ensemble"].realizations)


def test_a_sweep_beside_an_interrupted_caller_stops_and_resumes(maps, tmp_path, monkeypatch):
    """A map on a thread beside its caller (experiments._side_by_side.beside: the report's
    (ω, ξ) map) gets no Ctrl-C itself: when the caller is interrupted, the map's engine sees
    its thread's stop request while it waits (every STOP_POLL_S), saves the finished batch,
    stops the running one at its next compiled call, joins its threads, and --resume
    finishes to the table of one run."""
    import threading
    import time

    from chaoscam.experiments._side_by_side import beside
    from chaoscam.sweep import SweepInterrupted, _engine

    monkeypatch.setattr(_batch, "batch_size", lambda *a, **k: 2)
    stored_one, interrupted = threading.Event(), threading.Event()
    stopped, waits = [], []
    real_run, real_finished = _batch.run_batch, _engine._finished

    def held_back(tasks, backend="cpu", extend_to=None):
        if threading.current_thread().name.endswith("_1"):  # the second thread's batches
            assert interrupted.wait(60)
            time.sleep(10 * _engine.STOP_POLL_S)  # until the engine has seen the request
        return _noting_a_stop(real_run, stopped, tasks, backend, extend_to)

    def finished(backend, futures):
        waits.append(1)
        if len(waits) > 1:  # the loop waits again once a batch was stored
            stored_one.set()
        return real_finished(backend, futures)

    monkeypatch.setattr(_batch, "run_batch", held_back)
    monkeypatch.setattr(_engine, "_finished", finished)
    before = threading.active_count()
    out = tmp_path / "map.parquet"
    with pytest.raises(KeyboardInterrupt):
        with beside(
            None, regime_map, XI, SIGMA, engine="ensemble", out=out, workers=2, **KW
        ) as fut:
            assert stored_one.wait(60)
            interrupted.set()
            raise KeyboardInterrupt
    err = fut.exception()
    assert isinstance(err, SweepInterrupted) and "--resume" in str(err)
    saved = int(str(err).split(" of ")[0].split()[-1])
    assert 2 <= saved < 8
    assert stopped  # the batch under way stopped between two compiled calls
    assert threading.active_count() == before  # the map's and beside's threads joined
    monkeypatch.setattr(_batch, "run_batch", real_run)
    monkeypatch.setattr(_engine, "_finished", real_finished)
    done = regime_map(XI, SIGMA, engine="ensemble", out=out, resume=True, workers=2, **KW)
    frames_equal(done.realizations, maps["ensemble"].realizations)


def test_bifurcation_points_are_the_same_on_both_engines():
    """Sections of a diagram with continuation: equal on both engines."""
    kw = dict(duration=4.0, transient=2.0, initial_conditions=2, continuation=True)
    a = bifurcation("xi", "0.2:0.3:3", engine="ensemble", **kw)
    b = bifurcation("xi", "0.2:0.3:3", engine="process", workers=1, **kw)
    cols = [c for c in a.points.columns if c not in ("label", "period")]
    frames_equal(a.points[cols], b.points[cols])
    assert a.config["engine"] == "ensemble"


@pytest.mark.parametrize(
    ("kw", "words"),
    [
        (dict(engine="fast"), "engine = 'fast' must be one of"),
        (dict(engine="ensemble", classify=SpreadClassifier()), "use engine='process'"),
        (dict(engine="ensemble", lyapunov=True), "without lyapunov"),
        (dict(engine="ensemble", base=Params(integrator="adaptive")), "RK4"),
        (dict(engine="process", device="gpu"), r"device \(--device\) applies to engine='ensemble'"),
        (dict(device="tpu"), "device = 'tpu'"),
    ],
)
def test_bad_engine_choices_are_refused_with_the_reason(kw, words):
    with pytest.raises(SweepError, match=words):
        regime_map(XI, SIGMA, duration=1.0, **kw)


def test_auto_picks_the_process_engine_for_another_classifier():
    m = regime_map(XI, SIGMA, duration=1.0, classify=SpreadClassifier(), workers=1)
    assert m.config["engine"] == "process"
    assert isinstance(m.realizations, pd.DataFrame)


def test_the_sweeps_default_extension_is_classify_trajectorys():
    from chaoscam.classify import EXTEND_TO
    from chaoscam.sweep._tasks import DefaultClassifier

    assert DefaultClassifier().extend_to == _batch.BatchTask(()).extend_to == EXTEND_TO


def test_a_capped_extension_is_recorded_and_honoured():
    """DefaultClassifier(extend_to=None) on the ensemble engine: never extended, and the
    configuration says so."""
    from chaoscam.sweep._tasks import DefaultClassifier

    m = regime_map(
        Axis("xi", (0.3,)),
        Axis("omega", (26.0,)),
        duration=20.0,
        transient=10.0,
        classify=DefaultClassifier(extend_to=None),
    )  # 7 bands round an unstable orbit: undetermined on 10 s, chaotic on 40 s
    assert m.config["engine"] == "ensemble" and "extend_to=None" in m.config["classifier"]
    row = m.realizations.iloc[0]
    assert row["label"] == "undetermined" and "run longer" in row["reasons"]


@pytest.mark.parametrize("first", ["regime_map", "cli_progress_batch"])
def test_process_engine_forks_after_the_ensemble_engine_ran(first):
    """A fresh process that first runs the ensemble engine with two workers (its batch
    threads run members one by one: numba's threads are never started), or asks for the
    thread count as ``chaoscam ensemble`` does before its first launch (which starts them
    and fixes the layer), then forks a process-engine pool: the layer is unset or the
    fork-safe one and the workers live (with the GNU OpenMP layer every worker was killed
    at its fork: "lost its worker 4 times")."""
    import subprocess
    import sys
    from pathlib import Path

    setup = {
        "regime_map": "regime_map(x, y, realizations=2, duration=1.0, workers=2, "
        "engine='ensemble')",
        "cli_progress_batch": "from chaoscam.cli import _ensemble; "
        "_ensemble._progress_batch('cpu')",
    }[first]
    code = (
        "import numba; from chaoscam.sweep import Axis, regime_map; "
        "x = Axis('l_lambda', (0.008, 0.01)); y = Axis('l_lambda_sigma', (0.0, 0.002)); "
        f"{setup}\ntry:\n    print(numba.threading_layer())\nexcept ValueError:\n"
        "    print('unset')\n"
        "m = regime_map(x, y, realizations=2, duration=1.0, workers=2, engine='process'); "
        "print(len(m.realizations))"
    )
    root = Path(__file__).resolve().parents[2]
    run = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, cwd=root)
    assert run.returncode == 0, run.stderr[-2000:]
    layer = {"regime_map": "unset", "cli_progress_batch": "workqueue"}[first]
    assert run.stdout.split() == [layer, "6"]
    assert "Terminating" not in run.stderr


def test_the_table_says_how_long_the_label_was_recorded():
    """recorded_s is the extended run's recorded time where the default classifier extended
    an undetermined verdict (here 3 s -> 120 s), else the run's own."""
    from chaoscam import classify_trajectory, simulate

    m = regime_map(
        Axis("xi", (0.3,)),
        Axis("l_lambda_sigma", (0.002,)),
        engine="process",
        workers=1,
        **{**KW, "realizations": 1},
    )
    row = m.realizations.iloc[0]
    p = Params(xi=0.3, l_lambda_sigma=0.002)
    traj = simulate(
        p, duration=6.0, transient=3.0, seed=5, index=int(row["sim_index"]), series=False
    )
    v = classify_trajectory(traj)
    extended = v.settings.get("extended")
    assert extended is not None and row["recorded_s"] == extended["recorded_s"] == 120.0


@pytest.mark.parametrize("ready", [True, False])
def test_a_gpu_sweep_runs_large_batches_only_where_a_gpu_can_run(monkeypatch, ready):
    """A GPU thread runs one member, so GPU batches hold GPU_MAP_BATCH members; where no GPU
    can run, device="gpu" falls back to the CPU's batches."""
    import contextlib

    from chaoscam.integrate import _gpu
    from chaoscam.sweep import DefaultClassifier

    monkeypatch.setattr(_gpu, "gpu_status", lambda: (ready, "test"))
    said = contextlib.nullcontext() if ready else pytest.warns(_gpu.GPUFallbackWarning)
    with said:
        eng = _batch.resolve_engine(
            "ensemble", "gpu", DefaultClassifier(), "id", Params(), (20.0, 0.0), 2, None
        )
    cpu = _batch.resolve_engine(
        "ensemble", "cpu", DefaultClassifier(), "id", Params(), (20.0, 0.0), 2, None
    )
    assert eng.name == "ensemble" and cpu.pack_size < _batch.GPU_MAP_BATCH
    assert eng.pack_size == (_batch.GPU_MAP_BATCH if ready else cpu.pack_size)
    assert _batch.engine_device(eng, "gpu") == ("gpu" if ready else "cpu")


@pytest.mark.parametrize(("device", "large"), [("gpu", True), ("auto", False), ("cpu", False)])
def test_dask_workers_asked_for_their_gpus_get_batches_a_gpu_can_fill(device, large):
    """On Dask the driver cannot see the workers' devices: device="gpu" sends batches of
    GPU_MAP_BATCH (CPU-sized ones held a GPU for one member's run time each); "auto", settled
    on each worker by its batch's size, and "cpu" keep the CPU's batches."""
    from chaoscam.sweep import DefaultClassifier

    eng = _batch.resolve_engine(
        "ensemble", device, DefaultClassifier(), "id", Params(), (20.0, 0.0), None, object()
    )
    assert (eng.pack_size == _batch.GPU_MAP_BATCH) is large
    assert not eng.pipeline  # the workers run whole batches


def test_a_gpu_sweep_without_a_gpu_says_so_once(monkeypatch):
    """device="gpu" where no GPU can run: one GPUFallbackWarning for the sweep, and its
    records carry no fallback warning each (they ran on the CPU, as the config says)."""
    import warnings

    from chaoscam.integrate import _gpu

    monkeypatch.setattr(_gpu, "gpu_status", lambda: (False, "no CUDA device (test)"))
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        m = regime_map(
            Axis("l_lambda", (0.008,)), Axis("l_lambda_sigma", (0.001,)), realizations=2,
            duration=1.0, engine="ensemble", device="gpu", workers=2,
        )  # fmt: skip
    fallback = [w for w in caught if issubclass(w.category, _gpu.GPUFallbackWarning)]
    assert len(fallback) == 1 and "no CUDA device (test)" in str(fallback[0].message)
    assert m.config["device"] == "cpu"
    assert not m.realizations["warnings"].str.contains("GPU").any()


def test_auto_device_runs_a_small_sweep_on_the_cpu(monkeypatch):
    """device="auto" with a GPU here: a map of fewer than AUTO_GPU_MIN runs runs on the CPU
    (recorded so), without a notice; device="gpu" would have used the GPU."""
    import warnings

    from chaoscam.integrate import _gpu

    monkeypatch.setattr(_gpu, "gpu_status", lambda: (True, "Fake GPU"))
    with warnings.catch_warnings():
        warnings.simplefilter("error", _gpu.GPUFallbackWarning)
        m = regime_map(
            Axis("l_lambda", (0.008,)), Axis("l_lambda_sigma", (0.001,)), realizations=2,
            duration=1.0, engine="ensemble", device="auto", workers=2,
        )  # fmt: skip
    assert m.config["device"] == "cpu"


def test_a_batch_records_its_own_models_warnings_on_two_threads(monkeypatch):
    """Batches of 3 runs that mix two cells whose step warnings differ (each names its own
    contact period), on 2 batch threads: each record carries its own model's warnings only,
    as on the process engine (they carried their batch neighbours' too), and the process's
    warning state is as before (catch_warnings on two threads left a dead record list as
    its printer: every later warning vanished)."""
    import warnings

    from chaoscam._run_warnings import run_warnings

    monkeypatch.setattr(_batch, "batch_size", lambda *a, **k: 3)
    before = warnings.showwarning, warnings._showwarnmsg_impl, list(warnings.filters)
    base = Params(dt=8e-6)  # too coarse a step: each l_lambda's warning names its period
    m = regime_map(
        Axis("l_lambda", (0.008, 0.015)), Axis("l_lambda_sigma", (0.001,)), realizations=4,
        base=base, duration=2.0, transient=0.5, engine="ensemble", workers=2,
    )  # fmt: skip
    assert (warnings.showwarning, warnings._showwarnmsg_impl) == before[:2]
    assert list(warnings.filters) == before[2]
    for _, row in m.realizations.iterrows():
        own = run_warnings(base.replace(l_lambda=row["l_lambda"], l_lambda_sigma=0.001))
        assert own and row["warnings"] == " | ".join(own)
