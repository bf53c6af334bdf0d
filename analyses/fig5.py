"""Paper Fig. 5, reproduced: fractal stiffness K_n over D for three G.

Writes its data and a PNG into OUTDIR; ``chaoscam paper`` runs the same code.
Usage: python analyses/fig5.py [--quick] [--force] [--workers N] [OUTDIR]
(default OUTDIR: reports/paper-data; its existing files are replaced only with --force)
"""

from chaoscam.paper import figure_script

if __name__ == "__main__":
    figure_script(5)
