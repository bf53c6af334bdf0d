"""A full GPU wave's rate by run length, its device time apart from the host's (issue 13).

Run: python benchmarks/bench_gpu_wave.py [--members N] [--durations 0.25,2,5] [--cpu-members N]
                                          [--legs K]

One wave fills the device once (default 132 x 256 = 33,792 members: an H200's 132
multiprocessors at 8 warps each, what 216 registers a thread allow). For each duration it
runs one ensemble of the default model with l_lambda_sigma = 2 mm (as bench_gpu.py) and
prints the wall time, the time inside the kernel launches (the launch calls of the GPU
host's ``drive_members``) and the rest (the host: draws, set-up, copies, the result's
tables), and the rate in member-seconds a second, against ``--cpu-members`` members of the
same duration on 2 CPU threads of the same machine, measured in the same run.

Why: on 2026-11-27 33,792 x 0.25 s took 142.6 s on an H200 of which 5.1 s were the launch:
the batch set-up (now ``chaoscam.simulation.fresh``) sized every member's draws with a
maximum over the whole batch, once a member (quadratic, 137 s at that size). Fixed; this
benchmark says what a wave costs now.
The first cam period of ``--check`` members is compared with the CPU's (``GPU_TOLERANCE``;
bench_gpu.py's check); the launches are timed as bench_gpu_profile.py times them.
With ``--legs K`` each duration runs as K legs of equal length, the first a resumable
``chaoscam.solve`` and each next a ``chaoscam.extend`` on the GPU, and a line is printed
after each leg: a call that runs out of time still says how far the wave got, and the legs'
rates say whether later simulated seconds cost more than earlier ones. Each extension goes on
from its members' last section before the leg's end (the solution's ``resume`` copy), so it
runs again up to a cam period (0.22 s at the default omega): the legs' rates count only the
new seconds, a lower bound.
Why: on an H100 (2026-11-28) one launch of a full wave x 20 s did not end within the 250 s
a call left it, and printed nothing.
Without a GPU it says why on one line and exits 0.
"""

from __future__ import annotations

import argparse
import time

import numba
from bench_gpu import max_diff, timed  # run from benchmarks/, as the scripts are
from bench_gpu_profile import clocked, measure

import chaoscam
from chaoscam import Numerics, Params
from chaoscam.kernel import GPU_TOLERANCE, gpu_status
from chaoscam.simulation import ROOM


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--members", type=int, default=132 * 256, help="GPU members (one wave)")
    ap.add_argument("--durations", default="0.25,2,5", help="run lengths [s], comma-separated")
    ap.add_argument("--cpu-members", type=int, default=64, help="CPU sample a duration")
    ap.add_argument("--check", type=int, default=64, help="members in the GPU = CPU check")
    ap.add_argument("--legs", type=int, default=1, help="legs a duration, a line after each")
    args = ap.parse_args()
    durations = [float(x) for x in args.durations.split(",")]
    p, num = Params(l_lambda_sigma=0.002), Numerics()
    numba.set_num_threads(min(2, numba.config.NUMBA_NUM_THREADS))
    chaoscam.solve(p, num, indices=range(2), seed=1, duration=0.01)  # compile or load
    cpu_rate = {}
    for d in durations:
        _, wall = timed(p, num, args.cpu_members, d, "cpu")
        cpu_rate[d] = args.cpu_members * d / wall
        print(f"CPU, 2 threads: {args.cpu_members} x {d:g} s in {wall:.2f} s = "
              f"{cpu_rate[d]:,.0f} member-s/s", flush=True)  # fmt: skip
    ok, reason = gpu_status()
    if not ok or "simulator" in reason:
        print(f"GPU: not available ({reason}); nothing measured on a GPU")
        return
    t0 = time.perf_counter()
    chaoscam.solve(p, num, indices=range(64), seed=1, duration=0.01, backend="gpu")
    print(f"GPU: {reason}; compiled in {time.perf_counter() - t0:.1f} s", flush=True)
    diff = max_diff(p, num, range(args.check), 0.25, 0.0)
    verdict = "ok" if diff <= GPU_TOLERANCE else "FAILED"
    print(f"check: first cam period of {args.check} members, max |GPU - CPU| {diff:.1e} "
          f"(tolerance {GPU_TOLERANCE:g}): {verdict}", flush=True)  # fmt: skip
    for d in durations:
        if args.legs > 1:
            _in_legs(p, args.members, d, args.legs, cpu_rate[d])
            continue
        wall, clock, ens = measure(p, args.members, d, ROOM["gpu"])
        inside, launches = clock.launch, clock.launches
        _report(f"{args.members:,} x {d:g} s", args.members * d, wall, inside, launches,
                cpu_rate[d], ens)  # fmt: skip


def _report(what, member_seconds, wall, inside, launches, cpu_rate, ens) -> None:
    rate = member_seconds / wall
    print(
        f"GPU: {what} in {wall:.1f} s ({launches} launches {inside:.1f} s, host "
        f"{wall - inside:.1f} s) = {rate:,.0f} member-s/s = {rate / 20:,.1f} 20-s traj/s; "
        f"{rate / cpu_rate:.1f}x 2 CPU threads; statuses "
        f"{ens.members.status.value_counts().to_dict()}",
        flush=True,
    )


def _in_legs(p, members, duration, legs, cpu_rate) -> None:
    """One wave of ``duration`` in ``legs`` legs (module docstring), a line after each."""
    ends = [duration * (i + 1) / legs for i in range(legs)]
    total = 0.0
    with clocked() as clock:
        ens, start = None, 0.0
        for end in ends:
            t0 = time.perf_counter()
            before, launches = clock.launch, clock.launches
            if ens is None:
                ens = chaoscam.solve(p, indices=range(members), seed=1, duration=end,
                                     backend="gpu", resumable=True)  # fmt: skip
            else:
                ens = chaoscam.extend(ens, end, resumable=True, backend="gpu")
            wall = time.perf_counter() - t0
            total += wall
            _report(f"{members:,} x {start:g}-{end:g} s (leg)", members * (end - start), wall,
                    clock.launch - before, clock.launches - launches, cpu_rate, ens)  # fmt: skip
            start = end
    print(f"GPU: {members:,} x {duration:g} s in {legs} legs, {total:.1f} s = "
          f"{members * duration / total:,.0f} member-s/s", flush=True)  # fmt: skip


if __name__ == "__main__":
    main()
