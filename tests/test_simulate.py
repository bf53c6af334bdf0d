"""simulate(): physics invariants, statuses, outputs, reproducibility."""

import math
import subprocess
import sys
import warnings

import numpy as np
import pandas as pd
import pytest

from chaoscam import Numerics, ParameterError, Params, Status, simulate
from chaoscam.model import gap, gap_rate


@pytest.mark.filterwarnings("ignore:dt = .* resolves")
def test_free_flight_conserves_energy():
    """Without contact the follower is a pendulum: energy conserved to 1e-9 relative over 1 s."""
    p = Params(x_O=1.0, y_O=1.0, theta_f0=-math.pi / 2 + 0.5, omega_f0=0.0)
    tr = simulate(p, duration=1.0, output_dt=1e-3)
    assert tr.ok and tr.stats["n_impacts"] == 0 and not tr.series.contact.any()
    s = tr.series
    energy = 0.5 * p.inertia * s.omega_f**2 + 0.5 * p.m * p.g * p.l * np.sin(s.theta_f)
    assert np.max(np.abs(energy - energy.iloc[0])) / abs(energy.iloc[0]) <= 1e-9
    assert np.ptp(s.theta_f) > 0.9  # it really swung


@pytest.fixture(scope="module")
def default_run():
    return simulate(duration=5.0)


def test_impact_law_at_every_impact(default_run):
    """At each applied impact delta ~ 0 and the gap rate reverses, d(delta)+ = -xi d(delta)-;
    at a chattering end (approach slower than v_chatter) it is 0 (plastic closure)."""
    p = default_run.params
    imp = default_run.impacts
    assert len(imp) > 10
    d = gap(p, imp.t.values, imp.theta_f.values)
    before = gap_rate(p, imp.t.values, imp.theta_f.values, imp.omega_before.values)
    after = gap_rate(p, imp.t.values, imp.theta_f.values, imp.omega_after.values)
    assert np.max(np.abs(d)) < 1e-11
    np.testing.assert_allclose(before, imp.gap_rate_before.values, rtol=1e-12)
    end = (imp["kind"] == "chatter_end").to_numpy()
    np.testing.assert_allclose(after[~end], -p.xi * before[~end], rtol=1e-9, atol=1e-12)
    np.testing.assert_allclose(after[end], 0.0, atol=1e-12)
    assert np.all(-before[end] < p.v_chatter) and np.all(-before[~end] >= p.v_chatter)
    assert np.all(-before > p.v_min)


def test_default_run_outputs(default_run):
    """Series, section and impacts have the documented columns and sane values."""
    tr = default_run
    assert tr.status is Status.OK
    assert list(tr.series.columns) == [
        "member",
        "t",
        "theta_f",
        "omega_f",
        "theta_fc",
        "gap",
        "contact",
        "F_n",
        "l_lambda",
    ]
    assert (tr.series.F_n >= 0).all() and (tr.series.F_n[~tr.series.contact] == 0).all()
    k = tr.section.k.values
    np.testing.assert_allclose(tr.section.t.values, k * tr.params.cam_period, rtol=1e-12)
    assert 0 < tr.stats["contact_fraction"] < 1
    assert "impacts" in tr.summary()


def test_transient_is_discarded():
    """Outputs start at the transient; section indices continue from ceil(t0 / T)."""
    tr = simulate(duration=2.0, transient=1.0)
    assert tr.series.t.min() >= 1.0 and tr.impacts.t.min() >= 1.0
    assert tr.section.k.iloc[0] == math.ceil(1.0 / tr.params.cam_period)


def test_sections_only_mode_keeps_no_series():
    """series=False keeps sections and impacts only, identical to the full run's."""
    a = simulate(duration=1.0, series=False)
    b = simulate(duration=1.0)
    assert a.series is None
    assert a.section.equals(b.section) and a.impacts.equals(b.impacts)


def test_same_seed_same_realization_and_indices_differ():
    """A realization is a pure function of (seed, index)."""
    p = Params(l_lambda_sigma=0.002)
    a = simulate(p, duration=2.0, seed=3, index=1, series=False)
    b = simulate(p, duration=2.0, seed=3, index=1, series=False)
    c = simulate(p, duration=2.0, seed=3, index=2, series=False)
    assert a.impacts.equals(b.impacts) and a.section.equals(b.section)
    n = min(len(a.impacts), len(c.impacts))
    assert not np.array_equal(a.impacts.l_lambda.values[:n], c.impacts.l_lambda.values[:n])


def test_line_length_is_redrawn_at_each_applied_impact_in_impact_mode():
    """In 'impact' mode every applied impact, micro-impacts included, carries a fresh draw."""
    tr = simulate(Params(l_lambda_sigma=0.002, resample="impact"), duration=2.0, series=False)
    lam = tr.impacts.l_lambda.values
    assert len(np.unique(lam)) == len(lam) and lam.min() > tr.params.l_min


def test_each_contact_has_its_own_line_in_contact_mode():
    """Default 'contact' mode: each macro impact draws a new line; the micro-impacts and the
    chattering end that follow it in the same contact keep it."""
    tr = simulate(Params(l_lambda_sigma=0.002), duration=2.0, series=False)
    imp = tr.impacts
    kind = imp["kind"].astype(str).to_numpy()
    lam = imp.l_lambda.to_numpy()
    macro = kind == "macro"
    assert macro.sum() >= 10 and (~macro).sum() > 10 * macro.sum()  # mostly micro-impacts
    assert len(np.unique(lam[macro])) == macro.sum()
    contact_line = pd.Series(np.where(macro, lam, np.nan)).ffill().to_numpy()
    after_first = np.arange(len(lam)) >= np.argmax(macro)
    np.testing.assert_array_equal(lam[after_first], contact_line[after_first])


def test_contact_resampling_makes_the_realization_independent_of_the_step():
    """The line lengths of a realization, at its macro impacts and its sections, are the same
    at dt and dt/2 under 'contact' resampling, although the micro-impact count changes with
    dt; under 'impact' resampling that count shifts the draws."""

    def lines(p, dt):
        tr = simulate(p, dt=dt, duration=2.0, seed=5, series=False)
        imp = tr.impacts
        return imp.l_lambda[imp["kind"] == "macro"].to_numpy(), tr.section.l_lambda.to_numpy()

    p = Params(l_lambda_sigma=0.002)
    (a, sa), (b, sb) = lines(p, 2e-6), lines(p, 1e-6)
    assert len(a) == len(b) >= 10
    np.testing.assert_array_equal(a, b)
    np.testing.assert_array_equal(sa, sb)
    (a, _), (b, _) = (
        lines(p.replace(resample="impact"), 2e-6),
        lines(p.replace(resample="impact"), 1e-6),
    )
    assert not np.array_equal(a, b)


def test_interval_resampling_changes_only_on_the_grid():
    """In 'interval' mode l_lambda changes only at multiples of resample_dt."""
    p = Params(l_lambda_sigma=0.002, resample="interval", resample_dt=0.05)
    s = simulate(p, duration=1.0, output_dt=1e-3).series
    changes = s.t.values[1:][np.diff(s.l_lambda.values) != 0]
    assert len(changes) >= 18
    prev = changes - 1e-3  # the change happened within the sample interval before
    j = np.ceil(prev / 0.05 - 1e-9)
    assert np.all(j * 0.05 <= changes + 1e-12)


def test_sigma_zero_is_the_deterministic_system():
    """sigma = 0 gives the same run for every seed."""
    a = simulate(duration=1.0, seed=1, series=False)
    b = simulate(duration=1.0, seed=2, series=False)
    assert a.impacts.equals(b.impacts)


def test_leaving_the_cam_is_a_labelled_status():
    """A contact point off the rod ends the run with LEFT_REACH, not an exception."""
    tr = simulate(Params(x_O=-0.58), duration=1.0)
    assert tr.status is Status.LEFT_REACH and "reach" in tr.message
    assert tr.status.label == "left_reach"


def test_unresolved_step_warns_and_ends_labelled():
    """A step far too large for the contact warns, and the run records it: a non-OK status,
    or (since grazes inside a step are located, the run may survive) the steps per contact
    period in its stats."""
    with pytest.warns(RuntimeWarning, match="dt"):
        tr = simulate(dt=2e-4, duration=2.0)
    assert tr.status in (Status.LEFT_REACH, Status.NON_FINITE, Status.PENETRATION) or (
        tr.stats["steps_per_contact_period"] < 1.0
    )


def test_chattering_without_v_min_does_not_hang():
    """With v_min = 0 every closing is an impact; the run still ends, with many impacts."""
    tr = simulate(Params(v_min=0.0), duration=1.0, series=False)
    assert tr.ok and tr.stats["n_impacts"] > 50


@pytest.mark.parametrize(
    "kwargs, field",
    [
        ({"duration": -1.0}, "duration"),
        ({"duration": 1.0, "transient": 2.0}, "transient"),
        ({"output_dt": 1e-9}, "output_dt"),
        ({"omgea": 1.0}, "omgea"),
    ],
)
def test_bad_run_settings_are_refused(kwargs, field):
    """Run settings are validated with a message naming the field."""
    with pytest.raises(ParameterError, match=field):
        simulate(**kwargs)


def test_compilation_is_cached_across_processes():
    """A second process loads the kernel from numba's cache instead of compiling it."""
    code = (
        "import chaoscam; from chaoscam.kernel._driver import run_alone_rk4; "
        "chaoscam.simulate(duration=0.01); print(sum(run_alone_rk4.stats.cache_hits.values()))"
    )
    subprocess.run([sys.executable, "-c", code], check=True, capture_output=True)
    out = subprocess.run([sys.executable, "-c", code], check=True, capture_output=True, text=True)
    assert int(out.stdout.strip()) >= 1


def test_parquet_round_trip_keeps_provenance(tmp_path):
    """to_parquet stores the series and the settings used."""
    import json

    import pyarrow.parquet as pq

    tr = simulate(duration=0.5)
    path = tmp_path / "t.parquet"
    tr.to_parquet(path)
    table = pq.read_table(path)
    meta = json.loads(table.schema.metadata[b"chaoscam.trajectory"])
    assert meta["params"]["omega"] == 28.7 and meta["settings"]["duration"] == 0.5
    assert table.num_rows == len(tr.series)


@pytest.mark.parametrize("duration", [20.0, 0.05], ids=["20 s", "one section point"])
def test_a_trajectory_file_reads_back_its_section_and_impacts_bit_for_bit(tmp_path, duration):
    """The section and impacts kept in the file's metadata read back exactly, with their
    dtypes: to_json kept 15 significant digits (91 of 92 section points differed in the
    last bits) and a lone section point at t = 0.0 read back as an integer column."""
    from chaoscam import load_trajectory

    tr = simulate(Params(l_lambda_sigma=0.001), duration=duration)
    tr.to_parquet(tmp_path / "t.parquet")
    back = load_trajectory(tmp_path / "t.parquet")
    for name in ("section", "impacts"):
        pd.testing.assert_frame_equal(getattr(back, name), getattr(tr, name), check_exact=True)


def test_no_gravity_is_a_run_not_a_crash():
    """g = 0 is allowed: the run ends with a status (the flight horizon has no gravity cap),
    instead of a ZeroDivisionError in the kernel."""
    tr = simulate(Params(g=0.0), duration=0.5, series=False)
    assert tr.status is Status.OK and len(tr.impacts) > 0


def test_a_spread_the_fractal_stiffness_ignores_is_warned():
    """With stiffness = 'fractal' (K_n independent of l_lambda) a positive l_lambda_sigma
    gets one warning naming the field; without a spread there is none."""
    p, num = Params(stiffness="fractal"), Numerics(dt=4e-7)
    with pytest.warns(RuntimeWarning, match="l_lambda_sigma = 0.002 m has no effect"):
        simulate(p.replace(l_lambda_sigma=0.002), num, duration=0.01, series=False)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        simulate(p, num, duration=0.01, series=False)


def test_unknown_field_in_params_names_it_like_replace():
    """Params(foo=1) raises the ParameterError of .replace (the field, close names, the known
    ones), not the dataclass's TypeError."""
    with pytest.raises(ParameterError, match=r"unknown parameter 'omgea'.*Did you mean omega"):
        Params(omgea=30.0)


@pytest.mark.parametrize(
    "changes, field",
    [
        (dict(integrator="adaptive", h_max=1e-12), "h_max"),
        (dict(resample="interval", resample_dt=1e-12, l_lambda_sigma=0.001), "resample_dt"),
    ],
)
def test_runs_that_would_take_hours_for_other_fields_than_dt_are_refused(changes, field):
    """The run-time estimate counts the adaptive path's steps of at most h_max and the step
    cuts of interval resampling, not only steps of dt: such runs are refused with the field
    named, instead of starting and never finishing."""
    with pytest.raises(ParameterError, match=rf"refused; shorten duration or raise {field}"):
        simulate(duration=0.5, **changes)


def test_summary_of_a_run_with_no_recorded_step_says_so():
    """A run that leaves the cam's reach before its first step has no contact fraction: the
    summary says n/a instead of printing nan."""
    tr = simulate(Params(x_O=-0.58), duration=1.0, series=False)
    assert "contact fraction: n/a (no step recorded)" in tr.summary()
    assert "nan" not in tr.summary()
