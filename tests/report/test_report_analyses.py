"""The analyses/ scripts: one per paper figure, each writing its data and figure."""

import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]


def test_there_is_one_script_per_paper_figure():
    """analyses/ holds fig3.py ... fig10.py."""
    assert sorted(p.name for p in (ROOT / "analyses").glob("fig*.py")) == sorted(
        f"fig{n}.py" for n in range(3, 11)
    )


def test_fig5_script_writes_data_and_figure(tmp_path):
    """Running a script writes a PNG and a data file into OUTDIR and prints the comparison."""
    out = subprocess.run(
        [sys.executable, str(ROOT / "analyses" / "fig5.py"), "--quick", str(tmp_path)],
        check=True,
        capture_output=True,
        text=True,
    )
    assert "Fig. 5" in out.stdout
    data = list(tmp_path.glob("*.csv")) + list(tmp_path.glob("*.parquet"))
    assert list(tmp_path.glob("*.png")) and data
