"""Paper Fig. 6, reproduced: bifurcation over D for G = 1e-9 and 1e-10 m (fractal stiffness).

Writes its data and a PNG into OUTDIR; ``chaoscam paper`` runs the same code.
Usage: python analyses/fig6.py [--quick] [--force] [--workers N] [OUTDIR]
(default OUTDIR: reports/paper-data; its existing files are replaced only with --force)
"""

from chaoscam.paper import figure_script

if __name__ == "__main__":
    figure_script(6)
