#!/usr/bin/env bash
# Issue 13's GPU checks in one call on a lent NVIDIA machine (run from the repository root).
#
#   bash benchmarks/device_check.sh [WHEELS]     (about 7 minutes; results in $OUT)
#
# WHEELS (default .whl) holds cp312 wheels of what the device's image lacks: nolds and future
# (chaoscam's dependencies) and numpy 2.4 (numba-cuda 0.30 compiles no kernel under numpy 2.5,
# see chaoscam.kernel._gpu); they are installed with --target, nothing else is touched.
# Made where pip works (the device reaches no index), e.g.
#   pip download --no-deps --only-binary=:all: --python-version 3.12 --implementation cp \
#     --platform manylinux_2_28_x86_64 -d .whl nolds==0.6.2 future==1.0.0 numpy==2.4.6
# Steps: versions (the image's numba-cuda under its own numpy 2.5 compiles no kernel: seen on
# an H200, 2026-11-27); then, under one time limit (CHECK_SECONDS, default 330), a full wave's
# rate by run length against 2 CPU threads of the machine (bench_gpu_wave.py, DURATIONS,
# default 20 s, the run length the targets name, in LEGS legs, default 4, a line after each);
# with RUN_TESTS=1 the device tests; last, where ncu can read the counters (NCU_SECONDS,
# default 120), one Nsight Compute profile of a full wave's launch (33,792 members x
# 0.005 s) with the warp states only and every stall reason (instruction fetch among them):
# why 4x the warps gave 1.41x. Outputs go to $OUT where it is set (wave.log, ncu_full.txt).
# A regime map on the GPU (bench_regime_gpu.py: MAP_SECONDS, default 0 = skipped; MAP_RUNS
# realizations a cell, default 2048, 4 cells: two batches of 8,192, so that the second's
# launch can overlap the first's labels; MAP_DURATION simulated seconds, default 10)
# measures the extensions and fate runs of few members on the CPU (measured 2026-11-28:
# 530 members in 12.8 s on the host's 16 cores) and the next batch launched while the last is
# labelled (not yet measured: one batch then); it prints every device call and CPU batch
# with its start and length as it ends. A second call can run it alone, within the
# session's 15 minutes after a first default call (about 450 s):
# CHECK_SECONDS=0 NCU_SECONDS=0 MAP_SECONDS=300 bash benchmarks/device_check.sh .whl
#
# Measured 2026-11-28 (H100, two calls, 557 s and 150 s of the 15 minutes): 2 CPU threads
# 229 member-s/s at 20 s; compiled in 30.2 s; GPU = CPU check 1.9e-8; one launch of a full
# wave x 20 s (DURATIONS=20, no legs then) had not ended 245 s after it began (so under
# 2,760 member-s/s, 138 twenty-second traj/s, 12x the 2 threads) and printed nothing: hence
# LEGS. The map at MAP_RUNS=4096 did not end in 240 s; at 512 (second call,
# CHECK_SECONDS=0 NCU_SECONDS=0 MAP_SECONDS=262 MAP_RUNS=512): 2,048 runs in 108.7 s,
# 18.8 traj/s, 4.14x the 2-core process engine (since removed; PROFILE.md). A next
# session's first call can be the default (about 300 s for the wave, then the profile), its
# second the map (above: two batches of 8,192 x 10 s, about 60-90 s of launch each by these
# rates).
#
# Measured 2026-11-27 (H200, third session): after the host's quadratic set-up was fixed
# (e7a316b), 33,792 members x 0.25 / 2 / 5 s ran at 1,073 / 2,231 / 2,954 member-seconds a
# second, 14.0 / 11.3 / 11.3x the machine's 2 CPU threads, one launch a run. The full wave's
# profile with five sections (--print-details all) was stopped at 110 s in ncu's replay, so
# this one asks one section of a shorter launch. benchmarks/PROFILE.md has the sessions.
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
python3 -c "import numpy, numba, chaoscam; from chaoscam.kernel import gpu_status; print('numpy', numpy.__version__, '| numba', numba.__version__, '|', gpu_status())"

OUTDIR=${OUT:-/tmp}
if [ "${CHECK_SECONDS:-330}" != 0 ]; then
    step "a full wave's rate by run length (bench_gpu_wave.py, CHECK_SECONDS)"
    timeout -k 5 "${CHECK_SECONDS:-330}" python3 benchmarks/bench_gpu_wave.py \
        --durations "${DURATIONS:-20}" --legs "${LEGS:-4}" 2>&1 | tee "$OUTDIR/wave.log"
    echo "exit $?"
fi

if [ "${MAP_SECONDS:-0}" != 0 ]; then
    step "a regime map on the GPU (bench_regime_gpu.py, MAP_SECONDS)"
    timeout -k 5 "$MAP_SECONDS" python3 benchmarks/bench_regime_gpu.py \
        --realizations "${MAP_RUNS:-2048}" --duration "${MAP_DURATION:-10}" --reference 4 \
        2>&1 | tee "$OUTDIR/map.log"
    echo "exit $?"
fi

if [ "${RUN_TESTS:-0}" = 1 ]; then
    step "device tests (tests/kernel/test_gpu.py -m gpu)"
    timeout -k 5 300 python3 -m pytest -q -p no:cacheprovider -o addopts= -m gpu tests/kernel/test_gpu.py
    echo "exit $?"
fi

if [ "${NCU_SECONDS:-120}" = 0 ]; then
    echo "NCU_SECONDS=0: the profile skipped"
elif command -v ncu >/dev/null 2>&1; then
    step "Nsight Compute: a full wave's launch (33,792 members x 0.005 s), warp states"
    timeout -k 5 "${NCU_SECONDS:-120}" ncu --clock-control none --target-processes all \
        -k regex:advance_members --launch-skip 1 --launch-count 1 \
        --section WarpStateStats --print-details all \
        --metrics smsp__thread_inst_executed_per_inst_executed.ratio,smsp__warps_active.avg.per_cycle_active \
        python3 benchmarks/gpu_ncu_target.py 33792 0.005 2>&1 | tee "$OUTDIR/ncu_full.txt"
    echo "exit $?"
else
    echo "ncu not on the PATH: skipped"
fi
step done
