"""A headless Chromium opens the report from disk and renders a page that is not blank, whose
first screen (1400x900) shows the answer and its figure."""

from __future__ import annotations

import re
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


def _chromium(html, tmp_path, *args) -> str:
    """Headless Chromium on ``html`` (a file) with ``args``; its stdout."""
    cmd = [
        CHROMIUM,
        "--headless",
        "--no-sandbox",
        "--disable-gpu",
        "--disable-background-networking",
        "--disable-dev-shm-usage",
        f"--user-data-dir={tmp_path / 'profile'}",
        *args,
        html.as_uri(),
    ]
    return subprocess.run(cmd, capture_output=True, text=True, timeout=120, check=False).stdout


def _screenshot(html, tmp_path, height=1600, width=1200):
    """A headless Chromium screenshot of ``html`` (a file), as an RGB array."""
    import matplotlib.image as mpimg

    shot = tmp_path / "shot.png"
    _chromium(html, tmp_path, f"--screenshot={shot}", f"--window-size={width},{height}")
    assert shot.exists(), "chromium wrote no screenshot"
    return mpimg.imread(str(shot))[..., :3]


_GEOMETRY = """<script>window.addEventListener("load", () => {
  const box = (q) => document.querySelector(q).getBoundingClientRect();
  const t = box("#answer p.headline"), i = box("#answer img");
  document.body.dataset.geometry = [t.top, t.bottom, i.top, i.bottom, i.width,
                                    window.innerHeight].join(" ");
});</script>"""


def _first_screen(report, tmp_path) -> dict:
    """Where the headline and its figure lie in a 1400x900 window (laid out by Chromium, a
    script added to a copy of the report), and whether the screen's top shows anything."""
    import numpy as np

    probe = tmp_path / "probe.html"
    probe.write_text(report.read_text().replace("</body>", _GEOMETRY + "</body>"))
    dom = _chromium(probe, tmp_path, "--window-size=1400,900", "--dump-dom")
    found = re.search(r'data-geometry="([^"]+)"', dom)
    assert found, "chromium laid out no headline and figure"
    keys = ("text_top", "text_bottom", "img_top", "img_bottom", "img_width", "screen")
    geometry = dict(zip(keys, map(float, found.group(1).split()), strict=True))
    img = _screenshot(report, tmp_path, height=900, width=1400)
    flat = np.round(img[: img.shape[0] // 2].reshape(-1, 3) * 255).astype(np.uint8)
    geometry["colours"] = np.unique(flat, axis=0).shape[0]
    return geometry


def _check_first_screen(report, tmp_path) -> None:
    """The answer comes first in <main>, and its sentences and its whole figure, at a legible
    size, lie in the first screen of a 1400x900 window, which is not blank."""
    html = report.read_text()
    main = html[html.index("<main>") :]
    assert re.match(r'<main>\s*<section id="answer">', main), "the answer is not first in <main>"
    answer = main[: main.index("</section>")]
    assert '<p class="headline">' in answer and "<img " in answer
    g = _first_screen(report, tmp_path)
    assert 0 < g["text_top"] < g["screen"] and g["img_top"] >= 0
    assert g["img_bottom"] <= g["screen"], f"the figure runs past the first screen: {g}"
    assert g["img_bottom"] - g["img_top"] > 0.45 * g["screen"] and g["img_width"] > 500, g
    assert g["colours"] > 50, "the top of the first screen is blank"


@pytest.mark.skipif(CHROMIUM is None, reason="chromium is not installed (apt-get install chromium)")
def test_a_reports_first_screen_shows_its_answer_and_figure(tmp_path):
    """`chaoscam report` of a run and a bifurcation diagram: the headline and its figure
    fill the first 1400x900 screen."""
    from chaoscam.sweep import bifurcation

    chaoscam.simulate(duration=2.0, transient=0.5).to_parquet(tmp_path / "t.parquet")
    bif = bifurcation("l_lambda", "0.006:0.010:2", duration=2.0, transient=1.0, workers=1)
    bif.to_parquet(tmp_path / "b.parquet")
    report = tmp_path / "r.html"
    args = ["report", str(tmp_path / "t.parquet"), str(tmp_path / "b.parquet"), "--out"]
    assert main([*args, str(report)]) == 0
    _check_first_screen(report, tmp_path)


@pytest.mark.skipif(CHROMIUM is None, reason="chromium is not installed (apt-get install chromium)")
def test_the_paper_reports_first_screen_shows_its_answer_and_the_omega_xi_map(
    tmp_path, monkeypatch
):
    """The paper report (every stage, its runs shrunk): the first screen holds the headline
    and the (omega, xi) map it leads with."""
    from chaoscam.paper import run_paper
    from tests.report.test_report_paper import _shrink_the_runs

    _shrink_the_runs(monkeypatch)
    report = run_paper(quick=True, out=tmp_path / "paper.html", workers=1).path
    html = report.read_text()
    answer = html[html.index('<section id="answer">') : html.index("</section>")]
    assert "Regime map omega × xi (sensitivity-omega-xi.parquet)" in answer
    _check_first_screen(report, tmp_path)


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
