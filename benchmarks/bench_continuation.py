"""Continuation on the model, measured in one run (issue: continuation through impacts).

Prints the wall time of a 200-point branch (target <= 10 s on 2 cores) for the period-1 orbit
at xi = 0.1 from omega = 31 rad/s and the period-2 orbit born at its period doubling (from
omega = 32.5 rad/s), each with its events and the map calls' share.
"""

from __future__ import annotations

import time

import chaoscam
from chaoscam.continuation import continuation


def branch(omega: float, period: int) -> None:
    p = chaoscam.Params(xi=0.1, omega=omega)
    t0 = time.perf_counter()
    b = continuation(p, param="omega", to=omega + 1.5, period=period, max_points=200,
                     ds_max=0.004)  # fmt: skip
    wall = time.perf_counter() - t0
    n = b.points["point"].nunique()
    events = ", ".join(f"{r.kind} {r.value:.6g}" for r in b.events.itertuples())
    print(f"period {period}: {n} points in {wall:.2f} s ({1e3 * wall / n:.1f} ms a point); "
          f"events: {events}")  # fmt: skip


def main() -> None:
    continuation(chaoscam.Params(xi=0.1, omega=31.0), to=31.05, max_points=3)  # compile / cache
    branch(31.0, 1)
    branch(32.5, 2)


if __name__ == "__main__":
    main()
