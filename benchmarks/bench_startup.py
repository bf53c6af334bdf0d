"""Start-up of the command line, measured in one run (restructure issue).

Prints the wall time of ``python -c "import chaoscam"``, ``chaoscam --help`` and a whole
``chaoscam simulate --duration 20`` (each the best of 3 fresh processes; numba's kernel cache
warm), with the import time of the simulate path. Targets: --help <= 0.3 s, simulate <= 0.8 s.
"""

from __future__ import annotations

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


def main() -> None:
    py = sys.executable
    cli = [py, "-m", "chaoscam.cli"]
    subprocess.run([*cli, "simulate", "--duration", "0.01"], check=True, capture_output=True)
    imp = best_of([py, "-c", "import chaoscam"])
    path = best_of([py, "-c", "import chaoscam._simulate"])
    helped = best_of([*cli, "--help"])
    run = best_of([*cli, "simulate", "--duration", "20"])
    print(f"import chaoscam: {imp:.2f} s; import of the simulate path: {path:.2f} s")
    print(f"chaoscam --help: {helped:.2f} s (target <= 0.3 s)")
    print(f"chaoscam simulate --duration 20: {run:.2f} s (target <= 0.8 s)")


if __name__ == "__main__":
    main()
