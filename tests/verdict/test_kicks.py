"""The direct perturbation test (chaoscam.verdict.kick_test): finite kicks on the map itself,
which decide stability where chattering ends in sticking and no tangent can (docs/findings.md,
"Tangent dynamics checked independently")."""

from __future__ import annotations

import numpy as np
import pytest

from chaoscam import ParameterError, Params, kick_test, simulate


def _settled_point(p):
    sec = simulate(p, duration=130.0, transient=100.0, series=False).section
    return sec[["theta_f", "omega_f"]].to_numpy()[-1]


@pytest.mark.parametrize(
    ("changes", "n", "returns"),
    [
        ({"xi": 0.45}, 6, True),  # sticking period 6: every tangent-free measure attracts
        ({"omega": 32.5, "xi": 0.5}, 6, True),  # period 6 the tangent leaves undetermined
        ({"l_lambda": 0.015}, 8, False),  # 8-band chaos: 1e-8 kicks grow ~250x in 12 periods
    ],
    ids=["xi=0.45", "(32.5, 0.5)", "l_lambda=15mm"],
)
def test_kicks_tell_attracting_orbits_from_chaos(changes, n, returns):
    """Kicks of ±1e-7 and ±1e-6 rad (and ±30x in rad/s) return below a tenth of themselves
    within 40 orbit periods on the attracting orbits and not on the chaotic bands (measured at
    dt, largest separation over kick at the end: <= 5e-5 and 5e-4 for the orbits, 0.67 for the
    chaos, where some 1e-8 kicks grow 7x)."""
    p = Params(**changes)
    x = _settled_point(p)
    test = kick_test(p, x, n)
    assert test.returns is returns
    assert test.growth.shape == (3, 4, 41) and test.points.shape == (40 * n + 1, 2)
    assert np.allclose(test.growth[:, :, 0], 1.0, rtol=1e-6)  # the kicks, in the scaled norm
    if not returns:
        assert test.growth[:, :, -1].max() > 1.0  # some kick grows
    # Stopping at the first refusal gives the same answer, with the same bits where it ran.
    short = kick_test(p, x, n, until_refused=True)
    ran = ~np.isnan(short.growth)
    assert short.returns is returns and np.array_equal(short.growth[ran], test.growth[ran])
    assert bool(ran.all()) is returns  # all run when they return; some skipped when refused


def test_bad_arguments_name_themselves():
    """A kick of size 0 and n = 0 are ParameterErrors naming the argument."""
    with pytest.raises(ParameterError, match="kicks"):
        kick_test(Params(), (0.0, 1.0), kicks=(0.0,))
    with pytest.raises(ParameterError, match="n ="):
        kick_test(Params(), (0.0, 1.0), n=0)
