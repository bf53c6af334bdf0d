"""Ensembles on an NVIDIA GPU with numba-cuda: one CUDA thread per trajectory, running the CPU's
``@numba.njit`` kernel (:func:`._driver.advance`) from one source, refilled on the host as on
the CPU path; a resumed run is bit-identical.

Limits: not bit-identical to the CPU (NVVM fuses ``a * b + c``; libdevice's sin/cos/tanh may
differ in the last bit; the CUDA simulator is), chaotic runs part to O(0.1) over 20 s; sections
of the first cam period and of periodic runs after a transient agree within ``GPU_TOLERANCE``;
ensemble statistics are what it is for. One thread is slow (a warp's members branch apart), so
thousands must be in flight: 33,792 members of 5 s run 11.3x as fast as 2 CPU threads on an H200.
"""

from __future__ import annotations

import functools
import importlib.util
import re
import threading
import types
import warnings

import numpy as np

from .._util import recorded
from . import layout as k
from ._adaptive import run_chunk_adaptive
from ._driver import advance, drive_members
from ._rk4 import run_chunk

GPU_BATCH = 65_536  # members per device batch: ~19 kB each for 20 s runs, 42 kB with impacts kept
GPU_TOLERANCE = 1e-6  # rad and rad/s: GPU against CPU sections, first period or periodic
_BLOCK = 64  # threads per block: 202 registers a thread on an H200 (196 from ptxas 12.9)
_SMALL_GRID = r".*Grid size \d+ will likely result in GPU under-utilization"
"""numba-cuda's warning for a launch of few blocks (ANSI codes too): expected of a small batch."""
_NUMPY_TRAP = (2, 5)  # numba-cuda <= 0.30.4 compiles no kernel under numpy >= 2.5
DEVICE_LOCK = threading.Lock()
"""Held by each :func:`run_on_gpu` call: a GPU sweep launches its next batch from the driver's
thread while its labelling thread may extend members on the device; they take turns."""

AUTO_GPU_MIN = 4_096
"""Fewest members (or a sweep's runs) that ``"auto"`` runs on a GPU: from 4,096 0.25-s members
an H200 outruns a 16-core CPU (``"gpu"`` runs any size)."""


class GPUFallbackWarning(RuntimeWarning):
    """``backend="gpu"`` was asked for but cannot run; the CPU path is used instead."""


def gpu_status() -> tuple[bool, str]:
    """Whether the GPU backend can run here, and why in one line (naming the device): checks
    the numpy version, numba-cuda, a CUDA driver and device."""
    trap = _numpy_trap()
    if trap:
        return False, trap
    if importlib.util.find_spec("numba_cuda") is None:
        return False, "numba-cuda is not installed (pip install 'chaoscam[gpu]')"
    return _device_status()


def by_size(backend: str, members: int) -> str:
    """``backend`` with ``"auto"`` settled by size: ``"cpu"`` below :data:`AUTO_GPU_MIN`
    members, else ``"auto"`` (the GPU where one runs); ``"cpu"``, ``"gpu"`` as they are."""
    return "cpu" if backend == "auto" and members < AUTO_GPU_MIN else backend


def runs_on_gpu(backend: str) -> bool:
    """Whether ``backend`` ("cpu", "gpu", "auto") runs on a GPU here (:func:`gpu_status`)."""
    return backend in ("gpu", "auto") and gpu_status()[0]


def _numpy_trap() -> str:
    """Why the numpy version rules the backend out (no ``row_stack``), or ""."""
    match = re.match(r"(\d+)\.(\d+)", np.__version__)
    if match and tuple(int(x) for x in match.groups()) >= _NUMPY_TRAP:
        return (
            f"numpy {np.__version__} >= 2.5: numba-cuda fails to compile kernels there "
            "(numpy has no row_stack); pip install 'numpy<2.5'"
        )
    return ""


@functools.cache
def _device_status() -> tuple[bool, str]:
    try:
        from numba import cuda
    except ImportError as exc:  # e.g. numba-cuda without the CUDA Python bindings
        return False, "numba-cuda cannot be imported: " + " ".join(str(exc).split())
    try:
        if not cuda.is_available():
            return False, "no CUDA driver or device found (numba.cuda.is_available() is False)"
        dev = cuda.get_current_device()
    except Exception as exc:  # the driver's errors span lines; keep one
        return False, "no usable CUDA device: " + " ".join(str(exc).split())
    if _simulated(dev):
        return True, "CUDA simulator (NUMBA_ENABLE_CUDASIM=1)"
    name = dev.name.decode() if isinstance(dev.name, bytes) else str(dev.name)
    major, minor = dev.compute_capability
    return True, f"{name} (compute capability {major}.{minor})"


def _simulated(dev) -> bool:
    return "simulator" in type(dev).__module__


def _advance_members(y, cnt, c, n_stop, lam, series, section, impacts, status):
    """The kernel's source: ``step`` for each member still to run."""
    i = cuda.grid(1)  # noqa: F821
    if i < y.shape[0] and status[i] == k.NEED_BUFFER:
        status[i] = step(  # noqa: F821
            y[i], cnt[i], c[i], n_stop, lam[i], series[i], section[i], impacts[i]
        )


def _members(cuda, step):
    """``_advance_members`` with ``cuda``, ``step`` as globals (the simulator swaps ``cuda``)."""
    namespace = {"__name__": __name__, "cuda": cuda, "step": step, "k": k}
    code = _advance_members.__code__
    return types.FunctionType(code, namespace, "advance_members")


def _step_function(method: int | None):
    """The per-member function a kernel calls: the integrator itself when a batch has one (fewer
    registers: RK4 196, adaptive 184, ``advance`` 236 on sm_90)."""
    if method == k.METHOD_RK4:
        return run_chunk
    if method == k.METHOD_ADAPTIVE:
        return run_chunk_adaptive
    return advance


def _on_host(step):
    """``step`` under the simulator: its arrays are wrappers the CPU kernel cannot take."""

    def call(*args):
        return step(*(np.asarray(a) if hasattr(a, "shape") else a for a in args))

    return call


@functools.cache
def _kernel(method: int | None = None):
    """The compiled ensemble kernel for one integrator (``C_METHOD``), or both (None)."""
    from numba import cuda

    step = _step_function(method)
    if _simulated(cuda.get_current_device()):
        step = _on_host(step)
    return cuda.jit(_members(cuda, step))


def _batch_method(c: np.ndarray) -> int | None:
    """The integrator all members of a batch share, or None when they mix."""
    methods = np.unique(c[:, k.C_METHOD])
    return int(methods[0]) if methods.size == 1 else None


def kernel_ptx(cc: tuple[int, int] = (9, 0), method: int | None = None) -> str:
    """PTX of the ensemble kernel for compute capability ``cc`` (needs NVVM, not a device) and
    ``method`` (``layout.METHOD_*``, None for both). numba-cuda asks the current device for the
    capability even when given one, so a stand-in device is put in its place."""
    from unittest import mock

    import numba.cuda.dispatcher as dispatcher
    from numba import cuda, float64, int64

    a2, a3, i2 = float64[:, ::1], float64[:, :, ::1], int64[:, ::1]
    sig = (a2, i2, a2, int64, a2, a3, a3, a3, int64[::1])
    device = types.SimpleNamespace(compute_capability=cc)
    with mock.patch.object(dispatcher, "get_current_device", lambda: device):
        ptx, _ = cuda.compile_ptx(_members(cuda, _step_function(method)), sig, cc=cc)
    return ptx


def kernel_info(method: int | None = k.METHOD_RK4) -> dict:
    """Registers and local memory a thread of the compiled kernel uses on this device."""
    kern = _kernel(method)

    def first(value):
        return next(iter(value.values()), None) if isinstance(value, dict) else value

    return {
        "registers": first(kern.get_regs_per_thread()),
        "local_bytes": first(kern.get_local_mem_per_thread()),
        "block": _BLOCK,
    }


def _configured(kern, blocks: int):
    """``kern[blocks, _BLOCK]`` without the low-occupancy warning (:data:`_SMALL_GRID`)."""
    with recorded() as said:
        configured = kern[blocks, _BLOCK]
    for w in said:
        if not re.match(_SMALL_GRID, str(w.message)):
            warnings.warn_explicit(w.message, w.category, w.filename, w.lineno, source=w.source)
    return configured


def run_on_gpu(y, cnt, c, n_stop, lam, section, impacts, status, hand_back, keep_impacts=False):
    """Run the stacked members whose ``status`` is ``NEED_BUFFER`` (arrays as in
    :func:`chaoscam.simulation.run_batch`) to ``n_stop`` on the GPU, one call at a time
    (:data:`DEVICE_LOCK`), in place (``impacts`` only with ``keep_impacts``, else counted);
    ``hand_back(j, lam_j, n)`` empties member ``j``'s rows and returns its draws renewed."""
    with DEVICE_LOCK:
        _run_on_gpu(y, cnt, c, n_stop, lam, section, impacts, status, hand_back, keep_impacts)


def _run_on_gpu(y, cnt, c, n_stop, lam, section, impacts, status, hand_back, keep_impacts):
    from numba import cuda

    kern = _kernel(_batch_method(c))
    n = y.shape[0]

    def put(a):
        return cuda.to_device(np.ascontiguousarray(a))

    d_y, d_cnt, d_c, d_lam, d_status = (put(a) for a in (y, cnt, c, lam, status))
    d_series = cuda.device_array((n, 1, k.SERIES_COLS))
    if cnt[:, k.I_N_SECTION].any():  # rows of an earlier launch (a resumable run's first)
        d_section = put(section)
    else:
        d_section = cuda.device_array(section.shape)
    d_impacts = cuda.device_array(impacts.shape)
    blocks = (n + _BLOCK - 1) // _BLOCK
    configured = _configured(kern, blocks)

    def launch(need: np.ndarray) -> np.ndarray:
        configured(d_y, d_cnt, d_c, n_stop, d_lam, d_series, d_section, d_impacts, d_status)
        d_status.copy_to_host(status)
        return status[need]

    def refill(need: np.ndarray) -> None:
        d_cnt.copy_to_host(cnt)
        for j in need:  # the impact rows, and as many new draws as were used
            if keep_impacts:
                d_impacts[j].copy_to_host(impacts[j])
            lam[j] = hand_back(j, lam[j], int(cnt[j, k.I_LAM_POS]))
        d_cnt.copy_to_device(np.ascontiguousarray(cnt))
        if 8 * need.size < n:
            for j in need:
                d_lam[j].copy_to_device(lam[j])
        else:
            d_lam.copy_to_device(np.ascontiguousarray(lam))

    drive_members(n, launch, refill, np.flatnonzero(status == k.NEED_BUFFER))
    for d, host in ((d_y, y), (d_cnt, cnt), (d_section, section)):
        d.copy_to_host(host)
    if keep_impacts:
        d_impacts.copy_to_host(impacts)
