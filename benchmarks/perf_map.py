"""Where a regime map's CPU time goes, by compiled function (Linux ``perf``).

Run: python benchmarks/perf_map.py [--top N] [--keep FILE]

``perf`` names no function in numba's compiled code: it sees addresses in anonymous memory.
This script runs itself again with numba's cache in an empty folder (code loaded from the
cache keeps no function list, so numba compiles the kernels, about 30 s), writes
``/tmp/perf-PID.map`` (perf's format for code made at run time: start, size, name) from
numba's compiled libraries, with each function's address from its execution engine and its
size up to the next one's start, then records itself with ``perf record`` while it runs the
map of ``bench_regime_versions.py`` (3x3 cells x 6 realizations x 20 s, 2 workers),
warmed first, and prints the top of ``perf report`` with numba's names shortened
to ``module.function``. Functions numba inlined into their callers count in the callers.
The share of ``NRT_incref`` / ``NRT_decref`` (numba's reference counting) is how
``_nrt=False`` on the kernels was found (``benchmarks/PROFILE.md``).
"""

from __future__ import annotations

import argparse
import gc
import os
import re
import shutil
import signal
import subprocess
import sys
import tempfile
import time

from bench_regime_versions import benchmark_map, warm


def _short(name: str) -> str:
    """``_ZN8chaoscam6kernel4_rk49run_chunkB2v2...`` -> ``_rk4.run_chunk``."""
    if not name.startswith("_ZN"):
        return name
    parts, i = [], 3
    while i < len(name) and name[i].isdigit():
        j = i
        while name[j].isdigit():
            j += 1
        n = int(name[i:j])
        parts.append(name[j : j + n])
        i = j + n
    return ".".join(parts[-2:]) if parts else name


def write_perf_map(path: str) -> int:
    """Write perf's map of every function numba has compiled or loaded in this process;
    return how many."""
    from numba.core.registry import CPUDispatcher

    found = {}
    for obj in gc.get_objects():
        if not isinstance(obj, CPUDispatcher):
            continue
        for cres in obj.overloads.values():
            lib = cres.library
            engine = lib._codegen._engine
            for fn in lib._final_module.functions:
                if fn.is_declaration:
                    continue
                address = engine.get_function_address(fn.name)
                if address:
                    found[address] = _short(fn.name)
    starts = sorted(found)
    with open(path, "w") as fh:
        for a, b in zip(starts, [*starts[1:], starts[-1] + 4096], strict=True):
            fh.write(f"{a:x} {min(b - a, 1 << 20):x} {found[a]}\n")
    return len(starts)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--top", type=int, default=20, help="how many functions to print")
    ap.add_argument("--keep", help="keep perf's recording in this file")
    args = ap.parse_args()
    if shutil.which("perf") is None:
        sys.exit("perf_map: needs Linux perf on the PATH")
    if os.environ.get("CHAOSCAM_PERF_MAP") != "compiled":
        with tempfile.TemporaryDirectory() as cache:
            env = {**os.environ, "NUMBA_CACHE_DIR": cache, "CHAOSCAM_PERF_MAP": "compiled"}
            sys.exit(subprocess.run([sys.executable, *sys.argv], env=env).returncode)
    warm()
    perf_map = f"/tmp/perf-{os.getpid()}.map"
    print(f"{write_perf_map(perf_map)} compiled functions mapped", flush=True)
    data = args.keep or os.path.join(tempfile.mkdtemp(), "perf.data")
    rec = subprocess.Popen(
        ["perf", "record", "-F", "999", "-p", str(os.getpid()), "-o", data],
        stdout=subprocess.DEVNULL,
        stderr=subprocess.DEVNULL,
    )
    time.sleep(1.0)  # perf attaches
    t0 = time.perf_counter()
    benchmark_map()
    wall = time.perf_counter() - t0
    rec.send_signal(signal.SIGINT)
    rec.wait()
    report = subprocess.run(
        ["perf", "report", "-i", data, "--sort", "sym", "--stdio", "--no-children"],
        capture_output=True,
        text=True,
    ).stdout
    os.remove(perf_map)
    print(f"the map took {wall:.2f} s; samples by function (perf report):")
    rows = [r for r in report.splitlines() if r.strip() and not r.startswith("#")]
    for row in rows[: args.top]:
        print(re.sub(r"\s+", " ", row.strip()))


if __name__ == "__main__":
    main()
