"""The paper report's continuation part (chaoscam.paper._continued): the continued
period-doubling curve separates cells of different labels where it crosses a small (ω, ξ)
map's rows, and the part's sentence names the fold and the period doubling; Table 1's
period-2 orbit continued over Fig. 4's l_λ range."""

import numpy as np
import pandas as pd
import pytest

import chaoscam
from chaoscam.paper._continued import (
    _lambda_sentence,
    crossings,
    follow_lambda,
    follow_window,
    sides_differ,
)
from chaoscam.sweep import Axis, regime_map


@pytest.fixture(scope="module")
def window():
    return follow_window(0.2)


def test_flip_curve_separates_cells_of_different_labels(window, tmp_path_factory):
    """On a 3 x 2 map around the curve (omega 29.5, 31, 32.5; xi 0.1, 0.16) the period-doubling
    curve crosses each row once, between a P1 cell and a cell that is not P1."""
    _, curves = window
    out = tmp_path_factory.mktemp("map") / "map.parquet"
    rm = regime_map(Axis("omega", (29.5, 31.0, 32.5)), Axis("xi", (0.1, 0.16)), realizations=1,
                    duration=20.0, transient=10.0, out=out, progress=False)  # fmt: skip
    cross = crossings(curves.points[curves.points.kind == "period_doubling"], rm.cells)
    assert len(cross) == 2 and sides_differ(cross).all()
    assert (cross.period_lo == 1).all() and (cross.dominant_lo == "periodic").all()
    assert not ((cross.period_hi == 1) & (cross.dominant_hi == "periodic")).any()


def test_window_branch_ends_at_its_fold_and_doubling(window):
    """The branch's events: one fold at 29.0894 and one doubling at 32.0393 rad/s."""
    branch, curves = window
    ev = branch.events[branch.events.kind != "end"].set_index("kind")["value"]
    assert abs(ev["fold"] - 29.0894) < 1e-4 and abs(ev["period_doubling"] - 32.0393) < 1e-4
    assert set(curves.points.kind) == {"fold", "period_doubling"}
    assert isinstance(curves.points, pd.DataFrame) and curves.points.value2.max() >= 0.2


def test_table1_period_two_orbit_is_the_same_unstable_orbit_at_every_l_lambda():
    """Table 1's period-2 orbit (two impacts, no contact phase) continued over [0.001, 0.018]
    m keeps theta_f within 1e-9 rad and |mu1| within 1e-6 relative, unstable throughout, as
    Newton shooting finds it at both ends on its own; the sentence says so."""
    branch = follow_lambda(chaoscam.Numerics(), 0.001, 0.018)
    g = branch.points[branch.points.period == 2]
    assert g.value.min() <= 0.001 and g.value.max() >= 0.018
    assert (g.n_macro_impacts == 2).all() and not g.sticks.any() and not g.stable.any()
    assert float(g.groupby("j").theta_f.agg(np.ptp).max()) < 1e-9
    assert np.ptp(g.abs_mu) < 1e-6 * g.abs_mu.max()
    x0 = g[g.j == 0][["theta_f", "omega_f"]].to_numpy()[0]
    for l_lambda in (0.0015, 0.0175):
        orbit = chaoscam.periodic_orbit(chaoscam.Params(l_lambda=l_lambda), x0, 2)
        assert orbit.converged and abs(np.max(np.abs(orbit.multipliers)) - g.abs_mu.max()) < 1e-4
    text = _lambda_sentence(branch)
    assert "period-2 orbit" in text and "unstable throughout" in text
