"""Start-up of the command line, measured in one run (restructure issue).

Prints the wall time of ``python -c "import chaoscam"``, ``chaoscam --help`` and a whole
``chaoscam simulate --duration 20`` (each the best of 3 fresh processes; numba's kernel cache
warm), with the import time of the simulate path. Targets: --help <= 0.3 s, simulate <= 0.8 s.

Warm means as on any installed copy after its first run: numba's kernel cache and Python's
bytecode cache are written by a first run. That run is made with bytecode writing allowed
even where ``PYTHONDONTWRITEBYTECODE`` is set (as in our sandbox, where chaoscam's modules
would otherwise be compiled from source at every start, about 0.03 s more); the timed runs
then use the environment as it is.

It also prints where a simulate's time goes, measured in one fresh process: the imports, the
first kernel call (numba's CPU target initialisation, which imports scipy.linalg for its BLAS
check, plus loading the cached kernel) and the 20 s run itself. numba's share (its import and
its target initialisation) is a floor no change in chaoscam removes.
"""

from __future__ import annotations

import os
import subprocess
import sys
import time


def best_of(argv: list[str], repeat: int = 3) -> float:
    times = []
    for _ in range(repeat):
        t0 = time.perf_counter()
        subprocess.run(argv, check=True, capture_output=True)
        times.append(time.perf_counter() - t0)
    return min(times)


_PARTS = """
import time
t0 = time.perf_counter()
import numba
t1 = time.perf_counter()
t = time.perf_counter(); import scipy.linalg; blas = time.perf_counter() - t
from chaoscam.simulation import solve
t2 = time.perf_counter()
solve(duration=0.001)
t3 = time.perf_counter()
solve(duration=20.0)
t4 = time.perf_counter()
print(t1 - t0, blas, t2 - t1 - blas, t3 - t2, t4 - t3)
"""


def parts(py: str) -> list[float]:
    """(numba import, scipy.linalg import, chaoscam import, first call, 20 s run) [s]."""
    out = subprocess.run([py, "-c", _PARTS], check=True, capture_output=True, text=True)
    return [float(x) for x in out.stdout.split()]


def main() -> None:
    py = sys.executable
    cli = [py, "-m", "chaoscam.cli"]
    first = {k: v for k, v in os.environ.items() if k != "PYTHONDONTWRITEBYTECODE"}
    subprocess.run(
        [*cli, "simulate", "--duration", "0.01"], check=True, capture_output=True, env=first
    )
    imp = best_of([py, "-c", "import chaoscam"])
    path = best_of([py, "-c", "from chaoscam.simulation import solve"])
    helped = best_of([*cli, "--help"])
    run = best_of([*cli, "simulate", "--duration", "20"])
    print(f"import chaoscam: {imp:.2f} s; import of the simulate path: {path:.2f} s")
    print(f"chaoscam --help: {helped:.2f} s (target <= 0.3 s)")
    print(f"chaoscam simulate --duration 20: {run:.2f} s (target <= 0.8 s)")
    nb, blas, own, first, sim = min((parts(py) for _ in range(3)), key=sum)
    print(
        f"  of which: numba import {nb:.2f} s, scipy.linalg (numba's BLAS check) {blas:.2f} s, "
        f"chaoscam import {own:.2f} s, first kernel call (numba target set-up, cache load) "
        f"{first:.2f} s, the 20 s run {sim:.2f} s"
    )


if __name__ == "__main__":
    main()
