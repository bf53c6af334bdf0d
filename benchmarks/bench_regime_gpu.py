"""Regime map on a GPU against 2 CPU cores (issue 13), measured in one run.

Run: python benchmarks/bench_regime_gpu.py [--realizations N] [--reference N]

The (mu, sigma) map of 2 x 2 cells (mu = 0.008 and 0.015 m, sigma = 1 and 2 mm), default
model, ``--duration`` 20 s simulated (regime_map's duration: its first half the transient),
undetermined members extended to ``--extend-to`` recorded seconds (``regime_map``'s
``extend_to``). The GPU runs ``--realizations`` members a cell (``device="gpu"``: batches
launched on the device while the host labels the last); the reference runs the first
``--reference`` of them on 2 CPU cores (``device="cpu"``, ``workers=2``: a batch a thread).
Rates are trajectories per second end to end (the sweep's set-up, its host labelling and the
extension of undetermined members included; compilation excluded by a warm-up); the
reference rate is measured on its smaller sample (a rate does not depend on the sample size
beyond a batch).

It prints how the GPU run's wall time divides between the device calls (each listed with
its members and seconds), the CPU batches (the extension of undetermined members: a GPU
run's extension goes where ``backend="auto"`` puts it, the host's cores for fewer than
``chaoscam.kernel.AUTO_GPU_MIN`` members) and the rest of the host's work (labels, set-up,
checkpoints), and compares the labels of the realizations both ran: a GPU's sections equal
the CPU's only within ``GPU_TOLERANCE`` over a cam period and part later on chaotic runs (see
``chaoscam.kernel._gpu``), so chaotic members agree in label, not in numbers. The device
calls and CPU batches are timed by wrapping the batch runner's ``run_on_gpu`` and
``run_on_cpu`` where ``chaoscam.simulation._batch`` calls them (private: a benchmark's
instrument).
Each device call and CPU batch is also printed as it ends, so a call cut short by a time
limit still shows how far the map got.
Without a GPU it says why on one line and exits 0.

Measured on an H100 (2026-11-28, ``--realizations 512 --duration 20 --reference 4``, before
the process engine was removed): 2,048 runs in 108.7 s = 18.8 traj/s, 4.14x the 2-core
process engine (4.6 traj/s) and 3.78x the 2-core ensemble engine (5.0, today's one engine),
all 2,048 chaotic, the 16 both ran 100 % equal. One device call
of 87.1 s (20 s a member: 0.23 simulated seconds a second a thread, a lone thread's rate: the
batch was far from filling the device), the 530 undetermined members' extension on the host's
16 cores 12.8 s, the rest 8.7 s. At 4,096 a cell (two batches of 8,192) the map did not end
within the 240 s its call left it.
"""

from __future__ import annotations

import argparse
import os
import threading
import time

from chaoscam.kernel import gpu_status
from chaoscam.simulation import _batch
from chaoscam.sweep import Axis, regime_map


class _DeviceClock:
    """Wall time spent inside a batch runner (``run_on_gpu``: launches, transfers and
    refills; ``run_on_cpu``: the host's batches), with each call's members, start (seconds
    after ``origin``) and length: the starts show whether the host's work overlapped a
    launch (a GPU sweep labels a batch while the next one is launched)."""

    origin = time.perf_counter()

    def __init__(self, inner, name: str = "") -> None:
        self.calls: list[tuple[int, float, float]] = []
        self._lock = threading.Lock()
        self._inner = inner
        self._name = name  # printed as each call ends, when given (a call cut short says so)

    @property
    def seconds(self) -> float:
        return sum(s for _, _, s in self.calls)

    def __call__(self, *args, **kwargs):
        t0 = time.perf_counter()
        try:
            return self._inner(*args, **kwargs)
        finally:
            with self._lock:
                self.calls.append((int(args[0].shape[0]), t0, time.perf_counter() - t0))
                if self._name:
                    print(f"  {self._name}: {self.listing(most=0, last=1)}", flush=True)

    def listing(self, most: int = 12, last: int = 0) -> str:
        """The first ``most`` calls, or the ``last`` ones."""
        calls = self.calls[-last:] if last else self.calls[:most]
        shown = ", ".join(
            f"{n:,} members at {t - _DeviceClock.origin:.1f} s for {s:.1f} s" for n, t, s in calls
        )
        more = len(self.calls) - most
        return shown + (f", ... ({more} more)" if not last and more > 0 else "")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--realizations", type=int, default=1024, help="GPU members a cell")
    ap.add_argument("--reference", type=int, default=8, help="2-core members a cell")
    ap.add_argument("--duration", type=float, default=20.0, help="simulated [s]")
    ap.add_argument("--extend-to", type=float, default=40.0, help="extension cap [s]")
    args = ap.parse_args()
    ok, reason = gpu_status()
    if not ok or "simulator" in reason:
        print(f"GPU: not available ({reason}); nothing measured")
        return
    x = Axis("l_lambda", (0.008, 0.015))
    y = Axis("l_lambda_sigma", (0.001, 0.002))
    cells = len(x.values) * len(y.values)
    kw = dict(seed=1, duration=args.duration, extend_to=args.extend_to)
    print(
        f"GPU: {reason}; cores here {os.cpu_count()}; map 2 x 2 cells, {args.duration:g} s, "
        f"extended to {args.extend_to:g} s"
    )

    t0 = time.perf_counter()
    regime_map(Axis("l_lambda", (0.008,)), Axis("l_lambda_sigma", (0.001,)),
               realizations=2, duration=1.0, device="gpu")  # fmt: skip
    print(f"warm-up (GPU kernel compilation): {time.perf_counter() - t0:.1f} s")
    clock = _DeviceClock(_batch.run_on_gpu, "device call")
    host = _DeviceClock(_batch.run_on_cpu, "CPU batch")
    _batch.run_on_gpu, _batch.run_on_cpu = clock, host
    try:
        t0 = _DeviceClock.origin = time.perf_counter()
        gpu = regime_map(x, y, realizations=args.realizations, device="gpu", **kw)
        wall = time.perf_counter() - t0
    finally:
        _batch.run_on_gpu, _batch.run_on_cpu = clock._inner, host._inner
    runs = cells * args.realizations
    print(
        f"GPU map: {runs:,} runs in {wall:.1f} s = {runs / wall:,.1f} traj/s (device "
        f"{gpu.config.get('device')}); {clock.seconds:.1f} s in {len(clock.calls)} device "
        f"calls ({clock.listing()}); {host.seconds:.1f} s in {len(host.calls)} CPU batches "
        f"(extensions of few members: {host.listing()}); "
        + (
            f"{rest:.1f} s else on the host (labels, set-up, checkpoints)"
            if (rest := wall - clock.seconds - host.seconds) >= 0
            else f"the device calls and the CPU batches overlapped by at least {-rest:.1f} s"
        )
    )

    regime_map(Axis("l_lambda", (0.008,)), Axis("l_lambda_sigma", (0.001,)),
               realizations=2, duration=1.0, workers=2)  # fmt: skip
    t0 = time.perf_counter()
    ref = regime_map(x, y, realizations=args.reference, device="cpu", workers=2, **kw)
    wall_ref = time.perf_counter() - t0
    rate = cells * args.reference / wall_ref
    print(f"2 CPU cores: {cells * args.reference} runs in {wall_ref:.1f} s = {rate:.1f} traj/s")
    print(f"ratio GPU map / 2 CPU cores: {runs / wall / rate:.2f}x")
    a = gpu.realizations.set_index(["cell", "index"])
    b = ref.realizations.set_index(["cell", "index"])
    common = a.loc[b.index]
    agree = float((common["label"] == b["label"]).mean())
    print(
        f"labels of the {len(b)} realizations both ran, GPU against 2 CPU cores: "
        f"{agree:.0%} agree (GPU {common['label'].value_counts().to_dict()}, CPU "
        f"{b['label'].value_counts().to_dict()})"
    )
    print(f"GPU labels, all members: {gpu.realizations['label'].value_counts().to_dict()}")


if __name__ == "__main__":
    main()
