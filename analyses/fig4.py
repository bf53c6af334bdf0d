"""Paper Fig. 4, reproduced: bifurcation of theta_f over l_lambda in [0.001, 0.018] m.

Writes its data and a PNG into OUTDIR; ``chaoscam paper`` runs the same code.
Usage: python analyses/fig4.py [--quick] [--force] [--workers N] [OUTDIR]
(default OUTDIR: reports/paper-data; its existing files are replaced only with --force)
"""

from chaoscam.paper import figure_script

if __name__ == "__main__":
    figure_script(4)
