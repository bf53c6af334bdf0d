"""Bouncing ball on a sinusoidally vibrating table, simulated exactly (event-driven).

Dimensionless: time ``τ = ω t``, lengths in units of ``g / ω²``; the table moves as
``s(τ) = Γ sin τ``, ``Γ = A ω² / g``; the ball falls with unit acceleration and an impact
sets ``v⁺ - u = -e (v⁻ - u)``, ``u = Γ cos τ``, e the coefficient of restitution (Tufillaro,
Abbott & Reilly 1992, "An Experimental Approach to Nonlinear Dynamics and Chaos", ch. 4; Luck
& Mehta 1993, Phys. Rev. E 48, 3988). The flight is the exact parabola and an impact the
first root of the exact gap: no high-bounce approximation.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numba
import numpy as np

__all__ = [
    "BallRun",
    "ball_impact_map",
    "ball_period_one_theory",
    "bouncing_ball",
    "period_one_orbit",
    "period_one_thresholds",
]

_OK, _STUCK, _MAX_EVENTS, _NO_PROGRESS = 0, 1, 2, 3
_STATUS = {
    _OK: "ok",
    _STUCK: "stuck: the ball came to rest on the table and Γ <= 1 never lets it leave",
    _MAX_EVENTS: "max_events reached (endless chattering?): increase v_stick",
    _NO_PROGRESS: "a flight of zero length (time lost to round-off): shorten the run",
}


@numba.njit(cache=True)
def _gap(tau, t0, w, gamma):
    """Ball height above the table ``tau`` after leaving it at ``t0`` with relative speed w:
    ``w τ - τ²/2 + Γ cos t0 (τ - sin τ) + Γ sin t0 (1 - cos τ)``, small-τ terms in series."""
    if tau < 1e-2:
        t2 = tau * tau
        tms = tau * t2 / 6.0 * (1.0 - t2 / 20.0 * (1.0 - t2 / 42.0))
    else:
        tms = tau - math.sin(tau)
    s = math.sin(0.5 * tau)
    omc = 2.0 * s * s
    return w * tau - 0.5 * tau * tau + gamma * (math.cos(t0) * tms + math.sin(t0) * omc)


@numba.njit(cache=True)
def _next_impact(t0, w, gamma, h_max, h_min):
    """First τ > 0 where the gap closes: a scan with a step growing from the flight scale,
    then bisection. A release from the table (zero relative speed, gap ~ Γ cos t0 τ³ / 6)
    is scanned from τ = 1e-6: round-off in Γ sin t0 - 1 (~1e-16 t0) fakes an impact at
    τ ~ 1e-12."""
    a = 0.0 if w > 0.0 else 1e-6
    while True:
        h = 0.5 * a + w / (1.0 + gamma)
        h = min(max(h, h_min), h_max)
        b = a + h
        if _gap(b, t0, w, gamma) < 0.0:
            break
        a = b
    # bisection: gap(a) >= 0 > gap(b)
    for _ in range(200):
        m = 0.5 * (a + b)
        if m <= a or m >= b:
            break
        if _gap(m, t0, w, gamma) >= 0.0:
            a = m
        else:
            b = m
    return b


@numba.njit(cache=True)
def _run(t0, v0, gamma, e, n_impacts, h_max, h_min, v_stick, max_events):
    times = np.empty(n_impacts)
    vels = np.empty(n_impacts)
    leave_t = np.empty(n_impacts)  # when the ball leaves the table after impact k
    leave_v = np.empty(n_impacts)
    n_stick = 0
    t = t0
    v = v0
    k = 0
    events = 0
    status = _OK
    while k < n_impacts:
        events += 1
        if events > max_events:
            status = _MAX_EVENTS
            break
        w = v - gamma * math.cos(t)
        tau = _next_impact(t, w, gamma, h_max, h_min)
        t1 = t + tau
        if not t1 > t:
            status = _NO_PROGRESS
            break
        v_in = v - tau
        u = gamma * math.cos(t1)
        v_out = u + e * (u - v_in)
        times[k] = t1
        vels[k] = v_out
        if v_out - u < v_stick and gamma * math.sin(t1) <= 1.0:
            # the chattering sequence has converged: the ball rides the table until the
            # table's downward acceleration exceeds gravity (Γ sin τ > 1)
            if gamma <= 1.0:
                leave_t[k] = math.inf
                leave_v[k] = u
                k += 1
                status = _STUCK
                break
            n_stick += 1
            td = math.asin(1.0 / gamma)
            m = math.ceil((t1 - td) / (2.0 * math.pi))
            t = td + 2.0 * math.pi * m
            v = gamma * math.cos(t)
        else:
            t = t1
            v = v_out
        leave_t[k] = t
        leave_v[k] = v
        k += 1
    return times[:k], vels[:k], leave_t[:k], leave_v[:k], n_stick, status


@dataclass(frozen=True)
class BallRun:
    """Impacts of one bouncing-ball run (dimensionless units). The ball leaves the table
    after impact k at ``leave_times[k]`` with ``leave_velocities[k]``: at the impact itself,
    or at the end of a sticking episode."""

    times: np.ndarray  # impact times τ_k (unwrapped)
    velocities: np.ndarray  # absolute ball velocities just after each impact
    leave_times: np.ndarray
    leave_velocities: np.ndarray
    n_stick: int  # sticking episodes (complete chattering, then riding the table)
    status: str  # "ok", or why the run stopped early
    settings: dict = field(default_factory=dict)  # everything the run used

    def impact_section(self, discard: int = 0) -> np.ndarray:
        """Impact map points ``(τ_k mod 2π, v_k)``, shape (N - discard, 2)."""
        phase = np.mod(self.times[discard:], 2.0 * math.pi)
        return np.column_stack([phase, self.velocities[discard:]])

    def positions(self, t: np.ndarray) -> np.ndarray:
        """Ball height [g/ω²] at times `t` between the first and the last impact: the flight
        ``Γ sin τ_L + v_L (τ - τ_L) - (τ - τ_L)² / 2`` after leaving the table at τ_L with
        speed v_L, and the table's height ``Γ sin τ`` while sticking."""
        t = np.asarray(t, dtype=float)
        gamma = self.settings["gamma"]
        k = np.searchsorted(self.times, t, side="right") - 1
        if np.any(k < 0) or np.any(t > self.times[-1]):
            raise ValueError("times must lie between the first and the last impact")
        tl = self.leave_times[k]
        on_table = t < tl
        dt = t - tl
        flight = gamma * np.sin(tl) + self.leave_velocities[k] * dt - 0.5 * dt * dt
        return np.where(on_table, gamma * np.sin(t), flight)


def bouncing_ball(
    gamma: float,
    e: float,
    n_impacts: int,
    *,
    t0: float = 0.0,
    v0: float | None = None,
    h_max: float = 2.0 * math.pi / 1000.0,
    h_min: float = 1e-12,
    v_stick: float = 1e-9,
    max_events: int | None = None,
) -> BallRun:
    """Simulate the bouncing ball exactly, impact after impact.

    Parameters
    ----------
    gamma : float
        Γ = A ω² / g, the table's peak acceleration in units of g.
    e : float
        Coefficient of restitution in [0, 1).
    n_impacts : int
        Number of impacts to simulate.
    t0 : float
        Launch time (the ball leaves the table at τ = t0).
    v0 : float, optional
        Absolute launch velocity; default ``Γ cos t0 + π`` (a flight of about one period).
    h_max : float
        Largest scan step for the first root of the gap: a graze shallower than
        ``(1 + Γ) h_max² / 8`` (1.2e-5 g/ω² by default at Γ = 1.5) can be missed.
    h_min : float
        Smallest scan step (the release from the table, where the gap grows like τ³).
    v_stick : float
        Relative rebound speed below which complete chattering is cut and replaced by
        sticking (its accumulation point).
    max_events : int, optional
        Safety limit on flights, default ``50 * n_impacts``.

    Returns
    -------
    BallRun
    """
    if v0 is None:
        v0 = gamma * math.cos(t0) + math.pi
    if max_events is None:
        max_events = 50 * int(n_impacts)
    settings = dict(gamma=gamma, e=e, n_impacts=n_impacts, t0=t0, v0=v0, h_max=h_max,
                    h_min=h_min, v_stick=v_stick, max_events=max_events)  # fmt: skip
    times, vels, leave_t, leave_v, n_stick, status = _run(
        float(t0), float(v0), float(gamma), float(e), int(n_impacts), float(h_max),
        float(h_min), float(v_stick), int(max_events),
    )  # fmt: skip
    return BallRun(times, vels, leave_t, leave_v, int(n_stick), _STATUS[status], settings)


def ball_impact_map(
    state: np.ndarray, gamma: float, e: float, h_max: float = 2.0 * math.pi / 1000.0
) -> np.ndarray:
    """One step of the exact impact map ``(τ_k, v_k) -> (τ_{k+1}, v_{k+1})``: the ball leaves
    the table at τ_k with absolute velocity v_k (above the table's); the next impact time and
    rebound velocity. No sticking (`bouncing_ball` runs whole motions)."""
    t, v = float(state[0]), float(state[1])
    w = v - gamma * math.cos(t)
    tau = _next_impact(t, w, gamma, h_max, 1e-12)
    t1 = t + tau
    u = gamma * math.cos(t1)
    return np.array([t1, u + e * (u - (v - tau))])


def period_one_orbit(
    gamma: float,
    e: float,
    n: int = 1,
    *,
    guess: tuple[float, float] | None = None,
    tol: float = 1e-11,
    max_iter: int = 50,
    fd_step: float = 1e-6,
) -> tuple[np.ndarray, np.ndarray, bool]:
    """Find a period-one orbit (one impact every n table periods) by Newton's method.

    Solves ``P(τ, v) = (τ + 2π n, v)`` for the exact impact map P, with the Jacobian from
    central finite differences of P. The launch phase is reduced to [0, 2π).

    Parameters
    ----------
    gamma, e : float
        Γ and the coefficient of restitution, as in `bouncing_ball`.
    n : int
        Table periods per flight.
    guess : (phase, v), optional
        Starting point; by default the best phase on a 64-point grid with v = nπ (the speed
        giving a flight of n periods at a fixed height).
    tol, max_iter, fd_step : float, int, float
        Newton's tolerance on the residual norm, its iterations, the difference step.

    Returns
    -------
    orbit : ndarray, shape (2,)
        (phase, v) of the orbit found (last iterate if not converged).
    jacobian : ndarray, shape (2, 2)
        DP at the orbit; its eigenvalues are the orbit's Floquet multipliers.
    converged : bool
        Residual below `tol` with a valid flight (the ball leaves the table upwards).
    """

    def residual(x):
        if x[1] - gamma * math.cos(x[0]) <= 0.0:
            return None
        y = ball_impact_map(x, gamma, e)
        return np.array([y[0] - x[0] - 2.0 * math.pi * n, y[1] - x[1]])

    def jac(x):
        j = np.empty((2, 2))
        for i in range(2):
            dx = np.zeros(2)
            dx[i] = fd_step
            yp = ball_impact_map(x + dx, gamma, e)
            ym = ball_impact_map(x - dx, gamma, e)
            j[:, i] = (yp - ym) / (2.0 * fd_step)
        return j

    if guess is None:
        best, x = np.inf, None
        for ph in np.linspace(0.0, 2.0 * math.pi, 64, endpoint=False):
            cand = np.array([ph, n * math.pi])
            r = residual(cand)
            if r is not None and np.linalg.norm(r) < best:
                best, x = np.linalg.norm(r), cand
        if x is None:
            return np.array([np.nan, np.nan]), np.full((2, 2), np.nan), False
    else:
        x = np.array(guess, dtype=float)
    converged = False
    for _ in range(max_iter):
        r = residual(x)
        if r is None or not np.all(np.isfinite(r)):
            break
        if np.linalg.norm(r) < tol:
            converged = True
            break
        j = jac(x) - np.eye(2)
        try:
            step = np.linalg.solve(j, -r)
        except np.linalg.LinAlgError:
            break
        # damp steps that would leave the physical region
        lam = 1.0
        while lam > 1e-3 and residual(x + lam * step) is None:
            lam *= 0.5
        x = x + lam * step
        x[0] = math.fmod(x[0], 2.0 * math.pi) + (2.0 * math.pi if x[0] < 0 else 0.0)
    return x, jac(x), converged


def period_one_thresholds(
    e: float,
    n: int = 1,
    *,
    gamma_start: float,
    rel_tol: float = 1e-7,
) -> tuple[float, float]:
    """Saddle-node and period-doubling Γ of the period-one orbit, by continuation.

    From where runs at `gamma_start` settle (8 launch phases, speed nπ), refined by Newton
    (`period_one_orbit`), the orbit is followed down in Γ until Newton finds none and
    bisected on existence (the saddle-node), and up until ``1 + tr J + det J`` (the
    characteristic polynomial at -1) changes sign and bisected (the flip).

    Parameters
    ----------
    e, n : float, int
        Coefficient of restitution, and table periods per flight.
    gamma_start : float
        A Γ where the period-one orbit attracts (e.g. found by a classifier sweep);
        ValueError if none is found there.
    rel_tol : float
        Relative precision of both thresholds.

    Returns
    -------
    (gamma_exist, gamma_pd) : tuple of float
        Both to relative precision `rel_tol` (limited by the Newton tolerance near the fold,
        where the orbit depends on Γ like a square root).
    """
    x0 = None
    for phase in np.linspace(0.0, 2.0 * math.pi, 8, endpoint=False):
        run = bouncing_ball(gamma_start, e, 3000, t0=phase, v0=n * math.pi)
        gaps = np.diff(run.times[-10:])
        if run.status == "ok" and np.allclose(gaps, 2.0 * math.pi * n, atol=1e-6):
            guess = (run.times[-1] % (2.0 * math.pi), run.velocities[-1])
            x0, j0, ok = period_one_orbit(gamma_start, e, n, guess=guess)
            if ok and np.max(np.abs(np.linalg.eigvals(j0))) < 1.0:
                break
            x0 = None
    if x0 is None:
        raise ValueError(f"no attracting period-one orbit at gamma_start = {gamma_start}")

    def exists(g, guess):
        x, _, ok = period_one_orbit(g, e, n, guess=tuple(guess))
        return ok, x

    def flip_sign(g, guess):  # the sign of 1 + tr J + det J, the characteristic polynomial at -1
        x, j, ok = period_one_orbit(g, e, n, guess=tuple(guess))
        if not ok:
            raise ValueError(f"lost the period-one orbit at gamma = {g}")
        return np.sign(1.0 + np.trace(j) + np.linalg.det(j)), x

    def unflipped(g, guess):
        sign, x = flip_sign(g, guess)
        return sign == sign0, x

    gamma_exist, _ = _edge(exists, gamma_start, x0, 0.99, rel_tol,
                           "continuation downwards did not end")  # fmt: skip
    sign0, x_start = flip_sign(gamma_start, x0)  # the branch followed from gamma_start
    lo, hi = _edge(unflipped, gamma_start, x_start, 1.01, rel_tol, "no period doubling found")
    return gamma_exist, 0.5 * (lo + hi)


def _edge(holds, g, state, factor, rel_tol, stuck):
    """Where ``holds(g, state) -> (bool, state)`` stops holding: g stepped by `factor` from
    where it holds, then bisected to relative precision `rel_tol`, each probe started from
    the state of the last g where it held. Returns (last g where it holds, first where it
    does not); ValueError(`stuck`) when g leaves [1e-3, 1e3] first."""
    inside = g
    while True:
        g *= factor
        ok, new = holds(g, state)
        if not ok:
            break
        inside, state = g, new
        if not 1e-3 <= g <= 1e3:
            raise ValueError(stuck)
    outside = g
    while abs(outside - inside) > rel_tol * max(inside, outside):
        mid = 0.5 * (inside + outside)
        ok, new = holds(mid, state)
        if ok:
            inside, state = mid, new
        else:
            outside = mid
    return inside, outside


def ball_period_one_theory(e: float, n: int = 1) -> tuple[float, float]:
    """Closed-form thresholds of the period-one orbit (n table periods per flight).

    Existence ``Γ >= nπ (1 - e) / (1 + e)``, period doubling at ``Γ = sqrt[(2 (1 + e²) /
    (1 + e)²)² + (nπ (1 - e) / (1 + e))²]`` (Tufillaro et al. 1992, ch. 4; exact for the
    full model: a period-one flight starts and ends at the same table height). The target
    the numerics are checked against, never used inside them.
    """
    c = n * math.pi * (1.0 - e) / (1.0 + e)
    s = 2.0 * (1.0 + e * e) / (1.0 + e) ** 2
    return c, math.hypot(s, c)
