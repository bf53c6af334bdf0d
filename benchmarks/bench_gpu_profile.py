"""Where a GPU ensemble's time goes: launches against refills, per buffer room.

Run: python benchmarks/bench_gpu_profile.py

A member stops for a refill whenever its line-length draws or impact rows (the room,
``chaoscam.simulation.ROOM["gpu"]``) run out, and each stop is a relaunch of the batch, in which
the device waits for its slowest member and the host refills the draws of every member that
asked. The launches and refills are timed by wrapping the loop the GPU host runs them in
(``chaoscam.kernel.drive_members`` as ``chaoscam.kernel._gpu`` calls it: private, a
benchmark's instrument).
It measures one full wave of an H200 (132 x 256 members: 4 blocks, 8 warps, a multiprocessor),
one block a multiprocessor and one block, each 0.25 s, then the full wave with its impacts kept
(256 rows: every member stops for room three or four times in its first 0.05 s; not kept, the
impacts are only counted and a member stops only when its draws run out). For each it prints
the wall time, the number of launches, the time in launches and in refills, and the rate.
"""

from __future__ import annotations

import argparse
import contextlib
import time

import chaoscam
from chaoscam import Params
from chaoscam.kernel import _gpu, gpu_status
from chaoscam.simulation import ROOM


class _Clock:
    """Seconds spent in ``drive_members``' launches and refills, the launches made, and each
    launch's (members launched, seconds)."""

    def __init__(self) -> None:
        self.launch = self.refill = 0.0
        self.launches = 0
        self.each: list[tuple[int, float]] = []

    def _timed(self, fn, field: str):
        def timed(x):
            t0 = time.perf_counter()
            try:
                return fn(x)
            finally:
                setattr(self, field, getattr(self, field) + time.perf_counter() - t0)

        return timed

    def wrap(self, drive):
        def timed(n, launch, refill, need=None):
            def counted(x):
                self.launches += 1
                t0 = time.perf_counter()
                codes = launch(x)
                self.each.append((len(x), time.perf_counter() - t0))
                return codes

            return drive(n, self._timed(counted, "launch"), self._timed(refill, "refill"), need)

        return timed


@contextlib.contextmanager
def clocked():
    """A :class:`_Clock` on the GPU host's ``drive_members`` while inside (restored on the
    way out)."""
    clock = _Clock()
    inner, _gpu.drive_members = _gpu.drive_members, clock.wrap(_gpu.drive_members)
    try:
        yield clock
    finally:
        _gpu.drive_members = inner


def measure(p, members, duration, room, impacts=False):
    """(wall time, clock, ensemble) of one GPU ensemble with this room."""
    before, ROOM["gpu"] = ROOM["gpu"], room
    try:
        with clocked() as clock:
            t0 = time.perf_counter()
            ens = chaoscam.solve(p, indices=range(members), seed=1, duration=duration,
                                 backend="gpu", impacts=impacts)  # fmt: skip
            return time.perf_counter() - t0, clock, ens
    finally:
        ROOM["gpu"] = before


def main() -> None:
    argparse.ArgumentParser(description=__doc__.splitlines()[0]).parse_args()
    ok, reason = gpu_status()
    if not ok or "simulator" in reason:
        print(f"GPU: not available ({reason}); nothing measured")
        return
    print(f"GPU: {reason}")
    p = Params(l_lambda_sigma=0.002)
    small = ROOM["gpu"]
    full, per_sm = 132 * 256, 132 * 64  # an H200 at 8 warps, and at 2, a multiprocessor
    plan = [(full, 0.25, False), (per_sm, 0.25, False), (64, 0.25, False), (full, 0.25, True)]
    for members, duration, keep in plan:
        what = f"{members:>6,} x {duration:>4g} s" + (", impacts kept" if keep else "")
        wall, c, _ = measure(p, members, duration, small, keep)
        rate = members / wall
        print(
            f"{what}: {wall:7.2f} s = {rate:9,.1f} traj/s ({rate * duration / 20:9,.1f} 20-s "
            f"traj/s); {c.launches} launches {c.launch:.2f} s, refills {c.refill:.2f} s",
            flush=True,
        )
        each = ", ".join(f"{m:,} members {t:.2f} s" for m, t in c.each[:12])
        print(f"    launches: {each}{' ...' if len(c.each) > 12 else ''}", flush=True)


if __name__ == "__main__":
    main()
