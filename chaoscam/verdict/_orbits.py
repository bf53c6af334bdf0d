"""The tangent dynamics at work: Lyapunov spectrum, periodic orbits, finite kicks, all on the
stroboscopic map ``P: x(t_k) -> x(t_k + T)``, ``T = 2 pi / omega``, whose Jacobians the kernel
integrates through the impacts (tangent flow and saltation matrices). The map runs are
members of :func:`chaoscam.solve`'s batch runner started from a state.
"""

from __future__ import annotations

import dataclasses
import itertools
import math
import time
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from .._util import ParameterError, freeze_fields, real, warn, whole
from ..analysis import TangentSpectrum, spectrum_from_jacobians
from ..kernel import Status, section_jacobians
from ..kernel import layout as k
from ..model import Params, params_arg, realizations_identical
from ..numerics import Numerics
from ..simulation import ROOM, Solution, check_run, fresh, numerics_arg, run_batch, solve

__all__ = ["KickTest", "PeriodicOrbit", "iterate_map", "kick_test", "lyapunov_spectrum",
           "map_runner", "periodic_orbit", "stroboscopic_map"]  # fmt: skip


def lyapunov_spectrum(params: Params | Solution | None = None, numerics: Numerics | None = None,
                      *, duration: float = 120.0, transient: float = 60.0, seed: int = 0,
                      index: int = 0) -> TangentSpectrum:  # fmt: skip
    """Lyapunov spectrum [1/s] of one realization from its tangent dynamics through the impacts.

    Solves with ``tangent=True`` (or takes a one-member :class:`Solution` solved so, in place
    of ``params``) and applies :func:`chaoscam.analysis.spectrum_from_jacobians` (repeated QR,
    no separation to choose) to the recorded stroboscopic Jacobians. The tangent costs about
    0.1 of a run on RK4 and 2.5 runs on the adaptive path. With a random line length the
    exponents are those of the realization's random map sequence (L. Arnold, Random
    Dynamical Systems, 1998).
    """
    if isinstance(params, Solution):
        run = params
        given = [n for n, v, d in (("numerics", numerics, None), ("duration", duration, 120.0),
                 ("transient", transient, 60.0), ("seed", seed, 0), ("index", index, 0))
                 if v is not d and v != d]  # fmt: skip
        if given:  # they would be silently ignored: the solution's own are used
            raise ParameterError(
                f"give a solution or the run's settings, not both: {', '.join(given)} would "
                "be ignored (the solution's own are used)"
            )
    else:
        run = solve(params, numerics, indices=[index], seed=seed, duration=duration,
                    transient=transient, tangent=True)  # fmt: skip
    if run.jacobians is None:
        raise ValueError(
            "the solution has no Jacobians (solved without tangent=True, or read from a "
            "file): solve it again with tangent=True"
        )
    if run.status is not Status.OK:
        raise ValueError(f"the run ended {run.status.name}: {run.message}")
    keep = run.section["k"].to_numpy() > 0  # the k = 0 row is the initial state
    if not keep.any():
        raise ValueError(
            f"the run records no section point after its start (duration "
            f"{run.settings['duration']:g} s, cam period {run.params.cam_period:.3g} s): "
            "nothing to take exponents from"
        )
    spec = spectrum_from_jacobians(run.jacobians[keep], run.params.cam_period)
    if not math.isfinite(float(spec.stderr[0])):  # too few periods for the batch means
        warn(
            f"lambda_1 = {spec.exponents[0]:.3g} 1/s rests on {spec.n_periods} cam period(s), "
            "too few for its standard error (NaN): lengthen the recorded time "
            "(duration - transient)"
        )
    s = run.settings
    window = {"duration": s["duration"], "transient": s["transient"], "seed": s["seed"],
              "index": run.index}  # fmt: skip
    return dataclasses.replace(spec, settings={**spec.settings, **window})


class _MapRunner:
    """n iterates of the stroboscopic map of a deterministic model from a state at t = 0, and
    DP^n: one member of the batch runner started from that state."""

    def __init__(self, p: Params, num: Numerics, n: int, *, tangent: bool = True) -> None:
        if not realizations_identical(p):
            raise ParameterError(
                f"l_lambda_sigma = {p.l_lambda_sigma} m: periodic orbits need the "
                "deterministic model (l_lambda_sigma = 0, or the fractal stiffness)"
            )
        if num.integrator != "rk4":
            raise ParameterError("periodic orbits are computed on the RK4 grid (integrator='rk4')")
        # The fractal K_n ignores the line length: with sigma = 0 the same motion, no draws.
        self.p, self.num, self.n = p.replace(l_lambda_sigma=0.0), num, n
        self.duration = (int(math.floor(n * p.cam_period / num.dt)) + 2) * num.dt
        self.start = fresh([self.p], num, [0], 0, self.duration, 0.0, tangent=tangent, stride=0,
                           room=ROOM["cpu"])  # fmt: skip
        self.calls, self.watchers = 0, {}

    def _from(self, x: np.ndarray, s, series: list) -> Any:
        """A copy of the start ``s`` from the state x, its kept series begun with ``series``."""
        y = s.y.copy()
        y[0, k.Y_THETA], y[0, k.Y_OMEGA] = x
        kept = {"section": [[]], "impacts": [[]], "series": [series]}
        return dataclasses.replace(s, y=y, cnt=s.cnt.copy(), lam=s.lam.copy(), kept=kept,
                                   status=s.status.copy())  # fmt: skip

    def _rows(self, x: np.ndarray, impacts: bool = False):
        """The section rows of n cam periods from x (row 0: x itself), and the status (with
        ``impacts`` also the impact rows and the counters)."""
        self.calls += 1
        out = run_batch([self.p], self.num, [0], self._from(x, self.start, []), 0,
                        self.duration, room=ROOM["cpu"], keep_impacts=impacts)  # fmt: skip
        if impacts:
            return out.kept["section"][0], int(out.status[0]), out.kept["impacts"][0], out.cnt[0]
        return out.kept["section"][0], int(out.status[0])

    def watch(self, x: np.ndarray, every: int) -> tuple[np.ndarray, np.ndarray, int]:
        """The run of n cam periods from x sampled every ``every`` grid steps: its series
        rows (t, θ_f, θ̇_f, l_λ), its impact rows (``IMPACT_NAMES``) and its status."""
        if every not in self.watchers:
            self.watchers[every] = fresh([self.p], self.num, [0], 0, self.duration, 0.0,
                                         tangent=False, stride=every, room=ROOM["cpu"])  # fmt: skip
        s = self.watchers[every]
        start = self._from(x, s, [np.array([[0.0, *x, s.lam[0, 0]]])])
        out = run_batch([self.p], self.num, [0], start, 0, self.duration, room=ROOM["cpu"],
                        keep_impacts=True)  # fmt: skip
        return out.kept["series"][0], out.kept["impacts"][0], int(out.status[0])

    def __call__(self, x: np.ndarray) -> tuple[np.ndarray, np.ndarray, int]:
        """(P^n(x), DP^n(x), status)."""
        rows, code = self._rows(x)
        if code != k.OK or len(rows) < self.n + 1:
            return np.full(2, np.nan), np.full((2, 2), np.nan), code
        m = np.eye(2)
        for jac in section_jacobians(rows[1 : self.n + 1]):
            m = jac @ m
        return rows[self.n, 2:4].copy(), m, code

    def counts(self, x: np.ndarray) -> dict[str, Any]:
        """The orbit through x over its n periods: its section points x, P(x), ..., P^(n-1)(x)
        (``points``), the impacts of each kind (``n_macro_impacts``, ``n_micro_impacts``,
        ``n_chatter_ends``: chattering sequences that end in persistent contact), the
        ``contact_fraction`` of the grid steps, ``slow_closings``, the ``status`` and the
        times [s] of the impacts, ``impact_times`` (all kinds) and ``macro_times``."""
        rows, code, imp, cnt = self._rows(x, impacts=True)
        kept = imp[imp[:, 0] < self.n * self.p.cam_period]
        inside = kept[:, -1].astype(int)
        kinds = np.bincount(inside, minlength=3)
        pts = np.full((self.n, 2), np.nan)
        m = min(len(rows), self.n)
        pts[:m] = rows[:m, 2:4]
        steps = max(int(cnt[k.I_COUNTED_STEPS]), 1)
        return {"points": pts, "n_macro_impacts": int(kinds[k.IMPACT_MACRO]),
                "n_micro_impacts": int(kinds[k.IMPACT_MICRO]),
                "n_chatter_ends": int(kinds[k.IMPACT_CHATTER_END]),
                "contact_fraction": int(cnt[k.I_CONTACT_STEPS]) / steps,
                "slow_closings": int(cnt[k.I_SLOW_CLOSINGS]), "status": Status(code),
                "impact_times": kept[:, 0].copy(),
                "macro_times": kept[inside == k.IMPACT_MACRO, 0].copy()}  # fmt: skip

    def points(self, x: np.ndarray) -> np.ndarray:
        """x, P(x), ..., P^n(x), shape (n + 1, 2); NaN rows after a run that stopped."""
        rows, _ = self._rows(x)
        out = np.full((self.n + 1, 2), np.nan)
        m = min(len(rows), self.n + 1)
        out[:m] = rows[:m, 2:4]
        return out


def map_runner(params: Params, n: int = 1, numerics: Numerics | None = None):
    """The n-th iterate of the stroboscopic map of the deterministic model as a reusable
    callable: ``run(x) -> (P^n(x), DP^n(x), status code)`` (NaN where the run stopped: 0 is
    ``OK``), ``run.counts(x)`` (the orbit's section points, impacts by kind, contact
    fraction), ``run.points(x)`` and ``run.p`` (the model it runs). x = (θ_f [rad], θ̇_f
    [rad/s]) at t = 0, cam phase 0; DP^n through the impacts' saltation matrices. One call
    costs one run of n cam periods (about 1 ms a period on the default grid)."""
    return _MapRunner(params_arg(params), numerics_arg(numerics), whole("n", n, low=1))


def iterate_map(params: Params, x, n: int, numerics: Numerics | None = None) -> np.ndarray:
    """The section points ``x, P(x), ..., P^n(x)`` (shape (n + 1, 2)) of the deterministic
    model from the state x = (θ_f, θ̇_f) at t = 0 (does a point near an orbit settle on it?);
    NaN rows after a run that stopped (left the cam's reach)."""
    # no tangent: the state is bit-identical without it
    run = _MapRunner(params, numerics_arg(numerics), int(n), tangent=False)
    return run.points(np.asarray(x, dtype=float))


def stroboscopic_map(
    params: Params, x, n: int = 1, numerics: Numerics | None = None
) -> tuple[np.ndarray, np.ndarray]:
    """``(P^n(x), DP^n(x))``: n cam periods from the state x = (θ_f, θ̇_f) at t = 0 of the
    deterministic model (σ = 0), DP^n through the impacts' saltation matrices."""
    xn, m, code = _MapRunner(params, numerics_arg(numerics), int(n))(np.asarray(x, dtype=float))
    if code != k.OK:
        raise ValueError(f"the map could not be iterated: {Status(code).message}")
    return xn, m


KICKS = (1e-8, 1e-7, 1e-6)
"""Kick sizes of :func:`kick_test` [rad; θ̇_f kicks are ``omega_scale`` times larger]."""
KICK_DECIDES = 1e-7
"""Kicks at least this large decide :attr:`KickTest.returns`: sticking orbits jitter by ~1e-8
rad from period to period (located events move by whole bisection steps), so a 1e-8 kick can
stay near its own size on an attracting orbit (ξ = 0.525: 0.47 of itself after 12 periods)."""
KICK_RETURN = 0.1
"""A kick has returned when the separation it made is at most this fraction of it."""


@dataclass(frozen=True)
class KickTest:
    """Finite perturbations followed on the stroboscopic map (:func:`kick_test`).

    Attributes
    ----------
    kicks : tuple of float
        Kick sizes in θ_f [rad]; θ̇_f kicks are ``omega_scale`` times these [rad/s].
    growth : ndarray, shape (len(kicks), 4, periods + 1)
        Separation from the unkicked run over kick size, max over (θ_f, θ̇_f / omega_scale),
        after 0, n, ..., periods·n cam periods; axis 1: the direction, +θ_f, -θ_f, +θ̇_f, -θ̇_f.
    returns : bool
        Every kick of at least :data:`KICK_DECIDES` ends at most :data:`KICK_RETURN` of its
        size: the motion attracts what is near it, at the scale the model resolves.
    points : ndarray, shape (periods * n + 1, 2)
        The unkicked run's section points x, P(x), ..., P^(periods·n)(x): where it went.
    """

    kicks: tuple
    n: int
    periods: int
    omega_scale: float
    growth: np.ndarray
    returns: bool
    points: np.ndarray

    def __post_init__(self) -> None:
        freeze_fields(self, "growth", "points")


def kick_test(params: Params, x, n: int = 1, *, numerics: Numerics | None = None,
              kicks: tuple = KICKS, periods: int = 40, omega_scale: float = 30.0,
              until_refused: bool = False) -> KickTest:  # fmt: skip
    """The direct perturbation test at x = (θ_f, θ̇_f) (t = 0, deterministic model): kick θ_f
    by ± each of ``kicks`` and θ̇_f by ± ``omega_scale`` times as much, iterate ``periods`` × n
    cam periods (:func:`iterate_map`) and compare with the unkicked run; a :class:`KickTest`.

    Where chattering ends in sticking the grid map is not differentiable at the scale of its
    event jitter (at ξ = 0.525 the tangent's ``|μ|max`` is 5.9 while kicks of 1e-9 to 1e-6 return
    to a 1e-8 floor): kicks measure at finite sizes (docs/findings.md checks ``returns`` on the
    labelled sets). On chaotic bands many kicks return (sticking merges nearby motions), so
    four directions at two sizes decide together. With ``until_refused`` the kicks stop at the
    first deciding one that does not return (the rows not run NaN).
    """
    params, num, x = _start(params, numerics, x, "x")
    n = whole("n", n, low=1)
    periods = whole("periods", periods, low=1)
    omega_scale = real("omega_scale", omega_scale, low=0.0, strict=True)
    sizes = tuple(real("kicks", v, low=0.0, strict=True) for v in kicks)
    scale = np.array([1.0, omega_scale])
    points = iterate_map(params, x, periods * n, num)
    base = points[::n] / scale
    directions = np.array([[1.0, 0.0], [-1.0, 0.0], [0.0, 1.0], [0.0, -1.0]])
    growth = np.full((len(sizes), len(directions), periods + 1), np.nan)
    for i, j in itertools.product(range(len(sizes)), range(len(directions))):
        kicked = iterate_map(params, x + sizes[i] * scale * directions[j], periods * n, num)
        growth[i, j] = np.abs(kicked[::n] / scale - base).max(axis=1) / sizes[i]
        if until_refused and sizes[i] >= KICK_DECIDES and not growth[i, j, -1] <= KICK_RETURN:
            break  # refused: the kicks not run stay NaN
    final = growth[[i for i, v in enumerate(sizes) if v >= KICK_DECIDES], :, -1]
    returns = bool(final.size) and bool(np.all(final <= KICK_RETURN))
    return KickTest(sizes, n, periods, omega_scale, growth, returns, points)


@dataclass(frozen=True)
class PeriodicOrbit:
    """A periodic orbit of the stroboscopic map found by Newton shooting.

    Attributes
    ----------
    period : int
        n, in cam periods (the orbit's least period after checking its divisors).
    points : ndarray, shape (n, 2)
        The orbit's section points (θ_f [rad], θ̇_f [rad/s]), x_0 first.
    multipliers : ndarray, shape (2,)
        Floquet multipliers: the eigenvalues of DP^n at x_0 (complex in general).
    residual : float
        ``|P^n(x_0) - x_0|`` in the scaled norm (θ in rad, θ̇ times T) at the last iterate.
    converged : bool
        Newton's residual fell below `tol`.
    iterations, wall_time : int, float
        Newton iterations used, and seconds spent.
    settings : dict
        tol, max_iter, map_calls, cam_period, seed_period, and seed_status: how the map from
        ``x0`` ended (``LEFT_REACH`` or a divergence: no orbit from there, NaN multipliers).
    """

    period: int
    points: np.ndarray
    multipliers: np.ndarray
    residual: float
    converged: bool
    iterations: int
    wall_time: float
    settings: dict[str, Any] = field(default_factory=dict)

    def __post_init__(self) -> None:
        freeze_fields(self, "points", "multipliers", "settings")

    @property
    def stable(self) -> bool:
        """All multipliers inside the unit circle (an attracting orbit)."""
        return bool(np.max(np.abs(self.multipliers)) < 1.0)

    @property
    def certified(self) -> bool:
        """Converged and attracting: decisive evidence of a periodic response."""
        return self.converged and self.stable

    def distances(self, points: np.ndarray) -> np.ndarray:
        """Distance [rad, scaled: |(Δθ, T Δθ̇)|] from each section point to the orbit."""
        pts = np.asarray(points, dtype=float).reshape(-1, 2)
        w = np.array([1.0, self.settings["cam_period"]])
        d = np.linalg.norm((pts[:, None, :] - self.points[None, :, :]) * w, axis=2)
        return d.min(axis=1)

    def distance(self, points: np.ndarray) -> float:
        """Largest distance [rad, scaled] from the section points to the orbit."""
        return float(self.distances(points).max())


def periodic_orbit(params: Params, x0, period: int, *, numerics: Numerics | None = None,
                   tol: float = 1e-7, max_iter: int = 20) -> PeriodicOrbit:  # fmt: skip
    """Newton's method on ``P^n(x) = x`` with the monodromy matrix from the tangent dynamics.

    ``x ← x - (DP^n(x) - I)^{-1} (P^n(x) - x)``, the step halved while it does not lower the
    residual (damped Newton: Deuflhard 2004, *Newton Methods for Nonlinear Problems*, sec. 3),
    measured in the scaled norm ``|(Δθ, T Δθ̇)|`` [rad]. Seed it with a section point of a run
    that looks periodic (as the certificate of :func:`chaoscam.classify` does).

    ``tol`` [rad]: P is smooth only to the event tolerance (a located time jitters by
    ~``event_tol``) and to the chattering threshold ``v_chatter``, so residuals stall at ~1e-9
    to 1e-8 rad on orbits with chattering; 1e-7 rad is far below any band the classifier
    resolves. With ``|μ|max < 1`` and a residual r, a fixed point of the smooth branch lies within
    ``~r / (1 - |μ|max)`` of the returned one. The least period is the smallest divisor d of n
    with ``|P^d(x_0) - x_0|`` within ``max(10 residual, tol / 100)``: just past a flip the
    period-2d orbit's halves lie close (1.2e-7 rad on a period-16 orbit of the fractal
    stiffness whose residual is 5.7e-9 rad), so the bound follows the residual.

    Limits: P is piecewise smooth (a grazing impact or the chattering threshold makes it
    jump), so Newton may fail where the orbit grazes; ``converged`` then stays False.
    """
    t0 = time.perf_counter()
    params, num, x = _start(params, numerics, x0, "x0")
    n = whole("period", period, low=1)
    tol = real("tol", tol, low=0.0, strict=True, unit="rad")
    max_iter = whole("max_iter", max_iter, low=0)
    # up to (max_iter + 1) n periods, judged as one run (refused past the run limit, as solve)
    most = (max_iter + 1) * n
    check_run(params, num, most * params.cam_period, what=f"the shooting (up to {most} periods)")
    run = _MapRunner(params, num, n)
    x, m, res, it, first = _newton(run, x, params.cam_period, tol, max_iter)
    one = _MapRunner(params, num, 1)
    least, pts, m = _least_period(params, num, one, x, n, m, res, tol)
    # A map that left the model (the seed off the cam's reach) has no Jacobian: NaN.
    mult = np.linalg.eigvals(m) if np.isfinite(m).all() else np.full(2, np.nan + 0j)
    settings = {"tol": tol, "max_iter": max_iter, "map_calls": run.calls + one.calls,
                "cam_period": params.cam_period, "seed_period": n,
                "seed_status": first.name}  # fmt: skip
    return PeriodicOrbit(period=least, points=pts, multipliers=mult, residual=res,
                         converged=res <= tol, iterations=it, wall_time=time.perf_counter() - t0,
                         settings=settings)  # fmt: skip


def _start(params, numerics, x0, name: str) -> tuple[Params, Numerics, np.ndarray]:
    """The model, the numerics and the finite state ``name`` = (theta_f [rad], omega_f
    [rad/s]) a map function starts from, checked (a ParameterError naming the state)."""
    params, num = params_arg(params), numerics_arg(numerics)
    try:
        x = np.array(x0, dtype=float)
    except (TypeError, ValueError):
        x = np.full(1, np.nan)
    if x.shape != (2,) or not np.isfinite(x).all():
        raise ParameterError(
            f"{name} = {x0!r}: must be two finite numbers (theta_f [rad], omega_f [rad/s])"
        )
    return params, num, x


def _newton(run: _MapRunner, x: np.ndarray, period: float, tol: float, max_iter: int):
    """Damped Newton on ``P^n(x) = x``: (x, DP^n(x), residual, iterations, the seed's status)."""
    w = np.array([1.0, period])
    fx, m, code = run(x)
    first = Status(code)  # how the map from the seed ended (not OK: no orbit from there)
    res = float(np.linalg.norm((fx - x) * w)) if code == k.OK else math.inf
    it = 0
    while it < max_iter and res > tol and math.isfinite(res):
        it += 1
        try:
            dx = np.linalg.solve(m - np.eye(2), -(fx - x))
        except np.linalg.LinAlgError:
            break
        step = 1.0
        while step > 0.05:  # at most five halvings
            x_new = x + step * dx
            f_new, m_new, code = run(x_new)
            r_new = float(np.linalg.norm((f_new - x_new) * w)) if code == k.OK else math.inf
            if r_new < res:
                break
            step *= 0.5
        else:
            break
        x, fx, m, res = x_new, f_new, m_new, r_new
    return x, m, res, it, first


def _least_period(params, num, one: _MapRunner, x, n: int, m, res: float, tol: float):
    """(the least period among the divisors of n, the orbit's points, its monodromy)."""
    w = np.array([1.0, params.cam_period])
    pts = [x]
    for _ in range(n - 1):
        pts.append(one(pts[-1])[0])
    pts = np.array(pts)
    for d in range(1, n):
        if n % d == 0 and np.linalg.norm((pts[d] - pts[0]) * w) <= max(0.01 * tol, 10 * res):
            return d, pts[:d], stroboscopic_map(params, x, d, num)[1]
    return n, pts, m
