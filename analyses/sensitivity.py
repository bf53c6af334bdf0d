"""Why our reconstruction differs from the paper: the sweeps of the report's last section.

The stiffness K_n over 9 decades (through the follower's Young's modulus Y_f), the
restitution xi from 0.1 to 0.7 and an (omega, xi) regime map of the deterministic model,
each run classified with the package's default classifier; ``chaoscam paper`` runs the same
code (``chaoscam/paper/_sensitivity.py``) as its last stage.

Writes its data and PNGs into OUTDIR and prints the findings.
Usage: python analyses/sensitivity.py [--quick] [--force] [--workers N] [OUTDIR]
(default OUTDIR: reports/paper-data; its existing files are replaced only with --force)
"""

from chaoscam.paper import SENSITIVITY, figure_script

if __name__ == "__main__":
    figure_script(SENSITIVITY)
