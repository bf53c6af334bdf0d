"""classify_trajectory / classify_file: the verdict of a simulated run of the model."""

import json
import warnings

import pyarrow as pa
import pyarrow.parquet as pq
import pytest

import chaoscam
import chaoscam.classify as cl
from chaoscam import Params, Status
from chaoscam.classify import classify_file, classify_trajectory, load_trajectory

PERIODIC = Params(e=0.02)  # a period-1 response after ~2 s


@pytest.fixture(scope="module")
def periodic():
    return chaoscam.simulate(PERIODIC, duration=4.0, transient=2.0)


@pytest.fixture(scope="module")
def default3():
    return chaoscam.simulate(duration=3.0)


def test_periodic_run_is_period_1(periodic):
    """A period-1 response: label periodic, period 1 cam period, settings traceable."""
    v = classify_trajectory(periodic)
    assert (v.label, v.period) == ("periodic", 1)
    assert v.settings["trajectory"]["params"]["e"] == 0.02
    assert v.settings["forcing_period"] == pytest.approx(PERIODIC.cam_period)
    json.dumps(v.to_dict())


def test_section_only_run_is_classified_from_the_section():
    """series=False: the section with the tangent exponent decides; still period 1, and the
    sticking orbit (a zero Floquet multiplier) is certified by Newton shooting."""
    tr = chaoscam.simulate(PERIODIC, duration=4.0, transient=2.0, series=False)
    v = classify_trajectory(tr)
    assert (v.label, v.period) == ("periodic", 1)
    names = {e.name for e in v.evidence}
    assert all(n.startswith("section_") for n in names - {"exponent", "periodic_orbit"})
    orbit = next(e for e in v.evidence if e.name == "periodic_orbit")
    assert orbit.vote == "periodic" and orbit.detail.startswith("certified")
    assert min(v.settings["periodic_orbit"]["multipliers_abs"]) < 1e-6


def test_without_tangent_the_section_alone_decides():
    """tangent=False: only section evidence, no exponent or orbit."""
    tr = chaoscam.simulate(PERIODIC, duration=4.0, transient=2.0, series=False)
    v = classify_trajectory(tr, tangent=False)
    assert (v.label, v.period) == ("periodic", 1)
    assert all(e.name.startswith("section_") for e in v.evidence)


def test_an_adaptive_run_is_told_its_verdict_rests_on_the_rk4_grid(periodic):
    """An adaptive run without its tangent gets its exponent on the RK4 grid at its dt: a
    RuntimeWarning names that dt (the adaptive tolerances do not refine it); an RK4 run
    without its tangent, on its own grid, gets no such warning."""
    adaptive = chaoscam.simulate(
        PERIODIC.replace(integrator="adaptive"), duration=4.0, transient=2.0, series=False
    )
    with pytest.warns(RuntimeWarning, match=r"RK4 grid at dt = 2e-06 s.*refine dt"):
        v = classify_trajectory(adaptive)
    assert (v.label, v.period) == ("periodic", 1)
    with warnings.catch_warnings():
        warnings.simplefilter("error", RuntimeWarning)
        classify_trajectory(periodic)


def test_lyapunov_evidence_is_named_lyapunov_model(default3):
    """lyapunov=True adds the model's λ₁ [1/s] as evidence 'lyapunov_model', chaotic here."""
    v = classify_trajectory(default3, lyapunov=True)
    names = [e.name for e in v.evidence]
    assert "lyapunov_model" in names and "lyapunov" not in names
    e = v.evidence[names.index("lyapunov_model")]
    assert e.vote == "chaotic" and e.value > 0 and "Benettin" in e.detail
    assert v.settings["lyapunov_model"]["exponent"] == e.value


def test_section_only_lyapunov_value_is_per_second():
    """Section-only mode gets λ₁ T per iterate, but the evidence value stays in 1/s."""
    tr = chaoscam.simulate(duration=3.0, series=False)
    v = classify_trajectory(tr, lyapunov=True)
    e = next(e for e in v.evidence if e.name == "lyapunov_model")
    assert e.value == pytest.approx(v.settings["lyapunov_model"]["exponent"])
    assert "per iterate" in e.detail


def test_failed_run_is_undetermined_with_status():
    """A run that left the cam's reach is not classified: undetermined, status evidence."""
    tr = chaoscam.simulate(Params(x_O=-0.58), duration=1.0)
    assert tr.status is Status.LEFT_REACH
    v = classify_trajectory(tr, lyapunov=True, check_step=True)
    assert v.label == "undetermined" and v.period is None
    assert [e.name for e in v.evidence] == ["status"]
    assert v.evidence[0].value == int(Status.LEFT_REACH)
    assert "left_reach" in v.reasons[0]


def test_step_check_passes_when_the_label_holds(default3):
    """Halving dt keeps the label of a 3 s default run: step_check evidence 1 (unchanged)."""
    v = classify_trajectory(default3, check_step=True)
    e = v.evidence[-1]
    assert e.name == "step_check" and e.value == 1 and e.vote is None
    assert v.label == classify_trajectory(default3).label
    assert v.settings["step_check"]["dt_half"] == Params().dt / 2


def test_step_check_failure_makes_the_verdict_undetermined(periodic, default3, monkeypatch):
    """If the half-step run gives another label, the verdict is undetermined with the reason."""
    seen = {}

    def fake_half(traj, **kw):
        seen["dt"] = traj.params.dt
        return default3  # stands in for a half-step run that came out irregular

    monkeypatch.setattr(cl, "_resimulate_half_step", fake_half)
    v = classify_trajectory(periodic, check_step=True)
    assert v.label == "undetermined" and v.period is None
    assert any("halving the step" in r for r in v.reasons)
    assert v.evidence[-1].name == "step_check" and v.evidence[-1].value == 0


def test_step_check_extends_the_half_step_run_as_the_grid_run():
    """xi = 0.43 at Table 1 otherwise is undetermined on its 10 s recorded (period 11, no
    attracting orbit certified) and chaotic once extended to 40 s; its half-step run must be
    extended the same way before the two are compared (it was not: "chaotic" against an
    unextended "undetermined" read as a changed verdict)."""
    tr = chaoscam.simulate(Params(xi=0.43), duration=20.0, transient=10.0)
    v = classify_trajectory(tr, check_step=True)
    assert v.label == "chaotic", v.reasons
    assert v.settings["extended"]["recorded_s"] == 40.0
    assert v.evidence[-1].name == "step_check" and v.evidence[-1].value == 1
    assert v.settings["step_check"]["label"] == "chaotic"
    assert v.settings["step_check"]["recorded_s"] == 40.0  # extended as the grid run was


def test_step_check_does_not_rerun_an_undetermined_verdict(monkeypatch):
    """An undetermined verdict cannot change with the step: no half-step run, and the
    step_check evidence says why it has no value."""
    tr = chaoscam.simulate(duration=3.0, transient=2.0)
    plain = classify_trajectory(tr, extend_to=None)
    assert plain.label == "undetermined"

    def no_rerun(traj, **kw):
        raise AssertionError("re-simulated an undetermined verdict")

    monkeypatch.setattr(cl, "_resimulate_half_step", no_rerun)
    v = classify_trajectory(tr, extend_to=None, check_step=True)
    assert (v.label, v.reasons) == (plain.label, plain.reasons)
    e = v.evidence[-1]
    assert e.name == "step_check" and e.value is None and "cannot change" in e.detail
    assert v.settings["step_check"]["skipped"] is True
    assert v.settings["step_check"]["grid_label"] == "undetermined"


def test_half_step_run_is_the_same_realization(periodic):
    """The re-simulation keeps params, duration, transient, seed, index; only dt halves."""
    half = cl._resimulate_half_step(periodic)
    assert half.params == PERIODIC.replace(dt=PERIODIC.dt / 2)
    for key in ("duration", "transient", "seed", "index", "output_dt"):
        assert half.settings[key] == pytest.approx(periodic.settings[key])


def test_parquet_round_trip_gives_the_same_verdict(tmp_path, periodic, default3):
    """classify_file on Trajectory.to_parquet output equals classify_trajectory in memory."""
    for tr, name in ((periodic, "p.parquet"), (default3, "d.parquet")):
        tr.to_parquet(tmp_path / name)
        a, b = classify_trajectory(tr), classify_file(tmp_path / name)
        assert (a.label, a.period) == (b.label, b.period)
        assert [e.name for e in a.evidence] == [e.name for e in b.evidence]
        back = load_trajectory(tmp_path / name)
        assert back.params == tr.params and back.status is tr.status
        assert len(back.section) == len(tr.section) and len(back.impacts) == len(tr.impacts)


def test_section_only_parquet_loads_without_series(tmp_path):
    """A file written without a series rebuilds a section-only trajectory."""
    tr = chaoscam.simulate(PERIODIC, duration=4.0, transient=2.0, series=False)
    tr.to_parquet(tmp_path / "s.parquet")
    back = load_trajectory(tmp_path / "s.parquet")
    assert back.series is None
    assert classify_file(tmp_path / "s.parquet").label == classify_trajectory(tr).label


def test_wrong_files_raise_errors_naming_them(tmp_path):
    """Missing file, non-Parquet and foreign Parquet files: errors that name the file."""
    with pytest.raises(FileNotFoundError, match="nope.parquet"):
        load_trajectory(tmp_path / "nope.parquet")
    bad = tmp_path / "bad.parquet"
    bad.write_text("t,theta_f\n0,1\n")
    with pytest.raises(ValueError, match="bad.parquet.*not a Parquet"):
        load_trajectory(bad)
    foreign = tmp_path / "foreign.parquet"
    pq.write_table(pa.table({"x": [1.0, 2.0]}), foreign)
    with pytest.raises(ValueError, match="foreign.parquet.*not a chaoscam trajectory"):
        load_trajectory(foreign)


def test_undetermined_short_run_is_extended_until_it_settles():
    """l_lambda = 1 mm over 10 s recorded: the tangent exponent (2.3 +- 0.9 1/s over 46
    periods) cannot decide and the 10 s spectrum reads quasiperiodic, so without extension
    the verdict stays undetermined; extended (4x per round) it settles as chaotic, as the
    300 s run does (lambda_1 = 2.1 +- 0.09 1/s), and the extension is recorded."""
    tr = chaoscam.simulate(Params(l_lambda=0.001), duration=20.0, transient=10.0)
    short = classify_trajectory(tr, extend_to=None)
    assert short.label == "undetermined"
    v = classify_trajectory(tr)
    assert v.label == "chaotic"
    assert v.settings["extended"]["recorded_s"] > 10.0


# Measured on 20 s runs (10 s transient): 46 section points in n narrow bands that look
# periodic, with an exponent still undecided; a 4x longer run shows lambda_1 > 0.
UNSETTLED_BANDS = {
    "period 7 whose orbit is unstable (omega = 26, xi = 0.3)": (
        dict(omega=26.0, xi=0.3),
        0,
        "orbit found is unstable",
    ),
    # index 1: with the Newton crossing search, realizations 0 and 1 are undecided on their
    # short runs and 2 to 7 already have a positive exponent beyond its interval (chaotic)
    "random line length, 8 bands": (
        dict(l_lambda=0.008, l_lambda_sigma=0.0015),
        1,
        "the line length is random",
    ),
}


@pytest.mark.parametrize(
    ("changes", "index", "words"), list(UNSETTLED_BANDS.values()), ids=list(UNSETTLED_BANDS)
)
def test_bands_that_only_look_periodic_are_not_called_periodic(changes, index, words):
    """Periodic only with a certificate or a contracting exponent; else undetermined, and
    the extended run settles it (chaotic)."""
    from chaoscam import Params, simulate
    from chaoscam.classify import classify_trajectory

    traj = simulate(
        Params(**changes),
        duration=20.0,
        transient=10.0,
        seed=1,
        index=index,
        series=False,
        tangent=True,
    )  # the section path, as in ensembles
    short = classify_trajectory(traj, extend_to=None)
    assert short.label == "undetermined" and any(words in r for r in short.reasons)
    assert "run longer" in short.reasons[-1]  # the reason says what to run
    settled = classify_trajectory(traj)
    assert settled.label == "chaotic" and settled.settings["extended"]["recorded_s"] > 10.0


def test_classify_ensemble_extends_and_explains_like_classify_trajectory():
    """The ensemble's members: same verdicts as classify_trajectory, with a reason per
    undetermined member when not extended."""
    from chaoscam import Params, classify_ensemble, simulate
    from chaoscam.classify import classify_trajectory
    from chaoscam.integrate import simulate_ensemble

    p = Params(omega=26.0, xi=0.3)
    ens = simulate_ensemble(p, [0], seed=1, duration=20.0, transient=10.0, tangent=True)
    short = classify_ensemble(ens, p, extend_to=None).members.iloc[0]
    assert short["label"] == "undetermined" and "run longer" in short["reasons"]
    member = classify_ensemble(ens, p).members.iloc[0]
    traj = simulate(p, duration=20.0, transient=10.0, seed=1, index=0, tangent=True)
    assert member["label"] == classify_trajectory(traj).label == "chaotic"


def test_a_resumable_ensemble_is_extended_by_continuing_it(monkeypatch):
    """Undetermined members of a run kept resumable are continued (extend_ensemble), not run
    again from t = 0, and get the same verdicts, evidence and reasons as when run again."""
    from chaoscam import Params, _ensemble_verdicts
    from chaoscam.integrate import simulate_ensemble

    p = Params(omega=26.0, xi=0.3)
    run = dict(seed=1, duration=20.0, transient=10.0, tangent=True)
    again = _ensemble_verdicts.member_verdicts(simulate_ensemble(p, [0, 1], **run), p)
    calls = []
    real = _ensemble_verdicts.simulate_ensemble
    monkeypatch.setattr(
        _ensemble_verdicts,
        "simulate_ensemble",
        lambda *a, **kw: calls.append(kw["duration"]) or real(*a, **kw),
    )
    kept = simulate_ensemble(p, [0, 1], resumable=True, **run)
    continued = _ensemble_verdicts.member_verdicts(kept, p)
    assert calls == []  # no run from t = 0
    assert any("extended" in v.verdict.settings for v in again)
    for a, b in zip(again, continued, strict=True):
        assert (a.label, a.period, a.reasons) == (b.label, b.period, b.reasons)
        assert a.verdict.evidence == b.verdict.evidence
        ext_a, ext_b = a.verdict.settings.get("extended"), b.verdict.settings.get("extended")
        assert (ext_a is None) == (ext_b is None)
        if ext_a is not None:
            assert ext_a["recorded_s"] == ext_b["recorded_s"]


@pytest.mark.parametrize("series", [False, True], ids=["tangent run", "series run"])
def test_a_resumable_run_is_extended_by_continuing_it(monkeypatch, series):
    """classify_trajectory extends an undetermined run kept resumable by going on from it
    (extend_trajectory), not by running again from t = 0, with the same verdict, evidence
    and reasons (the extended verdict reads the longer run's section and Jacobians). A run
    kept with its series but without the tangent (and a copy) is simulated once with the
    tangent, resumable, and the extension rounds go on from that."""
    from chaoscam import Params, classify, simulate

    p = Params(omega=26.0, xi=0.3)
    run = dict(duration=20.0, transient=10.0, seed=1, index=0)
    again = classify.classify_trajectory(simulate(p, series=False, tangent=True, **run))
    calls = []
    real = classify.simulate
    monkeypatch.setattr(
        classify, "simulate", lambda *a, **kw: calls.append(kw["duration"]) or real(*a, **kw)
    )
    kept = simulate(p, series=series, tangent=not series, resumable=not series, **run)
    continued = classify.classify_trajectory(kept)
    assert calls == ([20.0] if series else [])  # only the tangent run, once
    assert again.settings["extended"]["continued_from_s"] is None
    assert 0.0 < continued.settings["extended"]["continued_from_s"] < 50.0
    assert (again.label, again.period, again.reasons) == (
        continued.label,
        continued.period,
        continued.reasons,
    )
    assert again.evidence == continued.evidence
    assert again.settings["extended"]["recorded_s"] == continued.settings["extended"]["recorded_s"]


def test_an_orbit_the_grid_calls_unstable_is_certified_on_refined_steps():
    """xi = 0.45: a sticking period-6 orbit whose dominant multiplier the default grid's tangent
    overstates (|mu| ~ 2-3 at dt = 2e-6 s, a positive grid exponent) while shooting at dt/2
    and dt/4 finds it attracting (|mu| < 0.1; lambda_1 = -2.75 +- 0.17 1/s on the adaptive
    path): periodic 6, with the refined multipliers as its evidence, on the single-run and
    the ensemble paths alike."""
    from chaoscam import Params, classify_ensemble, simulate
    from chaoscam.classify import classify_trajectory
    from chaoscam.integrate import simulate_ensemble
    from chaoscam.tangent import periodic_orbit

    p = Params(xi=0.45)
    traj = simulate(p, duration=20.0, transient=10.0, seed=1, series=False, tangent=True)
    x = traj.section[["theta_f", "omega_f"]].to_numpy()[-1]
    assert not periodic_orbit(p, x, 6).stable  # the grid alone would not certify it
    v = classify_trajectory(traj, extend_to=None)
    assert (v.label, v.period) == ("periodic", 6)
    orbit = next(e for e in v.evidence if e.name == "periodic_orbit")
    assert orbit.vote == "periodic" and "certified at every refined step" in orbit.detail
    refined = v.settings["periodic_orbit_refined"]
    assert [r["dt"] for r in refined] == [p.dt / 2, p.dt / 4]
    assert all(max(r["multipliers_abs"]) < 1 for r in refined)
    ens = simulate_ensemble(p, [0], seed=1, duration=20.0, transient=10.0, tangent=True)
    member = classify_ensemble(ens, p, extend_to=None).members.iloc[0]
    assert (member["label"], member["period"]) == ("periodic", 6)


def test_ensemble_verdicts_on_threads_equal_the_serial_ones(monkeypatch):
    """Members' verdicts run on the ensemble's threads (the certificates' shooting runs
    compiled without the GIL) equal those run one after another: label, period, reasons and
    every piece of evidence, for periodic orbits of periods 1, 6 (refined), 2 and 8 and an
    undetermined member; the shooting did run on the worker threads."""
    import dataclasses
    import threading

    from chaoscam import Params, _certify
    from chaoscam._ensemble_verdicts import member_verdicts
    from chaoscam.integrate import simulate_ensemble

    models = [Params(xi=0.2), Params(xi=0.45), Params(xi=0.24), Params(e=0.03), Params(xi=0.43)]
    ens = simulate_ensemble(models, [0] * 5, seed=1, duration=20.0, transient=10.0, tangent=True)
    where = []
    shoot = _certify.periodic_orbit

    def spied(*args, **kw):
        where.append(threading.current_thread().name)
        return shoot(*args, **kw)

    monkeypatch.setattr(_certify, "periodic_orbit", spied)
    serial = member_verdicts(
        dataclasses.replace(ens, settings={**ens.settings, "threads": 1}), models, extend_to=None
    )
    assert not any(n.startswith("chaoscam-verdict") for n in where)
    where.clear()
    threaded = member_verdicts(
        dataclasses.replace(ens, settings={**ens.settings, "threads": 2}), models, extend_to=None
    )
    assert where and all(n.startswith("chaoscam-verdict") for n in where)
    assert [(v.label, v.period) for v in threaded] == [
        ("periodic", 1), ("periodic", 6), ("periodic", 2), ("periodic", 8), ("undetermined", None),
    ]  # fmt: skip
    for a, b in zip(serial, threaded, strict=True):
        assert (a.label, a.period, a.reasons) == (b.label, b.period, b.reasons)
        assert [(e.name, e.vote, e.detail) for e in a.verdict.evidence] == [
            (e.name, e.vote, e.detail) for e in b.verdict.evidence
        ]


def test_threaded_calls_keep_order_and_stop_on_an_error():
    """_threaded returns results in the items' order; an exception reaches the caller and
    the calls not yet started are cancelled."""
    import time

    from chaoscam._ensemble_verdicts import _threaded

    square = lambda x: (time.sleep(0.01 * max(5 - x, 0)), x * x)[1]  # noqa: E731
    assert _threaded(square, list(range(5)), 3, [7, 6]) == ([0, 1, 4, 9, 16], [49, 36])
    started = []

    def fail_first(x):
        started.append(x)
        if x == 0:
            raise RuntimeError("member 0")
        time.sleep(0.05)
        return x

    with pytest.raises(RuntimeError, match="member 0"):
        _threaded(fail_first, list(range(40)), 2)
    assert len(started) < 40


def test_only_deterministic_members_are_judged_on_threads(monkeypatch):
    """A deterministic member's verdict may shoot its orbit (compiled, without the GIL) and
    goes to the threads; a random one's is Python under the GIL and stays on the calling
    thread, which threads only slowed (3.3 ms a member on one, 4.1-5.6 on 2-8). The
    verdicts are the same, in the members' order, as on one thread."""
    import dataclasses

    from chaoscam import Params, _ensemble_verdicts
    from chaoscam.integrate import simulate_ensemble

    fixed, random = Params(xi=0.2), Params(xi=0.2, l_lambda_sigma=0.001)
    plist = [fixed, random, random, fixed, random]
    ens = simulate_ensemble(plist, range(5), seed=1, duration=20.0, transient=10.0, tangent=True)
    one = dataclasses.replace(ens, settings={**ens.settings, "threads": 1})
    two = dataclasses.replace(ens, settings={**ens.settings, "threads": 2})
    serial = _ensemble_verdicts._verdicts(one, plist)
    pooled = []
    real = _ensemble_verdicts.ThreadPoolExecutor

    class Counted(real):
        def submit(self, fn, *args, **kwargs):
            pooled.append(args[-1][0])  # the member
            return super().submit(fn, *args, **kwargs)

    monkeypatch.setattr(_ensemble_verdicts, "ThreadPoolExecutor", Counted)
    threaded = _ensemble_verdicts._verdicts(two, plist)
    assert sorted(pooled) == [0, 3]
    assert [(v.label, v.period, v.reasons) for v in threaded] == [
        (v.label, v.period, v.reasons) for v in serial
    ]
    assert serial[0].label == "periodic" and "periodic_orbit" in serial[0].verdict.settings


def test_an_overflowed_tangent_is_undetermined_with_its_cause_and_not_extended():
    """l_lambda = 8 m (a length meant in mm): K_n is 1000x the intended one, RK4 at the
    default dt is past its stability limit in the contact, and the tangent overflows while
    the motion stays finite. The verdict (both engines) is undetermined, says why and what
    step would do, and is not extended (a longer run overflows too); it raised
    "jacobians hold NaN or inf" with a traceback from classify, report, ensemble and sweeps."""
    import warnings

    from chaoscam import classify_ensemble
    from chaoscam.integrate import simulate_ensemble

    p = Params(l_lambda=8.0)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)  # the step warning, tested elsewhere
        tr = chaoscam.simulate(p, duration=3.0, series=False, tangent=True)
        ens = simulate_ensemble(p, [0], duration=3.0, tangent=True)
    assert tr.ok
    v = classify_trajectory(tr)
    assert v.label == "undetermined" and "extended" not in v.settings
    (why,) = v.reasons
    assert why.startswith("the tangent overflowed: ") and "use dt <= 7.2e-08 s" in why
    assert [e.name for e in v.evidence][-1] == "tangent_overflow"
    members = classify_ensemble(ens, p).members
    assert list(members["label"]) == ["undetermined"]
    assert members["reasons"][0] == why


def test_analysis_options_go_where_they_apply():
    """An option of the series classifier on a run with a series is also fine when the run
    is extended (the extension has no series: it raised classify_section's TypeError);
    on a run kept without its series it is refused naming classify_section's options."""
    run = chaoscam.simulate(duration=2.0)
    v = classify_trajectory(run, spectrum_options={}, extend_to=40.0)
    assert v.settings["extended"]["recorded_s"] > 1.0
    bare = chaoscam.simulate(duration=2.0, series=False)
    with pytest.raises(TypeError, match="options are classify_section's: .*zero_one"):
        classify_trajectory(bare, spectrum_options={})


def test_one_label_with_or_without_the_series():
    """The series path needs what the section path needs for "chaotic" (the tangent
    exponent's vote, or two independent chaotic votes): omega = 45, xi = 0.2 over 1.5 s (11
    section points) was chaotic from a broadband spectrum alone with its series and periodic
    11 without, once extended; so the process and ensemble engines disagreed on that cell."""
    p = Params(omega=45.0, xi=0.2)
    labels = set()
    for series in (True, False):
        tr = chaoscam.simulate(p, duration=3.0, transient=1.5, series=series)
        v = chaoscam.classify_trajectory(tr)
        labels.add((v.label, v.period))
    assert labels == {("periodic", 11)}


def test_a_run_without_a_section_point_is_undetermined_or_extended():
    """A recorded window shorter than a cam period (no section point) was a raw ValueError
    from the analysis layer; it is undetermined with the reason, and the default (tangent,
    extended) runs it longer instead."""
    tr = chaoscam.simulate(duration=0.3, transient=0.25)
    for kw in ({"tangent": False}, {"lyapunov": True}, {"extend_to": None}):
        v = chaoscam.classify_trajectory(tr, **kw)
        assert v.label == "undetermined" and "no section point after t = 0.25 s" in v.reasons[0]
    assert chaoscam.classify_trajectory(tr).settings["extended"]["recorded_s"] > 1.0
