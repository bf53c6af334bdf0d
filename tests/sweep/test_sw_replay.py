"""replay: one realization of a finished sweep, run alone, is the run the sweep classified."""

import numpy as np
import pandas as pd
import pytest

from chaoscam import Numerics, Params, classify
from chaoscam.sweep import (
    Axis,
    bifurcation,
    read_regime_map,
    regime_map,
    replay,
    replay_params,
)

BASE = Params(l_lambda_sigma=0.002)


@pytest.fixture(scope="module")
def rmap():
    """Two cells, two realizations each (sigma > 0: different realizations), run as batch
    members, classified by the package's verdict (not extended)."""
    return regime_map(
        Axis("omega", (20.0, 30.0)),
        Axis("xi", (0.42,)),
        base=BASE,
        realizations=2,
        duration=3.0,
        transient=2.0,
        extend_to=None,  # no extension: a cheap test
        workers=1,
        progress=False,
    )


def test_regime_map_row_replays_its_own_run(rmap):
    """Every realization replayed alone has the sweep's section count, impact count and
    label; the two realizations of a cell are different runs."""
    impacts = []
    for row in rmap.realizations.itertuples():
        p, num = replay_params(rmap, row)
        assert (p.omega, p.xi, p.l_lambda_sigma) == (row.omega, row.xi, 0.002)
        assert num == Numerics()
        tr = replay(rmap, row)
        assert len(tr.section) == row.n_section
        assert tr.stats["n_impacts"] == row.n_impacts
        (verdict,) = classify(tr, extend_to=None)
        assert verdict.label == row.label
        impacts.append(tr.stats["n_impacts"])
    assert len(set(impacts)) > 1


def test_bifurcation_row_replays_its_section_points():
    """A continued branch (the second value starts from the first's end state) replays to
    the diagram's own section points, bit for bit, for each initial condition."""
    bif = bifurcation(
        "xi",
        [0.2, 0.25],
        initial_conditions=2,
        duration=3.0,
        transient=1.0,
        continuation=True,
        workers=1,
        progress=False,
    )
    assert bif.verdicts["continued"].any()
    for _, row in bif.verdicts.iterrows():  # pandas rows too
        tr = replay(bif, row, tangent=False)
        mine = bif.points[(bif.points["value_index"] == row["value_index"])
                          & (bif.points["ic"] == row["ic"])]  # fmt: skip
        np.testing.assert_array_equal(
            tr.section["theta_f"].to_numpy()[-len(mine) :], mine["theta_f"].to_numpy()
        )


def test_replay_reads_a_written_map_and_names_what_it_needs(tmp_path, rmap):
    """From a file it replays the same; a row without the fields, or something not a sweep,
    is refused with what to pass."""
    rmap.to_parquet(tmp_path / "m.parquet")
    back = read_regime_map(tmp_path / "m.parquet")
    row = back.realizations.iloc[0]
    assert len(replay(back, row, tangent=False).section) == row["n_section"]
    with pytest.raises(KeyError, match="realizations"):
        replay(back, {"omega": 20.0, "xi": 0.42})
    with pytest.raises(TypeError, match="RegimeMap or a Bifurcation"):
        replay(pd.DataFrame(), row)


def test_replay_tells_the_kind_of_a_sweep_written_before_kinds(rmap):
    """Files written before sweeps recorded their kind (which read_regime_map accepts) are
    told by their axes."""
    import dataclasses

    old = dataclasses.replace(rmap, config={k: v for k, v in rmap.config.items() if k != "kind"})
    row = old.realizations.iloc[0]
    assert replay_params(old, row) == replay_params(rmap, row)


def test_replay_refined_is_the_same_realization_at_a_finer_step(rmap):
    """refine = 2 runs the row's realization at dt / 4: the same draws and window as
    simulating the refined parameters directly, with a different step; refine < 0, a float or
    a bool is refused by name."""
    from chaoscam import simulate

    row = rmap.realizations.iloc[0]
    fine = replay(rmap, row, tangent=False, refine=2)
    assert fine.numerics.dt == Numerics().dt / 4
    p, num = replay_params(rmap, row)
    direct = simulate(p, num.refined().refined(), duration=3.0, transient=2.0,
                      seed=int(row["seed"]), index=int(row["sim_index"]),
                      output_dt=1e-3)  # fmt: skip
    np.testing.assert_array_equal(fine.section["theta_f"], direct.section["theta_f"])
    assert (
        fine.section["theta_f"].to_numpy()[-1]
        != replay(rmap, row, tangent=False).section["theta_f"].to_numpy()[-1]
    )
    for bad in (-1, 1.0, True):
        with pytest.raises(ValueError, match="refine"):
            replay(rmap, row, refine=bad)
