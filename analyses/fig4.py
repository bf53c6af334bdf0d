"""Paper Fig. 4, reproduced: writes its data and a PNG into OUTDIR.

A thin script over :func:`chaoscam.report._paper.fig4`, which `chaoscam paper` also runs.

Usage: python analyses/fig4.py [--quick] [OUTDIR]   (default OUTDIR: reports/paper-data)
"""

from __future__ import annotations

import sys
from pathlib import Path

from chaoscam.report._paper import fig4


def main(quick: bool, outdir) -> None:
    """Run Fig. 4 and print what it found against the paper."""
    outdir = Path(outdir)
    outdir.mkdir(parents=True, exist_ok=True)
    result = fig4(quick, outdir)
    for c in result.comparisons:
        print(f"{c.figure}: {c.verdict} - {c.found} ({c.reason})")


if __name__ == "__main__":
    args = [a for a in sys.argv[1:] if a != "--quick"]
    main("--quick" in sys.argv[1:], args[0] if args else "reports/paper-data")
