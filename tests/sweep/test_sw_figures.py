"""Sweep figures: heatmaps and bifurcation diagrams build from the tidy tables."""

import numpy as np
import pandas as pd
import pytest

from chaoscam.plot import (
    axis_label,
    bifurcation_figure,
    regime_map_figure,
)
from chaoscam.sweep import summarize_cells

pytest.importorskip("seaborn")


def _cells():
    rng = np.random.default_rng(np.random.SeedSequence(1))
    cells = pd.DataFrame(
        [(3 * i + j, i, j, 0.004 + 0.004 * i, 0.001 * j) for i in range(3) for j in range(3)],
        columns=["cell", "ix", "iy", "l_lambda", "l_lambda_sigma"],
    )
    labels = np.array(["periodic", "chaotic", "quasiperiodic", "left_reach"])
    rows = pd.DataFrame(
        {
            "cell": np.repeat(cells["cell"], 8),
            "label": labels[rng.integers(0, 4, 72)],
            "truncated_mass": 0.0,
        }
    )
    return summarize_cells(rows, cells)


def test_regime_map_figure_has_labelled_axes_with_units():
    """Three panels (dominant, P(chaotic), interval width), axes named with units."""
    fig = regime_map_figure(_cells(), x="l_lambda", y="l_lambda_sigma")
    axes = [a for a in fig.axes if a.get_title()]
    assert [a.get_title() for a in axes][0] == "dominant label"
    assert "interval" in axes[1].get_title()
    assert all(a.get_xlabel().endswith("[m]") and a.get_ylabel().endswith("[m]") for a in axes)
    assert "μ" in axes[0].get_xlabel()


def test_bifurcation_points_are_rasterised():
    """Thousands of points are drawn rasterised; the axes carry the units."""
    n = 5000
    pts = pd.DataFrame(
        {
            "param": "l_lambda",
            "value": np.repeat(np.linspace(0.001, 0.018, 50), n // 50),
            "theta_f": np.random.default_rng(0).random(n),
            "label": "chaotic",
        }
    )
    fig = bifurcation_figure(pts)
    ax = fig.axes[0]
    assert all(c.get_rasterized() for c in ax.collections)
    assert sum(len(c.get_offsets()) for c in ax.collections) == n
    assert ax.get_xlabel() == axis_label("l_lambda") and ax.get_ylabel().endswith("[rad]")


def test_deterministic_cells_show_one_run_not_an_interval():
    """A sigma = 0 cell is one run standing for identical realizations: its annotation and its
    row in the report's table say so, with no [lo, hi] interval; the other cells keep theirs."""
    from matplotlib.figure import Figure

    from chaoscam.plot import plot_probability
    from chaoscam.report._html import _p_chaotic_text

    cells = _cells().assign(deterministic=lambda c: c["l_lambda_sigma"] == 0.0)
    ax = Figure().subplots()
    plot_probability(cells, "l_lambda", "l_lambda_sigma", ax, annotate=True)
    texts = [t.get_text() for t in ax.texts]
    assert sum("one run" in t for t in texts) == 3  # the sigma = 0 row
    assert sum("[" in t for t in texts) == 6
    rows = cells.to_dict("records")
    shown = [_p_chaotic_text(r) for r in rows]
    for r, s in zip(rows, shown, strict=True):
        assert ("deterministic: one run" in s) == r["deterministic"]
        assert ("[" in s) != r["deterministic"]


def test_deterministic_cells_have_no_interval_width():
    """The width panel leaves a sigma = 0 cell blank and marks it "one run" (it was coloured
    as the narrowest width); the other cells keep their widths."""
    from matplotlib.figure import Figure

    from chaoscam.plot import plot_interval_width

    cells = _cells().assign(deterministic=lambda c: c["l_lambda_sigma"] == 0.0)
    ax = Figure().subplots()
    plot_interval_width(cells, "l_lambda", "l_lambda_sigma", ax)
    assert [t.get_text() for t in ax.texts] == ["one run"] * 3
    shown = ax.collections[0].get_array()
    assert np.ma.count(shown) == 6  # the three sigma = 0 cells are masked


def test_runs_without_section_points_are_marked():
    """A run that left no point after the transient (left_reach, diverged) is an x on the top
    edge, named in the legend; a sweep whose runs all have points gets no x."""
    pts = pd.DataFrame(
        {"param": "xi", "value": [0.1, 0.1, 0.2], "ic": 0, "theta_f": [0.0, 0.1, 0.2],
         "label": "periodic", "period": 1}
    )  # fmt: skip
    verdicts = pd.DataFrame(
        {"value": [0.1, 0.2, 0.7], "ic": 0, "label": ["periodic", "periodic", "left_reach"]}
    )
    ax = bifurcation_figure(pts, verdicts=verdicts).axes[0]
    legend = [t.get_text() for t in ax.get_legend().get_texts()]
    assert "no section point (left_reach)" in legend
    xs = [c for c in ax.collections if c.get_offsets().shape[0] and c.get_label().startswith("no")]
    assert xs[0].get_offsets()[:, 0].tolist() == [0.7]
    ax = bifurcation_figure(pts, verdicts=verdicts.iloc[:2]).axes[0]
    assert not any("no section" in t.get_text() for t in ax.get_legend().get_texts())


def _banded(width: float):
    """A diagram over l_lambda of 8-band chaos: 8 bands of ``width`` rad on [0, 0.3] rad."""
    rng = np.random.default_rng(np.random.SeedSequence(5))
    values = np.linspace(0.001, 0.018, 7)
    centres = np.linspace(0.0, 0.3, 8)
    pts = pd.DataFrame(
        [(v, 0, c + width * rng.random(), "chaotic") for v in values for c in centres
         for _ in range(6)],
        columns=["value", "ic", "theta_f", "label"],
    ).assign(param="l_lambda")  # fmt: skip
    verdicts = pd.DataFrame({"value": values, "ic": 0, "label": "chaotic", "ev_banded_chaos": 8.0})
    return pts, verdicts


def test_bands_too_narrow_to_see_get_a_zoomed_panel():
    """8-band chaos on bands of 3e-4 rad (1e-3 of the scale, invisible): a second panel zooms
    on one band, its limits around that band's width; bands of 0.02 rad (visible) or a
    diagram without band counts get none."""
    from chaoscam.plot import band_zoom

    pts, verdicts = _banded(3e-4)
    value, ic, n, lo, hi = band_zoom(pts, verdicts)
    assert n == 8 and 0 < hi - lo <= 3e-4 and value in set(verdicts["value"])
    fig = bifurcation_figure(pts, verdicts=verdicts)
    zoom = [a for a in fig.axes if "zoomed" in a.get_title()]
    assert len(zoom) == 1 and "8 bands" in zoom[0].get_title()
    assert np.diff(zoom[0].get_ylim())[0] < 4 * 3e-4
    wide_pts, wide = _banded(0.02)
    assert band_zoom(wide_pts, wide) is None
    assert len(bifurcation_figure(wide_pts, verdicts=wide).axes) == 1
    assert band_zoom(pts, verdicts.drop(columns="ev_banded_chaos")) is None
