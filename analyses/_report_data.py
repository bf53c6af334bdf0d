"""The report's sweeps, read for the audit scripts (kick_audit.py, fate_audit.py)."""

from __future__ import annotations

import sys
from pathlib import Path

from chaoscam.sweep import read_bifurcation, read_regime_map, replay_params

DATA = Path(__file__).resolve().parent.parent / "reports" / "paper-data"
"""Where ``chaoscam paper`` (the full report) writes its sweeps; not in the repository."""


def sweep_rows(data: Path, stage: str):
    """(sweep, rows, names) of the stage's file ``data/STAGE.parquet``: a regime map (it has
    a ``.cells.parquet`` companion) with its realizations and its two axes' names, or a
    diagram with its verdicts and ("value",). Exits with a one-line message if it is
    missing."""
    path = data / f"{stage}.parquet"
    if not path.is_file():
        sys.exit(f"{path}: no such file; run `chaoscam paper` (the full report) first")
    if (data / f"{stage}.cells.parquet").is_file():
        sweep = read_regime_map(path)
        return sweep, sweep.realizations, (sweep.config["x"]["name"], sweep.config["y"]["name"])
    sweep = read_bifurcation(path)
    return sweep, sweep.verdicts, ("value",)


def deterministic_rows(data: Path, stages, labels):
    """(stage, sweep, row, params, numerics, what) for each row labelled one of ``labels`` in
    the stages' files, of the deterministic model only (σ = 0: kicks and certificates ask
    it); ``what`` names the row's axis values (and initial condition) in words."""
    for stage in stages:
        sweep, rows, names = sweep_rows(data, stage)
        for _, row in rows[rows.label.isin(labels)].iterrows():
            p, num = replay_params(sweep, row)
            if p.l_lambda_sigma > 0:
                continue
            what = ", ".join(f"{n} = {row[n]:.4g}" for n in names)
            if "ic" in row:
                what += f", ic {row.ic}"
            yield stage, sweep, row, p, num, what
