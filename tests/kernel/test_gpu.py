"""The GPU ensemble backend (numba-cuda): choice, fallback, numpy guard, kernel, and results.

Without numba-cuda (CI) the simulator and PTX tests skip; without a device the ``gpu`` tests
skip. The simulator runs the compiled CPU kernel inside the CUDA driver logic, so there the
backends agree bit for bit; on a device they agree within ``GPU_TOLERANCE``.
"""

import importlib.util
import json
import os
import subprocess
import sys
import warnings

import numpy as np
import pytest

from chaoscam import Params, extend, solve
from chaoscam.kernel import _gpu
from chaoscam.kernel import layout as k
from chaoscam.simulation import CPU_BATCH, _batch, _solve

# a chattering model (refills on the way), its run settings, and a bit-for-bit comparison
from tests.simulation.test_resume import CHAOTIC, RUN, _same

HAS_NUMBA_CUDA = importlib.util.find_spec("numba_cuda") is not None
needs_numba_cuda = pytest.mark.skipif(not HAS_NUMBA_CUDA, reason="numba-cuda not installed")


def _on_device() -> bool:
    ok, reason = _gpu.gpu_status()
    return ok and "simulator" not in reason


def sections(ens) -> np.ndarray:
    return ens.sections[["k", "t", "theta_f", "omega_f", "l_lambda"]].to_numpy()


def _gpu_status_is(monkeypatch, status) -> None:
    """What the GPU's status says, for the kernel layer and for solve, which asks it."""
    monkeypatch.setattr(_gpu, "gpu_status", lambda: status)
    monkeypatch.setattr(_solve, "gpu_status", lambda: status)


@pytest.fixture
def no_gpu(monkeypatch):
    _gpu_status_is(monkeypatch, (False, "no CUDA device (test)"))


def test_unknown_backend_is_refused():
    """A backend other than cpu, gpu or auto raises a ValueError naming the allowed values."""
    with pytest.raises(ValueError, match=r"backend must be one of 'cpu', 'gpu', 'auto'"):
        solve(Params(), indices=[0], duration=0.01, backend="cuda")


def test_gpu_without_device_falls_back_with_one_warning(no_gpu):
    """backend="gpu" without a GPU warns once, with the reason, and equals backend="cpu"."""
    p = Params(l_lambda_sigma=0.002)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        ens = solve(p, indices=range(3), seed=4, duration=0.5, backend="gpu", batch=2)
    assert len(caught) == 1
    assert issubclass(caught[0].category, _gpu.GPUFallbackWarning)
    message = str(caught[0].message)
    assert "no CUDA device (test)" in message and "CPU" in message and "\n" not in message
    cpu = solve(p, indices=range(3), seed=4, duration=0.5, backend="cpu")
    assert ens.settings["backend"] == "cpu"
    np.testing.assert_array_equal(sections(ens), sections(cpu))
    assert ens.members.equals(cpu.members)


@pytest.mark.skipif(_on_device(), reason="a GPU is available here")
def test_real_status_without_device_is_a_fallback():
    """Here (no device) the real status says why, and backend="gpu" warns with that reason."""
    ok, reason = _gpu.gpu_status()
    assert not ok and reason and "\n" not in reason
    with pytest.warns(_gpu.GPUFallbackWarning, match="GPU backend unavailable"):
        solve(Params(), indices=[0], duration=0.01, backend="gpu")


def test_auto_backend_falls_back_silently(no_gpu):
    """backend="auto" without a GPU runs on the CPU with no warning."""
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        ens = solve(Params(), indices=[0], duration=0.01, backend="auto")
    assert ens.settings["backend"] == "cpu"


@pytest.fixture
def fake_gpu(monkeypatch) -> list[int]:
    """A GPU "Fake GPU" that runs its launches on the CPU; returns the members of each."""
    _gpu_status_is(monkeypatch, (True, "Fake GPU"))
    launched = []

    def fake_launcher(y, cnt, c, n_stop, lam, section, impacts, status, hand_back, keep=False):
        launched.append(y.shape[0])
        series = np.empty((y.shape[0], 1, k.SERIES_COLS))  # a GPU keeps no series
        _batch.run_on_cpu(y, cnt, c, n_stop, lam, series, section, impacts, status, hand_back)

    monkeypatch.setattr(_batch, "run_on_gpu", fake_launcher)
    return launched


def test_auto_backend_uses_an_available_gpu(monkeypatch, fake_gpu):
    """backend="auto" dispatches to the GPU launcher when one is available and the ensemble
    has AUTO_GPU_MIN members (here lowered to 3), and records it."""
    monkeypatch.setattr(_gpu, "AUTO_GPU_MIN", 3)
    launched = fake_gpu
    ens = solve(Params(), indices=range(3), duration=0.01, backend="auto")
    assert launched == [3]
    assert ens.settings["backend"] == "gpu" and ens.settings["device"] == "Fake GPU"
    assert ens.settings["batch"] == _gpu.GPU_BATCH


def test_auto_backend_keeps_a_small_ensemble_on_the_cpu(monkeypatch, fake_gpu):
    """Below AUTO_GPU_MIN members "auto" runs on the CPU, silently, even with a GPU here (a
    thousand members ran no faster on an H200 than on 2 CPU cores); "gpu" still launches."""
    monkeypatch.setattr(_gpu, "AUTO_GPU_MIN", 4)
    launched = fake_gpu
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        small = solve(Params(), indices=range(3), duration=0.01, backend="auto")
    assert launched == [] and small.settings["backend"] == "cpu"
    asked = solve(Params(), indices=range(3), duration=0.01, backend="gpu")
    assert launched == [3] and asked.settings["backend"] == "gpu"
    assert [_gpu.by_size(b, n) for b, n in [("auto", 3), ("auto", 4), ("gpu", 1), ("cpu", 9)]] == [
        "cpu",
        "auto",
        "gpu",
        "cpu",
    ]


@pytest.mark.parametrize("version", ["2.5.0", "2.5.0rc1", "3.0.0.dev0+git123"])
def test_numpy_2_5_rules_the_backend_out(monkeypatch, version):
    """Under numpy >= 2.5 (numba-cuda cannot compile there) the status says why and how to fix."""
    monkeypatch.setattr(np, "__version__", version)
    ok, reason = _gpu.gpu_status()
    assert not ok
    assert version in reason and "row_stack" in reason and "pip install 'numpy<2.5'" in reason
    with pytest.warns(_gpu.GPUFallbackWarning, match="row_stack"):
        ens = solve(Params(), indices=[0], duration=0.01, backend="gpu")
    assert ens.settings["backend"] == "cpu"


@pytest.mark.parametrize("version", ["2.4.6", "2.3.5", "1.26.4"])
def test_older_numpy_is_not_the_trap(monkeypatch, version):
    """numpy < 2.5 does not trigger the row_stack guard."""
    monkeypatch.setattr(np, "__version__", version)
    assert "row_stack" not in _gpu.gpu_status()[1]


def test_import_does_not_load_numba_cuda():
    """import chaoscam (and its solve path) leaves numba.cuda unimported."""
    code = "import sys, chaoscam, chaoscam.simulation._solve; print('numba.cuda' in sys.modules)"
    out = subprocess.run([sys.executable, "-c", code], check=True, capture_output=True, text=True)
    assert out.stdout.strip() == "False"


_SIMULATED = """
import json, sys, numpy as np
from chaoscam import Numerics, Params, extend, solve
from chaoscam.simulation import _batch
_batch.ROOM.update(gpu=(64, 256), cpu=(64, 256))  # many refills: relaunches on the device
out = {}
cases = {
    "refills": (Params(l_lambda_sigma=0.002, resample="interval", resample_dt=1e-4), "rk4", 0.1),
    "periodic": (Params(xi=0.2), "rk4", 0.0),
    "adaptive": (Params(l_lambda_sigma=0.002), "adaptive", 0.0),
    "impacts": (Params(l_lambda_sigma=0.002, v_min=0.0), "rk4", 0.0),
    "tangent": (Params(xi=0.45), "rk4", 0.0),
}
for name, (p, integrator, transient) in cases.items():
    runs = [solve(p, Numerics(integrator=integrator), indices=range(5), seed=2, duration=0.5,
                  transient=transient, backend=b, batch=3, impacts=True,
                  tangent=name == "tangent") for b in ("gpu", "cpu")]
    a, b = (r.sections.to_numpy() for r in runs)
    if name == "tangent":  # the Jacobians beside the section points too
        a, b = (np.column_stack([a, r.jacobians.reshape(len(a), -1)]) for r in runs)
    ia, ib = (r.impacts.to_numpy() for r in runs)
    out[name] = {"backend": runs[0].settings["backend"], "shape": a.shape == b.shape,
                 "n": len(a), "diff": float(np.abs(a - b).max()),
                 "impacts": ia.shape == ib.shape and bool(np.array_equal(ia, ib)),
                 "members": runs[0].members.equals(runs[1].members)}
# continued on the device from a copy kept on the way (two launches, then a resumed batch)
p = Params(l_lambda_sigma=0.002)
kw = dict(seed=2, transient=0.1, tangent=True)
short = solve(p, indices=range(5), duration=0.3, backend="gpu", batch=3, resumable=True, **kw)
longer = extend(short, 0.6)
made = solve(p, indices=range(5), duration=0.6, backend="cpu", **kw)
a, b = longer.sections.to_numpy(), made.sections.to_numpy()
out["continued"] = {"backend": longer.settings["backend"], "shape": a.shape == b.shape,
                    "n": len(a), "diff": float(np.abs(a - b).max()), "impacts": True,
                    "members": longer.members.equals(made.members)}
# continued on the CPU from the device's copy (the CPU's room: refills at other points)
on_cpu = extend(short, 0.6, backend="cpu")
a = on_cpu.sections.to_numpy()
legs = list(on_cpu.settings["backends"])
out["continued on the cpu"] = {"backend": "gpu" if legs == ["gpu", "cpu"] else str(legs),
                               "shape": a.shape == b.shape, "n": len(a),
                               "diff": float(np.abs(a - b).max()), "impacts": True,
                               "members": on_cpu.members.equals(made.members)}
print(json.dumps(out))
"""


@needs_numba_cuda
def test_simulated_gpu_equals_cpu():
    """Under the CUDA simulator the GPU driver (batches, relaunch after refills) equals the CPU
    path bit for bit: the kernel there runs the compiled CPU code, through the device
    arrays."""
    env = dict(os.environ, NUMBA_ENABLE_CUDASIM="1")
    out = subprocess.run(
        [sys.executable, "-c", _SIMULATED],
        check=True,
        capture_output=True,
        text=True,
        env=env,
        timeout=300,
    )
    result = json.loads(out.stdout.strip().splitlines()[-1])
    for case in result.values():
        assert case["backend"] == "gpu" and case["shape"] and case["n"] > 0
        assert case["diff"] == 0.0
        assert case["members"] and case["impacts"]


def test_a_small_launch_is_not_warned_about():
    """numba-cuda's low-occupancy warning, raised where a launch of few blocks is configured
    (a small batch or a refill), is dropped by run_on_gpu, else a sweep records it against
    every run of the batch; another warning raised there is raised again."""

    class Kernel:
        def __getitem__(self, config):
            msg = f"Grid size {config[0]} will likely result in GPU under-utilization due to low"
            warnings.warn(msg + " occupancy.", RuntimeWarning, stacklevel=1)
            warnings.warn("another hint", RuntimeWarning, stacklevel=1)
            return "configured"

    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        assert _gpu._configured(Kernel(), 16) == "configured"
    assert [str(w.message) for w in caught] == ["another hint"]


@needs_numba_cuda
@pytest.mark.parametrize("method", [None, 0, 1], ids=["both", "rk4", "adaptive"])
def test_kernel_compiles_to_ptx_for_h100(method):
    """The ensemble kernels (each integrator, and advance with both) compile to PTX for sm_90,
    without a device."""
    try:
        ptx = _gpu.kernel_ptx((9, 0), method)
    except Exception as exc:  # NVVM missing: nothing to check here
        if "NVVM" in str(exc) or "nvvm" in str(exc):
            pytest.skip(f"NVVM unavailable: {exc}")
        raise
    assert ".target sm_90" in ptx
    assert ".entry" in ptx and "advance_members" in ptx


@pytest.mark.gpu
@pytest.mark.skipif(not _on_device(), reason="no CUDA device")
@pytest.mark.parametrize(
    "params, duration, transient",
    [(Params(l_lambda_sigma=0.002), 0.25, 0.0), (Params(xi=0.2), 20.0, 10.0)],
    ids=["first-period", "periodic"],
)  # fmt: skip
def test_device_equals_cpu_within_tolerance(params, duration, transient):
    """On a GPU, sections of the first cam period and of a periodic orbit equal the CPU's."""
    runs = [
        solve(params, indices=range(8), seed=3, duration=duration, transient=transient, backend=b)
        for b in ("gpu", "cpu")
    ]
    assert runs[0].settings["backend"] == "gpu"
    a, b = (sections(r) for r in runs)
    assert a.shape == b.shape
    np.testing.assert_array_equal(a[:, 0], b[:, 0])
    np.testing.assert_allclose(a[:, 1:], b[:, 1:], rtol=0, atol=_gpu.GPU_TOLERANCE)
    assert (runs[0].members.status == "OK").all()


def test_a_gpu_runs_continuation_of_few_members_goes_to_the_cpu(monkeypatch, fake_gpu):
    """extend(backend="auto") of a GPU run continues fewer than AUTO_GPU_MIN members on the
    CPU, from the GPU's state and with the CPU's room; backend=None stays on the GPU. The
    fake GPU runs the CPU's kernel, so all three equal a CPU run made that long, bit for
    bit: only where they ran differs (and a real device's rounding)."""
    short = solve(CHAOTIC, indices=range(3), duration=2.0, resumable=True, backend="gpu", **RUN)
    assert short.settings["backend"] == "gpu" and len(fake_gpu) > 0
    launched = len(fake_gpu)
    on_gpu = extend(short, 4.0)
    assert len(fake_gpu) > launched and on_gpu.settings["backend"] == "gpu"
    launched = len(fake_gpu)
    on_cpu = extend(short, 4.0, members=[2, 0], backend="auto")
    assert len(fake_gpu) == launched  # not one launch
    assert on_cpu.settings["backend"] == "cpu" and list(on_cpu.settings["backends"]) == [
        "gpu",
        "cpu",
    ]
    assert on_cpu.settings["batch"] == CPU_BATCH
    _same(on_cpu, solve(CHAOTIC, indices=[2, 0], duration=4.0, backend="cpu", **RUN))
    _same(on_gpu, solve(CHAOTIC, indices=range(3), duration=4.0, backend="cpu", **RUN))
    monkeypatch.setattr(_gpu, "AUTO_GPU_MIN", 2)  # two members are now enough for the GPU
    extend(short, 4.0, members=[2, 0], backend="auto")
    assert len(fake_gpu) > launched


def test_a_gpu_solutions_extensions_run_on_the_cpu(fake_gpu):
    """classify on a GPU run: its undetermined member is extended on the CPU (no launch
    after the run's own), the extension's note says where, and the verdict is the CPU
    run's (the fake GPU runs the CPU's kernel)."""
    from chaoscam import classify

    p = Params(omega=27.0, xi=0.5)  # undetermined after 20 s, chaotic when extended
    run = dict(seed=1, duration=20.0, transient=10.0, tangent=True, resumable=True)
    ens = solve(p, indices=[0], backend="gpu", **run)
    launched = len(fake_gpu)
    (v,) = classify(ens)
    assert len(fake_gpu) == launched
    assert v.label == "chaotic" and v.settings["extended"]["backend"] == "cpu"
    (cpu,) = classify(solve(p, indices=[0], backend="cpu", **run))
    assert cpu.label == v.label and cpu.reasons == v.reasons


@pytest.mark.parametrize("resumable", [True, False])
def test_a_gpu_sweeps_fate_runs_run_on_the_cpu(fake_gpu, resumable):
    """The fate runs of a GPU batch's few chaotic members go to the CPU (by size), whether
    continued from the batch's copy or run again."""
    from chaoscam.sweep import _runs

    run = dict(duration=2.0, transient=0.0, tangent=True, resumable=resumable)
    ens = solve(CHAOTIC, indices=[0], seed=1, backend="gpu", **run)
    launched = list(fake_gpu)
    (fields,) = _runs._fates(ens, [0], 8.0)
    assert fake_gpu == launched and fields["fate"] == "OK"
