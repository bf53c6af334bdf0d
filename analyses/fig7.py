"""Paper Fig. 7, reproduced: mu = 0.008 m, sigma up to 0.004 m (regime map shared by Figs. 7-10).

Writes its data and a PNG into OUTDIR; ``chaoscam paper`` runs the same code.
Usage: python analyses/fig7.py [--quick] [--force] [--workers N] [OUTDIR]
(default OUTDIR: reports/paper-data; its existing files are replaced only with --force)
"""

from chaoscam.paper import figure_script

if __name__ == "__main__":
    figure_script(7)
