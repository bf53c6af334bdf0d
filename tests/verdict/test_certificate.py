"""The periodic-orbit certificate (chaoscam/verdict/_certificate.py) on cells of the (omega, xi)
map whose truth was settled by 600 s runs, step halving and shooting (docs/findings.md, "The
(omega, xi) map checked against the model"): each case is one the classifier got wrong before
the certificate's rule for it."""

import dataclasses

import numpy as np

from chaoscam import Numerics, Params, classify, simulate
from chaoscam.analysis import section_period
from chaoscam.verdict import KickTest, PeriodicOrbit, _certificate, iterate_map, stroboscopic_map
from chaoscam.verdict._certificate import APPROACH, MODEL_ATOL, _Run, _sharp_doubling, on_orbit

DT = Numerics().dt


def _map_cell(omega, xi, **kw):
    """A regime-map cell's run: 20 s, 10 s transient, section and tangent only."""
    traj = simulate(
        Params(omega=omega, xi=xi),
        duration=20.0,
        transient=10.0,
        series=False,
        tangent=True,
        resumable=True,
    )
    (v,) = classify(traj, **kw)
    return v


def _orbit(points, period_s=0.1):
    pts = np.asarray(points, dtype=float)
    return PeriodicOrbit(
        period=len(pts),
        points=pts,
        multipliers=np.array([0.5, 0.1]),
        residual=0.0,
        converged=True,
        iterations=1,
        wall_time=0.0,
        settings={"cam_period": period_s},
    )


def _run(points, extra=None):
    """The certificate's view of a run of the default model at the default step."""
    return _Run(Params(), Numerics(), points, {} if extra is None else extra)


def test_a_run_that_keeps_its_distance_is_not_on_the_orbit():
    """Points circling an orbit at a fixed 1e-4 rad are not on it; points within the band
    tolerance are; points whose distance halves over the run approach it."""
    orbit = _orbit([[0.0, 0.0], [1.0, 0.0]])
    k = np.arange(64)
    base = np.column_stack([k % 2, np.zeros(64)]).astype(float)
    circling = base + np.column_stack([1e-4 * (-1.0) ** (k // 2), np.zeros(64)])
    assert not on_orbit(orbit, circling)[0]
    assert on_orbit(orbit, base + 0.3 * MODEL_ATOL)[0]
    shrinking = base + np.column_stack([1e-3 * 0.97**k, np.zeros(64)])  # to 1.4e-4
    ok, dist, words = on_orbit(orbit, shrinking)
    assert ok and "approaches" in words and dist < APPROACH * 1e-3
    assert not on_orbit(orbit, shrinking[:12])[0]  # too short to see it approach


def test_bands_can_be_asked_for_without_distinct_centres():
    """section_period(distinct=False) accepts a lag two of whose narrow bands overlap (0, 1,
    0.5, 1.0002, ... with noise 1e-4: the two bands near 1 are one band split in two),
    which the default refuses; two bands 0.02 apart, 30 noise widths, are distinct (the
    tolerance, 0.05 of the extent, is not the measure of distinct): period 4."""
    rng = np.random.default_rng(0)
    noise = 1e-4 * rng.standard_normal(400)
    x = np.tile([0.0, 1.0, 0.5, 1.0002], 100) + noise
    assert section_period(x, rtol=0.05, allow_transient=False).period is None
    assert section_period(x, rtol=0.05, allow_transient=False, distinct=False).period == 4
    apart = np.tile([0.0, 1.0, 0.5, 1.02], 100) + noise
    assert section_period(apart, rtol=0.05, allow_transient=False).period == 4


def test_a_sticking_orbit_whose_newton_stalls_on_the_grid_is_certified_refined():
    """(omega, xi) = (20, 0.6): a sticking period 1 whose grid exponent is positive (the
    chattering artefact) and whose Newton iteration stalls at dt (residual ~1e-7 rad): shot
    again at dt/2 and dt/4, where it is attracting: periodic 1 (it was called chaotic)."""
    v = _map_cell(20.0, 0.6, extend_to=None)
    assert (v.label, v.period) == ("periodic", 1)
    orbit = next(e for e in v.evidence if e.name == "periodic_orbit")
    assert "certified at every refined step" in orbit.detail
    assert all(max(r["multipliers_abs"]) < 1 for r in v.settings["periodic_orbit_refined"])


def test_a_flip_unstable_period_sends_the_shooting_to_twice_the_period():
    """(37.5, 0.15): the section reads 8 bands (the 16 of the attractor lie within its
    tolerance), the period-8 orbit is flip-unstable; the period-16 orbit is attracting at the
    refined steps: periodic 16 (it was undetermined)."""
    v = _map_cell(37.5, 0.15)
    assert (v.label, v.period) == ("periodic", 16)
    section = next(e for e in v.evidence if e.name == "section_period")
    assert section.value == 8
    doubled = v.settings["periodic_orbit_doubled"]
    assert doubled["periodic_orbit"]["period"] == 16
    assert all(max(r["multipliers_abs"]) < 1 for r in doubled["periodic_orbit_refined"])


def test_a_section_sharper_at_twice_the_period_is_shot_for_there():
    """(38, 0.34): 6 bands of 4.7e-6 rad, 12 of 2.7e-7 rad over 10 s; Newton on P^6 stalls
    2e-6 rad off and the run keeps 1.2e-5 rad from that orbit (no flip to read), while the
    period-12 orbit is attracting at dt/2 and dt/4 and the run lies on it: periodic 12, as
    600 s runs at dt show (it was undetermined, and chaotic once extended)."""
    v = _map_cell(38.0, 0.34, extend_to=None)
    assert (v.label, v.period) == ("periodic", 12)
    assert next(e for e in v.evidence if e.name == "section_period").value == 6
    orbit = next(e for e in v.evidence if e.name == "periodic_orbit")
    assert "sharper at 2n, period 12 shot for: certified" in orbit.detail
    doubled = v.settings["periodic_orbit_doubled"]
    assert all(max(r["multipliers_abs"]) < 1 for r in doubled["periodic_orbit_refined"])


def test_only_a_section_periodic_to_the_band_tolerance_at_2n_is_sharp():
    """Period 2 with halves 1e-6 rad apart: sharp; the same with 1e-4 rad chaotic jitter
    on top, or a period 1 whose jitter is all there is: not."""
    p = Params()
    rng = np.random.default_rng(1)
    k = np.arange(64)
    two = np.column_stack([0.3 + 1e-6 * (k % 2), -2.0 + 0 * k]) + 1e-9 * rng.random((64, 2))
    assert _sharp_doubling(p, two, 1)
    assert not _sharp_doubling(p, two + 1e-4 * rng.random((64, 2)), 1)
    one = np.column_stack([0.3 + 0 * k, -2.0 + 0 * k]) + 1e-9 * rng.random((64, 2))
    assert not _sharp_doubling(p, one, 1)
    assert not _sharp_doubling(p, two[:3], 1)  # too short to tell


def test_an_attracting_orbit_the_run_does_not_approach_certifies_nothing():
    """(45, 0.2): shooting finds period-11 orbits near the run, which stays 2.5e-5 rad from
    them; the period 22 it settles on at dt is not attracting at dt/2 (600 s runs there keep
    11 bands of 3e-5 rad, lambda_1 > 0): never periodic 11 (it was certified period 11)."""
    v = _map_cell(45.0, 0.2)
    assert v.label != "periodic"
    orbit = next(e for e in v.evidence if e.name == "periodic_orbit")
    assert orbit.vote is None and "period 22 shot for" in orbit.detail


def test_chaos_in_bands_the_zero_one_test_cannot_see_is_banded_chaos():
    """(42.5, 0.15): lambda_1 > 0 beyond its interval in narrow bands that the period test
    reads as periodic and no attracting orbit explains: n-band chaos (it was undetermined
    after 120 s). How many bands depends on the window: over the 40 s the run is extended
    to, 8 bands within the period test's tolerance beside an unstable period-8 orbit
    (|mu| = 5.7); over 120 s at dt and at dt/2, 4 bands of ~2 % of the extent (measured with
    the Newton crossing search; before it, the 40 s window showed the 4)."""
    v = _map_cell(42.5, 0.15)
    assert v.label == "chaotic"
    band = next(e for e in v.evidence if e.name == "banded_chaos")
    assert band.vote == "chaotic" and band.value in (4, 8)


def _dt(kw):
    """The step a stand-in for the shooting was called at."""
    return kw["numerics"].dt


def test_an_orbit_that_fails_at_the_last_refined_step_is_not_certified(monkeypatch):
    """Attracting at dt/2, unstable at dt/4: "mixed", never "certified" (the loop stopped at
    the failing last step and counted two steps as two certificates)."""
    run = np.column_stack([np.zeros(40), np.zeros(40)])

    def shoot(p, x, n, **kw):
        mu = [0.5, 0.1] if _dt(kw) == DT / 2 else [1.02, 0.1]
        return dataclasses.replace(_orbit([[0.0, 0.0]]), multipliers=np.array(mu))

    monkeypatch.setattr(_certificate, "periodic_orbit", shoot)
    monkeypatch.setattr(_certificate, "iterate_map", lambda p, x, n, num: np.zeros((n + 1, 2)))
    status, best, orbits, summary = _certificate._refined(_run(run), 1, run[-1])
    assert status == "mixed" and best is None and len(orbits) == 2, summary


def test_a_refined_orbit_the_motion_does_not_settle_on_certifies_nothing():
    """(45, 0.4): a period-18 orbit is attracting at dt/2 and dt/4 and lies within the
    section's tolerance of the run, but the motion there does not settle on it (600 s runs
    at dt and dt/2 keep 9 chaotic bands): chaotic, not periodic 18."""
    v = _map_cell(45.0, 0.4)
    assert v.label == "chaotic"


def test_a_refined_newton_that_stalls_at_the_band_tolerance_still_certifies(monkeypatch):
    """Newton stalls within the band tolerance at dt/4 (residual 4e-7 rad, not converged)
    on an attracting orbit the motion settles on: that step certifies it, and with dt/2
    certified the orbit is ("certified"). A stall beyond the tolerance does not count.
    (The model's case, (32.5, 0.5), stalled at dt/4 until the Newton crossing search; there
    Newton now stalls at dt/2 and converges unstable at dt/4 (|mu|max 2.8): "mixed", so
    undetermined; 600 s runs: 6 bands, lambda_1 > 0 on the grid's tangent at dt, < 0 at
    dt/2.)"""
    run = np.zeros((40, 2))

    def shooter(residual):
        def shoot(p, x, n, **kw):
            o = _orbit([[0.0, 0.0]])
            if _dt(kw) == DT / 4:  # stalls at the finest step
                o = dataclasses.replace(o, converged=False, residual=residual)
            return o

        return shoot

    monkeypatch.setattr(_certificate, "iterate_map", lambda p, x, n, num: np.zeros((n + 1, 2)))
    monkeypatch.setattr(_certificate, "periodic_orbit", shooter(4e-7))
    status, best, orbits, summary = _certificate._refined(_run(run), 1, run[-1])
    assert status == "certified" and best is orbits[-1] and len(orbits) == 2, summary
    assert "(residual 4e-07)" in summary
    monkeypatch.setattr(_certificate, "periodic_orbit", shooter(10 * MODEL_ATOL))
    status, best, _, summary = _certificate._refined(_run(run), 1, run[-1])
    assert status == "mixed" and best is None, summary


def test_iterate_map_ends_where_the_map_does():
    """iterate_map's last point is P^n(x), and its first is x."""
    p = Params(xi=0.2)
    x = np.array([0.05, -0.3])
    seq = iterate_map(p, x, 3)
    assert seq.shape == (4, 2) and np.array_equal(seq[0], x)
    assert np.array_equal(seq[-1], stroboscopic_map(p, x, 3)[0])


def test_a_period_12_with_two_close_points_is_periodic():
    """Y_f = 3.16e5 Pa (K_n ~ 2.2e3 N/m), the stiffness sweep's run: an exact, attracting
    period 12 (bands of 1e-9 rad; 300 s runs at dt and dt/2 and a 1e-8 kick agree) two of
    whose points lie 9e-6 rad and 2.2e-4 rad/s·T apart, within the band tolerance: it was
    "undetermined" ("no period found") after 120 s, the tolerance taken as the measure of
    distinct bands."""
    from chaoscam.sweep import bifurcation

    b = bifurcation("Y_f", [3.16e5], duration=20.0, transient=10.0, workers=1)
    row = b.verdicts.iloc[0]
    assert (row["label"], row["period"]) == ("periodic", 12), row["reasons"]


def test_a_period_30_with_two_points_closer_than_the_floor_is_periodic():
    """xi = 0.30 after its chaotic start-up (it settles at t ~ 53 s at dt, 165 s at dt/2,
    310 s at dt/4, on the same orbit): an attracting period 30 (bands of 1e-8 rad) two of
    whose points lie 2.8e-6 rad and 1.6e-5 rad/s apart, closer than the model's absolute
    floor (1e-5 rad, 1e-5/T rad/s). With the floor in the distinct-band test every lag was
    refused and the run was "undetermined", its Birkhoff average voting a torus on the
    rotation number 3/5 (found by an independent referee)."""
    run = simulate(Params(xi=0.30), duration=300.0, transient=280.0, series=False, tangent=True)
    (v,) = classify(run)
    assert (v.label, v.period) == ("periodic", 30), v.reasons
    orbit = next(e for e in v.evidence if e.name == "periodic_orbit")
    assert orbit.vote == "periodic" and orbit.detail.startswith("certified")


def test_an_orbit_of_the_grid_alone_is_step_dependent_and_not_extended():
    """xi = 0.525: Newton certifies an attracting period 8 on the default grid (|mu|max
    0.05, the run on it), but at dt/2 it is unstable (|mu|max 3.7; 300 s runs at dt/2 and
    dt/4 keep 8 bands whose twins separate at +0.17 1/s): undetermined, with the reason and
    the step to use, and not extended (a longer run at this step says the same). It was
    "periodic 8"."""
    traj = simulate(Params(xi=0.525), duration=130.0, transient=10.0, tangent=True)
    (v,) = classify(traj)
    assert v.label == "undetermined"
    step = {e.name: e for e in v.evidence}["step_dependent"]
    assert (
        step.value == 8
        and "not at dt/2" in step.detail
        and "rerun with dt = 5e-07 s" in step.detail
    )
    assert "extended" not in v.settings
    # Finite kicks agree: they return at dt (the grid's attraction) and not at dt/2.
    kicks = v.settings["kick_test"]
    assert [r["returns"] for r in kicks] == [True, False], kicks
    assert "do not return" in step.detail


def test_kicks_certify_a_period_2_the_refined_step_leaves_open():
    """(28.75, 0.25): Newton certifies a period-2 orbit at dt (|mu|max 0.878), attracting at
    dt/2 too, but the run, still approaching it (5.1e-4 -> 4.3e-5 rad), does not settle on
    it within the refined step's periods: the shooting leaves it open. Kicks of 1e-7 and
    1e-6 rad return at dt and dt/2 (to 0.0063 of themselves): periodic 2, certified by
    kicks; 300 s runs at dt and dt/2 are periodic 2 over their last 150 s (lambda_1 = -0.062
    per iterate, certified). (The case before, Fig. 4's l_lambda = 16.75 mm at dt = 3.8e-7
    s, read |mu|max 2.0 and 2.3 at dt and dt/2 with Illinois-located events, and reads 0.24
    and 0.19 with the Newton crossing search: periodic 8, certified by Newton, no kicks.)"""
    v = _map_cell(28.75, 0.25)
    assert (v.label, v.period) == ("periodic", 2), v.reasons
    orbit = {e.name: e for e in v.evidence}["periodic_orbit"]
    assert orbit.vote == "periodic" and "not settled on" in orbit.detail
    assert "kicks of 1e-07, 1e-06 rad return" in orbit.detail
    assert all(r["returns"] for r in v.settings["kick_test"])


def test_banded_chaos_names_the_votes_it_outweighs():
    """Fig. 8's run (mu = 8 mm, sigma = 4 mm, seed 7, the paper's 20 s): the section period
    votes 8 on 8 narrow bands, the common-noise twins separate; the evidence of the chaotic
    verdict says why the periodic votes lose (a reader saw them stand next to it unexplained)."""
    traj = simulate(
        Params(l_lambda=0.008, l_lambda_sigma=0.004), duration=20.0, transient=10.0, seed=7
    )
    (v,) = classify(traj)
    votes = {e.name: e.vote for e in v.evidence}
    assert v.label == "chaotic" and votes["twins"] == "chaotic"
    band = next(e for e in v.evidence if e.name == "banded_chaos")
    named = [n for n, vote in votes.items() if vote in ("periodic", "quasiperiodic")]
    assert named and f"outweighs the {', '.join(named)} vote(s)" in band.detail


def _kicks(returns_at):
    """A stand-in for kick_test: returns (or not) at the steps in ``returns_at`` (dt
    divisors), the unkicked motion periodic."""

    def kick(p, x, n, **kw):
        f = round(DT / _dt(kw))
        growth = np.full((2, 4, 41), 0.01 if f in returns_at else 0.5)
        pts = np.tile([[0.1, 2.0]], (40 * n + 1, 1))
        return KickTest(kw["kicks"], n, 40, 30.0, growth, f in returns_at, pts)

    return kick


def _unstable_everywhere(monkeypatch, returns_at):
    def shoot(p, x, n, **kw):
        return dataclasses.replace(_orbit([[0.1, 2.0]]), multipliers=np.array([2.0, 0.1]))

    monkeypatch.setattr(_certificate, "periodic_orbit", shoot)
    monkeypatch.setattr(
        _certificate, "iterate_map", lambda p, x, n, num: np.tile([0.1, 2.0], (n + 1, 1))
    )
    monkeypatch.setattr(_certificate, "kick_test", _kicks(returns_at))
    rng = np.random.default_rng(1)
    return np.array([0.1, 2.0]) + 1e-9 * rng.standard_normal((40, 2))


def _certify(run, extra):
    return _certificate.certify(Params(), Numerics(), run, 1, extra)


def test_kicks_that_return_at_both_steps_certify_an_orbit_the_multipliers_call_unstable(
    monkeypatch,
):
    """Newton's orbit is unstable on the grid and at every refined step, the run lies on it,
    and finite kicks return at dt and dt/2: certified, by kicks (the map's derivative is not
    the judge below its event jitter), with a record per step."""
    run = _unstable_everywhere(monkeypatch, returns_at=(1, 2))
    extra: dict = {}
    cert = _certify(run, extra)
    assert cert.certified and cert.kicked and cert.refined, cert.detail
    assert [r["dt"] for r in extra["kick_test"]] == [DT, DT / 2]
    assert "kicks of 1e-07, 1e-06 rad return" in cert.detail


def test_kicks_that_return_on_the_grid_alone_certify_nothing(monkeypatch):
    """Kicks return at dt but not at dt/2: the attraction is the grid's (as at xi = 0.525),
    and the orbit stays unstable."""
    run = _unstable_everywhere(monkeypatch, returns_at=(1,))
    extra: dict = {}
    cert = _certify(run, extra)
    assert cert.status == "unstable" and not cert.kicked
    assert [r["returns"] for r in extra["kick_test"]] == [True, False]
    assert "do not return" in cert.detail


def test_no_kicks_for_a_run_that_keeps_away_from_the_orbit(monkeypatch):
    """Chaotic bands around an unstable orbit (the run 1e-4 rad from it) cost no kicks."""
    run = _unstable_everywhere(monkeypatch, returns_at=(1, 2)) + np.array([1e-4, 0.0])
    extra: dict = {}
    cert = _certify(run, extra)
    assert not cert.certified and "kick_test" not in extra


def test_kicks_decide_an_orbit_certified_on_the_grid_alone(monkeypatch):
    """Newton certifies the orbit at dt but not at dt/2 ("step-dependent"): kicks that return
    at both steps certify it; kicks that return at dt only leave it step-dependent."""

    def shoot(p, x, n, **kw):
        mu = [0.5, 0.1] if _dt(kw) == DT else [2.0, 0.1]
        return dataclasses.replace(_orbit([[0.1, 2.0]]), multipliers=np.array(mu))

    run = _unstable_everywhere(monkeypatch, returns_at=(1, 2))
    monkeypatch.setattr(_certificate, "periodic_orbit", shoot)
    cert = _certify(run, {})
    assert cert.certified and cert.kicked, cert.detail
    monkeypatch.setattr(_certificate, "kick_test", _kicks((1,)))
    assert _certify(run, {}).status == "step-dependent"


def test_a_run_shorter_than_8_orbit_periods_asks_no_kicks(monkeypatch):
    """Kicks follow 40 orbit periods at dt and dt/2: a run of fewer than 8 orbit periods
    (KICK_MIN_PERIODS) is not kicked; it stays unstable (a classifier that extends asks them
    on the longer run)."""
    run = _unstable_everywhere(monkeypatch, returns_at=(1, 2))[:7]
    extra: dict = {}
    cert = _certify(run, extra)
    assert cert.status == "unstable" and "kick_test" not in extra
