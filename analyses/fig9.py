"""Paper Fig. 9, reproduced: writes its data and a PNG into OUTDIR.

A thin script over :func:`chaoscam.report._paper.fig7_10`, which `chaoscam paper` also runs.
Figs. 7-10 share one script body (a regime map over mu x sigma and six responses).
Usage: python analyses/fig9.py [--quick] [OUTDIR]   (default OUTDIR: reports/paper-data)
"""

from __future__ import annotations

import sys
from pathlib import Path

from chaoscam.report._paper import fig7_10


def main(quick: bool, outdir) -> None:
    """Run Fig. 9 and print what it found against the paper."""
    outdir = Path(outdir)
    outdir.mkdir(parents=True, exist_ok=True)
    result = fig7_10(quick, outdir)
    for c in result.comparisons:
        print(f"{c.figure}: {c.verdict} - {c.found} ({c.reason})")


if __name__ == "__main__":
    args = [a for a in sys.argv[1:] if a != "--quick"]
    main("--quick" in sys.argv[1:], args[0] if args else "reports/paper-data")
