"""Paper Fig. 5, reproduced: fractal stiffness K_n over D for three G.

Writes its data and a PNG into OUTDIR; ``chaoscam paper`` runs the same code.
Usage: python analyses/fig5.py [--quick] [OUTDIR]   (default OUTDIR: reports/paper-data)
"""

from chaoscam.experiments import figure_script

if __name__ == "__main__":
    figure_script(5)
