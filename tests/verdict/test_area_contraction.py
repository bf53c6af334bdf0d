"""The stroboscopic map contracts area (docs/model.md, "What the model cannot do"): every
one-period Jacobian has |det| <= 1, <= xi^2 with a restitution jump, and a periodic orbit's
|mu_1 mu_2| <= xi^2, so no complex pair reaches the unit circle (analyses/monodromy_det.py
checks the labelled sets and the (omega, xi) map)."""

from __future__ import annotations

import math

import numpy as np
import pytest

from chaoscam import Params, solve
from chaoscam.verdict import periodic_orbit

EPS = np.finfo(float).eps


def _periods(p: Params, duration: float, transient: float):
    """(run, det J_k, its round-off tol_k, div_k, jumps with xi > 0) of the periods that
    start after the transient (their impacts all listed). tol_k = N eps (|j11 j22| + |j12
    j21|), N = T / dt steps: each step adding a relative eps to the entries, linearly."""
    run = solve(p, duration=duration, transient=transient, tangent=True, impacts=True)
    t = run.sections["t"].to_numpy()
    keep = t - p.cam_period >= transient
    j, t = run.jacobians[keep], t[keep]
    det = np.linalg.det(j)
    steps = p.cam_period / run.numerics.dt
    tol = steps * EPS * (np.abs(j[:, 0, 0] * j[:, 1, 1]) + np.abs(j[:, 0, 1] * j[:, 1, 0]))
    ti = run.impacts.loc[run.impacts["kind"] != "chatter_end", "t"].to_numpy()
    jumps = np.searchsorted(ti, t, "right") - np.searchsorted(ti, t - p.cam_period, "right")
    return run, det, tol, run.divergence[keep], jumps


@pytest.mark.parametrize(
    ("p", "duration", "transient"),
    [(Params(xi=0.2), 6.0, 2.0), (Params(), 8.0, 2.0), (Params(e=0.02), 6.0, 2.0)],
    ids=["period 1 with impacts", "chaotic", "sticking"],
)
def test_every_period_contracts_area(p, duration, transient):
    """div_k <= 0 and |det J_k| <= 1 in every period, <= xi^2 in those with a jump (round-off
    tol_k): one impact a period; chaos with flights, chattering and plastic closures (det 0);
    sticking after each chattering. The literal damping fails the first (div_k up to +0.68)."""
    _, det, tol, div, jumps = _periods(p, duration, transient)
    assert len(det) >= 15 and jumps.any()
    assert np.all(div <= 0.0)
    assert np.all(np.abs(det) <= 1.0 + tol)
    assert np.all(np.abs(det[jumps > 0]) <= p.xi**2 + tol[jumps > 0])


def test_an_impacting_orbit_has_multiplier_product_xi_squared():
    """The period-1 orbit at xi = 0.2 has one impact and no compliant contact a period, so
    |mu_1 mu_2| = xi^2 exactly (flight conserves area), to 1e-9 (round-off ~N eps = 2e-11)."""
    p = Params(xi=0.2)
    run, det, _, _, jumps = _periods(p, 6.0, 2.0)
    assert np.all(jumps == 1)
    orbit = periodic_orbit(p, run.sections[["theta_f", "omega_f"]].to_numpy()[-1], 1)
    assert orbit.converged and orbit.period == 1
    assert abs(np.prod(orbit.multipliers)) == pytest.approx(p.xi**2, rel=1e-9)


def test_a_focus_in_persistent_contact_stays_inside_the_unit_circle():
    """At omega = 15 rad/s the follower never leaves the cam: the orbit's multipliers are a
    complex pair with |mu|^2 = |mu_1 mu_2| = exp(int div dt) < 1, within 0.05 (RK4's own
    damping of the Hertz oscillation, (h Omega)^6 / 72 a step, ~0.012 over this period)."""
    p = Params(omega=15.0)
    run, det, _, div, jumps = _periods(p, 6.0, 3.0)
    assert not jumps.any()
    orbit = periodic_orbit(p, run.sections[["theta_f", "omega_f"]].to_numpy()[-1], 1)
    mu = orbit.multipliers
    assert orbit.converged and abs(mu[0].imag) > 0
    assert abs(mu[0]) == pytest.approx(abs(mu[1]), rel=1e-12)
    product = abs(np.prod(mu))
    assert product < 1e-6
    assert math.log(product) == pytest.approx(div[-1], abs=0.05)
