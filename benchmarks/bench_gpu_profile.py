"""Where a GPU ensemble's time goes: launches against refills, per buffer room and layout.

Run: python benchmarks/bench_gpu_profile.py [--budget SECONDS] [--plan scaling|layouts]

A member stops for a refill whenever its line-length draws or impact rows (the room,
``_ensemble._ROOM["gpu"]``) run out, and each stop is a relaunch of the batch, in which the
device waits for its slowest member and the host refills the draws of every member that asked.
The members' memory order on the device (``_gpu.GPU_LAYOUT``: "C", a member's row contiguous,
or "F", a field of consecutive members contiguous, which coalesces a warp's reads but took
255 registers with spills against 196 in ptxas 12.9) is the other choice compared.
For each (members, duration, room, layout) it prints the wall time, the number of launches,
the time in launches and in refills, and the rate.

Plans: "scaling" (the default) asks where a full device's time goes: one full wave (132 x
256 members: 4 blocks, 8 warps, a multiprocessor), one block a multiprocessor, one block,
each 0.25 s, then the full wave with its impacts kept (256 rows: every member stops for room
three or four times in its first 0.05 s; not kept, the impacts are only counted and a member
stops only when its draws run out), none skipped. "layouts", the earlier plan: short runs
first, and a configuration whose time, estimated from the one before it as if time grew with
members x duration (an overestimate while the device is not full), would pass ``--budget``
seconds in all is skipped with a note.

Measured on an H200, 2026-11-27 (third session), scaling: 33,792 / 8,448 / 64 members x
0.25 s took 142.6 / 10.2 / 1.10 s, of which the launch 5.12 / 1.80 / 1.09 s; the rest was the
host's quadratic set-up of a batch, since fixed (see benchmarks/PROFILE.md;
bench_gpu_wave.py measures a wave now).
"""

from __future__ import annotations

import argparse
import contextlib
import time

from chaoscam import Params
from chaoscam.integrate import _ensemble, _gpu, simulate_ensemble


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
    """A :class:`_Clock` on ``_gpu.drive_members`` while inside (restored on the way out)."""
    clock = _Clock()
    inner, _gpu.drive_members = _gpu.drive_members, clock.wrap(_gpu.drive_members)
    try:
        yield clock
    finally:
        _gpu.drive_members = inner


def measure(p, members, duration, room, layout, keep_impacts=False):
    """(wall time, clock, ensemble) of one GPU ensemble with this room and layout."""
    before, _ensemble._ROOM["gpu"] = _ensemble._ROOM["gpu"], room
    order, _gpu.GPU_LAYOUT = _gpu.GPU_LAYOUT, layout
    try:
        with clocked() as clock:
            t0 = time.perf_counter()
            ens = simulate_ensemble(p, range(members), seed=1, duration=duration,
                                    backend="gpu", keep_impacts=keep_impacts)  # fmt: skip
            return time.perf_counter() - t0, clock, ens
    finally:
        _ensemble._ROOM["gpu"], _gpu.GPU_LAYOUT = before, order


def _compiled(p) -> list[str]:
    """The layouts whose kernel compiles and runs here (an error is printed, not raised)."""
    ok = []
    for layout in ("C", "F"):
        t0 = time.perf_counter()
        try:
            measure(p, 64, 0.01, _ensemble._ROOM["gpu"], layout)
        except Exception as exc:  # keep the other layout's numbers
            print(f"layout {layout}: failed ({type(exc).__name__}: {exc}); not measured")
            continue
        print(f"layout {layout}: compiled and ran in {time.perf_counter() - t0:.1f} s")
        ok.append(layout)
    return ok


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--budget", type=float, default=150.0, help="seconds in all")
    ap.add_argument(
        "--plan",
        choices=("scaling", "layouts"),
        default="scaling",
        help="scaling: one full wave of an H200 (132 x 256 members), one block a "
        "multiprocessor and one block, 0.25 s each, then the full wave with its impacts kept, "
        "in the 'C' layout, none skipped (the caller's time limit stops it); layouts: the "
        "earlier plan over layouts, room and length, skipped by estimate",
    )
    args = ap.parse_args()
    ok, reason = _gpu.gpu_status()
    if not ok:
        print(f"GPU: not available ({reason}); nothing measured")
        return
    print(f"GPU: {reason}")
    p = Params(l_lambda_sigma=0.002)
    layouts = _compiled(p)
    small, big = _ensemble._ROOM["gpu"], (16_384, 4_096)
    # the open questions first: each layout at a full device, then the room, then length
    full, per_sm = 132 * 256, 132 * 64  # an H200 at 8 warps, and at 2, a multiprocessor
    scaling = [
        (full, 0.25, small, "C", False), (per_sm, 0.25, small, "C", False),
        (64, 0.25, small, "C", False), (full, 0.25, small, "C", True),
    ]  # fmt: skip
    plan = scaling if args.plan == "scaling" else [x + (False,) for x in [
        (64, 0.5, small, "C"), (64, 0.5, small, "F"),
        (8_192, 0.5, small, "C"), (8_192, 0.5, small, "F"),
        (40_000, 0.5, small, "C"), (40_000, 0.5, small, "F"),
        (8_192, 0.5, big, "C"), (40_000, 2.0, small, "best"), (40_000, 20.0, small, "best"),
    ]]  # fmt: skip
    last = None  # (wall, members, duration) of the configuration before
    walls: dict[tuple[int, str], float] = {}
    sections = {}
    start = time.perf_counter()
    for members, duration, room, layout, keep in plan:
        if layout == "best":  # the faster at 40,000 x 0.5 s
            layout = min(layouts, key=lambda x: walls.get((40_000, x), float("inf")))
        if layout not in layouts:
            continue
        what = f"{members:>6,} x {duration:>4g} s, room {room}, layout {layout}"
        what += ", impacts kept" if keep else ""
        if last is not None and args.plan == "layouts":
            guess = last[0] * members / last[1] * duration / last[2]
            if guess > args.budget - (time.perf_counter() - start):
                print(f"skipped {what}: about {guess:.0f} s")
                continue
        wall, c, ens = measure(p, members, duration, room, layout, keep)
        last = (wall, members, duration)
        walls[(members, layout)] = wall
        if members == 64:
            sections[layout] = ens.sections[["k", "t", "theta_f", "omega_f"]].to_numpy()
        rate = members / wall
        print(
            f"{what}: {wall:7.2f} s = {rate:9,.1f} traj/s ({rate * duration / 20:9,.1f} 20-s "
            f"traj/s); {c.launches} launches {c.launch:.2f} s, refills {c.refill:.2f} s",
            flush=True,
        )
        each = ", ".join(f"{m:,} members {t:.2f} s" for m, t in c.each[:12])
        print(f"    launches: {each}{' ...' if len(c.each) > 12 else ''}", flush=True)
    if len(sections) == 2:
        a, b = sections["C"], sections["F"]
        same = a.shape == b.shape and bool((a == b).all())
        diff = float(abs(a - b).max()) if a.shape == b.shape else float("inf")
        print(
            f"layouts C and F, 64 x 0.5 s sections: identical {same} (max |difference| {diff:.1e})"
        )


if __name__ == "__main__":
    main()
