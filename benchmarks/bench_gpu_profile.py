"""Where a GPU ensemble's time goes: kernel launches against host refills, per buffer room.

Run: python benchmarks/bench_gpu_profile.py [--budget SECONDS]

A member stops for a refill whenever its line-length draws or impact rows (the room,
``_ensemble._ROOM["gpu"]``) run out, and each stop is a relaunch of the batch, in which the
device waits for its slowest member and the host refills the draws of every member that asked.
For each (members, duration, room) it prints the wall time, the number of launches, the time in
launches and in refills, and the rate. Short runs first; a configuration whose time, estimated
from the one before it as if time grew with members x duration (an overestimate while the
device is not full), would pass ``--budget`` seconds in all is skipped with a note.
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


def measure(p, members, duration, room) -> tuple[float, _Clock]:
    clock = _Clock()
    inner, _gpu.drive_members = _gpu.drive_members, clock.wrap(_gpu.drive_members)
    before, _ensemble._ROOM["gpu"] = _ensemble._ROOM["gpu"], room
    try:
        t0 = time.perf_counter()
        simulate_ensemble(p, range(members), seed=1, duration=duration, backend="gpu")
        return time.perf_counter() - t0, clock
    finally:
        _gpu.drive_members, _ensemble._ROOM["gpu"] = inner, before


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
    simulate_ensemble(p, range(64), seed=1, duration=0.01, backend="gpu")
    print(f"GPU: {reason}; compiled in {time.perf_counter() - t0:.1f} s")
    small, big = _ensemble._ROOM["gpu"], (16_384, 4_096)
    plan = [
        (64, 0.5, small), (64, 0.5, big), (1_024, 0.5, small), (1_024, 0.5, big),
        (8_192, 0.5, small), (8_192, 0.5, big), (40_000, 0.5, big), (40_000, 2.0, big),
        (40_000, 20.0, big),
    ]  # fmt: skip
    per_member_second = None
    start = time.perf_counter()
    for members, duration, room in plan:
        if per_member_second is not None:
            guess = per_member_second * members * duration
            left = args.budget - (time.perf_counter() - start)
            if guess > left:
                print(f"skipped {members:,} x {duration:g} s, room {room}: about {guess:.0f} s")
                continue
        wall, c = measure(p, members, duration, room)
        rate = members / wall
        per_member_second = wall / (members * duration)
        print(
            f"{members:>6,} x {duration:>4g} s, room {room}: {wall:7.2f} s = {rate:9,.1f} traj/s "
            f"({rate * duration / 20:9,.1f} 20-s traj/s); {c.launches} launches "
            f"{c.launch:.2f} s, refills {c.refill:.2f} s",
            flush=True,
        )


if __name__ == "__main__":
    main()
