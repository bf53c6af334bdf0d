"""analyses/kick_audit.py: the kick certificate asked of a report's periodic verdicts."""

import importlib.util
import subprocess
import sys
from pathlib import Path

from chaoscam.sweep import Axis, regime_map

ROOT = Path(__file__).resolve().parents[2]
SCRIPT = ROOT / "analyses" / "kick_audit.py"


def _module():
    spec = importlib.util.spec_from_file_location("kick_audit", SCRIPT)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def test_an_earlier_audits_refused_rows_are_read_back(tmp_path):
    """--refused-from takes (stage, run) of the rows marked NO, and no others."""
    table = tmp_path / "audit.md"
    table.write_text(
        "2 periodic verdicts of the deterministic model\n\n"
        "| stage | run | period | dt [s] | kicks | agree |\n"
        "|---|---|---|---|---|---|\n"
        "| fig4 | value = 0.0065, ic 0 | 8 | 3.8e-07 | 71, 1.5e-06 | NO |\n"
        "| fig4 | value = 0.007, ic 0 | 8 | 3.8e-07 | 0.01, 1e-07; 0.02, 1e-07 | yes |\n"
        "refused: fig4 value = 0.0065, ic 0 (period 8): ...\n"
    )
    assert _module()._refused_in(table) == {("fig4", "value = 0.0065, ic 0")}


def test_a_settled_period_one_cell_is_certified_by_the_kicks(tmp_path):
    """A one-cell (omega, xi) map at (20, 0.3), period 1 with |mu| far below 1: the script
    replays it, asks the kicks at dt and dt/2, and counts it certified."""
    regime_map(
        Axis("omega", (20.0,)),
        Axis("xi", (0.3,)),
        duration=20.0,
        workers=1,
        out=tmp_path / "sensitivity-omega-xi.parquet",
    )
    done = subprocess.run(
        [
            sys.executable,
            str(SCRIPT),
            "--data",
            str(tmp_path),
            "--stages",
            "sensitivity-omega-xi",
            "--workers",
            "1",
        ],
        capture_output=True,
        text=True,
        timeout=600,
    )
    assert done.returncode == 0, done.stderr
    rows = [line for line in done.stdout.splitlines() if line.startswith("| sensitivity")]
    assert len(rows) == 1 and rows[0].endswith("| yes |"), done.stdout
    assert "kicks certify 1 of 1 periodic verdicts" in done.stdout
