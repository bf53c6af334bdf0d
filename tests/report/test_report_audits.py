"""analyses/kick_audit.py and fate_audit.py: a report's verdicts asked again (kicks, fate)."""

import importlib.util
import subprocess
import sys
from pathlib import Path

from chaoscam.sweep import Axis, bifurcation, regime_map

ROOT = Path(__file__).resolve().parents[2]
SCRIPT = ROOT / "analyses" / "kick_audit.py"
FATE = ROOT / "analyses" / "fate_audit.py"


def _module(monkeypatch):
    monkeypatch.syspath_prepend(str(SCRIPT.parent))  # its helper, analyses/_report_data.py
    spec = importlib.util.spec_from_file_location("kick_audit", SCRIPT)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def _audit(script: Path, data: Path, stages: str, *more: str):
    """Run an audit script on one worker over ``stages`` of the data folder ``data``."""
    return subprocess.run(
        [sys.executable, str(script), "--data", str(data), "--stages", stages, "--workers", "1"]
        + list(more),
        capture_output=True,
        text=True,
        timeout=600,
    )


def test_an_earlier_audits_refused_rows_are_read_back(tmp_path, monkeypatch):
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
    assert _module(monkeypatch)._refused_in(table) == {("fig4", "value = 0.0065, ic 0")}


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
    done = _audit(SCRIPT, tmp_path, "sensitivity-omega-xi")
    assert done.returncode == 0, done.stderr
    rows = [line for line in done.stdout.splitlines() if line.startswith("| sensitivity")]
    assert len(rows) == 1 and rows[0].endswith("| yes |"), done.stdout
    assert "kicks certify 1 of 1 periodic verdicts" in done.stdout


def test_a_chaotic_verdict_is_continued_to_the_horizon(tmp_path):
    """A one-value xi diagram at 0.31 (chaotic over its 10 s window, Table 1 otherwise): the
    fate audit runs it again to 40 s and reports its status and the verdict on the last half
    there, and counts it."""
    bifurcation("xi", (0.31,), duration=20.0, workers=1, out=tmp_path / "sensitivity-xi.parquet")
    done = _audit(FATE, tmp_path, "sensitivity-xi", "--horizon", "40")
    assert done.returncode == 0, done.stderr
    assert "1 verdicts (chaotic, undetermined) continued to 40 s" in done.stdout, done.stdout
    rows = [line for line in done.stdout.splitlines() if line.startswith("| sensitivity-xi")]
    assert len(rows) == 1 and "| chaotic | chaotic |" in rows[0], done.stdout
    assert "chaotic: chaotic 1" in done.stdout
