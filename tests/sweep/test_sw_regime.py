"""Regime maps: reproducibility, labels never dropped, adaptive sampling, checkpoints."""

import numpy as np
import pytest

from chaoscam import Params, simulate
from chaoscam.sweep import (
    Axis,
    SweepError,
    SweepInterrupted,
    checkpoint_dir,
    realization_index,
    regime_map,
    verdict_fields,
)

from ._helpers import (
    InterruptOnce,
    ParityClassifier,
    SpreadClassifier,
    frames_equal,
    one_run_per_batch,
)

MU = Axis("l_lambda", (0.006, 0.010))
SIGMA = Axis("l_lambda_sigma", (0.0, 0.002))
KW = dict(
    realizations=3, seed=11, duration=1.5, transient=0.5, classify=SpreadClassifier(), workers=1
)


@pytest.fixture(scope="module")
def reference():
    return regime_map(MU, SIGMA, **KW)


def test_rows_and_cells_shape(reference):
    """One row per (cell, realization), sorted; one summary row per cell with n = N, except
    the deterministic cells (sigma = 0: cells 0 and 2), computed once."""
    r, c = reference.realizations, reference.cells
    assert len(r) == 2 * 3 + 2 * 1 and len(c) == 4
    assert list(zip(r["cell"], r["index"], strict=True)) == [
        (c_, i) for c_ in range(4) for i in range(1 if c_ % 2 == 0 else 3)
    ]
    assert list(c["n"]) == [1, 3, 1, 3]
    assert list(c["deterministic"]) == [True, False, True, False]
    assert list(r.columns[:4]) == ["cell", "index", "l_lambda", "l_lambda_sigma"]


def test_same_seed_same_table_other_seed_other_random_cells(reference):
    """Seed fixes the table bit for bit; another seed changes the random cells only."""
    frames_equal(regime_map(MU, SIGMA, **KW).realizations, reference.realizations)
    other = regime_map(MU, SIGMA, **{**KW, "seed": 12}).realizations
    random = reference.realizations["l_lambda_sigma"] > 0
    a, b = reference.realizations, other
    assert not np.array_equal(a.loc[random, "ev_spread"], b.loc[random, "ev_spread"])
    assert np.array_equal(a.loc[~random, "ev_spread"], b.loc[~random, "ev_spread"])


def test_row_is_reproduced_by_simulate(reference):
    """Row (cell, i) is simulate(params_c, seed, realization_index(c, i)) + the classifier."""
    row = reference.realizations.iloc[5]
    assert row["sim_index"] == realization_index(row["cell"], row["index"])
    p = Params(l_lambda=row["l_lambda"], l_lambda_sigma=row["l_lambda_sigma"])
    traj = simulate(
        p, duration=1.5, transient=0.5, seed=11, index=int(row["sim_index"]), series=False
    )
    f = verdict_fields(SpreadClassifier()(traj))
    assert f["label"] == row["label"] and f["evidence"]["spread"] == row["ev_spread"]


def test_non_regular_runs_are_their_own_label():
    """omega = 45 rad/s, xi = 0.9 leaves the cam's reach: labelled left_reach, kept."""
    m = regime_map(
        Axis("omega", (28.7, 45.0)),
        Axis("xi", (0.42, 0.9)),
        duration=2.0,
        transient=0.5,
        classify=SpreadClassifier(),
        workers=1,
    )
    row = m.realizations.set_index(["omega", "xi"]).loc[(45.0, 0.9)]
    assert row["status"] == "LEFT_REACH" and row["label"] == "left_reach"
    cell = m.cells.set_index(["omega", "xi"]).loc[(45.0, 0.9)]
    assert cell["dominant"] == "left_reach" and cell["p_left_reach"] == 1.0
    assert len(m.realizations) == 4


def test_adaptive_sampling_adds_batches_until_target_or_cap():
    """Cells grow by N at a time; they stop once the widest half-width <= target, or at
    the cap: mixed cells at 6; the deterministic cells (sigma = 0) are one run with a point
    interval (half-width 0), never sampled further."""
    m = regime_map(
        MU,
        SIGMA,
        **{**KW, "realizations": 2, "classify": ParityClassifier()},
        target_halfwidth=0.3,
        max_realizations=6,
    )
    c = m.cells
    assert list(c["n"]) == [1, 6, 1, 6]
    assert list(c.loc[c["deterministic"], "halfwidth"]) == [0.0, 0.0]
    assert ((c["halfwidth"] <= 0.3) | (c["n"] == 6)).all()
    assert len(m.realizations) == c["n"].sum()
    r = m.realizations
    assert list(r.loc[r["cell"] == 1, "index"]) == list(range(6))


def test_interrupt_then_resume_gives_the_uninterrupted_table(tmp_path, monkeypatch, reference):
    """Ctrl-C mid-run saves the finished rows; resume finishes to the identical table and
    recomputes nothing that was saved; the finished output is then reused as is."""
    one_run_per_batch(monkeypatch)
    out = tmp_path / "m.parquet"
    cls = InterruptOnce(str(tmp_path / "marker"), victim=realization_index(3, 1))
    with pytest.raises(SweepInterrupted, match="--resume") as err:
        regime_map(MU, SIGMA, **{**KW, "classify": cls}, out=out, flush_interval=0)
    ckpt = checkpoint_dir(out)
    assert 0 < err.value.done < 8 and ckpt.is_dir() and not out.exists()
    saved = len(list(ckpt.glob("part-*.jsonl")))
    assert saved == err.value.done  # one part per record with flush_interval = 0
    res = regime_map(MU, SIGMA, **{**KW, "classify": cls}, out=out, resume=True, flush_interval=0)
    frames_equal(res.realizations, reference.realizations)
    frames_equal(res.cells, reference.cells)
    assert not ckpt.exists() and out.exists()
    again = regime_map(MU, SIGMA, **{**KW, "classify": cls}, out=out, resume=True)
    frames_equal(again.realizations, reference.realizations)


def test_a_ctrl_c_between_saving_a_record_and_counting_it_counts_it(tmp_path, monkeypatch):
    """A Ctrl-C after a record is stored but before the plan counts it: the message gives
    the records saved (it said one fewer)."""
    from chaoscam.sweep import _regime

    counted = _regime._RegimePlan.on_record
    calls = []

    def on_record(self, record):
        calls.append(1)
        if len(calls) == 2:
            raise KeyboardInterrupt
        return counted(self, record)

    monkeypatch.setattr(_regime._RegimePlan, "on_record", on_record)
    out = tmp_path / "m.parquet"
    with pytest.raises(SweepInterrupted, match=r"; 2 of \d+ runs are saved") as err:
        regime_map(MU, SIGMA, **KW, out=out, flush_interval=0)
    lines = [
        ln for f in checkpoint_dir(out).glob("part-*.jsonl") for ln in f.read_text().splitlines()
    ]
    assert err.value.done == 2 == sum(1 for ln in lines if not ln.startswith("#"))


def test_existing_output_or_other_configuration_is_refused(tmp_path):
    """Without resume an existing output is refused untouched; a checkpoint or output of
    another configuration is refused even with resume."""
    out = tmp_path / "m.parquet"
    regime_map(MU, SIGMA, **{**KW, "realizations": 1}, out=out)
    before = out.read_bytes()
    with pytest.raises(FileExistsError, match="--resume"):
        regime_map(MU, SIGMA, **{**KW, "realizations": 1}, out=out)
    with pytest.raises(SweepError, match="different configuration"):
        regime_map(MU, SIGMA, **{**KW, "realizations": 2}, out=out, resume=True)
    assert out.read_bytes() == before
    out2 = tmp_path / "n.parquet"
    cls = InterruptOnce(str(tmp_path / "marker"), victim=realization_index(1, 0))
    with pytest.raises(SweepInterrupted):
        regime_map(MU, SIGMA, **{**KW, "classify": cls}, out=out2)
    with pytest.raises(FileExistsError, match="--resume"):
        regime_map(MU, SIGMA, **{**KW, "classify": cls}, out=out2)
    with pytest.raises(SweepError, match="different configuration"):
        regime_map(MU, SIGMA, **{**KW, "classify": cls, "seed": 5}, out=out2, resume=True)


def test_readers_name_a_file_of_another_kind(tmp_path, reference):
    """read_regime_map round-trips a map (named by either file) and refuses a bifurcation
    diagram, a plain Parquet file and a missing companion, each naming the file."""
    import pandas as pd

    from chaoscam.sweep import bifurcation, read_bifurcation, read_regime_map

    out = tmp_path / "m.parquet"
    reference.to_parquet(out)
    for name in (out, tmp_path / "m.cells.parquet"):
        frames_equal(read_regime_map(name).cells, reference.cells)
    with pytest.raises(SweepError, match="m.parquet: a regime map, not a bifurcation diagram"):
        read_bifurcation(out)
    bif = tmp_path / "b.parquet"
    bifurcation("omega", [28.7], **{k: v for k, v in KW.items() if k != "realizations"}, out=bif)
    with pytest.raises(SweepError, match="a bifurcation diagram, not a regime map; read it"):
        read_regime_map(bif)
    plain = tmp_path / "p.parquet"
    pd.DataFrame({"x": [1]}).to_parquet(plain)
    with pytest.raises(SweepError, match="p.parquet: not a chaoscam regime map"):
        read_regime_map(plain)
    (tmp_path / "m.cells.parquet").unlink()
    with pytest.raises(FileNotFoundError, match="m.cells.parquet: no such file"):
        read_regime_map(out)


def test_a_custom_classifier_label_outside_the_four_is_refused():
    """A classifier returning label "wobbly" and period 2.7 was stored as ("wobbly", 2): the
    period cut silently and the label a cell's dominant one. The run's task fails naming it."""
    from types import SimpleNamespace

    from chaoscam.sweep._engine import TaskFailed

    def odd(traj):
        return SimpleNamespace(label="wobbly", period=None, evidence=(), reasons=())

    def cut(traj):
        return SimpleNamespace(label="periodic", period=2.7, evidence=(), reasons=())

    for classify, named in ((odd, "label 'wobbly' is not one of"), (cut, "period 2.7 is not")):
        with pytest.raises(TaskFailed, match=named):
            regime_map("xi=0.2", "l_lambda_sigma=0", classify=classify, realizations=1,
                       duration=0.3, workers=1)  # fmt: skip


def test_the_default_realizations_are_20_in_a_random_cell_and_1_in_a_deterministic_one():
    """realizations=None: N = 20 when some cell has a random line length (sigma > 0), and a
    deterministic cell (sigma = 0) runs once; a grid of deterministic cells only runs each
    once, and records N = 1."""
    kw = dict(seed=1, duration=0.3, transient=0.1, classify=ParityClassifier(), workers=1)
    mixed = regime_map(Axis("l_lambda", (0.008,)), SIGMA, **kw)
    assert list(mixed.cells["n"]) == [1, 20] and mixed.config["realizations"] == 20
    fixed = regime_map(Axis("l_lambda", (0.008,)), Axis("xi", (0.3, 0.4)), **kw)
    assert list(fixed.cells["n"]) == [1, 1] and fixed.config["realizations"] == 1


def test_progress_none_shows_a_bar_only_on_a_terminal(capsys):
    """progress=None (the default) shows the bar when stderr is a terminal: not here, where
    the tests capture it; progress=True shows it anyway."""
    kw = dict(realizations=1, duration=0.3, transient=0.1, classify=ParityClassifier(), workers=1)
    regime_map(Axis("l_lambda", (0.008,)), Axis("xi", (0.3,)), progress=None, **kw)
    assert "regime map" not in capsys.readouterr().err
    regime_map(Axis("l_lambda", (0.008,)), Axis("xi", (0.3,)), progress=True, **kw)
    assert "regime map: 100%" in capsys.readouterr().err
