"""A short GPU ensemble for Nsight Compute to profile (see device_check.sh).

Run under ncu: one warm-up launch (compilation), then the profiled one: 1,024 members of
0.05 s, default model with l_lambda_sigma = 2 mm (members differ, as in bench_gpu.py).
"""

from chaoscam import Params
from chaoscam.integrate import simulate_ensemble

p = Params(l_lambda_sigma=0.002)
simulate_ensemble(p, range(64), seed=1, duration=0.001, backend="gpu")
ens = simulate_ensemble(p, range(1_024), seed=1, duration=0.05, backend="gpu")
print("profiled run:", ens.settings["backend"], ens.members.status.value_counts().to_dict())
