"""Models whose realizations are all the same run (chaoscam.model.realizations_identical):
sigma = 0, and the fractal stiffness, whose K_n does not depend on the line length. A sweep
runs them once, and their periodic orbits are certified by shooting."""

from __future__ import annotations

import warnings

import numpy as np

from chaoscam import Params, classify, simulate
from chaoscam.model import realizations_identical
from chaoscam.sweep import Axis, regime_map

FRACTAL = Params(stiffness="fractal", xi=0.2)


def test_which_models_are_deterministic():
    """sigma = 0 and the fractal stiffness are deterministic; a Hertz spread is not."""
    assert realizations_identical(Params())  # sigma = 0
    assert not realizations_identical(Params(l_lambda_sigma=0.002))
    assert realizations_identical(FRACTAL.replace(l_lambda_sigma=0.002))


def _quiet(f, *args, **kw):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)  # "sigma has no effect": the point
        return f(*args, **kw)


def test_the_fractal_model_ignores_the_draws():
    """Two realizations of the fractal model with sigma > 0 draw different lines and have
    the same section, bit for bit: the premise of running it once."""
    p = FRACTAL.replace(l_lambda_sigma=0.002)
    a, b = (_quiet(simulate, p, duration=3.0, series=False, index=i) for i in (0, 7))
    assert a.section["l_lambda"].tolist() != b.section["l_lambda"].tolist()
    np.testing.assert_array_equal(
        a.section[["theta_f", "omega_f"]].to_numpy(), b.section[["theta_f", "omega_f"]].to_numpy()
    )


def test_a_fractal_cell_with_sigma_is_run_once():
    """Its cell is deterministic (one run, no Wilson interval over identical runs), with the
    label and impacts of the sigma = 0 cell."""
    m = _quiet(
        regime_map,
        Axis("xi", (0.2,)),
        Axis("l_lambda_sigma", (0.0, 0.002)),
        base=FRACTAL,
        realizations=3,
        duration=4.0,
        workers=1,
    )
    assert m.cells["deterministic"].all() and (m.cells["n"] == 1).all()
    r = m.realizations
    assert len(r) == 2 and r["label"].nunique() == 1 and r["n_impacts"].nunique() == 1


def test_a_fractal_periodic_orbit_is_certified_with_sigma():
    """The periodic-orbit certificate applies to the fractal model whatever sigma: the
    same certified period 1 as at sigma = 0 (before, sigma > 0 skipped it)."""
    verdicts = [
        _quiet(
            classify,
            _quiet(
                simulate, FRACTAL.replace(l_lambda_sigma=s), duration=10.0, series=False, index=3
            ),
        )[0]
        for s in (0.0, 0.002)
    ]
    for v in verdicts:
        orbit = {e.name: e for e in v.evidence}["periodic_orbit"]
        assert (v.label, v.period, orbit.vote) == ("periodic", 1, "periodic")
        assert orbit.detail.startswith("certified")
