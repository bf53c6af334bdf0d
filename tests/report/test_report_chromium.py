"""A headless Chromium opens the report from disk and renders a page that is not blank."""

from __future__ import annotations

import shutil
import subprocess
from pathlib import Path

import pytest

import chaoscam
from chaoscam.cli import main

CHROMIUM = next(
    (p for p in (shutil.which("chromium"), shutil.which("chromium-browser")) if p), None
)


@pytest.mark.skipif(CHROMIUM is None, reason="chromium is not installed (apt-get install chromium)")
def test_chromium_screenshot_is_not_blank(tmp_path):
    """The screenshot of the rendered report has many distinct colours (text and figures)."""
    import numpy as np

    chaoscam.simulate(duration=2.0, transient=0.5).to_parquet(tmp_path / "t.parquet")
    report = tmp_path / "r.html"
    assert main(["report", str(tmp_path / "t.parquet"), "--out", str(report)]) == 0
    img = _screenshot(report, tmp_path)
    flat = np.round(img.reshape(-1, 3) * 255).astype(np.uint8)
    assert np.unique(flat, axis=0).shape[0] > 50, "the screenshot is blank"
    assert (flat.min(axis=1) < 128).mean() > 0.005, "no dark pixels: nothing rendered"


def _screenshot(html, tmp_path, height=1600):
    """A headless Chromium screenshot of ``html`` (a file), as an RGB array."""
    import matplotlib.image as mpimg

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
        f"--window-size=1200,{height}",
        html.as_uri(),
    ]
    subprocess.run(cmd, capture_output=True, timeout=120, check=False)
    assert shot.exists(), "chromium wrote no screenshot"
    return mpimg.imread(str(shot))[..., :3]


PAPER = Path(__file__).resolve().parents[2] / "reports" / "paper.html"
MAPS_AND_SWEEPS = (
    "Regime map omega × xi (sensitivity-omega-xi.parquet)",
    "Regime map l_lambda × l_lambda_sigma (fig7-10.parquet)",
    "Bifurcation diagram over Y_f (sensitivity-stiffness.parquet)",
    "Bifurcation diagram over xi (sensitivity-xi.parquet)",
    "Bifurcation diagram over l_lambda (sensitivity-hertz.parquet)",
    "Bifurcation diagram over J (sensitivity-J.parquet)",
    "Bifurcation diagram over y_O (sensitivity-pivot.parquet)",
    "Bifurcation diagram over friction_arm (sensitivity-arm.parquet)",
    "Model parameters every run starts from",
    'id="sensitivity-stiffness"',
    'id="why"',
)


@pytest.mark.skipif(CHROMIUM is None, reason="chromium is not installed (apt-get install chromium)")
def test_committed_paper_report_has_its_maps_and_renders(tmp_path):
    """reports/paper.html holds the (omega, xi) and (mu, sigma) maps, the stiffness and
    restitution sweeps and the 'why the paper differs' section, and Chromium renders it:
    its images decode (an <img> that fails to decode draws nothing) and the page is not
    blank."""
    import base64
    import io
    import re

    import matplotlib.image as mpimg
    import numpy as np

    html = PAPER.read_text(encoding="utf-8")
    for text in MAPS_AND_SWEEPS:
        assert text in html, f"reports/paper.html lacks {text!r}: regenerate it"
    uris = re.findall(r'src="data:image/png;base64,([^"]+)"', html)
    assert len(uris) >= 15
    for u in uris:
        assert mpimg.imread(io.BytesIO(base64.b64decode(u))).size > 0
    img = _screenshot(PAPER, tmp_path, height=4000)
    flat = np.round(img.reshape(-1, 3) * 255).astype(np.uint8)
    assert np.unique(flat, axis=0).shape[0] > 50, "the screenshot is blank"
