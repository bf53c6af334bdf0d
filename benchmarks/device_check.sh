#!/usr/bin/env bash
# Issue 13's GPU checks in one call on a lent NVIDIA machine (run from the repository root).
#
#   bash benchmarks/device_check.sh [WHEELS]     (about 7 minutes; results in $OUT)
#
# WHEELS (default .whl) holds cp312 wheels of what the device's image lacks: nolds and future
# (chaoscam's dependencies) and numpy 2.4 (numba-cuda 0.30 compiles no kernel under numpy 2.5,
# see chaoscam.integrate._gpu); they are installed with --target, nothing else is touched.
# Made where pip works (the device reaches no index), e.g.
#   pip download --no-deps --only-binary=:all: --python-version 3.12 --implementation cp \
#     --platform manylinux_2_28_x86_64 -d .whl nolds==0.6.2 future==1.0.0 numpy==2.4.6
# Steps: versions (the image's numba-cuda under its own numpy 2.5 compiles no kernel: seen on
# an H200, 2026-11-27); then, under one time limit (CHECK_SECONDS, default 240), where a full
# device's time goes (bench_gpu_profile.py --plan scaling: a full wave, a block a
# multiprocessor and one block, 0.25 s each, then the full wave with its impacts kept, which
# stops every member for room three or four times; each split into launches and refills); with RUN_TESTS=1 the device tests; last, where ncu can read the
# counters (NCU_SECONDS each, default 90), two Nsight Compute profiles of one launch: a full
# wave (33,792 members x 0.02 s) with every stall reason (instruction fetch among them),
# active threads a warp and occupancy, then 1,024 members x 0.05 s with the full sections
# (memory, launch statistics). Outputs go to
# $OUT where it is set (profile.log, ncu_*.txt). About 7 minutes in all.
#
# Measured 2026-11-27 (H200, two calls): the RK4 kernel ("C", 216 registers) ran 2.16 of a
# warp's 32 threads at a time over 1,024 members' first launch (0.05 s), issuing every 6.2
# cycles with one warp a scheduler (L1 hit rate 99.8 %, memory 0.3 % busy); but in that
# launch every member stopped for a refill at its own time (256 impact rows; 811 impacts in
# the first 0.05 s), so idle lanes count with divergent ones: gpu_ncu_target.py now gives
# the room for one launch. 33,792 members x 0.5 s took 140 s staged in thread-local arrays
# and 145 s with a block barrier after every loop iteration (branch wip/gpu-variants),
# against 1.3-1.6 s for 64 members: where the full device's time goes is the first question.
set -u -o pipefail
WHEELS=${1:-.whl}
export PYTHONUNBUFFERED=1
step() { echo; echo "== $* ($(date -u +%T))"; }

step versions
nvidia-smi --query-gpu=name,driver_version,memory.total,clocks.max.sm --format=csv
python3 -c "import sys, numpy, numba; print('python', sys.version.split()[0], '| numpy', numpy.__version__, '| numba', numba.__version__)"
python3 -m pip list 2>/dev/null | grep -iE '^(numba|numba-cuda|cuda-bindings|cuda-python|llvmlite|scipy|pandas|pyarrow|seaborn|matplotlib|jinja2|tqdm) '

step "wheels: nolds, future, numpy 2.4 (--target, ahead of the image's)"
python3 -m pip install -q --no-index --no-deps --no-compile --no-cache-dir --target /tmp/site \
    "$WHEELS"/nolds-*.whl "$WHEELS"/future-*.whl "$WHEELS"/numpy-*.whl || exit 1
export PYTHONPATH=/tmp/site:$PWD
python3 -c "import numpy, numba, chaoscam; from chaoscam.integrate._gpu import gpu_status; print('numpy', numpy.__version__, '| numba', numba.__version__, '|', gpu_status())"

OUTDIR=${OUT:-/tmp}
step "where a full device's time goes (bench_gpu_profile.py --plan scaling, CHECK_SECONDS)"
timeout -k 5 "${CHECK_SECONDS:-240}" python3 benchmarks/bench_gpu_profile.py --plan scaling \
    2>&1 | tee "$OUTDIR/profile.log"
echo "exit $?"

if [ "${RUN_TESTS:-0}" = 1 ]; then
    step "device tests (tests/integrate/test_gpu.py -m gpu)"
    timeout -k 5 300 python3 -m pytest -q -p no:cacheprovider -m gpu tests/integrate/test_gpu.py
    echo "exit $?"
fi

ncu_run() {  # a name for the output, then ncu's options and the target
    local name=$1
    shift
    timeout -k 5 "${NCU_SECONDS:-90}" ncu --clock-control none --target-processes all \
        -k regex:advance_members --launch-skip 1 --launch-count 1 "$@" 2>&1 \
        | tee "$OUTDIR/ncu_$name.txt"
    echo "exit $?"
}
if command -v ncu >/dev/null 2>&1; then
    # every stall reason (--print-details all): a kernel of some 30,000 PTX lines may stall
    # on instruction fetch once 8 warps a multiprocessor run different parts of it
    step "Nsight Compute: a full wave's launch (33,792 members x 0.02 s), stall reasons"
    ncu_run full --section SpeedOfLight --section WarpStateStats --section SchedulerStats \
        --section Occupancy --print-details all \
        --metrics smsp__thread_inst_executed_per_inst_executed.ratio,smsp__inst_executed.sum \
        python3 benchmarks/gpu_ncu_target.py 33792 0.02
    step "Nsight Compute: 1,024 members x 0.05 s, full sections"
    ncu_run sections --section SpeedOfLight --section Occupancy --section LaunchStats \
        --section WarpStateStats --section SchedulerStats --section MemoryWorkloadAnalysis \
        --metrics smsp__thread_inst_executed_per_inst_executed.ratio \
        python3 benchmarks/gpu_ncu_target.py 1024 0.05
else
    echo "ncu not on the PATH: skipped"
fi
step done
