"""Where a GPU ensemble's time goes: launches against refills, per buffer room and layout.

Run: python benchmarks/bench_gpu_profile.py [--budget SECONDS]

A member stops for a refill whenever its line-length draws or impact rows (the room,
``_ensemble._ROOM["gpu"]``) run out, and each stop is a relaunch of the batch, in which the
device waits for its slowest member and the host refills the draws of every member that asked.
The members' memory order on the device (``_gpu.GPU_LAYOUT``: "C", a member's row contiguous,
or "F", a field of consecutive members contiguous, which coalesces a warp's reads but took
255 registers with spills against 196 in ptxas 12.9) is the other choice compared.
For each (members, duration, room, layout) it prints the wall time, the number of launches,
the time in launches and in refills, and the rate. Short runs first; a configuration whose
time, estimated from the one before it as if time grew with members x duration (an
overestimate while the device is not full), would pass ``--budget`` seconds in all is
skipped with a note.
"""

from __future__ import annotations

import argparse
import time

from chaoscam import Params
from chaoscam.integrate import _ensemble, _gpu, simulate_ensemble


class _Clock:
    def __init__(self) -> None:
        self.launch = self.refill = 0.0
        self.launches = 0

    def wrap(self, drive):
        def timed(n, launch, refill, need=None):
            def tl(x):
                t0 = time.perf_counter()
                try:
                    return launch(x)
                finally:
                    self.launch += time.perf_counter() - t0
                    self.launches += 1

            def tr(x):
                t0 = time.perf_counter()
                try:
                    return refill(x)
                finally:
                    self.refill += time.perf_counter() - t0

            return drive(n, tl, tr, need)

        return timed


def measure(p, members, duration, room, layout) -> tuple[float, _Clock]:
    clock = _Clock()
    inner, _gpu.drive_members = _gpu.drive_members, clock.wrap(_gpu.drive_members)
    before, _ensemble._ROOM["gpu"] = _ensemble._ROOM["gpu"], room
    order, _gpu.GPU_LAYOUT = _gpu.GPU_LAYOUT, layout
    try:
        t0 = time.perf_counter()
        simulate_ensemble(p, range(members), seed=1, duration=duration, backend="gpu")
        return time.perf_counter() - t0, clock
    finally:
        _gpu.drive_members, _ensemble._ROOM["gpu"] = inner, before
        _gpu.GPU_LAYOUT = order


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--budget", type=float, default=150.0, help="seconds in all")
    args = ap.parse_args()
    ok, reason = _gpu.gpu_status()
    if not ok:
        print(f"GPU: not available ({reason}); nothing measured")
        return
    p = Params(l_lambda_sigma=0.002)
    t0 = time.perf_counter()
    for layout in ("C", "F"):
        _gpu.GPU_LAYOUT, before = layout, _gpu.GPU_LAYOUT
        simulate_ensemble(p, range(64), seed=1, duration=0.01, backend="gpu")
        _gpu.GPU_LAYOUT = before
    print(f"GPU: {reason}; both layouts compiled in {time.perf_counter() - t0:.1f} s")
    small, big = _ensemble._ROOM["gpu"], (16_384, 4_096)
    plan = [
        (64, 0.5, small, "C"), (64, 0.5, big, "C"), (64, 0.5, small, "F"),
        (1_024, 0.5, small, "C"), (1_024, 0.5, small, "F"), (1_024, 0.5, big, "C"),
        (8_192, 0.5, small, "C"), (8_192, 0.5, small, "F"), (8_192, 0.5, big, "C"),
        (40_000, 0.5, small, "C"), (40_000, 0.5, small, "F"), (40_000, 2.0, small, "C"),
        (40_000, 20.0, small, "C"),
    ]  # fmt: skip
    last = None  # (wall, members, duration) of the configuration before
    start = time.perf_counter()
    for members, duration, room, layout in plan:
        what = f"{members:>6,} x {duration:>4g} s, room {room}, layout {layout}"
        if last is not None:
            guess = last[0] * members / last[1] * duration / last[2]
            if guess > args.budget - (time.perf_counter() - start):
                print(f"skipped {what}: about {guess:.0f} s")
                continue
        wall, c = measure(p, members, duration, room, layout)
        last = (wall, members, duration)
        rate = members / wall
        print(
            f"{what}: {wall:7.2f} s = {rate:9,.1f} traj/s ({rate * duration / 20:9,.1f} 20-s "
            f"traj/s); {c.launches} launches {c.launch:.2f} s, refills {c.refill:.2f} s",
            flush=True,
        )


if __name__ == "__main__":
    main()
