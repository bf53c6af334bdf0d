"""``chaoscam paper``: figure scripts write data and PNGs; the comparison table is filled."""

from __future__ import annotations

import re

import pandas as pd
import pytest

from chaoscam.cli import main


def test_paper_figs_3_and_5_agree_on_their_checkable_claims(tmp_path, capsys):
    """Figs. 3 and 5 (no dynamics) run in seconds, write their data and agree with the paper."""
    out = tmp_path / "paper.html"
    assert main(["paper", "--quick", "--figures", "3,5", "--out", str(out)]) == 0
    data = tmp_path / "paper-data"
    for name in ("fig3.csv", "fig3.png", "fig5.csv", "fig5.png"):
        assert (data / name).stat().st_size > 0
    text = out.read_text()
    rows = re.findall(r'<td class="([a-z-]+)">', text)
    assert rows == ["agrees", "agrees"]
    assert 'href="#fig3"' in text and 'href="#fig5"' in text  # each row links to its figure
    assert not re.search(r"https?:", text, re.IGNORECASE)


def test_paper_without_out_writes_where_git_does_not_look(tmp_path, monkeypatch, capsys):
    """No --out: out/paper.html, its folder created; a committed reports/paper.html in the
    same place is left alone, and .gitignore ignores the default folder."""
    import subprocess
    from pathlib import Path

    root = Path(__file__).resolve().parents[2]
    monkeypatch.chdir(tmp_path)
    (tmp_path / "reports").mkdir()
    (tmp_path / "reports" / "paper.html").write_text("committed")
    assert main(["paper", "--quick", "--figures", "5"]) == 0
    assert (tmp_path / "out" / "paper.html").stat().st_size > 0
    assert (tmp_path / "reports" / "paper.html").read_text() == "committed"
    assert "report: out/paper.html" in capsys.readouterr().out
    ignored = subprocess.run(["git", "check-ignore", "-q", "out/paper.html"], cwd=root, check=False)
    assert ignored.returncode == 0


def test_paper_rejects_unknown_figure(tmp_path, capsys):
    """An unknown figure number is a usage error."""
    assert main(["paper", "--figures", "2", "--out", str(tmp_path / "p.html")]) == 2
    assert "no figure" in capsys.readouterr().err


def test_paper_rejects_an_empty_figure_list(tmp_path, capsys):
    """--figures '' is a usage error, not every figure (which is what leaving it out means)."""
    assert main(["paper", "--quick", "--figures", "", "--out", str(tmp_path / "p.html")]) == 2
    assert "--figures '': expected numbers" in capsys.readouterr().err
    assert not (tmp_path / "p.html").exists()
    from chaoscam.paper import run_paper

    for figures in ([], [2]):  # the API too (it ran every figure for [])
        with pytest.raises(ValueError, match="choose from"):
            run_paper(quick=True, out=tmp_path / "p.html", figures=figures)


def test_sequence_rule_finds_the_papers_order_and_nothing_else():
    """The Fig. 4 rule: the paper's regimes must appear in order among the label runs."""
    from chaoscam.paper._paper import _is_subsequence, _runs

    wanted = ["chaotic", "periodic-2", "quasiperiodic", "chaotic"]
    labels = ["chaotic", "chaotic", "periodic-2", "quasiperiodic", "periodic", "chaotic"]
    assert _runs(labels)[0] == ("chaotic", 2)
    assert _is_subsequence(wanted, [lab for lab, _ in _runs(labels)])
    assert not _is_subsequence(wanted, ["quasiperiodic", "chaotic", "periodic-2", "chaotic"])


def test_a_failing_figure_is_reported_as_missing(tmp_path, monkeypatch, capsys):
    """A figure script that raises leaves a report that names the failure, does not claim
    the figure in its summary or title, and the command exits 1 (it exited 0)."""
    from chaoscam.paper import _paper

    def boom(quick, outdir, workers=None):
        raise RuntimeError("no luck")

    monkeypatch.setitem(_paper.FIGURES, 3, boom)
    from chaoscam.paper import run_paper

    run = run_paper(quick=True, out=tmp_path / "p.html", figures=[3, 5], echo=True)
    fail = "Fig. 3: line-length draws: failed with RuntimeError: no luck"
    assert run.failed == (fail,)
    text = run.path.read_text()
    assert fail in text
    assert "Fig. 5 — fractal stiffness against D" in text
    claims = text.replace("and Figs. 3–10); the authors", "")  # the source paper's citation
    assert "Fig. 5 in " in text and "Figs. 3" not in claims and "1 of 2 stages failed" in text
    assert "(incomplete: 1 of 2 stages failed)" in text
    err = capsys.readouterr().err  # the stages by their titles, not function names
    assert f"[1/2] Fig. 3: line-length draws ...\n[1/2] {fail}\n" in err
    assert "[2/2] Fig. 5: fractal stiffness ...\n" in err
    assert "[2/2] Fig. 5: fractal stiffness: " in err
    out = tmp_path / "c" / "p.html"
    out.parent.mkdir()
    assert main(["paper", "--quick", "--figures", "3,5", "--out", str(out)]) == 1
    err = capsys.readouterr().err
    assert "1 stage(s) failed" in err and "no luck" in err and out.exists()


def test_a_run_where_every_stage_failed_keeps_the_report_there(tmp_path, monkeypatch, capsys):
    """--resume (or --force) over a finished report, every stage failing: the report there
    is kept and the failure page goes beside it (it replaced a 2.5 MB report with a 12 KB
    page of failures)."""
    from chaoscam.paper import _paper

    out = tmp_path / "p.html"
    assert main(["paper", "--quick", "--figures", "5", "--out", str(out)]) == 0
    before = out.read_bytes()

    def boom(quick, outdir, workers=None):
        raise RuntimeError("no luck")

    monkeypatch.setitem(_paper.FIGURES, 5, boom)
    assert main(["paper", "--quick", "--figures", "5", "--resume", "--out", str(out)]) == 1
    assert out.read_bytes() == before
    failed = tmp_path / "p.failed.html"
    assert "no luck" in failed.read_text() and f"report: {failed}" in capsys.readouterr().out


def test_force_and_resume_together_are_refused(tmp_path, capsys):
    """The sweeps and ensembles refused --force with --resume; the paper (and figN.py)
    took both and resumed."""
    from chaoscam.paper import figure_script

    assert main(["paper", "--force", "--resume", "--out", str(tmp_path / "p.html")]) == 2
    assert "give one of them" in capsys.readouterr().err
    with pytest.raises(SystemExit) as stop:
        figure_script(3, [str(tmp_path), "--force", "--resume"])
    assert stop.value.code == 2 and "give one of them" in capsys.readouterr().err
    with pytest.raises(SystemExit) as stop:  # a named OUTDIR is the user's: not created
        figure_script(3, [str(tmp_path / "missing"), "--quick"])
    assert stop.value.code == 2 and "no such folder" in capsys.readouterr().err
    assert not (tmp_path / "missing").exists()


def test_a_stage_asked_for_by_a_later_figure_keeps_its_title(tmp_path, monkeypatch):
    """figures=[8]: the shared stage of Figs. 7-10 is titled as such (it fell back to the
    function's name, fig7_10)."""
    from chaoscam.paper import _paper, run_paper

    def boom(quick, outdir, workers=None):
        raise RuntimeError("no luck")

    for n in (7, 8, 9, 10):
        monkeypatch.setitem(_paper.FIGURES, n, boom)
    run = run_paper(quick=True, out=tmp_path / "p.html", figures=[8])
    assert run.failed == ("Figs. 7–10: random line length: failed with RuntimeError: no luck",)


def test_paper_refuses_a_worker_count_before_any_work(tmp_path, capsys):
    """--workers past the sweeps' limit: exit 2 at once, nothing written (every sweep of
    the report failed on it, and the command still exited 0)."""
    out = tmp_path / "p.html"
    assert main(["paper", "--quick", "--workers", "99999", "--out", str(out)]) == 2
    assert "--workers 99999: workers = 99999 must be in [1, " in capsys.readouterr().err
    assert list(tmp_path.iterdir()) == []


def _shrink_the_runs(monkeypatch):
    """Stand-ins for the figures' sweeps and runs: the same calls, two values, a second of
    model time (a fate horizon of one), the test classifier, in this process; the verdict
    of single runs without extensions."""
    import chaoscam.simulation
    import chaoscam.sweep
    import chaoscam.verdict
    from tests.sweep._helpers import SpreadClassifier

    bif, rmap = chaoscam.sweep.bifurcation, chaoscam.sweep.regime_map
    sim, judge = chaoscam.simulation.simulate, chaoscam.verdict.classify
    short = dict(duration=0.5, transient=0.25, workers=1, classify=SpreadClassifier())

    def small_bifurcation(param, values, **kw):
        kw = {**kw, "fate": 1.0} if kw.get("fate") else kw
        if not isinstance(values, str):
            return bif(param, list(values)[:2], **{**kw, **short})
        start, stop, _ = values.split(":")
        return bif(param, f"{start}:{stop}:2", **{**kw, **short})

    def small_regime_map(x, y, **kw):
        kw = {**kw, "fate": 1.0} if kw.get("fate") else kw
        return rmap(x, y, **{**kw, **short, "realizations": 2})

    def short_simulate(params, **kw):
        return sim(params, **{**kw, "duration": 1.0, "transient": 0.0})

    def quick_classify(run, **kw):
        return judge(run, **{**kw, "extend_to": None})

    monkeypatch.setattr(chaoscam.sweep, "bifurcation", small_bifurcation)
    monkeypatch.setattr(chaoscam.sweep, "regime_map", small_regime_map)
    monkeypatch.setattr(chaoscam.simulation, "simulate", short_simulate)
    monkeypatch.setattr(chaoscam.verdict, "classify", quick_classify)


@pytest.mark.parametrize("number", [3, 4, 5, 6, 7, 0])
def test_data_files_are_exactly_what_the_figures_write(tmp_path, monkeypatch, number):
    """data_files (what `paper` checks before the work) lists every file the figure script
    (0: the sensitivity stage) writes, and nothing it does not (runs shrunk, PNGs not drawn)."""
    import chaoscam.report
    from chaoscam.paper import _paper

    _shrink_the_runs(monkeypatch)
    monkeypatch.setattr(chaoscam.report, "png_bytes", lambda fig, dpi=None: b"\x89PNG")
    stage = _paper.sensitivity_stage if number == _paper.SENSITIVITY else _paper.FIGURES[number]
    res = stage(True, tmp_path, workers=1)
    assert sorted(p.name for p in tmp_path.iterdir()) == sorted(_paper.data_files(number))
    # the summary's timing line names the stage as the paper does
    names = {7: "Figs. 7–10", 0: "Sensitivity (why the paper differs)"}
    assert res.name == names.get(number, f"Fig. {number}")


def test_paper_refuses_any_existing_output_before_the_work(tmp_path, capsys):
    """An existing data file (not only the report): exit 2 naming it, before any figure
    runs; --force replaces it."""
    data = tmp_path / "paper-data"
    data.mkdir()
    (data / "fig5.png").write_bytes(b"old")
    args = ["paper", "--quick", "--figures", "3,5", "--out", str(tmp_path / "p.html")]
    assert main(args) == 2
    err = capsys.readouterr().err
    assert err.startswith(f"chaoscam: error: {data} already holds fig5.png")
    assert "--force" in err and "another folder" in err  # not "choose another name"
    assert [p.name for p in data.iterdir()] == ["fig5.png"]  # fig3 did not run
    assert not (tmp_path / "p.html").exists()
    assert main([*args, "--force"]) == 0
    assert (data / "fig5.png").read_bytes()[:4] == b"\x89PNG"


def test_an_interrupted_report_resumes_without_redoing_its_finished_sweeps(
    tmp_path, monkeypatch, capsys
):
    """Ctrl-C during Fig. 6's sweeps: exit 130 and one line saying what is kept and how to go
    on; a plain rerun is refused; --resume reads Fig. 4's finished sweep back (its file is
    not written again), runs the rest, and its findings equal an uninterrupted run's."""
    import chaoscam.sweep

    _shrink_the_runs(monkeypatch)
    small = chaoscam.sweep.bifurcation

    def stopped_at_fig6(param, values, **kw):
        if param == "D":
            raise KeyboardInterrupt
        return small(param, values, **kw)

    monkeypatch.setattr(chaoscam.sweep, "bifurcation", stopped_at_fig6)
    args = ["paper", "--quick", "--figures", "4,6", "--out", str(tmp_path / "p.html")]
    assert main(args) == 130
    err = capsys.readouterr().err
    last = err.splitlines()[-1]  # after the stages' progress lines
    assert (
        last.startswith("chaoscam: interrupted; the finished sweeps are kept")
        and "--resume" in last
    )
    assert err.count("interrupted") == 1
    fig4 = tmp_path / "paper-data" / "fig4.parquet"
    stamp = fig4.stat().st_mtime_ns
    assert main(args) == 2 and "pass --resume to continue" in capsys.readouterr().err
    monkeypatch.setattr(chaoscam.sweep, "bifurcation", small)
    assert main([*args, "--resume"]) == 0
    assert fig4.stat().st_mtime_ns == stamp  # read back, not run again
    resumed = capsys.readouterr().out
    (tmp_path / "fresh").mkdir()
    assert main([*args[:-1], str(tmp_path / "fresh" / "p.html")]) == 0
    fresh = capsys.readouterr().out

    def findings(text):
        return [line for line in text.splitlines() if not line.startswith(("Quick", "report:"))]

    assert findings(resumed) == findings(fresh) and len(findings(fresh)) > 3


def test_ctrl_c_in_the_sensitivity_stage_stops_the_map_beside_it_and_resume_finishes(
    tmp_path, monkeypatch
):
    """The (ω, ξ) map runs beside the stage's other sweeps: a Ctrl-C in the ξ sweep asks the
    map to stop too (it stops with its checkpoint), the stage raises the Ctrl-C, and a
    resumed stage gives the findings of a stage run without interruption."""
    import chaoscam.report
    import chaoscam.sweep
    from chaoscam.kernel import stops_here
    from chaoscam.paper import _paper
    from chaoscam.paper._stage import store_mode
    from chaoscam.sweep import SweepInterrupted

    _shrink_the_runs(monkeypatch)
    monkeypatch.setattr(chaoscam.report, "png_bytes", lambda fig, dpi=None: b"\x89PNG")
    small_bif, small_map = chaoscam.sweep.bifurcation, chaoscam.sweep.regime_map
    map_ends = []

    def stopped_at_xi(param, values, **kw):
        if param == "xi":
            raise KeyboardInterrupt
        return small_bif(param, values, **kw)

    def map_under_way(x, y, **kw):
        (stop,) = stops_here()  # the map's thread can be asked to stop ...
        assert stop.wait(60)  # ... and is, once the ξ sweep is interrupted
        try:
            return small_map(x, y, **kw)
        except SweepInterrupted as err:
            map_ends.append(err)
            raise

    monkeypatch.setattr(chaoscam.sweep, "bifurcation", stopped_at_xi)
    monkeypatch.setattr(chaoscam.sweep, "regime_map", map_under_way)
    with pytest.raises(KeyboardInterrupt) as err:  # every core: the map beside (its sweeps
        _paper.sensitivity_stage(True, tmp_path)  # run on one worker, the stand-ins')
    assert not isinstance(err.value, SweepInterrupted)  # the ξ sweep's Ctrl-C, not the map's
    assert len(map_ends) == 1 and "--resume" in str(map_ends[0])
    assert (tmp_path / "sensitivity-omega-xi.parquet.ckpt").is_dir()
    assert not (tmp_path / "sensitivity-omega-xi.parquet").exists()
    monkeypatch.setattr(chaoscam.sweep, "bifurcation", small_bif)
    monkeypatch.setattr(chaoscam.sweep, "regime_map", small_map)
    with store_mode(resume=True):
        resumed = _paper.sensitivity_stage(True, tmp_path, workers=1)
    (tmp_path / "fresh").mkdir()
    fresh = _paper.sensitivity_stage(True, tmp_path / "fresh", workers=1)
    assert resumed.why == fresh.why and len(fresh.why) == 5


def test_paper_unwritable_places_are_refused(tmp_path, capsys):
    """A paper-data that is a file, or a report folder that does not exist: exit 2 with a
    message, nothing run."""
    (tmp_path / "paper-data").write_text("not a folder")
    assert main(["paper", "--figures", "5", "--out", str(tmp_path / "p.html")]) == 2
    assert "is not a folder" in capsys.readouterr().err
    missing = tmp_path / "no" / "p.html"
    assert main(["paper", "--figures", "5", "--out", str(missing)]) == 2
    assert "does not exist" in capsys.readouterr().err
    assert not (tmp_path / "no").exists() and not (tmp_path / "p.html").exists()


def test_each_figure_is_rendered_once_and_the_report_embeds_its_file(tmp_path, monkeypatch):
    """The paper's stages render every figure once: the report embeds the very PNG written
    to paper-data (rendering was a fifth of a quick report's time, each figure drawn twice)."""
    import base64

    import chaoscam.report
    from chaoscam.paper import run_paper
    from chaoscam.report import _html

    _shrink_the_runs(monkeypatch)
    rendered = []

    def stub(fig, dpi=96):  # a distinct stand-in PNG per rendering
        rendered.append(b"\x89PNG-%d" % len(rendered))
        return rendered[-1]

    for module in (_html, chaoscam.report):  # the report's own, and the drawing thread's
        monkeypatch.setattr(module, "png_bytes", stub)
    out = run_paper(quick=True, out=tmp_path / "p.html", figures=[3, 4, 5, 7]).path
    files = {p.name: p.read_bytes() for p in (tmp_path / "paper-data").glob("*.png")}
    assert len(files) == 12  # figs 3, 4 (and its continued orbits), 5, the map, its random
    # response and six responses
    assert sorted(rendered) == sorted(files.values())  # once each, nothing else drawn
    text = out.read_text()
    found = re.findall(r'src="data:image/png;base64,([^"]+)"', text)
    embedded = {base64.b64decode(u) for u in found}
    assert len(found) == len(embedded)  # the answer's figure is not shown twice
    # every figure but the responses that share a verdict, which one panel stands for
    panels = text.count('<figure id="resp-')
    assert 1 <= panels <= 6 and embedded <= set(files.values())
    assert len(set(files.values()) - embedded) == 6 - panels


def test_the_summary_opens_with_the_labels_counted_from_the_tables():
    """The first line of the summary answers the question from the runs themselves: label
    counts of the paper's figures and, apart, of the sensitivity sweeps (with the periods)."""
    from types import SimpleNamespace

    from chaoscam.paper._run import _in_short

    def sweep(number, labels, periods):
        table = pd.DataFrame({"label": labels, "period": periods})
        return SimpleNamespace(
            number=number,
            bifurcations=[("b", SimpleNamespace(verdicts=table), b"")],
            regime_maps=[],
        )

    nan = float("nan")
    fig = sweep(4, ["chaotic", "chaotic", "undetermined"], [nan, nan, nan])
    sens = sweep(0, ["periodic", "periodic", "left_reach", "chaotic"], [1, 3, nan, nan])
    assert _in_short([fig, sens]) == (
        "In short: the 3 runs of the paper's figures are 0 periodic, 2 chaotic, 0 "
        "quasiperiodic, 1 undetermined, 0 out of reach or diverged. The 4 runs of the "
        "sensitivity sweeps, which move the stiffness, ξ and ω away from Table 1, are 2 "
        "periodic, 1 chaotic, 0 quasiperiodic, 0 undetermined, 1 out of reach or diverged "
        "(periods 1, 3)."
    )
    assert _in_short([sens]) == ""
    banded = sweep(4, ["chaotic", "chaotic", "periodic"], [nan, nan, 8])
    banded.bifurcations[0][1].verdicts["ev_banded_chaos"] = [8.0, nan, nan]
    assert "are 1 periodic, 2 chaotic (1 of them 8-band chaos), 0 quasiperiodic" in (
        _in_short([banded])
    )


def test_a_second_run_into_the_same_folder_is_refused(tmp_path, capsys):
    """While another process runs a report into this folder (it holds paper-data's lock),
    another report there is refused at once naming the holder, even with --force and under
    another name: they share paper-data (a second run started within the first's first
    seconds passed every check, and both wrote the same files)."""
    from tests.test_outputs import _hold_lock

    holder = _hold_lock(tmp_path / "paper-data")
    try:
        args = ["paper", "--quick", "--figures", "3", "--out", str(tmp_path / "q.html")]
        assert main([*args, "--force"]) == 2
        err = capsys.readouterr().err
        assert f"paper-data is in use by another chaoscam process (pid {holder.pid})" in err
        assert not (tmp_path / "q.html").exists() and not (tmp_path / "paper-data").exists()
    finally:
        holder.kill()
        holder.wait()
    assert main(args) == 0


def test_a_report_that_appeared_meanwhile_is_kept(tmp_path, monkeypatch):
    """Without force, a report file written by someone else during the run is not replaced:
    this run's report goes beside it, and the error names both."""
    from chaoscam.io import OutputError
    from chaoscam.paper import _paper, run_paper

    out = tmp_path / "p.html"
    fig3 = _paper.FIGURES[3]

    def meanwhile(quick, outdir, workers=None):
        out.write_text("theirs")
        return fig3(quick, outdir, workers=workers)

    monkeypatch.setitem(_paper.FIGURES, 3, meanwhile)
    with pytest.raises(OutputError, match="another process wrote it while this run worked") as err:
        run_paper(quick=True, out=out, figures=[3])
    assert out.read_text() == "theirs"
    kept = [p for p in tmp_path.glob("p.*.html")]
    assert len(kept) == 1 and str(kept[0]) in str(err.value)
    assert "Fig. 3 reproduced (quick run)" in kept[0].read_text()


def test_write_report_keeps_an_existing_file_and_needs_its_folder(tmp_path):
    """write_report never writes over a file unless replace=True (by default its report
    goes beside it, named in the error); a missing folder is refused (it was created)."""
    from chaoscam.io import OutputError
    from chaoscam.report import ReportParts, write_report

    out = tmp_path / "r.html"
    out.write_text("theirs")
    with pytest.raises(OutputError, match="another process wrote it while this run worked"):
        write_report(ReportParts(), out, title="t")
    assert out.read_text() == "theirs" and len(list(tmp_path.glob("r.*.html"))) == 1
    write_report(ReportParts(), out, title="t", replace=True)
    assert "<html" in out.read_text()
    with pytest.raises(OutputError, match="does not exist"):
        write_report(ReportParts(), tmp_path / "no" / "r.html", title="t")
    assert not (tmp_path / "no").exists()


def test_the_paper_headline_is_computed_from_the_verdicts():
    """The answer: each figure's commonest regime (n-band chaos said to look like period n),
    the figures that agree and differ, and the (omega, xi) map's regimes; other verdicts
    give another answer."""
    from types import SimpleNamespace as NS

    from chaoscam.paper._run import paper_headline
    from chaoscam.report import Comparison

    nan = float("nan")

    def fig4(labels, periods, bands):
        table = pd.DataFrame({"label": labels, "period": periods, "ev_banded_chaos": bands})
        return NS(number=4, name="Fig. 4", bifurcations=[("b", NS(verdicts=table), b"")],
                  regime_maps=[])  # fmt: skip

    comparisons = [Comparison("Fig. 4", "p", "f", "differs", "r")]
    comparisons.append(Comparison("Fig. 5", "p", "f", "agrees", "r"))
    banded = fig4(["chaotic"] * 3, [nan] * 3, [8.0, 8.0, nan])
    assert paper_headline([banded], comparisons) == [
        "Where the paper looks, the motion is mostly 8-band chaos: Fig. 4 (bifurcation over "
        "l_λ): 8-band chaos in 2 of 3 runs, chaotic in 1. That is chaos on 8 narrow bands: at "
        "full scale it looks like period 8 (the bifurcation diagrams zoom on a band).",
        "Against the paper's claims: Fig. 5 agrees; Fig. 4 differs.",
    ]
    cells = pd.DataFrame({"dominant": ["periodic", "periodic", "chaotic", "left_reach"],
                          "period": [1, 3, nan, nan]})  # fmt: skip
    sens = NS(number=0, name="s", bifurcations=[],
              regime_maps=[("d/sensitivity-omega-xi.parquet", NS(cells=cells), b"")])  # fmt: skip
    periodic = fig4(["periodic"] * 3, [2, 2, 2], [nan] * 3)
    lines = paper_headline([periodic, sens], comparisons[1:], lead=True)
    assert lines == [
        "Where the paper looks, the motion is mostly period 2: Fig. 4 (bifurcation over l_λ): "
        "period 2 in 3 of 3 runs.",
        "Against the paper's claims: Fig. 5 agrees.",
        "Away from Table 1 the regime moves with what the paper leaves open: of the 4 cells of "
        "the (ω, ξ) map shown here, 2 are periodic (periods 1, 3), 1 is chaotic and 1 is out of "
        "the cam's reach.",
    ]
