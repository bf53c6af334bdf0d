"""Pseudo-arclength continuation (chaoscam.continuation): analytic thresholds of the bouncing
ball through the generic core, the model's period doubling and fold at xi = 0.1, the
multipliers against Newton shooting, step-halving invariance, the branch switch, the CLI."""

import math

import numpy as np
import pandas as pd
import pytest

import chaoscam
from chaoscam.cli import main
from chaoscam.continuation import MapFailed, Settings, continuation, follow
from chaoscam.testsystems import ball_impact_map, ball_period_one_theory

XI = 0.1


def _ball(e, n=1, d=1e-6):
    """The ball's impact map less the table's n periods, DP by central differences."""
    shift = np.array([2.0 * math.pi * n, 0.0])

    def fun(x, gamma):
        if x[1] - gamma * math.cos(x[0]) <= 0.0:
            raise MapFailed("the ball would leave downwards")

        def p(y):
            return ball_impact_map(y, gamma, e) - shift

        cols = [(p(x + d * v) - p(x - d * v)) / (2.0 * d) for v in np.eye(2)]
        return p(x), np.column_stack(cols)

    return fun


def _diagonal(mu):
    """The map x -> diag(mu(λ), 0.1) x: its fixed point 0 at every λ, multipliers mu(λ), 0.1."""

    def fun(x, lam):
        dp = np.diag([mu(lam), 0.1])
        return dp @ x, dp

    return fun


@pytest.mark.parametrize(
    "mu, kinds",
    [(lambda lam: -0.5 - lam, [("period_doubling", 0.5, "")]),  # smooth: located at 0.5
     (lambda lam: 20.0 if lam < 0.5 else -15.0, []),  # jumps across -1, unstable both sides
     (lambda lam: -0.5 if lam < 0.5 else -1.5, [("period_doubling", 0.5, "not located")])],
)  # fmt: skip
def test_a_test_function_that_jumps_is_no_located_event(mu, kinds):
    """A multiplier through -1 is located; one that jumps across it without a change of
    stability is no event; one that jumps and changes stability is an event not located."""
    st = Settings(weights=(1.0, 1.0, 1.0), lo=0.0, hi=1.0, h0=0.05, h_min=1e-6, h_max=0.05,
                  event_tol=1e-8)  # fmt: skip
    _, events = follow(_diagonal(mu), (0.0, 0.0, 0.11), st)
    got = [(k, p.u[-1], d) for k, p, d in events if k != "end"]
    assert len(got) == len(kinds)
    for (k, lam, detail), (kind, where, note) in zip(got, kinds, strict=True):
        assert k == kind and abs(lam - where) < 1e-6 and note in detail


@pytest.mark.parametrize("e", [0.5, 0.3])
def test_ball_fold_and_period_doubling_match_the_closed_form(e):
    """The core follows the ball's period-one orbit down through its saddle-node and up
    through its flip; both located within 1e-6 relative of the closed-form thresholds."""
    fold, flip = ball_period_one_theory(e)
    g0 = 0.5 * (fold + flip)
    u0 = (math.acos(fold / g0), math.pi, g0)
    st = Settings(weights=(1.0, 1.0, 1.0), lo=0.9 * fold, hi=1.05 * flip, h0=0.01,
                  h_min=1e-8, h_max=0.05, tol=1e-11, event_tol=1e-9)  # fmt: skip
    found = {}
    for direction in (1.0, -1.0):
        _, events = follow(_ball(e), u0, st, direction=direction)
        found.update({kind: p for kind, p, _ in events if kind != "end"})
    assert abs(found["fold"].u[2] - fold) <= 1e-6 * fold
    assert abs(found["period_doubling"].u[2] - flip) <= 1e-6 * flip
    assert np.isclose(found["period_doubling"].multipliers[0], -1.0, atol=1e-6)


@pytest.fixture(scope="module")
def up():
    """The period-1 branch at xi = 0.1 from omega = 30 to 33, switched at its doubling."""
    return continuation(chaoscam.Params(xi=XI, omega=30.0), param="omega", to=33.0, switch=True)


def test_period_doubling_between_32_and_32_1(up):
    """One period doubling on the period-1 branch, in (32.0, 32.1) rad/s, multiplier -1."""
    pd_ = up.events[(up.events.kind == "period_doubling") & (up.events.branch == 0)]
    assert len(pd_) == 1
    assert 32.0 < pd_.value.iloc[0] < 32.1
    assert abs(pd_.mu1_re.iloc[0] + 1.0) < 1e-4
    main = up.points[up.points.branch == 0]
    assert (main.stable == (main.value < pd_.value.iloc[0])).all()
    assert (main.n_macro_impacts == 1).all() and not main.sticks.any()


def test_doublings_lie_where_brute_force_turns_period_n_into_2n(up):
    """Each doubling of the period-1 and period-2 orbits lies between the last omega where
    runs from the model's initial state are P(n) and the first where they are P(2n)."""
    two = continuation(chaoscam.Params(xi=XI, omega=32.5), param="omega", to=33.5, period=2)
    found = [(1, up.events[(up.events.kind == "period_doubling") & (up.events.branch == 0)]),
             (2, two.events[two.events.kind == "period_doubling"])]  # fmt: skip
    brute = chaoscam.bifurcation(
        "omega", [31.75, 32.25, 33.0, 33.25], base=chaoscam.Params(xi=XI), progress=False
    ).verdicts
    periods = dict(zip(brute.value, brute.period, strict=True))
    for n, ev in found:
        assert len(ev) == 1
        below = max(v for v, k in periods.items() if k == n and v < ev.value.iloc[0])
        above = min(v for v, k in periods.items() if k == 2 * n and v > ev.value.iloc[0])
        assert not any(below < v < above for v in periods)


def test_doubled_branch_is_stable_period_two(up):
    """The switched branch is period 2, born on the side where period 1 is unstable, and
    attracting past its first points (a supercritical flip)."""
    two = up.points[up.points.branch == 1]
    value = up.events[up.events.kind == "period_doubling"].value.iloc[0]
    assert (two.period == 2).all() and (two.value >= value - 1e-6).all()
    assert two[two.value > value + 0.01].stable.all()
    assert (two.n_macro_impacts == 2).all()


def test_multipliers_agree_with_newton_shooting(up):
    """A point's multipliers are those periodic_orbit finds there from its section point."""
    row = up.points[up.points.branch == 0].iloc[10]
    p = chaoscam.Params(xi=XI, omega=float(row.value))
    orbit = chaoscam.periodic_orbit(p, (row.theta_f, row.omega_f), 1)
    mu = sorted(orbit.multipliers, key=lambda m: -abs(m))
    assert np.allclose([row.mu1_re + 1j * row.mu1_im, row.mu2_re + 1j * row.mu2_im], mu,
                       atol=1e-5)  # fmt: skip


def test_no_neimark_sacker_under_hunt_crossley(up):
    """|mu1 mu2| <= xi^2 on every orbit with a jump: no complex pair reaches the unit circle."""
    mu1 = up.points.mu1_re + 1j * up.points.mu1_im
    mu2 = up.points.mu2_re + 1j * up.points.mu2_im
    assert (np.abs(mu1 * mu2) <= XI**2**up.points.period + 1e-6).all()
    assert "neimark_sacker" not in set(up.events.kind)


@pytest.fixture(scope="module")
def down():
    return continuation(chaoscam.Params(xi=XI, omega=31.0), param="omega", to=28.0)


def test_fold_between_29_and_29_1_followed_onto_the_unstable_side(down):
    """Down from 31 rad/s the branch turns at a fold in (29.0, 29.1), where a multiplier is
    +1, and goes on with omega increasing, unstable (|mu1| > 1), past the impact that
    crosses the section (the section moves) for more than 0.5 rad/s."""
    fold = down.events[down.events.kind == "fold"]
    assert len(fold) == 1 and 29.0 < fold.value.iloc[0] < 29.1
    assert abs(fold.mu1_re.iloc[0] - 1.0) < 1e-4
    after = down.points[down.points.s > fold.s.iloc[0]]
    assert len(after) >= 10 and not after.stable.any() and (after.value > fold.value.iloc[0]).all()
    assert "section" in set(down.events.kind) and (after.section_phase > 0).any()
    assert after.value.max() > fold.value.iloc[0] + 0.5


def test_moved_section_keeps_the_orbit_and_its_multipliers(down):
    """On the moved section the branch is the same orbit: Newton shooting on the model's own
    section from the table's phase-0 state converges there with the same multipliers."""
    moved = down.points[(down.points.section_phase > 0)].iloc[[5, -5]]
    for row in moved.itertuples():
        p = chaoscam.Params(xi=XI, omega=row.value)
        orbit = chaoscam.periodic_orbit(p, (row.theta_f, row.omega_f), 1)
        assert orbit.converged and np.allclose(orbit.points[0], (row.theta_f, row.omega_f),
                                               atol=1e-6)  # fmt: skip
        assert abs(np.max(np.abs(orbit.multipliers)) - row.abs_mu) < 1e-4 * row.abs_mu


def test_unstable_side_ends_at_a_located_grazing(down):
    """The unstable side ends where a flight touches the cam: ψ falls linearly to 0, a run
    from the orbit at the grazing has a flight minimum of the gap below 1e-8 m, and just past
    it (1e-4 rad/s) Newton finds no period-1 orbit."""
    ev = down.events
    graze = ev[ev.kind == "grazing"]
    assert len(graze) == 1 and ev.kind.iloc[-1] == "end"
    lam = graze.value.iloc[0]
    side = down.points[down.points.section_phase > 0]
    psi = side.flight_margin.to_numpy()[-6:]
    assert (np.diff(psi) < 0).all() and psi[-1] < 1e-5
    p = chaoscam.Params(xi=XI, omega=lam)
    run = chaoscam.simulate(p.replace(theta_f0=graze.theta_f.iloc[0],
                                      omega_f0=graze.omega_f.iloc[0]),
                            duration=p.cam_period, output_dt=2e-6)  # fmt: skip
    g = run.series.gap.to_numpy()
    inner = (g[1:-1] < g[:-2]) & (g[1:-1] < g[2:]) & (g[1:-1] > 0)
    assert 0 < g[1:-1][inner].min() < 1e-8
    past = chaoscam.periodic_orbit(p.replace(omega=lam + 1e-4), (graze.theta_f.iloc[0],
                                   graze.omega_f.iloc[0]), 1)  # fmt: skip
    assert not past.converged


def test_event_location_unchanged_when_the_step_is_halved():
    """The period doubling's location moves by less than 1e-5 rad/s with half the
    continuation steps, and by less than 1e-6 rad/s with half the RK4 step dt."""
    p = chaoscam.Params(xi=XI, omega=31.5)
    values = []
    for f, num in ((1.0, None), (0.5, None), (1.0, chaoscam.Numerics(dt=1e-6))):
        b = continuation(p, param="omega", to=32.5, ds=0.005 * f, ds_max=0.02 * f, numerics=num)
        values.append(b.events[b.events.kind == "period_doubling"].value.iloc[0])
    assert abs(values[0] - values[1]) < 1e-5 and abs(values[0] - values[2]) < 1e-6


def test_corrector_does_not_jump_to_the_follower_off_the_cam():
    """At xi = 0.3 from omega = 25 a corrector of 7 iterations lands on the follower hanging
    off the cam (theta_f = pi/2, no impact), whose tangent points the same way: the step is
    refused, and the impacting branch goes on to its grazing at 25.53 rad/s."""
    b = continuation(chaoscam.Params(xi=0.3, omega=25.0), param="omega", to=35.0)
    assert (b.points.n_macro_impacts == 2).all() and (b.points.theta_f.abs() < 0.1).all()
    ev = b.events.set_index("kind").value
    assert "impact_change" not in ev and 25.5 < ev["grazing"] < 25.6


def test_fold_and_grazing_unchanged_when_the_step_and_dt_are_halved(down):
    """The fold and the grazing move by less than event_tol = 1e-6 rad/s with half the
    continuation steps and with half the RK4 step dt (the fold at tol = 1e-9: its λ is as good
    as the corrector's residual over |∂P/∂λ|, 1e-6 rad/s at the default tol = 1e-7)."""
    p = chaoscam.Params(xi=XI, omega=31.0)
    runs = {
        "base": continuation(p, param="omega", to=28.0, tol=1e-9),
        "ds/2": continuation(p, param="omega", to=28.0, tol=1e-9, ds=0.0025, ds_max=0.01),
        "dt/2": continuation(p, param="omega", to=28.0, numerics=chaoscam.Numerics(dt=1e-6)),
    }
    at = {k: b.events.groupby("kind").value.first() for k, b in runs.items()}
    at["default"] = down.events.groupby("kind").value.first()
    for kind in ("fold", "grazing"):
        assert abs(at["ds/2"][kind] - at["base"][kind]) < 1e-6
        assert abs(at["dt/2"][kind] - at["default"][kind]) < 1e-6


def test_cli_writes_points_and_events_and_refuses_overwrite(tmp_path, capsys):
    """continue writes FILE.parquet and FILE.events.parquet, reports the period doubling,
    and refuses to overwrite without --force (exit 2)."""
    out = tmp_path / "branch.parquet"
    args = ["continue", "--param", "omega", "--from", "31.8", "--to", "32.3", "--set",
            "xi=0.1", "--period", "1", "--out", str(out)]  # fmt: skip
    assert main(args) == 0
    assert "period_doubling at omega = 32.0" in capsys.readouterr().out
    events = pd.read_parquet(tmp_path / "branch.events.parquet")
    assert set(events.kind) == {"period_doubling", "end"}
    assert len(pd.read_parquet(out)) > 5
    assert main(args) == 2
    assert "exists" in capsys.readouterr().err
    assert main([*args, "--force"]) == 0


def test_cli_start_without_orbit_is_exit_2(tmp_path, capsys):
    """A start from which Newton finds no orbit is a one-line error, exit 2, no file."""
    out = tmp_path / "b.parquet"
    code = main(["continue", "--from", "31", "--to", "32", "--set", "xi=0.1", "--x0", "0.5",
                 "30", "--out", str(out)])  # fmt: skip
    assert code == 2 and "no period-1 orbit" in capsys.readouterr().err
    assert not out.exists()


def test_interrupted_branch_resumes_from_its_checkpoint(tmp_path, monkeypatch):
    """A run interrupted on its doubled branch resumes from its checkpoint: branch 0 as it
    finished (no new start), branch 1 followed on from its 6th point, both where an
    uninterrupted run puts them, and the checkpoint is removed once done; other settings
    are refused."""
    from chaoscam.continuation import _branch

    p, ckpt = chaoscam.Params(xi=XI, omega=31.9), tmp_path / "b.parquet.ckpt"
    whole = continuation(p, param="omega", to=32.2, switch=True)
    monkeypatch.setattr(_branch, "CHECKPOINT_S", 0.0)
    save = _branch._Checkpoint.save

    def stop(self, b, n, points, events, now=False):
        save(self, b, n, points, events, now)
        if b == 1 and len(points) == 6:
            raise KeyboardInterrupt

    monkeypatch.setattr(_branch._Checkpoint, "save", stop)
    with pytest.raises(KeyboardInterrupt):
        continuation(p, param="omega", to=32.2, switch=True, checkpoint=ckpt)
    monkeypatch.setattr(_branch._Checkpoint, "save", save)
    with pytest.raises(ValueError, match="other settings"):
        continuation(p, param="omega", to=32.25, switch=True, checkpoint=ckpt)
    resumed = []
    follow = _branch.follow
    monkeypatch.setattr(_branch, "find_start", lambda *a, **k: pytest.fail("a new start"))
    monkeypatch.setattr(_branch, "follow", lambda *a, **k: resumed.append(k["resume"])
                        or follow(*a, **k))  # fmt: skip
    b = continuation(p, param="omega", to=32.2, switch=True, checkpoint=ckpt)
    assert b.settings["resumed"] and not ckpt.exists()
    assert [len(r[0]) for r in resumed] == [6]
    for k in (0, 1):
        got, want = (x.points[x.points.branch == k] for x in (b, whole))
        assert len(got) == len(want) and np.allclose(got.value, want.value, atol=1e-6, rtol=0)
    pd_ = [x.events[x.events.kind == "period_doubling"].value.iloc[0] for x in (b, whole)]
    assert abs(pd_[0] - pd_[1]) < 1e-6


def test_cli_refuses_a_checkpoint_without_resume(tmp_path, capsys):
    """An interrupted branch's checkpoint beside the output: exit 2 saying --resume, unless
    --force (which starts over)."""
    out = tmp_path / "b.parquet"
    (tmp_path / "b.parquet.ckpt").write_text("{}")
    args = ["continue", "--from", "31.9", "--to", "32.0", "--set", "xi=0.1", "--out", str(out)]
    assert main(args) == 2 and "--resume" in capsys.readouterr().err
    assert main([*args, "--force"]) == 0 and not (tmp_path / "b.parquet.ckpt").exists()
