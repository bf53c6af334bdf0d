"""The paper report's figures drawn on one thread beside the stages (paper._stage)."""

import threading

import pytest

from chaoscam.paper import FigureResult
from chaoscam.paper._stage import Drawing, draw, drawing, png_of, settle, uri_of
from chaoscam.report import FigureItem


def _line_figure(x):
    from matplotlib.figure import Figure

    fig = Figure(figsize=(2, 1.5))
    fig.subplots().plot([0, x])
    return fig


def _drawing_threads() -> list[str]:
    return [t.name for t in threading.enumerate() if t.name.startswith("chaoscam-draw")]


def test_inside_drawing_a_figure_is_built_and_drawn_beside_the_caller(tmp_path):
    """draw returns at once; the figure is built on the drawing thread while the caller goes
    on (the build sees an event the caller sets only after draw returned); settle puts the
    PNG, which is the file's, in the result, and the item's URI; no thread outlives the
    block."""
    go, seen = threading.Event(), []

    def build(x):
        seen.append((threading.current_thread().name, go.wait(10)))
        return _line_figure(x)

    with drawing():
        pending = draw(tmp_path / "a.png", build, 1.0)
        assert isinstance(pending, Drawing)
        go.set()
        res = FigureResult(4, bifurcations=[("a.parquet", None, pending)])
        res.figures.append(FigureItem("a", "A", uri_of(pending), "alt", "caption"))
        settle(res)
    (name, waited), png = seen[0], res.bifurcations[0][2]
    assert name.startswith("chaoscam-draw") and waited
    assert png[:4] == b"\x89PNG" and (tmp_path / "a.png").read_bytes() == png
    assert res.figures[0].uri.startswith("data:image/png;base64,")
    assert _drawing_threads() == []


def test_outside_drawing_a_figure_is_drawn_at_once_on_the_calling_thread(tmp_path):
    names = []

    def build(x):
        names.append(threading.current_thread().name)
        return _line_figure(x)

    png = draw(tmp_path / "b.png", build, 2.0)
    assert png[:4] == b"\x89PNG" and names == [threading.current_thread().name]
    assert uri_of(png).startswith("data:image/png;base64,") and png_of(png) is png


def test_a_drawings_error_is_raised_where_it_is_settled(tmp_path):
    def broken():
        raise ValueError("cannot draw this")

    with drawing():
        pending = draw(tmp_path / "c.png", broken)
        with pytest.raises(ValueError, match="cannot draw this"):
            settle(FigureResult(5, regime_maps=[("c.parquet", None, pending)]))
    assert not (tmp_path / "c.png").exists() and _drawing_threads() == []


def test_a_stage_whose_figure_fails_to_draw_is_reported_failed(tmp_path, monkeypatch):
    """In run_paper a drawing's error fails its stage, as an error of the stage itself does;
    the other stages and their figures stand."""
    import chaoscam.report
    from chaoscam.paper import run_paper

    real = chaoscam.report.png_bytes

    def fig5_fails(fig, dpi=96):
        if tuple(fig.get_size_inches()) == (8.0, 4.5):  # Fig. 5's size
            raise RuntimeError("no ink")
        return real(fig, dpi=dpi)

    monkeypatch.setattr(chaoscam.report, "png_bytes", fig5_fails)  # what the drawing calls
    run = run_paper(quick=True, out=tmp_path / "p.html", figures=[3, 5])
    assert run.failed == ("Fig. 5: fractal stiffness: failed with RuntimeError: no ink",)
    text = run.path.read_text()
    assert "Fig. 3 — random contact-line length over time" in text and "no ink" in text
    assert (tmp_path / "paper-data" / "fig3.png").exists() and _drawing_threads() == []


def test_a_stages_figures_are_drawn_while_the_next_stage_runs(tmp_path, monkeypatch):
    """Fig. 3's figure is still being built when Fig. 5's stage starts: its build waits for
    an event that stage sets, and it sees it (a stage no longer waits for its own figures,
    they are settled once every stage has run); both figures reach the report."""
    import chaoscam.report
    from chaoscam.paper import _paper, run_paper

    real_png, real_fig5 = chaoscam.report.png_bytes, _paper.FIGURES[5]
    next_stage, seen = threading.Event(), []

    def fig3_waits(fig, dpi=96):
        if tuple(fig.get_size_inches()) == (9.0, 3.6):  # Fig. 3's size
            seen.append(next_stage.wait(20))
        return real_png(fig, dpi=dpi)

    def fig5_starts(*args, **kwargs):
        next_stage.set()
        return real_fig5(*args, **kwargs)

    monkeypatch.setattr(chaoscam.report, "png_bytes", fig3_waits)
    monkeypatch.setitem(_paper.FIGURES, 5, fig5_starts)
    run = run_paper(quick=True, out=tmp_path / "p.html", figures=[3, 5])
    assert seen == [True] and run.failed == ()
    assert (tmp_path / "paper-data" / "fig3.png").exists()
    assert (tmp_path / "paper-data" / "fig5.png").exists() and _drawing_threads() == []
