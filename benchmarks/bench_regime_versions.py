"""One timed regime map with whichever chaoscam is installed: to compare versions.

Run: python benchmarks/bench_regime_versions.py map [TABLE.parquet]
     python benchmarks/bench_regime_versions.py --against PYTHON [--pairs N]
     python benchmarks/bench_regime_versions.py --make-filed DIR

``map``: 3x3 cells of (l_lambda, l_lambda_sigma) x 6 realizations x 20 s, seed 1, 2
workers, each version's default classifier, warmed first by a small map, timed once. Only
``regime_map(x, y, realizations=, seed=, duration=, workers=)`` is called, which every
version since issue 13 was filed takes: the filed one ran one process task per realization,
this one runs batches of realizations on threads (its one engine). Prints the time, the
trajectories per second, the CPU time (worker processes included) and the labels, and
writes the realizations' table if asked.

``--against PYTHON`` is issue 13's 2-core target (>= 1.8x "against today's process-based
sweep at equal settings", read as the sweep when the issue was filed, ed91016): it runs the
map N times (default 3) with another environment's python, alternated with this checkout's,
each in its own process started from an empty folder (so that neither imports the other
from it), and prints each pair's ratio and the ratio of the best times. ``--make-filed DIR``
makes that environment: ed91016's files in DIR/src (``git archive``: the repository is not
changed) and a virtual environment in DIR/venv with them installed (needs the package
index), then prints the ``--against`` line to run. Run on an idle machine: both use both
cores.
"""

from __future__ import annotations

import argparse
import os
import resource
import subprocess
import sys
import tempfile
import time

from chaoscam.sweep import Axis, regime_map

MODE = "map"
FILED = "ed91016"  # the commit at which issue 13 was filed: its sweep, one process a run
GOAL = 1.8


def _cpu() -> float:
    """CPU seconds used so far by this process and its finished children (the filed
    version's worker processes are children)."""
    me = resource.getrusage(resource.RUSAGE_SELF)
    kids = resource.getrusage(resource.RUSAGE_CHILDREN)
    return me.ru_utime + me.ru_stime + kids.ru_utime + kids.ru_stime


def warm() -> None:
    """A small map first: numba's caches loaded (or compiled), the imports done."""
    regime_map(
        Axis("l_lambda", (0.008,)),
        Axis("l_lambda_sigma", (0.001,)),
        realizations=2,
        duration=1.0,
        workers=2,
    )


def benchmark_map():
    """The benchmark's map."""
    x = Axis.linspace("l_lambda", 0.008, 0.014, 3)
    y = Axis.linspace("l_lambda_sigma", 0.001, 0.002, 3)
    return regime_map(x, y, realizations=6, seed=1, duration=20.0, workers=2)


def one_map(table_path: str | None = None) -> None:
    """The timed map, warmed first; prints its line."""
    warm()
    t0, c0 = time.perf_counter(), _cpu()
    runs = benchmark_map()
    wall, cpu = time.perf_counter() - t0, _cpu() - c0
    table = runs.realizations
    if table_path is not None:
        table.to_parquet(table_path)
    print(
        f"{MODE}: {wall:.2f} s, {len(table) / wall:.2f} traj/s, CPU {cpu:.1f} s, "
        f"load {os.getloadavg()[0]:.2f}; labels {table['label'].value_counts().to_dict()}; "
        f"median impacts a run {table['n_impacts'].median():.0f}"
    )


def _timed(python: str) -> tuple[float, str]:
    """One map in its own process (``python``, an empty working folder, so that neither
    version imports the other from it): its time and its line."""
    with tempfile.TemporaryDirectory() as here:
        out = subprocess.run(
            [python, os.path.abspath(__file__), MODE],
            cwd=here,
            capture_output=True,
            text=True,
        )
    line = out.stdout.strip().splitlines()[-1] if out.stdout.strip() else ""
    if out.returncode != 0 or not line.startswith(f"{MODE}: "):
        sys.exit(f"{python} {MODE} failed:\n{out.stderr[-2000:]}")
    return float(line.split()[1]), line


def compare(other: str, pairs: int) -> None:
    """``pairs`` alternated maps, ``other``'s then this checkout's; prints each pair's ratio
    and the best times' ratio against GOAL."""
    theirs, ours = [], []
    for i in range(pairs):
        t, line = _timed(other)
        theirs.append(t)
        print(f"pair {i + 1}, other  {line}", flush=True)
        t, line = _timed(sys.executable)
        ours.append(t)
        print(f"pair {i + 1}, this   {line}; ratio {theirs[-1] / t:.2f}x", flush=True)
    ratio = min(theirs) / min(ours)
    print(
        f"best of {pairs}: other {min(theirs):.2f} s, this {min(ours):.2f} s: ratio "
        f"{ratio:.2f}x (goal >= {GOAL}: {'met' if ratio >= GOAL else 'not met'}); pair by "
        f"pair {', '.join(f'{a / b:.2f}x' for a, b in zip(theirs, ours, strict=True))}"
    )


def make_filed(folder: str) -> None:
    """FILED's files and a virtual environment with them installed, under ``folder``."""
    root = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
    src, venv = os.path.join(folder, "src"), os.path.join(folder, "venv")
    os.makedirs(src)
    archive = subprocess.Popen(["git", "-C", root, "archive", FILED], stdout=subprocess.PIPE)
    subprocess.run(["tar", "-x", "-C", src], stdin=archive.stdout, check=True)
    if archive.wait() != 0:
        sys.exit(f"git archive {FILED} failed")
    for cmd in (
        [sys.executable, "-m", "venv", venv],
        [os.path.join(venv, "bin", "pip"), "install", "-q", "-e", src],
    ):
        subprocess.run(cmd, check=True)
    print(f"now: python {__file__} --against {os.path.join(venv, 'bin', 'python')}")


def main() -> None:
    if len(sys.argv) > 1 and sys.argv[1] == MODE:
        if len(sys.argv) > 3:
            sys.exit(f"usage: {sys.argv[0]} {MODE} [TABLE.parquet]")
        one_map(sys.argv[2] if len(sys.argv) == 3 else None)
        return
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--against", metavar="PYTHON", help="another environment's python")
    ap.add_argument("--pairs", type=int, default=3, help="alternated pairs (default 3)")
    ap.add_argument("--make-filed", metavar="DIR", help=f"make an environment of {FILED}")
    args = ap.parse_args()
    if args.make_filed:
        make_filed(args.make_filed)
    elif args.against:
        if args.pairs < 1:
            ap.error("--pairs: at least 1")
        compare(args.against, args.pairs)
    else:
        ap.error(f"give {MODE} [TABLE.parquet], --against PYTHON or --make-filed DIR")


if __name__ == "__main__":
    main()
