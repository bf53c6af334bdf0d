"""Two-parameter continuation (chaoscam.continuation.curve): the bouncing ball's flip and
saddle-node curves in (Γ, e) against their closed forms, the model's period-doubling curve in
(omega, xi) through the one-parameter doubling, its points doublings of the one-parameter
branch at their xi, the multiplier product, the fold curve, the CLI."""

import math

import numpy as np
import pandas as pd
import pytest

import chaoscam
from chaoscam.cli import main
from chaoscam.continuation import CurveMap, MapFailed, Settings, continuation, curve, follow
from chaoscam.testsystems import ball_impact_map, ball_period_one_theory

XI = 0.1


def _ball_pair(d=1e-6):
    """The ball's impact map less the table's period in (Γ, e), DP by central differences."""
    shift = np.array([2.0 * math.pi, 0.0])

    def pmap(x, gamma, e):
        if x[1] - gamma * math.cos(x[0]) <= 0.0 or not 0.0 < e < 1.0:
            raise MapFailed("the ball would leave downwards")

        def p(y):
            return ball_impact_map(y, gamma, e) - shift

        cols = [(p(x + d * v) - p(x - d * v)) / (2.0 * d) for v in np.eye(2)]
        return p(x), np.column_stack(cols)

    return pmap


@pytest.mark.parametrize("kind, sigma", [("fold", 1.0), ("period_doubling", -1.0)])
def test_ball_curves_match_the_closed_form(kind, sigma):
    """The saddle-node and flip curves Γ(e) of the ball's period-one orbit, followed in
    (Γ, e) from e = 0.5 to 0.2, lie within 1e-6 relative of ball_period_one_theory(e)."""
    e0 = 0.5
    gamma = ball_period_one_theory(e0)[kind == "period_doubling"]
    w = (1.0, 1.0, 1.0, 1.0 / 0.3)
    st = Settings(weights=w, lo=0.2, hi=e0, h0=0.01, h_min=1e-8, h_max=0.05, tol=1e-9)
    u0 = (math.acos(ball_period_one_theory(e0)[0] / gamma), math.pi, gamma * 1.001, e0)
    points, events = follow(CurveMap(_ball_pair(), sigma, w), u0, st, direction=-1.0, kinds=())
    assert events[-1][0] == "end" and points[-1].u[3] <= 0.2 + 1e-9
    assert len(points) > 10
    for p in points:
        exact = ball_period_one_theory(p.u[3])[kind == "period_doubling"]
        assert abs(p.u[2] - exact) <= 1e-6 * exact


@pytest.fixture(scope="module")
def flip():
    """The period-doubling curve from the one-parameter doubling at xi = 0.1, to xi = 0.25."""
    p = chaoscam.Params(xi=XI, omega=31.9)
    branch = continuation(p, param="omega", to=32.2)
    row = branch.events[branch.events.kind == "period_doubling"].iloc[0]
    return row, curve(p, row, second="xi", to=0.25)


def test_flip_curve_starts_at_the_branch_doubling(flip):
    """The curve's first point is the branch's doubling (32.0393 rad/s at xi = 0.1), every
    point has a multiplier -1, and it reaches xi = 0.25."""
    row, c = flip
    first = c.points.iloc[0]
    assert first.value2 == XI and abs(first.value - row.value) < 1e-6
    assert abs(first.value - 32.0393) < 1e-4
    assert np.allclose(c.points.mu1_re, -1.0, atol=1e-6) and np.abs(c.points.test).max() < 1e-6
    assert c.points.value2.max() >= 0.25 and c.events.kind.iloc[-1] == "end"


def test_flip_curve_multiplier_product_is_xi_squared(flip):
    """One jump a period, no contact: det DP = xi^2, so the other multiplier is -xi^2."""
    _, c = flip
    assert (c.points.n_macro_impacts == 1).all()
    assert np.allclose(c.points.mu2_re, -(c.points.value2**2), atol=1e-6)


def test_flip_curve_points_are_branch_doublings(flip):
    """One-parameter continuation at a curve point's xi finds its doubling at that point's
    omega (within 1e-5 rad/s)."""
    _, c = flip
    pt = c.points.iloc[(c.points.value2 - 0.2).abs().argmin()]
    p = chaoscam.Params(xi=float(pt.value2), omega=float(pt.value) - 0.15)
    b = continuation(p, (pt.theta_f, pt.omega_f), param="omega", to=float(pt.value) + 0.15)
    found = b.events[b.events.kind == "period_doubling"]
    assert len(found) == 1 and abs(found.value.iloc[0] - pt.value) < 1e-5


def test_fold_curve_from_the_branch_fold():
    """The fold at 29.0894 rad/s (xi = 0.1) continues in xi with a multiplier +1."""
    p = chaoscam.Params(xi=XI, omega=30.0)
    b = continuation(p, param="omega", to=28.9)
    row = b.events[b.events.kind == "fold"].iloc[0]
    c = curve(p, row, second="xi", to=0.15)
    assert abs(c.points.value.iloc[0] - 29.0894) < 1e-4
    assert np.allclose(c.points.mu1_re, 1.0, atol=1e-5) and c.points.value2.max() >= 0.15


def test_cli_curve_writes_the_curves(tmp_path, capsys):
    """continue --curve xi --curve-to 0.2 writes FILE.curves.parquet (a multiplier -1 along
    the curve from the branch's doubling) and FILE.curves.events.parquet."""
    out = tmp_path / "b.parquet"
    args = ["continue", "--from", "31.9", "--to", "32.2", "--set", "xi=0.1", "--curve", "xi",
            "--curve-to", "0.2", "--out", str(out)]  # fmt: skip
    assert main(args) == 0
    assert "curves:" in capsys.readouterr().out
    pts = pd.read_parquet(tmp_path / "b.curves.parquet")
    assert set(pts.kind) == {"period_doubling"} and pts.value2.max() >= 0.2
    assert np.allclose(pts.mu1_re, -1.0, atol=1e-6)
    assert pd.read_parquet(tmp_path / "b.curves.events.parquet").kind.iloc[-1] == "end"
    assert main(args[:-4] + ["--out", str(out)]) == 2  # --curve without --curve-to


def test_grazing_curve_from_the_unstable_side_grazing():
    """The grazing that ends the fold's unstable side (29.9713 rad/s at xi = 0.1) continues
    in xi: it starts where the branch located it, its margin psi stays below 1e-8 m, and at a
    point of it an orbit exists 1e-3 rad/s to the flight side (psi > 0) and none 1e-3 past."""
    p = chaoscam.Params(xi=XI, omega=31.0)
    b = continuation(p, param="omega", to=28.0)
    row = b.events[b.events.kind == "grazing"].iloc[0]
    c = curve(p, row, second="xi", to=0.15, ds_max=0.1)
    pts = c.points
    assert set(pts.kind) == {"grazing"} and pts.value2.max() >= 0.15 - 1e-12
    assert abs(pts.value.iloc[0] - row.value) < 1e-5 and (pts.test.abs() < 1e-8).all()
    assert (np.diff(pts.value) < 0).all()  # the grazing moves to lower omega with more damping
    mid = pts.iloc[len(pts) // 2]
    q = p.replace(xi=mid.value2)
    inside = chaoscam.periodic_orbit(q.replace(omega=mid.value - 1e-3), (mid.theta_f,
                                     mid.omega_f), 1)  # fmt: skip
    past = chaoscam.periodic_orbit(q.replace(omega=mid.value + 1e-3), (mid.theta_f,
                                   mid.omega_f), 1)  # fmt: skip
    assert inside.converged and inside.period == 1 and not past.converged
