"""How the settled sets' tests classify a configuration: as a user would, through the CLI."""

from __future__ import annotations

import json

from chaoscam.cli import main


def classified_through_the_cli(params: dict, tmp_path, capsys) -> dict:
    """The JSON verdict of `chaoscam classify --json` on a 120 s run (60 s transient) of
    `chaoscam simulate --set NAME=VALUE ...` with ``params``."""
    run = tmp_path / "run.parquet"
    sets = [f"--set={k}={v}" for k, v in params.items()]
    argv = ["simulate", "--duration", "120", "--transient", "60", *sets, "--out", str(run)]
    assert main(argv) == 0
    capsys.readouterr()
    assert main(["classify", "--json", str(run)]) == 0
    return json.loads(capsys.readouterr().out)
