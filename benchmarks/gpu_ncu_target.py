"""A short GPU ensemble for Nsight Compute to profile (see device_check.sh).

Run under ncu: python benchmarks/gpu_ncu_target.py [MEMBERS] [DURATION]
(default 1,024 members of 0.05 s). One warm-up launch (compilation), then the profiled
ensemble (``chaoscam.solve(..., backend="gpu")``; the kernel is named ``advance_members``):
the default model with l_lambda_sigma = 2 mm (members differ, as in bench_gpu.py).

With room for 2,048 draws and 4,096 impact rows a member (``chaoscam.simulation.ROOM``;
16,384 draws took minutes of host time for a full wave), so that the profiled launch is
the whole run: each member applies 440-960 impacts in its first 0.05 s (the initial
contact's chattering; 811 the median, 1,024 members on the CPU), and with the default room
(256 rows) every member would stop for a refill inside the launch, at its own time, leaving
its warp's lane idle until the slowest one stops. The profile of 2026-11-27 (2.16 threads
active of 32) was taken so: it counts those idle lanes with the divergent ones.
Without a GPU it says why on one line and exits 0.
"""

import sys

import chaoscam
from chaoscam import Params
from chaoscam.kernel import gpu_status
from chaoscam.simulation import ROOM

ok, reason = gpu_status()
if not ok or "simulator" in reason:
    print(f"GPU: not available ({reason}); nothing to profile")
    sys.exit(0)
members = int(sys.argv[1]) if len(sys.argv) > 1 else 1_024
duration = float(sys.argv[2]) if len(sys.argv) > 2 else 0.05
# one launch: no member stops for a refill (impacts not kept are only counted; a new
# contact's draw is one of at most 960 impacts in 0.05 s)
ROOM["gpu"] = (2_048, 4_096)
p = Params(l_lambda_sigma=0.002)
chaoscam.solve(p, indices=range(64), seed=1, duration=0.001, backend="gpu")
ens = chaoscam.solve(p, indices=range(members), seed=1, duration=duration, backend="gpu")
counts = ens.members.status.value_counts().to_dict()
print(f"profiled run ({members} x {duration:g} s):", ens.settings["backend"], counts)
