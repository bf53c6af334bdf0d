#!/usr/bin/env bash
# Issue 13's GPU checks in one call on a lent NVIDIA machine (run from the repository root).
#
#   bash benchmarks/device_check.sh [WHEELS]     (about 7 minutes)
#
# WHEELS (default .whl) holds cp312 wheels of what the device's image lacks: nolds and future
# (chaoscam's dependencies) and numpy 2.4 (numba-cuda 0.30 compiles no kernel under numpy 2.5,
# see chaoscam.integrate._gpu); they are installed with --target, nothing else is touched.
# Made where pip works (the device reaches no index), e.g.
#   pip download --no-deps --only-binary=:all: --python-version 3.12 --implementation cp \
#     --platform manylinux_2_28_x86_64 -d .whl nolds==0.6.2 future==1.0.0 numpy==2.4.6
# Steps, most important first: versions; whether the image's own numba-cuda compiles a kernel
# under its numpy; then in one Python process (the GPU kernels compiled once), under one time
# limit (CHECK_SECONDS, default 300): the rate against members, layout ("C" rows or "F"
# member-minor, and whether they give the same sections) and buffer room (bench_gpu_profile.py,
# up to 40,000 members within a 90 s budget), the device tests (tests/integrate/test_gpu.py
# -m gpu, both layouts), and with RUN_MAP=1 a regime map on the GPU against the 2-core
# engines (bench_regime_gpu.py, about 140 s, measured once already); last, where ncu can read
# the counters, an Nsight Compute profile of one short launch (gpu_ncu_target.py;
# NCU_SECONDS, default 120): how much of each warp runs (branch divergence), occupancy, memory
# traffic and what the warps wait on. About 7 minutes in all without the map. bench_gpu.py's
# 40,000 x 20 s did not finish in 340 s on an H200 (2026-11-27): run it alone, with a longer
# limit, once the profile says it can.
set -u
WHEELS=${1:-.whl}
export PYTHONUNBUFFERED=1
step() { echo; echo "== $* ($(date -u +%T))"; }

step versions
nvidia-smi --query-gpu=name,driver_version,memory.total,clocks.max.sm --format=csv
python3 -c "import sys, numpy, numba; print('python', sys.version.split()[0], '| numpy', numpy.__version__, '| numba', numba.__version__)"
python3 -m pip list 2>/dev/null | grep -iE '^(numba|numba-cuda|cuda-bindings|cuda-python|llvmlite|scipy|pandas|pyarrow|seaborn|matplotlib|jinja2|tqdm) '

step "the image's numba-cuda under its own numpy: a trivial kernel"
timeout -k 5 90 python3 - <<'PY'
import numpy as np
from numba import cuda

@cuda.jit
def add(a):
    i = cuda.grid(1)
    if i < a.size:
        a[i] += 1.0

a = cuda.to_device(np.zeros(64))
add[1, 64](a)
print("compiled and ran:", a.copy_to_host().sum() == 64.0)
PY
echo "exit $?"

step "wheels: nolds, future, numpy 2.4 (--target, ahead of the image's)"
python3 -m pip install -q --no-index --no-deps --no-compile --no-cache-dir --target /tmp/site \
    "$WHEELS"/nolds-*.whl "$WHEELS"/future-*.whl "$WHEELS"/numpy-*.whl || exit 1
export PYTHONPATH=/tmp/site:$PWD
python3 -c "import numpy, numba, chaoscam; from chaoscam.integrate._gpu import gpu_status; print('numpy', numpy.__version__, '| numba', numba.__version__, '|', gpu_status())"

step "bench_gpu_profile, device tests (and the regime map with RUN_MAP=1): one process"
timeout -k 5 "${CHECK_SECONDS:-300}" python3 - <<'PY'
import os
import runpy
import sys
import time
import traceback

import pytest

T0 = time.perf_counter()


def run(script, *argv):
    print(f"-- {script} {' '.join(argv)} at {time.perf_counter() - T0:.0f} s", flush=True)
    sys.argv = [script, *argv]
    try:
        runpy.run_path(script, run_name="__main__")
    except Exception:
        traceback.print_exc()


run("benchmarks/bench_gpu_profile.py", "--budget", "90")
code = pytest.main(["-q", "-p", "no:cacheprovider", "-m", "gpu", "tests/integrate/test_gpu.py"])
print(f"-- device tests: pytest exit {int(code)} at {time.perf_counter() - T0:.0f} s")
if os.environ.get("RUN_MAP") == "1":  # measured 2026-11-27: about 140 s, whatever the size
    run("benchmarks/bench_regime_gpu.py", "--realizations", "256", "--reference", "4")
PY
echo "exit $?"

step "Nsight Compute: one launch of 1,024 members x 0.05 s (warp efficiency, occupancy, stalls)"
if ! command -v ncu >/dev/null 2>&1; then
    echo "ncu not on the PATH: skipped"
elif [ "$(id -u)" != 0 ] && grep -q "RmProfilingAdminOnly: 1" /proc/driver/nvidia/params 2>/dev/null; then
    echo "GPU counters are for root only here: skipped"
else
    timeout -k 5 "${NCU_SECONDS:-120}" ncu --target-processes all -k regex:advance_members \
        --launch-skip 1 --launch-count 1 --section SpeedOfLight --section Occupancy \
        --section LaunchStats --section WarpStateStats --section SchedulerStats \
        --section MemoryWorkloadAnalysis \
        --metrics smsp__thread_inst_executed_per_inst_executed.ratio,smsp__sass_thread_inst_executed_op_dfma_pred_on.sum \
        python3 benchmarks/gpu_ncu_target.py
    echo "exit $?"
fi
step done
