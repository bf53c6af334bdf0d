"""Bifurcation diagrams: section points after the transient, continuation, initial states."""

import numpy as np
import pytest

from chaoscam import Numerics, Params
from chaoscam.model import contact_angle
from chaoscam.sweep import (
    Axis,
    SweepInterrupted,
    bifurcation,
    initial_offsets,
    realization_index,
)
from chaoscam.sweep._grid import validate_grid

from ._helpers import InterruptOnce, SpreadClassifier, frames_equal

KW = dict(duration=1.5, transient=0.5, classify=SpreadClassifier(), workers=1)


@pytest.fixture(scope="module")
def chained():
    return bifurcation("l_lambda", "0.004:0.012:4", initial_conditions=2, continuation=True, **KW)


def test_points_are_the_section_after_the_transient():
    """Every point lies at t = k 2 pi / omega >= transient; verdicts count them."""
    b = bifurcation("omega", [28.7, 30.0], **KW)
    pts, v = b.points, b.verdicts
    assert len(v) == 2 and (pts["t"] >= 0.5 - 1e-12).all()
    for val, g in pts.groupby("value"):
        assert np.allclose(g["t"], g["k"] * 2 * np.pi / val, rtol=0, atol=1e-9)
    assert list(v["n_points"]) == [int((pts["value"] == x).sum()) for x in v["value"]]
    assert (v["recorded_s"] == 1.0).all()  # a classifier that never extends: the run's own
    assert (pts["label"] == pts["value"].map(dict(zip(v["value"], v["label"], strict=True)))).all()


def test_continuation_starts_from_the_previous_last_point(chained):
    """Value v+1 of a chain starts from value v's last section point (same cam phase)."""
    v, pts = chained.verdicts, chained.points
    for j in (0, 1):
        chain = v[v["ic"] == j].sort_values("value_index")
        assert list(chain["continued"]) == [False, True, True, True]
        for a, b in zip(chain["value_index"][:-1], chain["value_index"][1:], strict=True):
            last = pts[(pts["ic"] == j) & (pts["value_index"] == a)].iloc[-1]
            row = chain[chain["value_index"] == b].iloc[0]
            assert row["theta_f0"] == last["theta_f"] and row["omega_f0"] == last["omega_f"]


def test_initial_conditions_are_lifted_off_the_cam(chained):
    """ic 0 starts in contact (NaN); the others above the contact angle, within the box."""
    first = chained.verdicts[chained.verdicts["value_index"] == 0].sort_values("ic")
    assert np.isnan(first["theta_f0"].iloc[0])
    th_c = float(contact_angle(Params(l_lambda=0.004), 0.0))
    d, om = initial_offsets(2)[0]
    assert first["theta_f0"].iloc[1] == pytest.approx(th_c + d) and 0 <= d <= 0.3
    assert first["omega_f0"].iloc[1] == om and abs(om) <= 3.0
    offs = initial_offsets(6)
    assert len(set(offs)) == 5


def test_initial_offsets_are_scipys_halton_points_bit_for_bit():
    """The offsets computed without scipy.stats are the ones scipy's unscrambled Halton
    sequence gave (the diagrams made before stay the same bits)."""
    from scipy.stats import qmc

    from chaoscam.sweep._bifurcation import IC_BOX

    n = 300
    u = qmc.Halton(d=2, scramble=False).random(n)[1:]
    d_theta, omega = IC_BOX
    want = [(float(a * d_theta), float((2.0 * b - 1.0) * omega)) for a, b in u]
    assert initial_offsets(n) == want
    assert initial_offsets(1) == [] and initial_offsets(0) == []


def test_explicit_initial_states():
    """Given states are used as they are, for every value."""
    b = bifurcation("xi", [0.42], initial_conditions=[(0.1, 0.0), (0.2, 1.0)], **KW)
    assert list(b.verdicts["theta_f0"]) == [0.1, 0.2]
    assert list(b.verdicts["omega_f0"]) == [0.0, 1.0]


def test_interrupted_chain_resumes_identically(tmp_path, chained):
    """A continuation run stopped mid-chain resumes to the same diagram."""
    out = tmp_path / "b.parquet"
    cls = InterruptOnce(str(tmp_path / "m"), victim=realization_index(2, 1))
    args = ("l_lambda", "0.004:0.012:4")
    with pytest.raises(SweepInterrupted):
        bifurcation(
            *args,
            initial_conditions=2,
            continuation=True,
            out=out,
            flush_interval=0,
            **{**KW, "classify": cls},
        )
    res = bifurcation(
        *args,
        initial_conditions=2,
        continuation=True,
        out=out,
        resume=True,
        **{**KW, "classify": cls},
    )
    frames_equal(res.points, chained.points)
    frames_equal(res.verdicts, chained.verdicts)


def test_paper_figure_grids_validate():
    """Fig. 6's D in [1.36, 1.56] with fractal stiffness is valid for G = 1e-9 and 1e-10 m."""
    for g in (1e-9, 1e-10):
        validate_grid(Params(stiffness="fractal", G=g), Numerics(), [Axis.parse("D=1.36:1.56:41")])


@pytest.mark.parametrize("name, values", [("theta_f0", [0.1, 0.2]), ("omega_f0", [-1.0, 1.0])])
def test_a_diagram_over_the_initial_state_starts_each_run_there(name, values):
    """A diagram over theta_f0 or omega_f0 (a slice of the basins) starts each run at the
    swept value: its section is the one simulate gives from there, not the default start's
    (the base state used to overwrite it)."""
    from chaoscam import simulate

    kw = dict(duration=1.0, transient=0.5, workers=1)
    b = bifurcation(name, values, **kw)
    assert list(b.verdicts[name]) == values
    for value in values:
        want = simulate(Params(**{name: value}), duration=1.0, transient=0.5, series=False)
        got = b.points[b.points["value"] == value]
        assert np.array_equal(got["theta_f"].to_numpy(), want.section["theta_f"].to_numpy())


@pytest.mark.parametrize(
    "kw, what",
    [
        (dict(initial_conditions=2), "initial_conditions must be 1"),
        (dict(initial_conditions=[(0.1, 0.0)]), "initial_conditions must be 1"),
        (dict(continuation=True), "continuation"),
    ],
)
def test_a_diagram_over_the_initial_state_refuses_what_would_overwrite_it(kw, what):
    """Other initial conditions and continuation set the state themselves: refused by name."""
    from chaoscam.sweep import SweepError

    with pytest.raises(SweepError, match=what):
        bifurcation("theta_f0", [0.1, 0.2], duration=1.0, workers=1, **kw)


def test_a_sweep_that_finished_nothing_leaves_no_checkpoint(tmp_path):
    """A bad explicit initial condition is named (initial_conditions[0]) before any run, and
    a sweep whose runs all failed keeps no empty checkpoint, which would only block the
    corrected command as 'an interrupted run'."""
    from chaoscam.model import ParameterError

    out = tmp_path / "b.parquet"
    with pytest.raises(ParameterError, match=r"initial_conditions\[0\] = \(10.0, 0.0\)"):
        bifurcation("l_lambda", "0.008:0.012:2", initial_conditions=[(10.0, 0.0)], out=out,
                    duration=0.5, workers=1, progress=False)  # fmt: skip

    def broken(traj):
        raise RuntimeError("classifier broke")

    with pytest.raises(Exception, match="classifier broke"):
        bifurcation("l_lambda", "0.008:0.012:2", classify=broken, out=out, duration=0.5,
                    workers=1, progress=False)  # fmt: skip
    assert list(tmp_path.iterdir()) == []
    b = bifurcation("l_lambda", "0.008:0.012:2", initial_conditions=[(0.1, 0.0)], out=out,
                    duration=0.5, workers=1, progress=False)  # fmt: skip
    assert len(b.verdicts) == 2 and out.exists()
