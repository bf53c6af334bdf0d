"""Paper Fig. 3, reproduced: the contact-line length process (resampled every 0.01 s).

Writes its data and a PNG into OUTDIR; ``chaoscam paper`` runs the same code.
Usage: python analyses/fig3.py [--quick] [--force] [--workers N] [OUTDIR]
(default OUTDIR: reports/paper-data; its existing files are replaced only with --force)
"""

from chaoscam.paper import figure_script

if __name__ == "__main__":
    figure_script(3)
