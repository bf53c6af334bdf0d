"""GPU ensemble throughput against the CPU ensemble path, measured in one run (numba-cuda).

Runs ``--members`` (default 40,000) trajectories of ``--duration`` (default 20 s) on the GPU,
one CUDA thread each (``chaoscam.solve(..., backend="gpu")``), and ``--cpu-members`` of them
on the CPU (``backend="cpu"``, ``--cpu-threads`` numba threads, default 2: the
2-core reference); the CPU rate is measured on that smaller sample and extrapolated (traj/s
does not depend on the ensemble size beyond a batch). Prints both rates end to end (host
set-up and transfers included, compilation excluded), their ratio, and the targets: >= 3,000
traj/s on an H100 and >= 200x the 2-core CPU path.

The model is the default one with ``l_lambda_sigma = 0.002`` (as in bench_ensemble.py), so
that members differ. Check: GPU and CPU sections agree within ``GPU_TOLERANCE`` for the first
cam period of the first ``--check`` members and for a periodic configuration (8 members,
``Params(xi=0.2)``, 20 s after a 10 s transient); chaotic 20 s runs part after a few periods
on any two roundings, so only their statistics are compared (mean impacts per member).

Without a GPU it says why on one line, still measures the CPU rate, and exits 0.
"""

from __future__ import annotations

import argparse
import time

import numba
import numpy as np

import chaoscam
from chaoscam import Numerics, Params
from chaoscam.kernel import GPU_TOLERANCE, gpu_status, kernel_info
from chaoscam.kernel import layout as k

H100_TARGET = 3_000.0  # traj/s
RATIO_TARGET = 200.0  # GPU / 2-core CPU


def timed(p, num, members, duration, backend, **kw):
    t0 = time.perf_counter()
    kw = dict(indices=range(members), seed=1, duration=duration, backend=backend, **kw)
    ens = chaoscam.solve(p, num, **kw)
    return ens, time.perf_counter() - t0


def max_diff(p, num, indices, duration, transient) -> float:
    kw = dict(indices=indices, seed=1, duration=duration, transient=transient)
    a, b = (chaoscam.solve(p, num, backend=backend, **kw).sections for backend in ("gpu", "cpu"))
    if a.shape != b.shape or not np.array_equal(a.k, b.k):
        return float("inf")
    cols = ["t", "theta_f", "omega_f", "l_lambda"]
    return float(np.abs(a[cols].to_numpy() - b[cols].to_numpy()).max())


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--members", type=int, default=40_000, help="GPU ensemble size")
    ap.add_argument("--duration", type=float, default=20.0, help="trajectory length [s]")
    ap.add_argument("--cpu-members", type=int, default=64, help="CPU sample size")
    ap.add_argument("--cpu-threads", type=int, default=2, help="numba threads on the CPU")
    ap.add_argument("--sigma", type=float, default=0.002, help="l_lambda_sigma [m]")
    ap.add_argument("--batch", type=int, default=None, help="GPU members per batch")
    ap.add_argument("--check", type=int, default=64, help="members in the GPU = CPU check")
    ap.add_argument(
        "--integrator",
        choices=("rk4", "adaptive"),
        default="rk4",
        help="Numerics.integrator of every member (both backends)",
    )
    args = ap.parse_args()
    p, num = Params(l_lambda_sigma=args.sigma), Numerics(integrator=args.integrator)
    print(f"model: default, l_lambda_sigma = {args.sigma:g} m, integrator = {args.integrator}")

    threads = min(args.cpu_threads, numba.config.NUMBA_NUM_THREADS)
    numba.set_num_threads(threads)
    chaoscam.solve(p, num, indices=range(2), seed=1, duration=0.1)  # compile or load
    cpu, cpu_wall = timed(p, num, args.cpu_members, args.duration, "cpu")
    cpu_rate = args.cpu_members / cpu_wall
    print(
        f"CPU ({threads} threads): {args.cpu_members} x {args.duration:g} s in "
        f"{cpu_wall:.1f} s = {cpu_rate:.1f} traj/s (measured on this sample, extrapolated "
        f"to any ensemble size)"
    )

    ok, reason = gpu_status()
    if not ok or "simulator" in reason:
        print(
            f"GPU: no GPU available ({reason}); GPU rate not measured "
            f"(targets: >= {H100_TARGET:,.0f} traj/s on an H100, >= {RATIO_TARGET:.0f}x CPU)"
        )
        return

    t0 = time.perf_counter()
    chaoscam.solve(p, num, indices=range(64), seed=1, duration=0.01, backend="gpu")
    method = k.METHOD_ADAPTIVE if args.integrator == "adaptive" else k.METHOD_RK4
    info = kernel_info(method)
    print(
        f"GPU: {reason}; kernel compiled in {time.perf_counter() - t0:.1f} s, "
        f"{info.get('registers')} registers and {info.get('local_bytes')} B local memory "
        f"a thread, {info.get('block')} threads a block"
    )
    gpu, gpu_wall = timed(p, num, args.members, args.duration, "gpu", batch=args.batch)
    gpu_rate = args.members / gpu_wall
    ratio = gpu_rate / cpu_rate
    print(
        f"GPU: {args.members:,} x {args.duration:g} s in {gpu_wall:.1f} s = "
        f"{gpu_rate:,.0f} traj/s (target >= {H100_TARGET:,.0f} on an H100: "
        f"{'met' if gpu_rate >= H100_TARGET else 'NOT met'})"
    )
    print(
        f"ratio GPU / CPU ({threads} threads): {ratio:.0f}x (target >= {RATIO_TARGET:.0f}x: "
        f"{'met' if ratio >= RATIO_TARGET else 'NOT met'})"
    )
    statuses = gpu.members.status.value_counts().to_dict()
    print(
        f"GPU statuses {statuses}; impacts per member: GPU {gpu.members.n_impacts.mean():.1f} "
        f"(all), CPU {cpu.members.n_impacts.mean():.1f} (sample)"
    )

    n = min(args.check, args.members)
    first = max_diff(p, num, range(n), min(0.25, args.duration), 0.0)
    periodic = max_diff(Params(xi=0.2), num, range(min(n, 8)), 20.0, 10.0)
    tol = GPU_TOLERANCE
    verdict = "ok" if max(first, periodic) <= tol else "FAILED"
    print(
        f"check GPU = CPU within {tol:g} (max |difference| of sections): first cam period "
        f"of {n} members {first:.1e}, periodic Params(xi=0.2) {periodic:.1e}: {verdict}"
    )


if __name__ == "__main__":
    main()
