"""The paper report's continuation part (chaoscam.paper._continued): the continued
period-doubling curve separates cells of different labels where it crosses a small (ω, ξ)
map's rows, and the part's sentence names the fold and the period doubling."""

import pandas as pd
import pytest

from chaoscam.paper._continued import crossings, follow_window, sides_differ
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
