"""The tangent dynamics through the impacts: Jacobians, invariants, spectrum, periodic orbits
(chaoscam/verdict/_orbits.py and the kernel's tangent it reads)."""

from __future__ import annotations

import math

import numpy as np
import pytest

from chaoscam import Numerics, ParameterError, Params, simulate
from chaoscam.analysis import spectrum_from_jacobians
from chaoscam.verdict import lyapunov_spectrum, periodic_orbit, stroboscopic_map
from chaoscam.verdict._orbits import _MapRunner

SMOOTH = Params(xi=0.2)  # one macro impact a period, no chattering: a period-1 response
ADAPTIVE = Numerics(integrator="adaptive")


def _fd_jacobian(run, x, eps):
    cols = [(run(x + eps * e)[0] - run(x - eps * e)[0]) / (2 * eps) for e in np.eye(2)]
    return np.column_stack(cols)


@pytest.mark.parametrize("params", [SMOOTH, Params()], ids=["xi=0.2", "default"])
def test_map_jacobian_matches_finite_differences(params):
    """Through flight, impacts (saltation) and compliant contact the tangent equals the central
    difference of the stroboscopic map where that map is smooth (periods without chattering).

    The map itself is smooth only to the event tolerance: located times jitter by ~1e-12 s,
    which moves the state by ~5e-12 after a jump, so a difference quotient with step eps
    carries noise ~5e-12/eps; eps = 1e-6 keeps it near 1e-5 of J."""
    tr = simulate(params, duration=25.0, transient=20.0, series=False)
    run = _MapRunner(params, Numerics(), 1)
    checked = 0
    for x in tr.section[["theta_f", "omega_f"]].to_numpy()[:8]:
        _, jac, _ = run(x)
        fd6 = _fd_jacobian(run, x, 1e-6)
        fd7 = _fd_jacobian(run, x, 1e-7)
        if np.abs(fd6 - fd7).max() > 1e-3 * np.abs(fd6).max():
            continue  # the map is not smooth at this scale here (a chattering sequence)
        assert np.abs(jac - fd6).max() <= 1e-4 * np.abs(fd6).max()
        checked += 1
    assert checked >= 4


def test_liouville_invariant_per_period():
    """ln|det J_k| equals the divergence integral plus 2 ln(xi) per restitution jump (det S =
    xi^2), period by period, to 1e-6."""
    p = SMOOTH
    tr = simulate(p, duration=30.0, transient=10.0, series=False, tangent=True)
    t_sec = tr.section["t"].to_numpy()
    jumps = np.histogram(tr.impacts["t"].to_numpy(), bins=np.r_[t_sec[0] - p.cam_period, t_sec])[0]
    lhs = np.log(np.abs(np.linalg.det(tr.jacobians)))
    rhs = tr.divergence + 2.0 * math.log(p.xi) * jumps
    assert np.all(jumps[1:] >= 1)
    assert np.allclose(lhs[1:], rhs[1:], rtol=0, atol=1e-6)


def test_spectrum_sum_equals_mean_log_determinant():
    """lambda_1 + lambda_2 from QR equals the time average of ln|det J_k| (relative 1e-3)."""
    spec = lyapunov_spectrum(SMOOTH, duration=40.0, transient=20.0)
    assert np.isfinite(spec.exponents).all()
    assert spec.exponents.sum() == pytest.approx(spec.det_log, rel=1e-3)


def test_tangent_does_not_change_the_motion():
    """The state is computed by the same operations with and without the tangent."""
    a = simulate(duration=3.0, series=False)
    b = simulate(duration=3.0, series=False, tangent=True)
    assert np.array_equal(a.section.to_numpy(), b.section.to_numpy())
    assert np.array_equal(
        a.impacts.drop(columns="kind").to_numpy(), b.impacts.drop(columns="kind").to_numpy()
    )


@pytest.mark.parametrize(
    "numerics",
    [Numerics(flight_merge=1), ADAPTIVE],
    ids=["rk4 unmerged", "adaptive"],
)
@pytest.mark.parametrize("periods", [20.0, 20.37, 20.999], ids=["on", "inside", "just before"])
def test_tangent_skipped_in_the_transient_changes_no_recorded_jacobian(numerics, periods):
    """The tangent is carried only from shortly before the recording starts: the Jacobians
    written at recorded sections are those of a run that records (so carries the tangent)
    from t = 0, to the bit, whether the recording starts on a section time, inside a period
    or just before a section. (Flight is not merged on RK4 here: a merged block may not
    cross the recording's start, so with merging the states themselves depend on it.)"""
    p = Params()
    T = p.cam_period
    full = simulate(p, numerics, duration=25 * T, tangent=True, series=False)
    late = simulate(p, numerics, duration=25 * T, transient=periods * T, tangent=True, series=False)
    k0 = int(late.section["k"].iloc[0])
    assert len(late.section) >= 3
    same = full.section["k"].to_numpy() >= k0
    np.testing.assert_array_equal(full.section[same].to_numpy(), late.section.to_numpy())
    np.testing.assert_array_equal(full.jacobians[same], late.jacobians)


def test_spectrum_of_known_matrices():
    """QR on a constant diagonal map gives its log eigenvalues; a singular step gives -inf."""
    jac = np.repeat(np.diag([3.0, 0.5])[None], 100, axis=0)
    spec = spectrum_from_jacobians(jac, 2.0)
    assert spec.exponents == pytest.approx([math.log(3) / 2, math.log(0.5) / 2])
    jac[10] = np.array([[1.0, 2.0], [2.0, 4.0]])
    spec = spectrum_from_jacobians(jac, 1.0)
    assert math.isfinite(spec.exponents[0]) and spec.exponents[1] == -math.inf


def test_a_periodic_response_has_a_negative_exponent():
    """A period-1 response (e = 0.02 m) contracts: lambda_1 < 0, clearly below the zero band
    (the classifier's is 0.01 per iterate, 0.05 1/s); the default (8-band chaos) has
    lambda_1 > 0 beyond 2 standard errors."""
    periodic = lyapunov_spectrum(Params(e=0.02), duration=20.0, transient=10.0)
    assert periodic.exponents[0] < -1.0
    chaotic = lyapunov_spectrum(Params(), duration=60.0, transient=20.0)
    assert chaotic.exponents[0] > 2.0 * chaotic.stderr[0] > 0


def test_the_spectrum_of_a_solution_is_that_of_its_realization():
    """Given a one-member solution solved with the tangent, the spectrum is the one
    lyapunov_spectrum solves for the same realization, to the bit, with its window and
    realization recorded; a solution without Jacobians, or with numerics besides, is refused."""
    p = Params(l_lambda_sigma=0.002)
    run = simulate(p, duration=20.0, transient=10.0, seed=3, index=1, tangent=True)
    a = lyapunov_spectrum(run)
    b = lyapunov_spectrum(p, duration=20.0, transient=10.0, seed=3, index=1)
    assert np.array_equal(a.exponents, b.exponents) and np.array_equal(a.local, b.local)
    assert (a.settings["seed"], a.settings["index"]) == (3, 1)
    c = lyapunov_spectrum(p, duration=20.0, transient=10.0, seed=3, index=2)
    assert not np.array_equal(c.exponents, a.exponents)  # another realization
    with pytest.raises(ValueError, match="no Jacobians"):
        lyapunov_spectrum(simulate(p, duration=2.0))
    with pytest.raises(ParameterError, match="not both"):
        lyapunov_spectrum(run, Numerics())


def test_a_failed_or_too_short_run_says_so():
    """A run that leaves the cam's reach has no spectrum: a ValueError naming its status;
    one too short for the batch means warns and says to lengthen the recorded time; a
    transient longer than the run names the field."""
    with pytest.raises(ValueError, match="LEFT_REACH"):
        lyapunov_spectrum(Params(x_O=-0.58), duration=1.0, transient=0.0)
    with pytest.warns(RuntimeWarning, match="lengthen the recorded time"):
        spec = lyapunov_spectrum(Params(), duration=2.0, transient=0.0)
    assert math.isnan(spec.stderr[0])
    with pytest.raises(ParameterError, match="transient"):
        lyapunov_spectrum(Params(), duration=1.0, transient=2.0)


def test_periodic_orbit_certified_for_period_one():
    """xi = 0.2 settles on a period-1 orbit: Newton converges from a section point, the
    multipliers lie inside the unit circle and equal the eigenvalues of a finite-difference
    monodromy, and the run sits on the orbit."""
    tr = simulate(SMOOTH, duration=60.0, transient=40.0, series=False)
    pts = tr.section[["theta_f", "omega_f"]].to_numpy()
    orbit = periodic_orbit(SMOOTH, pts[-1], 1)
    assert orbit.converged and orbit.certified and orbit.period == 1
    run = _MapRunner(SMOOTH, Numerics(), 1)
    fd = _fd_jacobian(run, orbit.points[0], 1e-6)  # eps: see the test above
    assert np.sort(np.abs(orbit.multipliers)) == pytest.approx(
        np.sort(np.abs(np.linalg.eigvals(fd))), rel=1e-4
    )
    assert orbit.distance(pts[-20:]) < 1e-6
    assert orbit.wall_time < 1.0


def test_periodic_orbit_reduces_to_least_period():
    """Seeded for period 2 on a period-1 orbit, shooting reports period 1."""
    tr = simulate(SMOOTH, duration=60.0, transient=40.0, series=False)
    orbit = periodic_orbit(SMOOTH, tr.section[["theta_f", "omega_f"]].to_numpy()[-1], 2)
    assert orbit.period == 1


def test_stroboscopic_map_refuses_random_model():
    """Periodic orbits need the deterministic model: a clear error naming the field."""
    with pytest.raises(Exception, match="l_lambda_sigma"):
        stroboscopic_map(Params(l_lambda_sigma=0.001), (0.0, 0.0), 1)


def test_adaptive_path_carries_the_tangent_where_the_map_is_smooth():
    """integrator='adaptive' (an RK4 step of V along each DOP853 step): the map's Jacobian
    equals central differences to 1e-4 and the spectrum equals the RK4 one to 1e-2 for a
    flight-and-impact response (xi = 0.2). Where chattering dominates the two disagree
    (measured on the default: -21 against +3.2 1/s), which is why the classifier takes the
    exponent on the RK4 grid."""
    p = SMOOTH
    tr = simulate(p, ADAPTIVE, duration=25.0, transient=20.0, series=False)
    x0 = tr.section[["theta_f", "omega_f"]].to_numpy()[0]
    period = p.cam_period

    def strobe(x, tangent=False):
        q = p.replace(theta_f0=float(x[0]), omega_f0=float(x[1]))
        r = simulate(q, ADAPTIVE, duration=period + 1e-5, series=False, tangent=tangent)
        i = r.section.index[r.section["k"] == 1][0]
        point = r.section.loc[i, ["theta_f", "omega_f"]].to_numpy(float)
        return point, (r.jacobians[i] if tangent else None)

    _, jac = strobe(x0, True)
    fd = np.column_stack(
        [(strobe(x0 + 1e-6 * e)[0] - strobe(x0 - 1e-6 * e)[0]) / 2e-6 for e in np.eye(2)]
    )
    assert np.abs(jac - fd).max() <= 1e-4 * np.abs(fd).max()
    a = lyapunov_spectrum(SMOOTH, duration=60.0, transient=30.0)
    b = lyapunov_spectrum(SMOOTH, ADAPTIVE, duration=60.0, transient=30.0)
    assert b.exponents == pytest.approx(a.exponents, rel=1e-2)


def test_floquet_multipliers_converge_under_step_refinement():
    """The certified orbits' multipliers converge as dt is halved: exactly unchanged (8
    digits) for a flight-and-impact orbit (xi = 0.2), and converging for the chattering-and-
    sticking period 1 at e = 0.02 m (measured 0.089, 0.0087, 0.0049, 0.0043 at dt = 2e-6 ...
    2.5e-7 s: the differences fall ~6x per halving, order ~2.5; the default step overstates
    the multiplier 20x, never its stability). Before micro-flights shorter than a step were
    located the sequence was 0.50, 0.015, 0.0058, 0.0043 with J moving 4x per halving."""
    for changes, seed_x, exact in (
        ({"xi": 0.2}, None, True),
        ({"e": 0.02}, (-3.7812e-09, 1.1038714), False),
    ):
        p = Params(**changes)
        if seed_x is None:
            x = simulate(p, duration=80.0, transient=60.0, series=False).section
            seed_x = x[["theta_f", "omega_f"]].to_numpy()[-1]
        mu = []
        for dt in (2e-6, 1e-6, 5e-7, 2.5e-7):
            orbit = periodic_orbit(p, seed_x, 1, numerics=Numerics(dt=dt), tol=1e-9)
            assert orbit.certified
            mu.append(float(np.abs(orbit.multipliers).max()))
        steps = np.abs(np.diff(mu))
        if exact:
            assert steps.max() < 1e-7 * mu[0]
        else:
            assert steps[0] > 3 * steps[1] > 9 * steps[2]
            assert steps[2] < 0.25 * mu[-1]


def test_impacts_per_period_converge_under_step_refinement():
    """Every micro-flight of a chattering sequence is located whatever the step, so the
    impacts applied over one period of the sticking orbit (e = 0.02 m) no longer grow as dt
    shrinks (measured 294, 294, 295, 295 at dt = 2e-6 ... 2.5e-7 s; 230, 263, 282, 292 when
    micro-flights shorter than a step were stepped over)."""
    p = Params(e=0.02, theta_f0=-3.7812e-09, omega_f0=1.1038714)
    counts = [
        len(simulate(p, Numerics(dt=dt), duration=p.cam_period, series=False).impacts)
        for dt in (1e-6, 5e-7, 2.5e-7)
    ]
    assert max(counts) - min(counts) <= 0.02 * max(counts)


STICKING_SEED = (-3.7812e-09, 1.1038714)  # the e = 0.02 m sticking period 1's section point


def _adaptive_period(p, x):
    """(P(x), the stroboscopic Jacobian over that period, the impacts in it) on the adaptive
    integrator."""
    q = p.replace(theta_f0=float(x[0]), omega_f0=float(x[1]))
    tr = simulate(q, ADAPTIVE, duration=1.5 * q.cam_period, series=False, tangent=True)
    assert len(tr.section) == 2  # the sections at t = 0 and t = T
    impacts = tr.impacts[tr.impacts["t"] <= q.cam_period]
    return tr.section[["theta_f", "omega_f"]].to_numpy()[1], tr.jacobians[1], impacts


def test_adaptive_path_locates_the_sticking_orbits_micro_flights():
    """The adaptive path applies as many impacts over one period of the sticking orbit (e =
    0.02 m) as converged RK4 (295 at dt = 5e-7 and 2.5e-7 s; adaptive 295, 5/201/89 by
    kind). Before micro-flights from the surface were bracketed and a rebound's opening was
    taken as flight it applied 273 (5/198/70): a zero-length opening after each rebound
    filled the chattering guard, which then stepped over the rest."""
    p = Params(e=0.02, theta_f0=STICKING_SEED[0], omega_f0=STICKING_SEED[1])
    fine = Numerics(dt=2.5e-7)
    ref = len(simulate(p, fine, duration=p.cam_period, series=False).impacts)
    _, _, impacts = _adaptive_period(p, STICKING_SEED)
    assert abs(len(impacts) - ref) <= 0.02 * ref


def test_adaptive_stroboscopic_jacobian_on_the_sticking_orbit():
    """On the sticking period 1 (e = 0.02 m, the orbit from RK4 shooting at dt = 2.5e-7 s) the
    adaptive path's map returns to the orbit (1.8e-10 rad/s), its Jacobian's column along
    theta_f' matches central differences of its own map (measured 1.9 % and 0.8 %: the map
    jitters at ~1e-9, fwd and bwd quotients differ by 20 %), and its dominant multiplier is
    RK4's at dt = 2.5e-7 s within 5 % (measured 0.004154 against 0.004272; RK4's sequence
    0.089, 0.0087, 0.0049, 0.0043 extrapolates to ~0.00415). Before the port: 6.8e-6, with
    the tangent taken as one RK4 step per DOP853 step 0.00381, and the map missed the orbit
    by 8e-7 rad/s. The column along theta_f cannot be checked so: moving theta_f by even
    1e-9 rad on this contact (sticking) section point changes the impacts of the period
    from 294 to 135...1275, so the map is not differentiable at any resolvable scale there."""
    p = Params(e=0.02)
    orbit = periodic_orbit(p, STICKING_SEED, 1, numerics=Numerics(dt=2.5e-7), tol=1e-9)
    assert orbit.certified
    mu_rk4 = float(np.abs(orbit.multipliers).max())
    x = np.asarray(orbit.points[0], dtype=float)
    px, jac, _ = _adaptive_period(p, x)
    assert np.abs(px - x).max() < 1e-8
    eps = 1e-6
    e2 = np.array([0.0, eps])
    fd = (_adaptive_period(p, x + e2)[0] - _adaptive_period(p, x - e2)[0]) / (2 * eps)
    assert np.all(np.abs(jac[:, 1] - fd) <= 0.05 * np.abs(fd))
    mu = float(np.abs(np.linalg.eigvals(jac)).max())
    assert abs(mu - mu_rk4) <= 0.05 * mu_rk4


@pytest.mark.slow
def test_default_exponent_converges_under_step_halving():
    """The default (chaotic, 8 narrow bands) lambda_1 converges with dt once every micro-flight
    is located and the clock is exact (cam angle reduced exactly, substeps ending on
    representable times): measured over 300 s (two initial conditions) 2.54, 1.74, 1.51, 1.47,
    1.32 +- 0.05 1/s at dt = 2e-6 ... 1.25e-7 s, the adaptive path 1.39-1.48 whatever its dt.
    dt = 5e-7 and 2.5e-7 agree within three combined standard errors, and so do dt = 2.5e-7
    and the adaptive path (with the naive clock RK4 gave 2.45, 2.26, 2.06 at 5e-7 ... 1.25e-7
    and the adaptive path 1.48)."""
    p, window = Params(), dict(duration=360.0, transient=60.0)
    a = lyapunov_spectrum(p, Numerics(dt=5e-7), **window)
    b = lyapunov_spectrum(p, Numerics(dt=2.5e-7), **window)
    c = lyapunov_spectrum(p, ADAPTIVE, **window)
    assert a.exponents[0] > 0 and b.exponents[0] > 0 and c.exponents[0] > 0
    for x, y in ((a, b), (b, c)):
        gap = abs(x.exponents[0] - y.exponents[0])
        assert gap <= 3.0 * math.hypot(x.stderr[0], y.stderr[0])


def test_least_period_keeps_a_freshly_doubled_orbit():
    """Fractal stiffness, D = 1.4, G = 1e-9 m: a period-16 orbit whose halves lie ~1e-7 rad
    apart (just past a flip) is period 16, not the period 8 a bound of 10 tol (1e-6 rad)
    read it as; 160 s runs at dt and dt/2 repeat every 16 periods to 1e-7 rad, every 8 only
    to 2e-6."""
    p, num = Params(stiffness="fractal", G=1e-9, D=1.4), Numerics(dt=3.9e-7)
    tr = simulate(p, num, duration=20.0, transient=10.0, series=False)
    orbit = periodic_orbit(p, tr.section[["theta_f", "omega_f"]].to_numpy()[-1], 16, numerics=num)
    assert orbit.converged and orbit.period == 16
