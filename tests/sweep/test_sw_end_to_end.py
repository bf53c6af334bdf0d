"""The sweeps with the package's verdict (chaoscam.classify)."""

import numpy as np
import pytest

from chaoscam.sweep import Axis, bifurcation, regime_map


def test_regime_map_with_the_package_classifier():
    """Every realization gets one of the classifier's labels or a status label; the
    deterministic cell (sigma = 0) runs once, the random one twice."""
    m = regime_map(
        Axis("l_lambda", (0.008,)),
        Axis("l_lambda_sigma", (0.0, 0.002)),
        realizations=2,
        duration=4.0,
        workers=1,
    )
    allowed = {"periodic", "quasiperiodic", "chaotic", "undetermined", "left_reach", "diverged"}
    assert set(m.realizations["label"]) <= allowed
    assert m.cells["n"].tolist() == [1, 2]
    assert m.cells["deterministic"].tolist() == [True, False]


def test_bifurcation_with_the_package_classifier():
    """A two-value diagram with the default classifier has one verdict per value."""
    b = bifurcation("l_lambda", [0.006, 0.010], duration=4.0, workers=1)
    assert len(b.verdicts) == 2 and len(b.points) > 0


def test_lyapunov_exponents_are_summarised_per_cell():
    """With lyapunov=True each run carries its tangent spectrum (lambda_1 with its standard
    error, lambda_2 <= lambda_1, in 1/s); the cell has lambda_1's mean and spread."""
    m = regime_map(
        Axis("l_lambda", (0.008,)),
        Axis("l_lambda_sigma", (0.001,)),
        realizations=2,
        duration=3.0,
        lyapunov=True,
        workers=1,
    )
    r = m.realizations
    assert r[["ev_lyapunov_1", "ev_lyapunov_1_stderr", "ev_lyapunov_2"]].notna().all().all()
    assert (r["ev_lyapunov_2"] <= r["ev_lyapunov_1"]).all()
    cell = m.cells.iloc[0]
    assert cell["lyapunov_n"] == 2
    assert cell["lyapunov_mean"] == pytest.approx(np.mean(r["ev_lyapunov_1"]), rel=1e-12)
