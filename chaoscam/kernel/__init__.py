"""The compiled kernels: fixed-step RK4 with located impacts (the reference), adaptive DOP853,
the tangent dynamics through the impacts, and the loop that drives them on CPU threads or a GPU.

Kernels take floats and arrays and return status codes (:class:`Status`); they never raise.
Their memory layout is :mod:`chaoscam.kernel.layout`. Names resolve lazily (numba loads on use).
"""

from __future__ import annotations

from pathlib import Path

from .._util import lazy_face
from ._numba_cache import guard

# cached kernels call functions of other files here: a callee's edit must empty the cache
guard(Path(__file__).parent)

_LAZY = {
    "alone_kernel": ("._driver", "alone_kernel"),
    "AUTO_GPU_MIN": ("._gpu", "AUTO_GPU_MIN"),
    "by_size": ("._gpu", "by_size"),
    "CALL_STEPS": ("._constants", "CALL_STEPS"),
    "check_stop": ("._driver", "check_stop"),
    "contact_fraction": ("._driver", "contact_fraction"),
    "drive_members": ("._driver", "drive_members"),
    "fork_safe_threads": ("._driver", "fork_safe_threads"),
    "GPU_BATCH": ("._gpu", "GPU_BATCH"),
    "gpu_status": ("._gpu", "gpu_status"),
    "GPU_TOLERANCE": ("._gpu", "GPU_TOLERANCE"),
    "GPUFallbackWarning": ("._gpu", "GPUFallbackWarning"),
    "initial_counters": ("._constants", "initial_counters"),
    "initial_state": ("._constants", "initial_state"),
    "kernel_constants": ("._constants", "kernel_constants"),
    "kernel_info": ("._gpu", "kernel_info"),
    "kernel_ptx": ("._gpu", "kernel_ptx"),
    "members_kernel": ("._driver", "members_kernel"),
    "members_on_this_thread": ("._driver", "members_on_this_thread"),
    "on_this_thread": ("._driver", "on_this_thread"),
    "run_on_gpu": ("._gpu", "run_on_gpu"),
    "runs_on_gpu": ("._gpu", "runs_on_gpu"),
    "section_jacobians": ("._tangent", "section_jacobians"),
    "Status": ("._status", "Status"),
    "stop_on": ("._driver", "stop_on"),
    "StopRequested": ("._driver", "StopRequested"),
    "stops_here": ("._driver", "stops_here"),
    "thread_count": ("._driver", "thread_count"),
}

__all__ = sorted(_LAZY)

__getattr__, __dir__ = lazy_face(__name__, _LAZY)
