"""What a GPU warp would make of the RK4 ensemble kernel's work, modelled on the CPU.

Run: python benchmarks/gpu_warp_model.py [DURATION]   (default 4 s; about 10 s)
     python benchmarks/gpu_warp_model.py --tail [MEMBERS [DURATION]] [--keep-impacts]

A warp runs 32 members in SIMT: in a step of the kernel's loop, a member in merged free
flight, one in a contact step and one locating an impact take different branches, and the
warp runs all of them. Here 32 members (the default model with ``l_lambda_sigma = 2 mm``,
bench_gpu.py's seed) are run one loop iteration of the RK4 kernel at a time (the compiled
single-member call :func:`chaoscam.kernel.alone_kernel` gives for RK4 constants, the same
``run_chunk`` the GPU threads run; ``C_CALL_STEPS = 1``; a call resumes bit for bit), each
call timed with the processor's cycle counter (``llvm.readcyclecounter``). From those costs
``c[j, i]`` (member j, its i-th iteration):

- **lockstep efficiency**: the warp's threads meet after every iteration and an iteration
  lasts as long as its dearest thread's: ``sum c / (32 sum_i max_j c[j, i])``, the share of
  a warp's 32 lanes doing work. An upper bound for today's kernel, whatever its
  reconvergence (threads on different branches take their sum, not their maximum);
- the same with every iteration that applied an impact costed as a median iteration: how
  much of the loss the impacts are;
- **equal-units bound**: ``mean_j C_j / max_j C_j`` with ``C_j = sum_i c[j, i]``, what a kernel
  whose every thread does one equal unit of work (an RK4 substep of any kind) per warp
  step could reach.

Each for the first half second (the stiff initial contact), the rest, and the whole run.
The cycle counter sees the machine's interruptions too: the maxima are noisy by a few %.
Measured on the 2-core development machine (2026-11-27, runs of 4 s and 20 s, six in all):
lockstep 0.14-0.20 (5-6 of 32 lanes) in every window; impacts as cheap as a median
iteration 0.23-0.28 (iterations with an impact are 0.9 % of them and 13 % of the cycles
after the first half second, 1.8 % and 20 % in it); equal-units bound 0.64-0.97 (the
noisiest figure: one interruption moves a member's total). Nsight Compute on an H200 read
2.16 threads active of 32 for the RK4 kernel over its first 0.05 s, a launch in which each
member also stopped for a refill at its own time (PROFILE.md).

``--tail MEMBERS [DURATION] [--keep-impacts]``: whole members' costs as GPU threads run
them, stopping for room (``chaoscam.simulation.ROOM["gpu"]``) as they do: how long one launch waits
for its slowest member, and how much longer the batch takes when it is relaunched at every
stop and waits for the slowest again each time. Measured here (2026-11-27): with 256 impact
rows kept, 20-s members stop 43-49 times and 512 of them relaunched take 2.10x one launch
(5 s, 2,048 members: 2.17x; 0.5 s, 8,192: 1.62x, one launch waiting 3.65x a mean member);
with the impacts only counted (the default), none stop.
"""

from __future__ import annotations

import sys

import numpy as np
from llvmlite import ir
from numba import njit, types
from numba.core import cgutils
from numba.extending import intrinsic

from chaoscam import Numerics, Params
from chaoscam.kernel import alone_kernel
from chaoscam.kernel import layout as k
from chaoscam.simulation import ROOM, fresh

WARP = 32


@intrinsic
def _cycles(typingctx):
    """The processor's cycle counter (``llvm.readcyclecounter``)."""

    def codegen(context, builder, signature, args):
        fnty = ir.FunctionType(ir.IntType(64), [])
        fn = cgutils.get_or_insert_function(builder.module, fnty, "llvm.readcyclecounter")
        return builder.call(fn, [])

    return types.int64(), codegen


@njit
def _iterations(run, y, cnt, c, n_stop, lam, section, impacts, cost, at, hits):
    """Run each member one loop iteration a call of ``run`` (the compiled kernel call); record
    each call's cycles (``cost``), the member's time after it (``at``) and the impacts it
    applied (``hits``). Returns the iterations per member (0 if a member ran out of draws or
    of ``cost``'s columns)."""
    series = np.empty((1, k.SERIES_COLS))
    n = y.shape[0]
    done = np.zeros(n, np.int64)
    for j in range(n):
        for i in range(cost.shape[1]):
            before = cnt[j, k.I_N_IMPACT]
            t0 = _cycles()
            code = run(y[j], cnt[j], c[j], n_stop, lam[j], series, section[j], impacts[j])
            cost[j, i] = _cycles() - t0
            at[j, i] = y[j, k.Y_TIME]
            hits[j, i] = cnt[j, k.I_N_IMPACT] - before
            if code != k.NEED_BUFFER:
                done[j] = i + 1
                break
            if cnt[j, k.I_LAM_POS] > lam.shape[1] - 64:
                break  # out of draws: done[j] stays 0
            if cnt[j, k.I_N_SECTION] > section.shape[1] - 8:
                cnt[j, k.I_N_SECTION] = 0
    return done


def _aligned(values: np.ndarray, inside: np.ndarray) -> np.ndarray:
    """Each member's values inside its window, from the window's first iteration on."""
    first = np.argmax(inside, axis=1)
    length = inside.sum(axis=1)
    out = np.zeros((values.shape[0], int(length.max())), dtype=values.dtype)
    for j in range(values.shape[0]):
        out[j, : length[j]] = values[j, first[j] : first[j] + length[j]]
    return out


@njit
def _between_stops(run, y, cnt, c, n_stop, draws, width, section, impacts, cost, stops):
    """Each member run as a GPU thread runs it (``run``: the compiled kernel call): stopping
    whenever its ``width`` draws or its impact rows run out, refilled as ``run_batch``'s
    ``hand_back`` does (rows emptied, used draws dropped, the stream's next ones appended: a
    window sliding along ``draws``).
    ``cost[j, s]``: cycles of member j's s-th run between stops; ``stops[j]``: their count."""
    series = np.empty((1, k.SERIES_COLS))
    for j in range(y.shape[0]):
        offset = 0
        s = 0
        while s < cost.shape[1]:
            lam = draws[j, offset : offset + width]
            t0 = _cycles()
            code = run(y[j], cnt[j], c[j], n_stop, lam, series, section[j], impacts[j])
            cost[j, s] = _cycles() - t0
            s += 1
            if code != k.NEED_BUFFER or offset + width + cnt[j, k.I_LAM_POS] > draws.shape[1]:
                break
            cnt[j, k.I_N_IMPACT] = 0
            offset += cnt[j, k.I_LAM_POS]
            cnt[j, k.I_LAM_POS] = 0
        stops[j] = s


def tail(members: int, duration: float = 0.5, keep_impacts: bool = False) -> None:
    """Whole members' costs as GPU threads: a launch lasts as long as its slowest member, and
    a member stops for room (``ROOM["gpu"]``: its draws, and its impact rows when impacts are
    kept) several times a run, each stop a relaunch of the batch that waits for the slowest
    member again."""
    p, num = Params(l_lambda_sigma=0.002), Numerics()
    draws_room, rows = ROOM["gpu"]
    rows = rows if keep_impacts else 0  # as run_batch: impacts not kept are only counted
    n_stop = int(round(duration / num.dt))
    cost = np.zeros((members, 400), np.int64)
    stops = np.zeros(members, np.int64)
    for s0 in range(0, members, 2048):
        m = min(2048, members - s0)
        st = fresh([p] * m, num, list(range(s0, s0 + m)), 1, duration, 0.0, tangent=False,
                   stride=0, room=(100_000, rows))  # fmt: skip
        width = draws_room + (st.lam.shape[1] - 100_000)  # the GPU's: room and margin
        section = np.empty((m, int(duration / p.cam_period) + 8, k.SECTION_COLS))
        impacts = np.empty((m, rows + 64 if rows else 0, k.IMPACT_COLS))
        _between_stops(alone_kernel(st.c), st.y, st.cnt, st.c, n_stop, st.lam, width, section,
                       impacts, cost[s0 : s0 + m], stops[s0 : s0 + m])  # fmt: skip
    mc = cost / 1e6
    whole = mc.sum(axis=1)
    q = np.percentile(whole, [50, 90, 99, 99.9])
    print(
        f"{members:,} members x {duration:g} s, room {draws_room} draws, "
        f"{rows if keep_impacts else 'no'} impact rows: {stops.min()}-"
        f"{stops.max()} runs between stops a member; Mcycles a member: median {q[0]:.1f}, p90 "
        f"{q[1]:.1f}, p99 {q[2]:.1f}, p99.9 {q[3]:.1f}, max {whole.max():.1f} "
        f"({whole.max() / q[0]:.1f}x the median)"
    )
    for size in sorted({WARP, 64, 2048, members}):
        if size > members:
            continue
        groups = range(0, members // size * size, size)
        one = np.mean([whole[a : a + size].max() for a in groups])
        relaunched = np.mean([mc[a : a + size].max(axis=0).sum() for a in groups])
        mean = whole.mean()
        print(
            f"  {size:,} together: one launch waits {one / mean:.2f}x a mean member, "
            f"relaunched at every stop {relaunched / mean:.2f}x ({relaunched / one:.2f}x "
            f"one launch)"
        )


def main(duration: float = 4.0) -> None:
    p, num = Params(l_lambda_sigma=0.002), Numerics()
    start = fresh([p] * WARP, num, list(range(WARP)), 1, duration, 0.0, tangent=False, stride=0,
                  room=(200_000, 4096))  # fmt: skip
    c = start.c.copy()
    c[:, k.C_CALL_STEPS] = 1.0  # one loop iteration a call
    run = alone_kernel(c)  # the RK4 kernel's compiled single-member call
    n_stop = int(round(duration / num.dt))
    width = int(60_000 * duration) + 10_000  # iterations: about 41,500 a simulated second
    cost = np.zeros((WARP, width), np.int64)
    at = np.zeros((WARP, width))
    hits = np.zeros((WARP, width), np.int64)
    section = np.empty((WARP, 64, k.SECTION_COLS))
    impacts = np.empty((WARP, 0, k.IMPACT_COLS))  # no rows: the kernel only counts them
    warm = [a[:1].copy() for a in (start.y, start.cnt, c, start.lam, section, impacts)]
    _iterations(run, *warm[:3], 10, *warm[3:], cost[:1, :5].copy(), at[:1, :5].copy(),
                hits[:1, :5])  # fmt: skip
    done = _iterations(run, start.y, start.cnt, c, n_stop, start.lam, section, impacts, cost, at,
                       hits)  # fmt: skip
    if (done == 0).any():
        raise SystemExit("a member ran out of draws or of iterations: enlarge the room")
    print(f"{WARP} members x {duration:g} s: {done.min():,}-{done.max():,} iterations each")
    cost = cost.astype(float)
    for lo, hi in [(0.0, 0.5), (0.5, duration), (0.0, duration)]:
        inside = (at > lo) & (at <= hi)
        c_in = np.where(inside, cost, 0.0)
        median = float(np.median(cost[inside]))
        lanes = _aligned(cost, inside)
        cheap = np.where(hits > 0, median, cost)
        cheap_lanes = np.where(_aligned(hits, inside) > 0, median, lanes)
        work = c_in.sum()
        lockstep = work / (WARP * lanes.max(axis=0).sum())
        no_impacts = np.where(inside, cheap, 0.0).sum() / (WARP * cheap_lanes.max(axis=0).sum())
        totals = c_in.sum(axis=1)
        hit = inside & (hits > 0)
        print(
            f"t in ({lo:g}, {hi:g}] s: lockstep efficiency {lockstep:.2f} "
            f"({lockstep * WARP:.1f} of {WARP} lanes); impacts at a median iteration's cost "
            f"{no_impacts:.2f}; equal-units bound {totals.mean() / totals.max():.2f}. "
            f"Iterations with an impact: {hit.sum() / inside.sum():.4f} of them, "
            f"{cost[hit].sum() / work:.2f} of the cycles (median iteration {median:.0f} cycles)"
        )


if __name__ == "__main__":
    if sys.argv[1:2] == ["--tail"]:
        keep = "--keep-impacts" in sys.argv
        args = [a for a in sys.argv[2:] if a != "--keep-impacts"]
        tail(int(args[0]) if args else 8192, *map(float, args[1:2]), keep_impacts=keep)
    else:
        main(*(float(a) for a in sys.argv[1:2]))
