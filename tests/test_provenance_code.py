"""The code record of sweeps and ensembles (chaoscam.io.code_identity): it changes with the
sources that decide results and not with the drivers, and a checkpoint or output made by
other code is not resumed, with a message that says so."""

from __future__ import annotations

import shutil
import subprocess
import sys
from pathlib import Path

import pytest

from chaoscam.io import code_identity
from chaoscam.sweep import SweepError
from chaoscam.sweep._store import CheckpointStore as Checkpoint

PACKAGE = Path(__file__).resolve().parents[1] / "chaoscam"


def _identity_of(root: Path) -> dict:
    code = "import json, chaoscam.io as p; print(json.dumps(p.code_identity()))"
    out = subprocess.run(
        [sys.executable, "-c", code], cwd=root, capture_output=True, text=True, timeout=120
    )
    assert out.returncode == 0, out.stderr
    import json

    return json.loads(out.stdout)


def test_the_fingerprint_follows_the_kernels_not_the_drivers(tmp_path):
    """A copy of the package has the same fingerprint; an edit to a kernel module changes
    it, an edit to the command line does not."""
    copy = tmp_path / "chaoscam"
    shutil.copytree(PACKAGE, copy, ignore=shutil.ignore_patterns("__pycache__", "*.nb?"))
    first = _identity_of(tmp_path)
    assert first == code_identity()
    with (copy / "cli" / "_report.py").open("a") as f:
        f.write("\n# a driver's comment\n")
    assert _identity_of(tmp_path)["sources"] == first["sources"]
    with (copy / "kernel" / "_rk4.py").open("a") as f:
        f.write("\n# a kernel's comment\n")
    assert _identity_of(tmp_path)["sources"] != first["sources"]


def test_a_checkpoint_of_other_code_is_not_resumed(tmp_path):
    """Same settings, other sources: refused, naming the two fingerprints."""
    config = {"kind": "regime_map", "seed": 1, "code": code_identity()}
    Checkpoint(tmp_path / "ckpt", config, resume=False).open()
    other = {**config, "code": {**config["code"], "sources": "0123456789abcdef"}}
    with pytest.raises(SweepError, match="made by other chaoscam code: sources .*0123456789abcdef"):
        Checkpoint(tmp_path / "ckpt", other, resume=True)
    with pytest.raises(SweepError, match=r"it differs in: seed\)"):
        Checkpoint(tmp_path / "ckpt", {**config, "seed": 2}, resume=True)
    Checkpoint(tmp_path / "ckpt", dict(config), resume=True)  # the same code resumes


def test_sweeps_record_their_code_and_device(tmp_path, monkeypatch):
    """A regime map's configuration holds the code record and where it ran; its finished
    output is reused by the same code and refused by other code."""
    from chaoscam.sweep import Axis, _regime, regime_map

    kw = dict(realizations=1, duration=1.0, workers=1, out=tmp_path / "m.parquet")
    x, y = Axis("l_lambda", (0.008,)), Axis("l_lambda_sigma", (0.0,))
    rm = regime_map(x, y, **kw)
    assert rm.config["code"] == code_identity() and rm.config["device"] == "cpu"
    assert regime_map(x, y, resume=True, **kw).config == rm.config
    monkeypatch.setattr(
        _regime, "code_identity", lambda: {**code_identity(), "sources": "fedcba9876543210"}
    )
    with pytest.raises(SweepError, match="other chaoscam code"):
        regime_map(x, y, resume=True, **kw)
