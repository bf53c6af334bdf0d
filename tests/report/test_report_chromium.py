"""A headless Chromium opens the report from disk and renders a page that is not blank."""

from __future__ import annotations

import shutil
import subprocess

import pytest

import chaoscam
from chaoscam.cli import main

CHROMIUM = next(
    (p for p in (shutil.which("chromium"), shutil.which("chromium-browser")) if p), None
)


@pytest.mark.skipif(CHROMIUM is None, reason="chromium is not installed (apt-get install chromium)")
def test_chromium_screenshot_is_not_blank(tmp_path):
    """The screenshot of the rendered report has many distinct colours (text and figures)."""
    import matplotlib.image as mpimg
    import numpy as np

    chaoscam.simulate(duration=2.0, transient=0.5).to_parquet(tmp_path / "t.parquet")
    report = tmp_path / "r.html"
    assert main(["report", str(tmp_path / "t.parquet"), "--out", str(report)]) == 0
    shot = tmp_path / "shot.png"
    cmd = [
        CHROMIUM,
        "--headless",
        "--no-sandbox",
        "--disable-gpu",
        "--disable-background-networking",
        "--disable-dev-shm-usage",
        f"--user-data-dir={tmp_path / 'profile'}",
        f"--screenshot={shot}",
        "--window-size=1200,1600",
        report.as_uri(),
    ]
    subprocess.run(cmd, capture_output=True, timeout=60, check=False)
    assert shot.exists(), "chromium wrote no screenshot"
    img = mpimg.imread(str(shot))[..., :3]
    flat = np.round(img.reshape(-1, 3) * 255).astype(np.uint8)
    assert np.unique(flat, axis=0).shape[0] > 50, "the screenshot is blank"
    assert (flat.min(axis=1) < 128).mean() > 0.005, "no dark pixels: nothing rendered"
