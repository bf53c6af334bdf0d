"""A sweep's fate horizon: runs not labelled periodic go on, to see whether they stay.

(omega, xi) = (25 rad/s, 0.67) is chaotic over its first 20 s and leaves the cam's reach
at t = 23.1 s (transient chaos); (25, 0.40) is a certified period 2. The engine must
continue exactly the runs not labelled periodic, with the same bits as a direct
``simulate`` to the horizon, and leave the labels alone.
"""

import math

import numpy as np
import pandas as pd
import pytest

import chaoscam
from chaoscam import Params
from chaoscam.sweep import Axis, SweepError, bifurcation, realization_index, regime_map

OMEGA = Axis("omega", (25.0,))
XI = Axis("xi", (0.4, 0.67))
KW = dict(duration=20.0, transient=10.0, fate=40.0, workers=2)


@pytest.fixture(scope="module")
def rmap():
    return regime_map(OMEGA, XI, **KW)


def _left_at(p: Params, index: int) -> float:
    """The last section time of a direct run to the horizon (where it stopped)."""
    tr = chaoscam.simulate(p, duration=40.0, transient=0.0, index=index, series=False)
    assert tr.status.name == "LEFT_REACH"
    return float(tr.section["t"].iloc[-1])


def test_chaos_that_leaves_later_is_recorded_and_the_label_kept(rmap):
    """The chaotic run is continued to the horizon and leaves where a direct run to it
    leaves (the same bits); the periodic one is not continued; the labels are kept."""
    rows = rmap.realizations.set_index("xi")
    per, cha = rows.loc[0.4], rows.loc[0.67]
    assert per["label"] == "periodic" and per["period"] == 2
    assert pd.isna(per["fate"]) and math.isnan(per["left_at"])  # not continued
    assert cha["label"] == "chaotic" and cha["status"] == "OK"  # label kept
    assert cha["fate"] == "LEFT_REACH"
    p = Params(omega=25.0, xi=0.67)
    assert cha["left_at"] == _left_at(p, realization_index(int(cha["cell"]), 0))
    assert 22.6 < cha["left_at"] < 23.6
    cells = rmap.cells.set_index("xi")
    assert cells.loc[0.67, "n_transient"] == 1 and cells.loc[0.4, "n_transient"] == 0
    assert rmap.config["fate"] == 40.0


def test_a_run_that_stays_is_recorded_as_staying():
    """(42.5, 0.40) is chaotic and stays in reach up to 40 s (it leaves at 122 s)."""
    rm = regime_map(Axis("omega", (42.5,)), Axis("xi", (0.4,)), **KW)
    row = rm.realizations.iloc[0]
    assert row["label"] == "chaotic" and row["fate"] == "OK" and math.isnan(row["left_at"])
    assert row["fate_label"] == "chaotic" and pd.isna(row["fate_period"])  # still, at 20-40 s
    assert rm.cells["n_transient"].iloc[0] == 0 and rm.cells["n_settled"].iloc[0] == 0


@pytest.fixture(scope="module")
def settling():
    """xi = 0.3459 at Table 1 otherwise: labelled chaotic over 10-20 s, periodic 6 over the
    fate run's last half (50-100 s). The motion itself does not change: from 10 s to 300 s it
    keeps 6 bands of 4e-7 to 8e-7 rad; the grid's tangent exponent is positive, and kicks from
    the 40-s extension's end do not return (the largest ends at 0.87 of its 1e-6 rad) while
    those from 100 s do. At dt/2 the 10-20 s window is periodic 6, and 300-s runs at dt, dt/2
    and dt/4 are periodic 6 over 200-300 s: a verdict that moves with its window
    (docs/classify-map-report.md, "Fate of the motion"). Found by scanning xi at the edges of
    the period-6 window; a run whose motion settles (xi = 0.28 before 2026-11-28's eighth
    session) was not found again among 275 (omega, xi) cells."""
    kw = dict(duration=20.0, transient=10.0, fate=100.0, workers=1)
    return regime_map(Axis("xi", (0.3459,)), Axis("omega", (Params().omega,)), **kw)


def test_chaos_that_settles_later_gets_the_verdict_at_the_horizon(settling):
    """The fate run's last half is classified (certificate included): periodic 6; the label
    over the recorded window is kept (undetermined: its 6-band chaos is the step's), the cell
    counts the run as settled, the figure marks the cell with ->P6 and the sentence names it."""
    from matplotlib.figure import Figure

    from chaoscam.paper._sensitivity import transient_finding
    from chaoscam.plot import SETTLED_MARK, plot_dominant

    row = settling.realizations.iloc[0]
    # the recorded window's 6-band chaos is the grid's: checked at dt/2 (step_marginal) it
    # differs, so the label is undetermined with the reason
    assert row["label"] == "undetermined" and "halving the step" in row["reasons"]
    assert row["fate"] == "OK"
    assert (row["fate_label"], row["fate_period"]) == ("periodic", 6)
    cell = settling.cells.iloc[0]
    assert (cell["n_settled"], cell["settled_period"], cell["n_transient"]) == (1, 6, 0)
    ax = Figure().subplots()
    plot_dominant(settling.cells, "xi", "omega", ax)
    assert [t.get_text() for t in ax.texts] == [f"{SETTLED_MARK}P6"]
    assert any("runs periodic (n)\nlater" in t.get_text() for t in ax.get_legend().get_texts())
    s = transient_finding(settling.realizations, 100.0, "value", name=lambda r: "here")
    assert "the 1 value labelled undetermined stays in the cam's reach." in s
    assert "1 of them is periodic on the continued run's last half (period 6;" in s
    assert "(here): 1 labelled otherwise needed the longer window for a verdict." in s


def test_without_a_horizon_nothing_is_continued():
    rm = regime_map(OMEGA, Axis("xi", (0.67,)), duration=20.0, transient=10.0, workers=1)
    assert rm.realizations["fate"].isna().all() and rm.config["fate"] is None
    assert rm.cells["n_transient"].tolist() == [0]


def test_bifurcation_verdicts_carry_the_fate():
    """The verdicts carry the fate, and the report's table shows it per run (the full
    report's Fig. 4 and sensitivity diagrams have a horizon); a diagram without one has no
    such columns."""
    from chaoscam.report._html import ReportParts, add_bifurcation

    b = bifurcation("xi", [0.4, 0.67], base=Params(omega=25.0), **KW)
    v = b.verdicts.set_index("value")
    assert v.loc[0.67, "fate"] == "LEFT_REACH" and 22.6 < v.loc[0.67, "left_at"] < 23.6
    assert pd.isna(v.loc[0.4, "fate"])
    parts = ReportParts()
    add_bifurcation(parts, "b.parquet", b, png=b"")
    table = parts.bifurcations[0]
    assert table["header"][-3:] == ["at the fate horizon", "label there", "period there"]
    rows = {r[0]: r for r in table["rows"]}
    assert rows["0.67"][-3] == "LEFT_REACH" and rows["0.4"][-3:] == ("", "", "")
    plain = bifurcation("xi", [0.67], base=Params(omega=25.0), duration=2.0, workers=1)
    add_bifurcation(parts, "p.parquet", plain, png=b"")
    assert "at the fate horizon" not in parts.bifurcations[1]["header"]


@pytest.mark.parametrize("fate", [20.0, 5.0, float("inf"), float("nan"), True, "300"])
def test_a_horizon_not_beyond_the_duration_is_refused(fate):
    with pytest.raises(SweepError, match=r"fate = .* must be a finite number > duration = 20 s"):
        regime_map(OMEGA, XI, duration=20.0, fate=fate, workers=1)


def test_resuming_with_another_horizon_is_refused(tmp_path):
    out = tmp_path / "m.parquet"
    kw = dict(duration=2.0, transient=1.0, workers=1, out=out)
    regime_map(OMEGA, Axis("xi", (0.4,)), fate=3.0, **kw)
    with pytest.raises(SweepError, match="different configuration"):
        regime_map(OMEGA, Axis("xi", (0.4,)), fate=4.0, resume=True, **kw)


def test_the_map_figure_marks_transient_cells(rmap):
    from matplotlib.figure import Figure

    from chaoscam.plot import TRANSIENT_MARK, plot_dominant

    ax = Figure().subplots()
    plot_dominant(rmap.cells, "omega", "xi", ax)
    texts = [t.get_text() for t in ax.texts]
    assert sorted(texts) == ["P2", TRANSIENT_MARK]
    assert any("transient" in t.get_text() for t in ax.get_legend().get_texts())
    ax = Figure().subplots()
    plot_dominant(rmap.cells.assign(n_transient=0), "omega", "xi", ax)
    assert [t.get_text() for t in ax.texts if t.get_text()] == ["P2"]
    assert not any("transient" in t.get_text() for t in ax.get_legend().get_texts())


def test_the_report_sentence_is_computed_from_the_rows():
    from chaoscam.paper._sensitivity import transient_finding

    nan = np.nan
    rows = pd.DataFrame(
        {
            "label": ["chaotic", "chaotic", "undetermined", "periodic"],
            "fate": ["LEFT_REACH", "OK", "LEFT_REACH", None],
            "left_at": [27.9, nan, 228.9, nan],
        }
    )
    s = transient_finding(rows, 300.0, "cell")
    # Named by their labels: the runs that already left the cam's reach are not continued,
    # so "not labelled periodic" overcounted them (the committed report said 51 of 98).
    assert "the 3 cells labelled chaotic or undetermined: 2 leave the cam's reach" in s
    assert "(last section at 27.9–229 s), 1 labelled chaotic" in s and "transient chaos" in s
    assert transient_finding(rows.iloc[[1]], 300.0, "value").endswith(
        "the 1 value labelled chaotic stays in the cam's reach."
    )
    named = transient_finding(rows, 300.0, "cell", lambda r: f"ω = 1 (left at {r.left_at:g} s)")
    assert "recorded window, at ω = 1 (left at 27.9 s): transient" in named
    assert "none labelled chaotic" in transient_finding(rows.iloc[1:3], 300.0, "cell")
    assert transient_finding(rows.iloc[[3]], 300.0, "cell") == ""
    assert transient_finding(rows.drop(columns="fate"), 300.0, "cell") == ""


def test_the_time_estimate_counts_the_horizon_for_every_run(monkeypatch):
    """The budget check sees the fate runs as an upper bound: the sweep's estimated time is
    1 + fate / duration times the one without a horizon."""
    import chaoscam.simulation

    seen = []

    class Stop(Exception):
        pass

    def spy(job, **kw):
        seen.append(job.seconds)
        raise Stop

    monkeypatch.setattr(chaoscam.simulation, "check_budget", spy)
    with pytest.raises(Stop):
        regime_map(OMEGA, XI, duration=20.0, fate=300.0, workers=1)
    with pytest.raises(Stop):
        regime_map(OMEGA, XI, duration=20.0, workers=1)
    with_fate, without = seen
    assert with_fate == pytest.approx((1 + 300.0 / 20.0) * without, rel=1e-12)


def test_the_html_report_summary_counts_the_transient_runs(rmap, tmp_path):
    from chaoscam.cli import main

    path = tmp_path / "m.parquet"
    rmap.to_parquet(path)
    out = tmp_path / "r.html"
    assert main(["report", str(path), "--out", str(out)]) == 0
    text = out.read_text()
    assert "continued to 40 s, 1 of the 1 realizations labelled chaotic stop" in text
    plain = regime_map(OMEGA, Axis("xi", (0.4,)), duration=2.0, transient=1.0, workers=1)
    plain.to_parquet(tmp_path / "p.parquet")
    assert main(["report", str(tmp_path / "p.parquet"), "--out", str(tmp_path / "p.html")]) == 0
    assert "continued to" not in (tmp_path / "p.html").read_text()


def test_the_command_line_summary_names_the_continued_runs(tmp_path, capsys):
    """`regime-map --fate`: the summary counts the continued runs by their labels (the run
    that left the cam's reach within the recorded window is not one of them) and gives a
    single time as one number. (25 rad/s, 0.67): chaotic over 2 s, out of reach at 23.12 s."""
    from chaoscam.cli import main

    argv = ["regime-map", "--x", "omega=25,42.5", "--y", "xi=0.67", "--duration", "4"]
    argv += ["--transient", "2", "--fate", "40", "--workers", "1", "--quiet"]
    assert main([*argv, "--out", str(tmp_path / "f.parquet")]) == 0
    out = capsys.readouterr().out
    assert "labels: chaotic 1, left_reach 1" in out
    assert "fate: 1 of the 1 run(s) labelled chaotic stopped later (LEFT_REACH 1; " in out
    assert "last section at 23.12 s): transient motion" in out
    argv = ["bifurcation", "--param", "xi", "--values", "0.3459", "--duration", "20"]
    argv += ["--transient", "10", "--fate", "100", "--workers", "1", "--quiet"]
    assert main([*argv, "--out", str(tmp_path / "b.parquet")]) == 0
    out = capsys.readouterr().out
    assert "stayed in the cam's reach; 1 periodic on the continued" in out
    assert "run's last half (period(s) 6 1)" in out


def test_the_report_clause_is_empty_when_no_run_was_continued():
    """A horizon, but every run periodic (or out of reach): no "0 of the 0 cells" clause."""
    from chaoscam.sweep._stats import fate_clause

    rows = pd.DataFrame({"label": ["periodic", "left_reach"], "fate": [None, None]})
    assert fate_clause(rows, 300.0, "cells") == ""
    rows.loc[0, ["label", "fate"]] = ["chaotic", "OK"]
    assert fate_clause(rows, 300.0, "cells").startswith("; continued to 300 s, 0 of the 1 cells")


def test_a_horizon_without_a_whole_late_period_is_not_judged():
    """A fate run whose last half holds no whole cam period (a horizon just past a short
    run) crashed the sweep in the classifier (no Jacobian); it is now left unjudged."""
    rm = regime_map(Axis("omega", (42.5,)), Axis("xi", (0.3,)), duration=0.05, transient=0.0,
                    fate=0.1, workers=1)  # fmt: skip
    row = rm.realizations.iloc[0]
    assert row["fate"] == "OK" and row["fate_label"] is None


def test_the_summary_says_nothing_of_settling_where_nothing_was_judged():
    """Rows without fate verdicts (an adaptive sweep, a file from before them): the HTML
    summary said "0 settle"; now it leaves the later verdicts out."""
    from chaoscam.sweep._stats import fate_clause

    rows = pd.DataFrame({"label": ["chaotic"], "fate": ["OK"], "fate_label": [None]})
    assert "periodic later" not in fate_clause(rows, 300.0, "runs")
    rows["fate_label"] = ["periodic"]
    assert "and 1 are periodic later (transient motion)" in fate_clause(rows, 300.0, "runs")


def test_the_clause_calls_nothing_transient_where_nothing_was():
    """Every continued run stayed and none settled: the clause gives the counts and no
    "(transient motion)", which described nothing (the full report's stiffness diagrams)."""
    from chaoscam.sweep._stats import fate_clause

    rows = pd.DataFrame({"label": ["chaotic"], "fate": ["OK"], "fate_label": ["chaotic"]})
    clause = fate_clause(rows, 300.0, "runs")
    said = "; continued to 300 s, 0 of the 1 runs labelled chaotic stop before it"
    assert clause == said + " and 0 are periodic later"
    rows["fate"] = ["LEFT_REACH"]
    assert fate_clause(rows, 300.0, "runs").endswith("(transient motion)")


def test_the_sentence_tells_a_settling_from_a_verdict_that_needed_longer():
    """(omega, xi) = (45, 0.20) is undetermined over 10 s and periodic 11 (to the band
    tolerance, not certified) on 150-300 s, where it is the same motion (period 22 at dt,
    bands 4e-7 rad): the sentence said it "settles on a periodic orbit ... certified"."""
    from chaoscam.paper._sensitivity import transient_finding

    rows = pd.DataFrame(
        {
            "label": ["chaotic", "undetermined"],
            "fate": ["OK", "OK"],
            "left_at": [np.nan, np.nan],
            "fate_label": ["periodic", "periodic"],
            "fate_period": pd.array([30, 11], dtype="Int64"),
        }
    )
    s = transient_finding(rows, 300.0, "cell")
    assert "2 of them are periodic on the continued run's last half (period 11, 30;" in s
    assert "1 labelled chaotic settles later and 1 labelled otherwise needed the longer" in s
    assert "certified" not in s


def test_fate_runs_continued_from_the_batch_copy_equal_runs_made_again(monkeypatch):
    """The engine continues a batch's fate runs from its resumable copy; their fields
    (status, where it left, the verdict on the last half) equal those of runs made again
    from t = 0, and a horizon whose last half would start before the transient is run again
    (the rows judged would be missing from a continued run)."""
    from chaoscam.sweep import _runs

    plist = [Params(omega=25.0, xi=0.67), Params(omega=25.0, xi=0.45)]  # leaves; stays
    run = dict(indices=[3, 5], seed=1, duration=20.0, transient=10.0, tangent=True)
    kept = chaoscam.solve(plist, resumable=True, **run)
    plain = chaoscam.solve(plist, **run)
    calls = []
    real = _runs.extend
    monkeypatch.setattr(_runs, "extend", lambda *a, **k: calls.append(1) or real(*a, **k))
    continued = _runs._fates(kept, [0, 1], 40.0)
    assert calls == [1]  # continued from the copy, not run again
    again = _runs._fates(plain, [0, 1], 40.0)
    assert calls == [1]  # no copy: run again
    assert continued == again
    assert continued[0]["fate"] == "LEFT_REACH" and 22.6 < continued[0]["left_at"] < 23.6
    assert continued[1]["fate"] == "OK" and continued[1]["fate_label"] == "chaotic"
    _runs._fates(kept, [0, 1], 20.5)
    assert calls == [1]  # last half from ~10.1 s: too near the transient, run again
