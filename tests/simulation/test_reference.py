"""The compiled path against the independent solve_ivp path, and step-size convergence."""

import numpy as np
import pytest

from chaoscam import Numerics, Params, simulate, simulate_reference

DURATION = 0.7  # three impacts after the initial compliant contact


# Integrator cross-checks are made with closings slower than 1 mm/s left to the compliant
# contact (the withdrawn v_min decision): from the initial contact the default v_min = 0 starts
# with a chattering sequence of micro-impacts whose times depend on rounding, which is not
# what these tests measure. The chattering limit has tests of its own (test_chattering.py).
CHECK = Params(v_min=1e-3)


@pytest.fixture(scope="module")
def reference():
    return simulate_reference(CHECK, DURATION)


def first_impacts(dt, n=3):
    tr = simulate(CHECK, Numerics(dt=dt), duration=DURATION, series=False)
    return tr.impacts.iloc[:n]


@pytest.mark.slow  # 11-17 s on 2 cores: a check of the check, run with -m slow
def test_reference_is_converged_at_its_default_tolerance(reference):
    """The reference moves < 2e-8 s, 1e-8 rad when its rtol is cut fourfold, to 2.5e-14 (near
    solve_ivp's floor of 100 eps): it is a reference."""
    tighter = simulate_reference(CHECK, DURATION, rtol=2.5e-14, atol=2.5e-16)
    a, b = reference.impacts.iloc[:3], tighter.impacts.iloc[:3]
    assert np.max(np.abs(a.t.values - b.t.values)) < 2e-8
    assert np.max(np.abs(a.theta_f.values - b.theta_f.values)) < 1e-8


def test_reference_sees_three_impacts(reference):
    """The reference run has at least three impacts to compare."""
    assert len(reference.impacts) >= 3


@pytest.mark.parametrize("dt, tol_t", [(2e-6, 1e-6), (1e-6, 2e-7)])
def test_numba_and_solve_ivp_agree_on_first_impacts(reference, dt, tol_t):
    """The first three impacts of a default run agree with solve_ivp (tol_t s, 1e-5 rad)."""
    ours = first_impacts(dt)
    ref = reference.impacts.iloc[:3]
    assert np.max(np.abs(ours.t.values - ref.t.values)) < tol_t
    assert np.max(np.abs(ours.theta_f.values - ref.theta_f.values)) < 1e-5
    assert np.max(np.abs(ours.omega_before.values - ref.omega_before.values)) < 1e-3


def test_halving_the_step_leaves_first_impacts_unchanged():
    """dt 2e-6 -> 1e-6 moves the first three impacts by < 2e-6 s, and convergence is >= 3rd order.

    The error estimate |t(dt) - t(dt/2)| must shrink by at least 2^3 when dt is halved again.
    """
    a, b, c = (first_impacts(dt).t.values for dt in (2e-6, 1e-6, 5e-7))
    assert np.max(np.abs(a - b)) < 2e-6
    assert np.abs(a[0] - b[0]) < 2e-7
    assert np.all(np.abs(b - c) * 8 < np.abs(a - b))


def test_reference_and_kernel_sections_agree(reference):
    """The stroboscopic points before the first impacts agree to 1e-6 rad."""
    ours = simulate(CHECK, Numerics(dt=1e-6), duration=DURATION, series=False).section
    n = min(len(ours), len(reference.section))
    assert n >= 3
    assert np.max(np.abs(ours.theta_f.values[:n] - reference.section.theta_f.values[:n])) < 1e-6


def fast_impacts(num, n=10):
    imp = simulate(Params(), num, duration=20.0, series=False).impacts
    return imp[-imp.gap_rate_before > 0.01].iloc[:n]


def test_flight_merging_agrees_with_plain_fixed_step_on_impacts():
    """Merged flight steps (default) match plain RK4 on the first ten impacts to 1e-6 s, rad."""
    a = fast_impacts(Numerics(flight_merge=1))
    b = fast_impacts(Numerics())
    assert Numerics().flight_merge > 1 and len(a) == len(b) == 10
    assert np.max(np.abs(a.t.values - b.t.values)) < 1e-6
    assert np.max(np.abs(a.theta_f.values - b.theta_f.values)) < 1e-6


@pytest.mark.parametrize("changes", [{"xi": 0.2}, {"omega": 45.0}], ids=["xi0.2", "omega45"])
def test_flight_merging_agrees_on_periodic_sections(changes):
    """On periodic responses the 20 s stroboscopic sections agree to 1e-6 rad."""
    p = Params(**changes)
    a = simulate(p, Numerics(flight_merge=1), duration=20.0, series=False).section
    b = simulate(p, Numerics(), duration=20.0, series=False).section
    assert len(a) == len(b) > 90
    assert np.max(np.abs(a.theta_f.values - b.theta_f.values)) < 1e-6
    assert np.max(np.abs(a.omega_f.values - b.omega_f.values)) < 1e-5


def test_pausing_for_buffers_does_not_change_a_run():
    """A run sampled at every step (many buffer hand-backs) equals the sections-only run.

    4 s keep 2,000,001 rows, about 490 hand-backs of the 4,096-row series buffer, through
    19 sections and 3,352 impacts (sticking and chattering included); 20 s took 45 s here."""
    a = simulate(duration=4.0, series=False)
    b = simulate(duration=4.0, output_dt=2e-6)
    assert len(b.series) > 100 * 4096 and len(a.section) >= 15 and len(a.impacts) > 1000
    assert a.section.equals(b.section) and a.impacts.equals(b.impacts)


def test_a_process_that_simulated_can_fork_workers():
    """After simulate() in the parent, forked workers still run (fork-safe threading layer)."""
    import subprocess
    import sys

    code = (
        "import multiprocessing as mp, chaoscam\n"
        "chaoscam.simulate(duration=0.2, series=False)\n"
        "def f(i):\n"
        "    return len(chaoscam.simulate(duration=0.2, series=False).section)\n"
        "if __name__ == '__main__':\n"
        "    with mp.get_context('fork').Pool(2) as pool:\n"
        "        print(sum(pool.map(f, range(4))))\n"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120)
    assert out.returncode == 0 and out.stdout.strip() == "4", out.stderr


def _resolved(impacts):
    """Impacts with a resolved approach speed: closings slower than 1e-9 m/s, which the kernel
    sees right after a plastic closure at some steps (rounding of a zero gap rate), left out."""
    return impacts[-impacts.gap_rate_before > 1e-9].reset_index(drop=True)


@pytest.fixture(scope="module")
def chattering():
    return _resolved(simulate_reference(Params(), 0.002).impacts)


@pytest.mark.parametrize("dt, tol_t", [(2e-6, 3e-8), (1e-6, 1e-9)])
def test_reference_follows_the_chattering_of_the_default_model(chattering, dt, tol_t):
    """With v_min = 0 the reference resolves every micro-flight of the first chattering
    sequences (0.1-1 µs each, shorter than its solver steps): over the first 2 ms it applies
    the kernel's 106 impacts, of the same kinds, at the same times to tol_t (measured:
    1.3e-8 s at dt = 2e-6 s, 1.4e-10 s at 1e-6 s; the reference that searched closings from
    the surface saw 29 of them)."""
    ours = _resolved(simulate(Params(), Numerics(dt=dt), duration=0.002, series=False).impacts)
    assert len(chattering) == len(ours) >= 100
    np.testing.assert_array_equal(chattering.kind.to_numpy(), ours["kind"].cat.codes.to_numpy())
    assert np.max(np.abs(chattering.t.values - ours.t.values)) < tol_t
    assert np.max(np.abs(chattering.omega_after.values - ours.omega_after.values)) < 2 * tol_t


@pytest.mark.slow
def test_reference_and_kernel_agree_on_the_first_macro_impact_of_the_default_model():
    """After 18 ms of chattering (~820 impacts) and the sticking contact to 0.2 s, the first
    macro impact of the default model agrees with the reference to 3e-8 s at dt = 2e-6 s
    (measured 9.4e-9 s; 8.5e-10 s at dt = 1e-6 s). The reference before its flights were cut
    into provably open pieces stepped over the last chattering sequence and was 7.1e-7 s off,
    whatever the kernel's step."""
    ref = simulate_reference(Params(), 0.21).impacts
    ours = simulate(duration=0.21, series=False).impacts
    t_ref = ref.t[ref["kind"] == 0].iloc[0]
    t_ours = ours.t[ours["kind"] == "macro"].iloc[0]
    assert abs(t_ref - t_ours) < 3e-8
