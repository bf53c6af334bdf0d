"""Tests of the Lyapunov exponents: repeated QR on map Jacobians (spectrum_from_jacobians) on
textbook systems with known exponents, and the estimates from a series."""

import math
import warnings

import numpy as np
import pytest

from chaoscam.analysis import DoubtfulEstimateWarning, lyapunov_from_series, spectrum_from_jacobians
from chaoscam.testsystems import (
    flow_trajectory,
    henon_jacobian,
    henon_step,
    logistic_jacobian,
    logistic_step,
    lorenz,
)


def _jacobians(step, jacobian, x0, n, transient=100):
    """The Jacobians J_k = DP(x_{k-1}) along n iterates of the orbit of ``step`` from x0."""
    x = np.asarray(x0, dtype=float)
    for _ in range(transient):
        x = step(x)
    out = []
    for _ in range(n):
        out.append(jacobian(x))
        x = step(x)
    return np.array(out)


def _henon_jacobians(n):
    """The Hénon map's (a = 1.4, b = 0.3) Jacobians along n iterates of an orbit."""
    return _jacobians(henon_step, henon_jacobian, [0.1, 0.1], n)


def test_henon_spectrum_and_its_sum():
    """Hénon orbit: λ₁ = 0.419 (within 3σ), λ₂ = -1.623 per iterate (2 %), λ₁ + λ₂ = ln 0.3."""
    spec = spectrum_from_jacobians(_henon_jacobians(20_000), 1.0)
    assert spec.n_periods == 20_000
    assert abs(spec.exponents[0] / 0.419 - 1) < 0.02
    assert abs(spec.exponents[1] / -1.623 - 1) < 0.02
    assert abs(spec.exponents[0] - 0.4192) < 3 * spec.stderr[0]
    assert math.isclose(spec.exponents.sum(), math.log(0.3), rel_tol=1e-12)
    assert math.isclose(spec.det_log, math.log(0.3), rel_tol=1e-12)


def test_gram_schmidt_matches_householder_qr():
    """The QR growths ln R_kk equal numpy's Householder QR (an independent path) to 1e-12."""
    jac = _henon_jacobians(2000)
    q, local = np.eye(2), []
    for m in jac:
        q, r = np.linalg.qr(m @ q)
        q = q * np.sign(np.diag(r))
        local.append(np.log(np.abs(np.diag(r))))
    spec = spectrum_from_jacobians(jac, 1.0)
    np.testing.assert_allclose(spec.local, local, rtol=0, atol=1e-12)


def test_logistic_r4_exponent_is_ln2():
    """Logistic r = 4 as diag(f'(x_k), 1/2): λ₁ = ln 2 within 1 %, λ₂ = ln(1/2) exactly."""
    f = _jacobians(
        lambda x: logistic_step(x, 4.0), lambda x: logistic_jacobian(x, 4.0), [0.3], 20_000
    )
    jac = np.zeros((len(f), 2, 2))
    jac[:, 0, 0] = f[:, 0, 0]
    jac[:, 1, 1] = 0.5
    spec = spectrum_from_jacobians(jac, 1.0)
    assert abs(spec.exponents[0] / math.log(2) - 1) < 0.01
    assert math.isclose(spec.exponents[1], math.log(0.5), rel_tol=1e-12)


def test_linear_map_gives_its_log_eigenvalues_per_unit_time():
    """A constant non-normal map (eigenvalues 3, 0.2; 0.5 s an iterate): λ_i = ln|μ_i| / 0.5."""
    p = np.array([[1.0, 1.0], [0.5, -1.0]])
    a = p @ np.diag([3.0, 0.2]) @ np.linalg.inv(p)
    spec = spectrum_from_jacobians(np.repeat(a[None], 200, axis=0), 0.5)
    assert spec.exponents == pytest.approx([math.log(3) / 0.5, math.log(0.2) / 0.5], rel=0.01)


def test_complex_multiplier_pair_gives_its_modulus():
    """A rotation scaled by 0.9 (a complex multiplier pair) gives λ₁ = λ₂ = ln 0.9."""
    c, s = math.cos(0.7), math.sin(0.7)
    rot = 0.9 * np.array([[c, -s], [s, c]])
    spec = spectrum_from_jacobians(np.repeat(rot[None], 200, axis=0), 1.0)
    assert spec.exponents == pytest.approx([math.log(0.9)] * 2, rel=1e-9)


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
