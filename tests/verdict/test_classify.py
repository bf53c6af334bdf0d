"""chaoscam.classify (chaoscam/verdict/_classify.py): the verdict of every member of a run, from
its section and tangent exponent, extended while undetermined, checked at half the step."""

import dataclasses
import json
import threading
import time
import warnings

import pyarrow as pa
import pyarrow.parquet as pq
import pytest

import chaoscam
from chaoscam import Numerics, Params, Status, classify, load_trajectory, simulate, solve
from chaoscam.verdict import _certificate, _classify, periodic_orbit

PERIODIC = Params(e=0.02)  # a period-1 response after ~2 s


@pytest.fixture(scope="module")
def periodic():
    return simulate(PERIODIC, duration=4.0, transient=2.0)


@pytest.fixture(scope="module")
def default3():
    return simulate(duration=3.0)


def test_periodic_run_is_period_1(periodic):
    """A period-1 response: label periodic, period 1 cam period, settings traceable."""
    (v,) = classify(periodic)
    assert (v.label, v.period) == ("periodic", 1)
    assert v.settings["trajectory"]["params"]["e"] == 0.02
    assert v.settings["trajectory"]["numerics"] == Numerics().to_dict()
    assert v.settings["exponent_time"] == pytest.approx(PERIODIC.cam_period)  # 1/s -> per iterate
    json.dumps(v.to_dict())


def test_the_verdict_is_taken_from_the_section_and_the_tangent(periodic):
    """Even on a run kept with its series, only section evidence, the tangent exponent and
    the orbit certificate vote: period 1, and the sticking orbit (a zero Floquet multiplier)
    is certified by Newton shooting."""
    (v,) = classify(periodic)
    assert (v.label, v.period) == ("periodic", 1)
    names = {e.name for e in v.evidence}
    assert {"exponent", "periodic_orbit"} <= names
    assert all(n.startswith("section_") for n in names - {"exponent", "periodic_orbit"})
    orbit = next(e for e in v.evidence if e.name == "periodic_orbit")
    assert orbit.vote == "periodic" and orbit.detail.startswith("certified")
    assert min(v.settings["periodic_orbit"]["multipliers_abs"]) < 1e-6


def test_an_adaptive_run_is_told_its_verdict_rests_on_the_rk4_grid(periodic):
    """An adaptive run without its tangent gets its exponent on the RK4 grid at its dt: a
    RuntimeWarning names that dt (the adaptive tolerances do not refine it); an RK4 run
    without its tangent, on its own grid, gets no such warning."""
    adaptive = simulate(
        PERIODIC, Numerics(integrator="adaptive"), duration=4.0, transient=2.0, series=False
    )
    with pytest.warns(RuntimeWarning, match=r"RK4 grid at dt = 2e-06 s.*refine dt"):
        (v,) = classify(adaptive)
    assert (v.label, v.period) == ("periodic", 1)
    with warnings.catch_warnings():
        warnings.simplefilter("error", RuntimeWarning)
        classify(periodic)


def test_failed_run_is_undetermined_with_status():
    """A run that left the cam's reach is not classified: undetermined, status evidence."""
    tr = simulate(Params(x_O=-0.58), duration=1.0)
    assert tr.status is Status.LEFT_REACH
    (v,) = classify(tr, check_step=True)
    assert v.label == "undetermined" and v.period is None
    assert [e.name for e in v.evidence][0] == "status"
    assert v.evidence[0].value == int(Status.LEFT_REACH)
    assert "left_reach" in v.reasons[0]
    assert v.settings["status"] == "LEFT_REACH"


def test_step_check_passes_when_the_label_holds(default3):
    """Halving dt keeps the label of a 3 s default run: step_check evidence 1 (unchanged)."""
    (v,) = classify(default3, check_step=True)
    e = v.evidence[-1]
    assert e.name == "step_check" and e.value == 1 and e.vote is None
    assert v.label == classify(default3)[0].label
    assert v.settings["step_check"]["dt_half"] == Numerics().dt / 2


def _spy_solve(monkeypatch, replace=None):
    """Record the numerics and arguments of every solve the verdict makes; with ``replace``,
    a solve at a step other than the default's runs the model ``replace`` instead."""
    calls = []
    real = _classify.solve

    def spied(models, num, **kw):
        calls.append((list(models), num, kw))
        if replace is not None and num.dt != Numerics().dt:
            models = [replace] * len(models)
        return real(models, num, **kw)

    monkeypatch.setattr(_classify, "solve", spied)
    return calls


def test_step_check_failure_makes_the_verdict_undetermined(periodic, monkeypatch):
    """If the half-step run gives another label, the verdict is undetermined with the reason
    (the half-step run replaced by one of the default, irregular model)."""
    tangent = simulate(PERIODIC, duration=4.0, transient=2.0, series=False, tangent=True)
    calls = _spy_solve(monkeypatch, replace=Params())
    (v,) = classify(tangent, check_step=True, extend_to=None)
    assert [c[1].dt for c in calls] == [Numerics().dt / 2]  # the half-step run, replaced
    assert v.label == "undetermined" and v.period is None
    assert any("halving the step" in r for r in v.reasons)
    assert v.evidence[-1].name == "step_check" and v.evidence[-1].value == 0
    assert v.settings["step_check"]["grid_label"] == "periodic"


def test_half_step_run_is_the_same_realization(monkeypatch):
    """The re-simulation keeps the model, duration, transient, seed and index; only dt
    halves (and the tangent is kept)."""
    p = Params(xi=0.2, l_lambda_sigma=0.002)  # random: the seed and index matter
    run = simulate(p, duration=20.0, transient=10.0, seed=3, index=2, series=False, tangent=True)
    calls = _spy_solve(monkeypatch)
    (v,) = classify(run, check_step=True, extend_to=None)
    assert v.label == "periodic"  # checked, so re-run
    ((models, num, kw),) = calls
    assert models == [p] and num == Numerics().refined() and num.dt == Numerics().dt / 2
    assert kw["indices"] == [2] and kw["seed"] == 3 and kw["tangent"] is True
    assert (kw["duration"], kw["transient"]) == (20.0, 10.0)


def test_step_check_extends_the_half_step_run_as_the_grid_run():
    """xi = 0.43 at Table 1 otherwise is undetermined on its 10 s recorded and chaotic once
    extended to 40 s; its half-step run must be extended the same way before the two are
    compared ("chaotic" against an unextended "undetermined" read as a changed verdict)."""
    tr = simulate(Params(xi=0.43), duration=20.0, transient=10.0)
    (v,) = classify(tr, check_step=True)
    assert v.label == "chaotic", v.reasons
    assert v.settings["extended"]["recorded_s"] == 40.0
    assert v.evidence[-1].name == "step_check" and v.evidence[-1].value == 1
    assert v.settings["step_check"]["label"] == "chaotic"
    assert v.settings["step_check"]["recorded_s"] == 40.0  # extended as the grid run was


def test_step_check_does_not_rerun_an_undetermined_verdict(monkeypatch):
    """An undetermined verdict cannot change with the step: no half-step run, and the
    step_check evidence says why it has no value."""
    tr = simulate(duration=3.0, transient=2.0, tangent=True)
    (plain,) = classify(tr, extend_to=None)
    assert plain.label == "undetermined"
    calls = _spy_solve(monkeypatch)
    (v,) = classify(tr, extend_to=None, check_step=True)
    assert calls == []
    assert (v.label, v.reasons) == (plain.label, plain.reasons)
    e = v.evidence[-1]
    assert e.name == "step_check" and e.value is None and "cannot change" in e.detail
    assert v.settings["step_check"]["skipped"] is True
    assert v.settings["step_check"]["grid_label"] == "undetermined"


@pytest.mark.parametrize("series", [True, False], ids=["with series", "section only"])
def test_a_run_read_back_from_its_file_gets_the_same_verdict(tmp_path, series):
    """A run written with to_parquet and read with load_trajectory (its model, numerics,
    seed and index from the file) gets the verdict of the run in memory, for a periodic and
    an irregular run, kept with or without its series."""
    for p, duration, transient in ((PERIODIC, 4.0, 2.0), (Params(), 3.0, 0.0)):
        tr = simulate(p, duration=duration, transient=transient, series=series)
        path = tmp_path / f"{p.e}.parquet"
        tr.to_parquet(path)
        back = load_trajectory(path)
        assert (back.series is None) is not series
        (a,), (b,) = classify(tr, extend_to=None), classify(back, extend_to=None)
        assert (a.label, a.period, a.reasons) == (b.label, b.period, b.reasons)
        assert a.evidence == b.evidence


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
    """l_lambda = 1 mm over 10 s recorded: the tangent exponent cannot decide and the
    period-8 orbit the section suggests is unstable, so without extension the verdict stays
    undetermined; extended (4x per round) it settles as chaotic, as the 300 s run does
    (lambda_1 = 2.1 +- 0.09 1/s), and the extension is recorded."""
    tr = simulate(Params(l_lambda=0.001), duration=20.0, transient=10.0)
    (short,) = classify(tr, extend_to=None)
    assert short.label == "undetermined"
    (v,) = classify(tr)
    assert v.label == "chaotic"
    assert v.settings["extended"]["recorded_s"] > 10.0


# Measured on 20 s runs (10 s transient): 46 section points in n narrow bands that look
# periodic, with an exponent still undecided; a 4x longer run shows lambda_1 > 0. (With a
# random line length the common-noise twins settle such bands on the short run: test_rules.py.)
UNSETTLED_BANDS = {
    "period 7 whose orbit is unstable (omega = 26, xi = 0.3)": (
        dict(omega=26.0, xi=0.3),
        0,
        "orbit found is unstable",
    ),
}


@pytest.mark.parametrize(
    ("changes", "index", "words"), list(UNSETTLED_BANDS.values()), ids=list(UNSETTLED_BANDS)
)
def test_bands_that_only_look_periodic_are_not_called_periodic(changes, index, words):
    """Periodic only with a certificate or a contracting exponent; else undetermined, and
    the extended run is not periodic either."""
    traj = simulate(
        Params(**changes),
        duration=20.0,
        transient=10.0,
        seed=1,
        index=index,
        series=False,
        tangent=True,
    )
    (short,) = classify(traj, extend_to=None)
    assert short.label == "undetermined" and any(words in r for r in short.reasons)
    assert "run longer" in short.reasons[-1]  # the reason says what to run
    (settled,) = classify(traj)
    # chaotic on the extended run at dt; its 7 bands lie on an orbit unstable only at that
    # step, and at dt/2 the verdict differs: undetermined, saying so (the holdout set leaves
    # (26, 0.3) unsettled: lambda_1 = +1.77 at dt, -0.46 at dt/2)
    assert settled.label == "undetermined" and settled.settings["extended"]["recorded_s"] > 10.0
    assert settled.settings["step_check"]["grid_label"] == "chaotic"
    assert any("halving the step changes the verdict" in r for r in settled.reasons)


def _spy_extend(monkeypatch):
    """The solutions the verdict's extension rounds made."""
    made = []
    real = _classify.extend

    def spied(*args, **kw):
        made.append(real(*args, **kw))
        return made[-1]

    monkeypatch.setattr(_classify, "extend", spied)
    return made


@pytest.mark.parametrize("series", [False, True], ids=["tangent run", "series run"])
def test_a_resumable_run_is_extended_by_continuing_it(monkeypatch, series):
    """Undetermined members of a run kept resumable are continued (extend from the kept
    copy), not run again from t = 0, with the same verdicts, evidence, reasons and recorded
    time as when run again (the extended verdict reads the longer run's section and
    Jacobians). A run kept with its series but without the tangent is solved once with the
    tangent, resumable, and the extension rounds go on from that."""
    p = Params(omega=26.0, xi=0.3)
    run = dict(indices=[0, 1], seed=1, duration=20.0, transient=10.0)
    made = _spy_extend(monkeypatch)
    again = classify(solve(p, tangent=True, **run))
    # the extensions at the run's step (its 7 bands are also checked at dt/2: step_marginal)
    at_dt = lambda: [m for m in made if m.numerics == Numerics()]  # noqa: E731
    assert at_dt() and all(m.settings["continued_from"] is None for m in at_dt())
    kept = solve(p, series=series, tangent=not series, resumable=not series, **run)
    made.clear()
    calls = _spy_solve(monkeypatch)
    continued = classify(kept)
    assert len([c for c in calls if c[1] == Numerics()]) == (1 if series else 0)  # the tangent's
    assert made and all(m.settings["continued_from"] is not None for m in made)
    assert any("extended" in v.settings for v in again)
    for a, b in zip(again, continued, strict=True):
        assert (a.label, a.period, a.reasons) == (b.label, b.period, b.reasons)
        assert a.evidence == b.evidence
        ext_a, ext_b = a.settings.get("extended"), b.settings.get("extended")
        assert (ext_a is None) == (ext_b is None)
        if ext_a is not None:
            assert ext_a["recorded_s"] == ext_b["recorded_s"]


def test_an_orbit_the_grid_calls_unstable_is_certified_on_refined_steps():
    """xi = 0.45: a sticking period-6 orbit whose dominant multiplier the default grid's tangent
    overstates (|mu| ~ 2-3 at dt = 2e-6 s, a positive grid exponent) while shooting at dt/2
    and dt/4 finds it attracting (|mu| < 0.1; lambda_1 = -2.75 +- 0.17 1/s on the adaptive
    path): periodic 6, with the refined multipliers as its evidence."""
    p = Params(xi=0.45)
    traj = simulate(p, duration=20.0, transient=10.0, seed=1, series=False, tangent=True)
    x = traj.section[["theta_f", "omega_f"]].to_numpy()[-1]
    assert not periodic_orbit(p, x, 6).stable  # the grid alone would not certify it
    (v,) = classify(traj, extend_to=None)
    assert (v.label, v.period) == ("periodic", 6)
    orbit = next(e for e in v.evidence if e.name == "periodic_orbit")
    assert orbit.vote == "periodic" and "certified at every refined step" in orbit.detail
    refined = v.settings["periodic_orbit_refined"]
    dt = Numerics().dt
    assert [r["dt"] for r in refined] == [dt / 2, dt / 4]
    assert all(max(r["multipliers_abs"]) < 1 for r in refined)


def _threads(sol, n):
    return dataclasses.replace(sol, settings={**sol.settings, "threads": n})


def test_verdicts_on_threads_equal_the_serial_ones(monkeypatch):
    """Members' verdicts run on the solution's threads (the certificates' shooting runs
    compiled without the GIL) equal those run one after another: label, period, reasons and
    every piece of evidence, for periodic orbits of periods 1, 6 (refined), 2 and 8 and an
    undetermined member; the shooting did run on the worker threads."""
    models = [Params(xi=0.2), Params(xi=0.45), Params(xi=0.24), Params(e=0.03), Params(xi=0.43)]
    sol = solve(models, indices=[0] * 5, seed=1, duration=20.0, transient=10.0, tangent=True)
    where = []
    shoot = _certificate.periodic_orbit

    def spied(*args, **kw):
        where.append(threading.current_thread().name)
        return shoot(*args, **kw)

    monkeypatch.setattr(_certificate, "periodic_orbit", spied)
    serial = classify(_threads(sol, 1), extend_to=None)
    assert where and not any(n.startswith("chaoscam-verdict") for n in where)
    where.clear()
    threaded = classify(_threads(sol, 2), extend_to=None)
    assert where and all(n.startswith("chaoscam-verdict") for n in where)
    assert [(v.label, v.period) for v in threaded] == [
        ("periodic", 1), ("periodic", 6), ("periodic", 2), ("periodic", 8), ("undetermined", None),
    ]  # fmt: skip
    for a, b in zip(serial, threaded, strict=True):
        assert (a.label, a.period, a.reasons) == (b.label, b.period, b.reasons)
        assert [(e.name, e.vote, e.detail) for e in a.evidence] == [
            (e.name, e.vote, e.detail) for e in b.evidence
        ]


def test_threaded_calls_keep_order_and_stop_on_an_error():
    """_threaded returns results in the items' order; an exception reaches the caller and
    the calls not yet started are cancelled."""
    square = lambda x: (time.sleep(0.01 * max(5 - x, 0)), x * x)[1]  # noqa: E731
    assert _classify._threaded(square, list(range(5)), 3, [7, 6]) == ([0, 1, 4, 9, 16], [49, 36])
    started = []

    def fail_first(x):
        started.append(x)
        if x == 0:
            raise RuntimeError("member 0")
        time.sleep(0.05)
        return x

    with pytest.raises(RuntimeError, match="member 0"):
        _classify._threaded(fail_first, list(range(40)), 2)
    assert len(started) < 40


def test_only_deterministic_members_are_judged_on_threads(monkeypatch):
    """A deterministic member's verdict may shoot its orbit (compiled, without the GIL) and
    goes to the threads; a random one's is Python under the GIL and stays on the calling
    thread, which threads only slowed (3.3 ms a member on one, 4.1-5.6 on 2-8). The
    verdicts are the same, in the members' order, as on one thread."""
    fixed, random = Params(xi=0.2), Params(xi=0.2, l_lambda_sigma=0.001)
    plist = [fixed, random, random, fixed, random]
    sol = solve(plist, indices=range(5), seed=1, duration=20.0, transient=10.0, tangent=True)
    serial = _classify._judge_all(_threads(sol, 1), 0.0, {})
    pooled = []
    real = _classify.ThreadPoolExecutor

    class Counted(real):
        def submit(self, fn, *args, **kwargs):
            pooled.append(args[-1])  # the member
            return super().submit(fn, *args, **kwargs)

    monkeypatch.setattr(_classify, "ThreadPoolExecutor", Counted)
    threaded = _classify._judge_all(_threads(sol, 2), 0.0, {})
    assert sorted(pooled) == [0, 3]
    assert [(v.label, v.period, v.reasons) for v in threaded] == [
        (v.label, v.period, v.reasons) for v in serial
    ]
    assert serial[0].label == "periodic" and "periodic_orbit" in serial[0].settings


def test_an_overflowed_tangent_is_undetermined_with_its_cause_and_not_extended():
    """l_lambda = 8 m (a length meant in mm): K_n is 1000x the intended one, RK4 at the
    default dt is past its stability limit in the contact, and the tangent overflows while
    the motion stays finite. The verdict is undetermined, says why and what step would do,
    and is not extended (a longer run overflows too); it raised "jacobians hold NaN or inf"
    with a traceback from classify, report, ensemble and sweeps."""
    p = Params(l_lambda=8.0)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)  # the step warning, tested elsewhere
        tr = simulate(p, duration=3.0, series=False, tangent=True)
    assert tr.ok
    (v,) = classify(tr)
    assert v.label == "undetermined" and "extended" not in v.settings
    (why,) = v.reasons
    assert why.startswith("the tangent overflowed: ") and "use dt <= 7.2e-08 s" in why
    assert [e.name for e in v.evidence][-1] == "tangent_overflow"


def test_options_of_the_removed_series_classifier_are_refused_by_name():
    """The verdict takes classify_section's options only (it judges from the section): an
    option of the series classifier is a TypeError naming the options it takes, on a run
    kept with or without its series."""
    for series in (True, False):
        run = simulate(duration=2.0, series=series)
        with pytest.raises(TypeError, match="options are classify_section's: .*zero_one"):
            classify(run, spectrum_options={})


def test_a_run_without_a_section_point_is_undetermined_or_extended():
    """A recorded window shorter than a cam period (no section point) was a raw ValueError
    from the analysis layer; it is undetermined with the reason, and the default (extended)
    runs it longer instead."""
    tr = simulate(duration=0.3, transient=0.25)
    (v,) = classify(tr, extend_to=None)
    assert v.label == "undetermined" and "0 section point(s) after the transient" in v.reasons[0]
    assert classify(tr)[0].settings["extended"]["recorded_s"] > 1.0


def test_one_verdict_per_member_in_the_members_order():
    """classify returns one verdict per member of a solution, in order, each with its own
    model and realization recorded; anything but a Solution is refused."""
    models = [PERIODIC, Params(x_O=-0.58), PERIODIC]
    sol = solve(models, indices=[4, 5, 6], duration=4.0, transient=2.0, tangent=True)
    verdicts = classify(sol, extend_to=None)
    assert [v.label for v in verdicts] == ["periodic", "undetermined", "periodic"]
    assert verdicts[1].settings["status"] == "LEFT_REACH"
    for v, p, i in zip(verdicts, models, (4, 5, 6), strict=True):
        assert v.settings["trajectory"]["params"] == p.to_dict()
        assert v.settings["trajectory"]["settings"]["index"] == i
    with pytest.raises(TypeError, match="Solution"):
        chaoscam.classify(sol.sections)


def test_a_verdict_the_step_decides_is_checked_at_half_the_step_unasked():
    """(omega, xi) = (25, 0.5), the issue's case: at the default dt the run lies on a period-7
    orbit in 7 bands of 1-6e-5 rad that the grid's multipliers call unstable (7-band chaos);
    at dt/2 kicks return to it (periodic 7) and at dt/4 it is certified. classify checks such
    a verdict at dt/2 by itself and answers undetermined, saying why, not chaotic."""
    run = simulate(Params(xi=0.5, omega=25.0), duration=120.0, transient=60.0, series=False)
    (v,) = classify(run)
    assert v.label == "undetermined"
    assert any("halving the step changes the verdict" in r for r in v.reasons)
    assert v.settings["step_check"]["grid_label"] == "chaotic"
    assert (v.settings["step_check"]["label"], v.settings["step_check"]["period"]) == (
        "periodic",
        7,
    )
