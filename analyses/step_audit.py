"""Step audit of a report's figure sweeps: do their labels hold when the step is halved?

Reads the sweeps that ``chaoscam paper`` wrote into DATA (Fig. 4, Fig. 6's two diagrams,
Figs. 7-10's map; ``s``: the sensitivity sweeps, every sensitivity-*.parquet), draws K
decided runs from each (seeded), replays each alone (``chaoscam.sweep.replay``) and
classifies it with ``check_step=True``; prints one line per run and the report's sentence.
The full report runs the same audit with K = 5. With --ladder 2,4,8: each drawn run (any
label) classified at dt, dt/2, dt/4 and dt/8 and compared with the finest (docs/findings.md,
"The figures' step": --figures 6 --per-sweep 100 --ladder 2,4,8); with --label L only the
runs labelled L (docs/findings.md, "The undetermined runs down the step ladder": --figures
4,6,s --label undetermined). Writes nothing.

Usage: python analyses/step_audit.py [--figures 4,6,7,s] [--per-sweep K] [--seed N]
       [--extend-to S] [--ladder K,K [--label L]] [--workers N] [DATA]
       (default DATA: reports/paper-data)
"""

from chaoscam.paper import audit_script

if __name__ == "__main__":
    raise SystemExit(audit_script())
