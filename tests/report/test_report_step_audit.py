"""The step audit: sampled runs of the paper figures' sweeps, replayed and checked at dt/2."""

import pandas as pd
import pytest

from chaoscam.paper import _step_audit as sa
from chaoscam.paper._step_audit import AuditRow, audit_sample, audit_sentence, step_audit
from chaoscam.sweep import bifurcation


@pytest.fixture(scope="module")
def small_diagram():
    """Three values of e with a period-1 response after ~2 s, not extended (cheap)."""
    return bifurcation(
        "e",
        [0.02, 0.021, 0.022],
        duration=4.0,
        transient=2.0,
        extend_to=None,
        workers=1,
        progress=False,
    )


def test_sample_is_seeded_and_draws_decided_labels_only():
    """Only periodic, quasiperiodic or chaotic rows; the same seed draws the same rows (in
    table order); asking for more than there are gives all of them."""
    labels = ["chaotic", "undetermined", "periodic", "left_reach", "quasiperiodic"] * 8
    table = pd.DataFrame({"label": labels, "n": range(len(labels))})
    a, b = audit_sample(table, 5), audit_sample(table, 5)
    assert a.equals(b) and len(a) == 5 and list(a["n"]) == sorted(a["n"])
    assert set(a["label"]) <= {"periodic", "quasiperiodic", "chaotic"}
    assert list(audit_sample(table, 5, seed=1)["n"]) != list(a["n"])
    assert len(audit_sample(table, 100)) == 24


def _row(where, recorded, replayed, half, held):
    return AuditRow("Fig. 4", where, recorded, replayed, half, held, 1.5)


def test_sentence_counts_and_names_what_did_not_hold():
    """Kept, undetermined at dt/2, another label and not reproduced are told apart; the
    last three are named."""
    rows = [
        _row("a", "chaotic", "chaotic", "chaotic", True),
        _row("b", "chaotic", "chaotic", "undetermined", False),
        _row("c", "chaotic", "chaotic", "periodic 8", False),
        _row("d", "periodic 2", "chaotic", "chaotic", True),
    ]
    text = audit_sentence(rows)
    assert "4 runs" in text and "(6 s of work)" in text
    assert (
        "3 reproduce their label; at half the step 1 keeps it, 1 is undetermined and 1 gets" in text
    )
    assert "Undetermined at half the step: Fig. 4 at b: chaotic → undetermined" in text
    assert "Another label: Fig. 4 at c: chaotic → periodic 8" in text
    assert "Not reproduced: Fig. 4 at d (recorded periodic 2, replayed chaotic)" in text
    assert audit_sentence([]) == ""


def test_audit_replays_a_diagrams_runs_on_worker_threads(small_diagram):
    """A small diagram: two of its decided runs replayed on two threads come back with the
    recorded label, with their step check."""
    bif = small_diagram
    assert bif.verdicts["label"].isin(sa.LABELS).sum() >= 2
    rows = step_audit([("Fig. X", bif)], 2, extend_to=None, workers=2)
    assert len(rows) == 2 and all(r.reproduced for r in rows)
    assert all(r.where.startswith("e = ") and r.half != "not re-run" for r in rows)
    assert step_audit([("Fig. X", bif)], 0, extend_to=None) == []


@pytest.mark.parametrize("quick", [True, False])
def test_quick_report_audits_nothing_and_full_audits_every_sweep(quick):
    assert (sa.PER_SWEEP[quick] == 0) is quick


def test_a_figures_sweeps_are_named_by_what_differs():
    """Fig. 6's two diagrams differ in G (and dt): each audited run names its sweep so; a
    sweep at a step other than the default names its step (the audit halves it)."""
    from types import SimpleNamespace

    from chaoscam import Numerics, Params

    def sweep(dt=None, **base):  # a sweep's record: its base model and its numerics
        numerics = Numerics() if dt is None else Numerics(dt=dt)
        config = {"base": Params(**base).to_dict(), "numerics": numerics.to_dict()}
        return SimpleNamespace(config=config)

    assert sa.sweep_names("Fig. 3", []) == []  # a figure without a sweep
    one = [sweep(G=1e-9, dt=3.9e-7)]
    assert sa.sweep_names("Fig. 4", one) == ["Fig. 4 (dt = 3.9e-07)"]  # not the default step
    assert sa.sweep_names("Fig. 7", [sweep(dt=2e-6)]) == ["Fig. 7"]  # the default step
    assert sa.sweep_names("Fig. 7", [sweep()]) == ["Fig. 7"]
    two = [*one, sweep(G=1e-10, dt=2e-7)]
    assert sa.sweep_names("Fig. 9", [sweep(), sweep()]) == ["Fig. 9 (sweep 1)", "Fig. 9 (sweep 2)"]
    assert sa.sweep_names("Fig. 9", [one[0], one[0]]) == [
        "Fig. 9 (dt = 3.9e-07, sweep 1)",
        "Fig. 9 (dt = 3.9e-07, sweep 2)",
    ]
    assert sa.sweep_names("Fig. 6", two) == [
        "Fig. 6 (G = 1e-09, dt = 3.9e-07)",
        "Fig. 6 (G = 1e-10, dt = 2e-07)",
    ]


def test_audit_stage_skips_figures_without_sweeps_and_reports_a_failure(monkeypatch, small_diagram):
    """The full report's audit stage over its stages' results: a figure without a sweep
    (Fig. 3, Fig. 5) and the sensitivity stage are passed over, a figure's sweep is audited;
    a failure goes to "What is missing" and the report goes on."""
    bif = small_diagram
    from chaoscam.paper import FigureResult, _run
    from chaoscam.paper._paper import SENSITIVITY
    from chaoscam.report import ReportParts

    results = [
        FigureResult(3),
        FigureResult(4, bifurcations=[("fig4.parquet", bif, b"")]),
        FigureResult(SENSITIVITY, bifurcations=[("s.parquet", bif, b"")]),
    ]
    monkeypatch.setitem(sa.PER_SWEEP, False, 1)
    said, parts = [], ReportParts()
    rows, seconds = _run._audit_stage(results, False, 1, said.append, parts)
    assert [r.figure for r in rows] == ["Fig. 4"] and rows[0].reproduced and seconds > 0
    assert _run._audit_stage(results, True, 1, said.append, parts) == ([], 0.0)

    def broken(*a, **k):
        raise RuntimeError("no pool")

    monkeypatch.setattr(_run, "step_audit", broken)
    assert _run._audit_stage(results, False, 1, said.append, parts) == ([], 0.0)
    assert parts.missing == ["Step audit: failed with RuntimeError: no pool"]


def test_audit_script_reads_a_reports_data_and_refuses_bad_input(tmp_path, capsys, small_diagram):
    """analyses/step_audit.py over a data folder holding a Fig. 4 diagram: one line per
    audited run and the sentence; a missing file, K < 1 or S <= 0: exit 2 naming it."""
    bif = small_diagram
    from chaoscam.paper import audit_script

    bif.to_parquet(tmp_path / "fig4.parquet")
    args = ["--figures", "4", "--per-sweep", "1", "--workers", "1", "--extend-to", "4"]
    assert audit_script([*args, str(tmp_path)]) == 0
    out = capsys.readouterr().out.splitlines()
    assert out[0].startswith("Fig. 4 | e = 0.02") and "| holds |" in out[0]
    assert out[1].startswith("Step audit: 1 run labelled") and "1 reproduces its label" in out[1]
    for bad, says in (
        ([*args, str(tmp_path / "none")], "fig4.parquet is missing"),
        # chaoscam paper writes a paper-data folder: named only for one
        ([*args, str(tmp_path / "none")], f"with `python analyses/fig4.py {tmp_path}/none`"),
        ([*args, str(tmp_path / "paper-data")], f"`chaoscam paper --out {tmp_path}/paper.html`"),
        (["--per-sweep", "0", str(tmp_path)], "--per-sweep 0: must be at least 1"),
        (["--extend-to", "-1", str(tmp_path)], "--extend-to -1.0: must be"),
        (["--extend-to", "inf", str(tmp_path)], "--extend-to inf: must be a finite"),
        (["--seed", "-1", str(tmp_path)], "--seed -1: must be an integer >= 0"),
        (["--figures", "4,5", str(tmp_path)], "--figures 4,5: choose among 4, 6, 7, s"),
        (["--figures", "s", str(tmp_path)], "sensitivity-*.parquet: write them with"),
        (["--label", "chaotic", str(tmp_path)], "--label chaotic: only with --ladder"),
        (["--ladder", "2", "--label", "odd", str(tmp_path)], "invalid choice: 'odd'"),
        (["--ladder", "3", str(tmp_path)], "--ladder 3: give powers of two >= 2"),
        (["--ladder", "4,2", str(tmp_path)], "--ladder 4,2: give powers of two >= 2"),
        (["--ladder", "1,2", str(tmp_path)], "--ladder 1,2: give powers of two >= 2"),
        (["--ladder", "x", str(tmp_path)], "--ladder x: give powers of two >= 2"),
    ):
        with pytest.raises(SystemExit) as stop:
            audit_script(bad)
        assert stop.value.code == 2 and says in capsys.readouterr().err


def test_audit_reads_the_sensitivity_sweeps_and_a_ladder_follows_one_label(
    tmp_path, monkeypatch, small_diagram
):
    """--figures s: every sensitivity-*.parquet of the folder (not its companions), each
    named by its file, read as the kind its record says; --label: the ladder draws only rows
    with that label (the jobs it would run, captured instead of run)."""
    from chaoscam.paper._step_audit import read_sweeps

    small_diagram.to_parquet(tmp_path / "sensitivity-e.parquet")
    small_diagram.to_parquet(tmp_path / "fig4.parquet")
    got = read_sweeps(tmp_path, ["s", 4])
    assert [name for name, _ in got] == ["sensitivity-e", "Fig. 4"]
    assert got[0][1].verdicts.equals(small_diagram.verdicts)
    monkeypatch.setattr(sa, "side_by_side", lambda fn, jobs, workers, prefix: jobs)
    table = small_diagram.verdicts
    mixed = table.assign(label=["undetermined", "periodic", "undetermined"][: len(table)])
    sweep = type("Sweep", (), {"config": small_diagram.config, "verdicts": mixed})()
    jobs = sa.step_ladder([("S", sweep)], (1,), 5, None, label="undetermined")
    assert [job[2]["label"] for job in jobs] == ["undetermined"] * 2
    assert len(sa.step_ladder([("S", sweep)], (1,), 5, None)) == len(table)
    # a rung whose run leaves the cam's reach is labelled so, as a sweep labels it, with no
    # exponent (not "undetermined" with the verdict's reason)
    import chaoscam.sweep
    from chaoscam.kernel import Status

    left = type("Run", (), {"status": Status.LEFT_REACH, "ok": False})()
    monkeypatch.setattr(chaoscam.sweep, "replay", lambda settings, row, refine: left)
    job = jobs[0][:3] + ((1,), None)
    row = sa._ladder_one(job)
    assert [tag for _, tag, _ in row.rungs] == ["left_reach", "left_reach"]
    assert all(lam != lam for _, _, lam in row.rungs)  # NaN


def test_a_ladder_counts_the_runs_the_step_no_longer_moves():
    """settled: one decided label at every halved step (dt/2 down), not the sweep's own
    step; "undetermined" everywhere, or labels that differ, are not settled."""
    from chaoscam.paper._step_audit import LadderRow, ladder_sentence, settled

    def row(*tags):
        return LadderRow("F", "x", tags[0], tuple((h, t, 0.1) for h, t in enumerate(tags)), 1.0)

    rows = [
        row("undetermined", "chaotic", "chaotic", "chaotic"),  # settled: chaotic
        row("period 6", "period 12", "period 12", "period 12"),  # settled: period 12
        row("chaotic", "undetermined", "undetermined", "period 8"),  # not
        row("chaotic", "left_reach", "chaotic", "left_reach"),  # not
        row("chaotic", "undetermined", "undetermined", "undetermined"),  # not: no decision
        row("undetermined", "chaotic", "chaotic", "chaotic"),  # settled: chaotic
    ]
    assert [settled(r) for r in rows] == ["chaotic", "period 12", None, None, None, "chaotic"]
    text = ladder_sentence(rows)
    assert text.endswith(
        "Settled (one decided label at dt/2, dt/4, dt/8): 3 of 6 (chaotic 2, period 12 1)."
    )
    assert settled(row("chaotic")) is None and "Settled" not in ladder_sentence([row("x")])


@pytest.mark.slow  # 9 s: the ladder (an analysis tool); the audit is tested by default
def test_ladder_follows_every_drawn_run_down_the_step(tmp_path, capsys, small_diagram):
    """--ladder 2,4: two runs of any label, each classified at dt, dt/2 and dt/4; the first
    rung is the recorded verdict (the replay is the sweep's run); the sentence compares dt
    and dt/2 with dt/4."""
    from chaoscam.paper import audit_script
    from chaoscam.paper._step_audit import ladder_sample, ladder_sentence, step_ladder

    table = pd.DataFrame({"label": ["chaotic", "undetermined"] * 5})
    assert "undetermined" in set(ladder_sample(table, 6)["label"])  # any label: 6 > 5 chaotic
    bif = small_diagram
    rows = step_ladder([("Fig. X", bif)], (1, 2), 2, None, workers=2)
    assert len(rows) == 2
    for r in rows:
        assert [h for h, _, _ in r.rungs] == [0, 1, 2] and r.rungs[0][1] == r.recorded
    text = ladder_sentence(rows)
    assert text.startswith("Step ladder: 2 runs of Fig. X classified at dt, dt/2, dt/4")
    assert "Against dt/4: at dt " in text and "; at dt/2 " in text
    bif.to_parquet(tmp_path / "fig4.parquet")
    args = ["--figures", "4", "--per-sweep", "1", "--workers", "1", "--ladder", "2"]
    assert audit_script([*args, str(tmp_path)]) == 0
    out = capsys.readouterr().out.splitlines()
    assert out[0].startswith("Fig. 4 | e = ") and " | dt: " in out[0] and " | dt/2: " in out[0]
    assert out[1].startswith("Step ladder: 1 run")
