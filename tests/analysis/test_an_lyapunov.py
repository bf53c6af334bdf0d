"""Tests of the Lyapunov routines: exponents from the equations and from series."""

import math
import warnings

import numpy as np
import pytest

from chaoscam.analysis import (
    DoubtfulEstimateWarning,
    lyapunov_benettin,
    lyapunov_benettin_map,
    lyapunov_from_series,
    lyapunov_spectrum_map,
)
from chaoscam.testsystems import (
    ball_impact_map,
    flow_advance,
    flow_trajectory,
    henon_jacobian,
    henon_step,
    logistic_jacobian,
    logistic_step,
    lorenz,
    period_one_orbit,
    rossler,
    ueda,
)

TWO_PI = 2 * math.pi


def test_logistic_r4_exponent_is_ln2():
    """The tangent-map exponent of the logistic map at r = 4 is ln 2 within 5 %."""
    res = lyapunov_spectrum_map(
        lambda x: logistic_step(x, 4.0),
        lambda x: logistic_jacobian(x, 4.0),
        [0.3],
        20_000,
        transient=100,
    )
    assert abs(res.largest / math.log(2) - 1) < 0.05


def test_henon_spectrum_and_its_sum():
    """Hénon: λ₁ ≈ 0.420 within 5 %, and λ₁ + λ₂ = ln b exactly (mean ln |det J|)."""
    res = lyapunov_spectrum_map(henon_step, henon_jacobian, [0.1, 0.1], 20_000, transient=100)
    assert abs(res.largest / 0.420 - 1) < 0.05
    assert math.isclose(res.exponents.sum(), math.log(0.3), rel_tol=1e-10)


def test_henon_two_trajectory_agrees_with_tangent_map():
    """Benettin's two-trajectory estimate on the Hénon map agrees with the QR estimate."""
    ben = lyapunov_benettin_map(henon_step, [0.1, 0.1], 20_000, transient=100)
    qr = lyapunov_spectrum_map(henon_step, henon_jacobian, [0.1, 0.1], 20_000, transient=100)
    assert abs(ben.exponent - qr.largest) < 4 * math.hypot(ben.stderr, qr.stderr[0]) + 0.005


def test_lorenz_exponent():
    """Lorenz (10, 28, 8/3): λ₁ ≈ 0.906 within 5 % (Benettin on the equations)."""
    res = lyapunov_benettin(
        flow_advance(lorenz(), 0.005),
        [1.0, 1.0, 20.0],
        renorm_time=0.5,
        n_renorm=4000,
        transient_time=50.0,
    )
    assert abs(res.exponent / 0.906 - 1) < 0.05
    assert res.message == ""


def test_rossler_exponent():
    """Rössler (0.2, 0.2, 5.7): λ₁ ≈ 0.0714 within 10 % (Benettin on the equations)."""
    res = lyapunov_benettin(
        flow_advance(rossler(), 0.01),
        [1.0, 1.0, 0.0],
        renorm_time=2.0,
        n_renorm=10_000,
        transient_time=500.0,
    )
    assert abs(res.exponent / 0.0714 - 1) < 0.10


@pytest.mark.slow  # 6-8 s: a textbook system; the model's exponents are tested by default
def test_ueda_exponent():
    """Ueda (k = 0.05, B = 7.5): λ₁ ≈ 0.0999 within 5 % for the (x, x') directions.

    Single trajectories of 8000 forcing periods scatter by ±0.002 (finite-time
    fluctuations), so the estimate is the mean over 8 seeded initial conditions.
    """
    rng = np.random.default_rng(np.random.SeedSequence(0))
    adv = flow_advance(ueda(), TWO_PI / 400)
    values = [
        lyapunov_benettin(
            adv,
            [*rng.uniform(-3.0, 3.0, 2), 0.0],
            renorm_time=TWO_PI,
            n_renorm=8000,
            transient_time=100 * TWO_PI,
            components=(0, 1),
            seed=i,
        ).exponent
        for i in range(8)
    ]
    assert abs(np.mean(values) / 0.0999 - 1) < 0.05


def test_autonomous_limit_cycle_has_zero_exponent():
    """Rössler c = 2.5 (a limit cycle): λ₁ = 0, the exponent along the flow."""
    res = lyapunov_benettin(
        flow_advance(rossler(c=2.5), 0.01),
        [1.0, 1.0, 0.0],
        renorm_time=2.0,
        n_renorm=2000,
        transient_time=500.0,
    )
    assert abs(res.exponent) < 0.003


def test_forced_periodic_response_has_negative_exponent():
    """Weakly forced Duffing: the (x, v) exponents of a periodic response are -k/2 < 0."""
    res = lyapunov_benettin(
        flow_advance(ueda(b=0.3), TWO_PI / 200),
        [0.1, 0.0, 0.0],
        renorm_time=TWO_PI,
        n_renorm=1000,
        transient_time=300 * TWO_PI,
        components=(0, 1),
    )
    assert abs(res.exponent / -0.025 - 1) < 0.05


def test_nonsmooth_map_matches_floquet_multiplier():
    """Benettin on the bouncing ball's impact map gives ln |μ_max| of the period-one orbit."""
    gamma, e = 1.5, 0.5
    x, jac, ok = period_one_orbit(gamma, e, guess=(0.9, 3.1))
    assert ok
    expected = math.log(np.max(np.abs(np.linalg.eigvals(jac))))
    res = lyapunov_benettin_map(
        lambda s: ball_impact_map(s, gamma, e), [x[0], x[1] + 1e-3], 3000, transient=500, d0=1e-9
    )
    assert abs(res.exponent / expected - 1) < 0.02


def test_collapsed_separation_is_reported_not_raised():
    """A superstable map (x -> 0.5) merges the trajectories: -inf with a message."""
    res = lyapunov_benettin_map(lambda s: np.full_like(s, 0.5), [0.2], 100)
    assert res.exponent == -math.inf and "merged" in res.message


def test_series_estimate_for_lorenz():
    """Rosenstein's estimate from a Lorenz x(t) series is within 20 % of 0.906."""
    _, s = flow_trajectory(
        lorenz(), [1.0, 1.0, 20.0], dt=0.005, n_samples=20_000, sample_every=2, transient_time=50.0
    )
    res = lyapunov_from_series(s[:, 0], 0.01)
    assert res.stride == 10 and res.n_used == 2000
    assert abs(res.exponent / 0.906 - 1) < 0.20


def test_series_estimate_flags_doubtful_input():
    """Constant or short series are flagged doubtful, with a DoubtfulEstimateWarning."""
    with pytest.warns(DoubtfulEstimateWarning):
        res = lyapunov_from_series(np.ones(3000), 0.01)
    assert res.doubtful and math.isnan(res.exponent)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", DoubtfulEstimateWarning)
        short = lyapunov_from_series(np.sin(np.arange(300) * 0.3), 0.1)
    assert short.doubtful


def test_series_eckmann_on_lorenz_is_doubtful():
    """Eckmann's estimate on an oversampled Lorenz series fails its flow check (no zero)."""
    _, s = flow_trajectory(
        lorenz(), [1.0, 1.0, 20.0], dt=0.005, n_samples=20_000, sample_every=2, transient_time=50.0
    )
    res = lyapunov_from_series(s[:, 0], 0.01, method="eckmann", warn=False)
    assert res.doubtful and res.exponents.size == 4


def test_jump_between_the_trajectories_is_flagged():
    """A jump separating the two trajectories (an impact between them) is flagged."""

    def advance(state, duration):
        return state + duration * (1.0 if state[0] > 0.5 else 0.0) * np.array([1.0])

    res = lyapunov_benettin(
        advance, [0.5 - 2e-9], renorm_time=1.0, n_renorm=5, n_align=0, d0=1e-8, seed=1
    )
    assert "linear regime" in res.message
