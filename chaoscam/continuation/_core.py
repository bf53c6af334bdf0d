"""Pseudo-arclength continuation of fixed points of a map ``P(x; λ)``, x in R^m, with its test
functions located along the branch, generic over the map: the model's stroboscopic map, the
bouncing ball's impact map and a bifurcation curve's extended system go through the same code.

Unknowns u = (x, λ), scaled to z = w u (``weights``); the branch is ``G(u) = P(x; λ) - x = 0``,
a curve in R^(m+1) whose tangent is the null vector of ``G_u = [DP - I | ∂P/∂λ]`` (its
signed minors: the cross product of its two scaled rows when m = 2). A step: the predictor
``z_p = z + h t``, then Newton on the extended system ``(G(z), t·(z - z_k) - h) = 0``
(Keller's pseudo-arclength condition; Kuznetsov 2004, *Elements of Applied Bifurcation
Theory*, sec. 10.2; Dankowicz & Schilder 2013, *Recipes for Continuation*, ch. 3).
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

import numpy as np

__all__ = ["MapPoint", "Settings", "follow", "null_vector"]

CONTINUOUS = ("fold", "period_doubling", "neimark_sacker")
"""Test functions located by the Illinois secant on arclength: ``fold`` the λ component of
the oriented tangent (∝ det(DP - I), a multiplier through +1), ``period_doubling``
det(DP + I) (a multiplier through -1), ``neimark_sacker`` det DP - 1 while the multipliers are
a complex pair (``|μ1 μ2| = 1``). Any other kind is read from the point's observation
(``info[kind]``, e.g. ``grazing``: the flights' margin ψ). A sign change where the function
does not go to zero (``|f| > JUMP max(|f_a|, |f_b|)`` at the located point) is a jump, not a
zero: no event, except for the kinds above where the stability (``|μ|max < 1``) differs on
the two sides, an event whose detail says it was not located (on a sticking orbit the
multipliers of the grid map jump, e.g. from +27 to -15, without a bifurcation)."""
JUMP = 0.1
"""See :data:`CONTINUOUS`."""
CORRECTOR_FAILED = "the corrector failed at the least step"
"""How the ``end`` event's reason begins where the step fell below ``h_min``."""


class MapFailed(Exception):
    """The map could not be evaluated at (x, λ) (the run left the model, λ out of range)."""


@dataclass(frozen=True)
class Settings:
    """How a branch is followed (scaled units: z = weights * (x, λ)).

    Attributes
    ----------
    h0, h_min, h_max : float
        First, least and largest arclength step (scaled). A step whose corrector fails is
        halved; one that converges in at most ``easy`` iterations is followed by one
        ``grow`` times longer; the branch ends when the step would fall below ``h_min``.
    tol : float
        Corrector tolerance on the scaled residual ``|w_x (P(x) - x)|``.
    max_iter : int
        Newton iterations of one corrector.
    fd_step : float
        Relative step of the central difference ∂P/∂λ ≈ (P(λ + δ) - P(λ - δ)) / 2δ,
        ``δ = fd_step max(|λ|, 1)``: truncation ~δ² P''' and round-off ~ε_P / δ balance near
        δ ~ ε_P^(1/3), ε_P the map's own noise (1e-10 rad on the model's located events).
        ∂P/∂λ enters only the Newton matrix and the tangent, never the residual, so its
        error slows the corrector but does not move the branch.
    event_tol : float
        Events are located until their arclength bracket is at most ``event_tol * w_λ``
        long: λ then to within ``event_tol`` (λ's units).
    max_points, lo, hi : int, float, float
        Most points, and the λ interval the branch must stay in.
    min_cos : float
        A step whose new tangent makes with the last one an angle whose cosine is below this
        is refused and retried shorter (a guard against jumping between branches).
    max_jump : float
        A step whose corrected point lies farther than ``max_jump`` times the step from its
        predictor is refused and retried shorter: the corrector went to another branch (on
        the model, from an impacting orbit to the follower hanging off the cam, whose tangent
        points the same way).
    """

    weights: tuple
    lo: float
    hi: float
    h0: float
    h_min: float
    h_max: float
    tol: float = 1e-7
    max_iter: int = 8
    easy: int = 3
    grow: float = 1.5
    fd_step: float = 1e-5
    event_tol: float = 1e-6
    max_points: int = 500
    min_cos: float = 0.8
    max_jump: float = 1.0


@dataclass
class MapPoint:
    """A point of the branch: u = (x1, x2, λ) unscaled, its scaled unit tangent t, DP, the
    scaled residual, Newton's iterations, the arclength s, and what ``observe`` said."""

    u: np.ndarray
    t: np.ndarray
    dp: np.ndarray
    residual: float
    iterations: int
    s: float = 0.0
    info: dict[str, Any] = field(default_factory=dict)

    @property
    def multipliers(self) -> np.ndarray:
        """Eigenvalues of DP, the larger modulus first."""
        mu = np.linalg.eigvals(self.dp).astype(complex)
        return mu[np.argsort(-np.abs(mu), kind="stable")]

    def test(self, kind: str) -> float:
        """The value of test function ``kind`` (:data:`CONTINUOUS`) here."""
        if kind == "fold":
            return float(self.t[-1])
        if kind == "period_doubling":
            return float(np.linalg.det(self.dp + np.eye(len(self.dp))))
        if kind == "neimark_sacker":
            tr, det = np.trace(self.dp), np.linalg.det(self.dp)
            return float(det - 1.0) if tr * tr < 4.0 * det else math.nan
        return float(self.info.get(kind, math.nan))


class _Branch:
    """One branch being followed: the map, its settings, the corrector and the locators."""

    def __init__(self, fun: Callable, st: Settings, observe: Callable | None) -> None:
        self.fun, self.st, self.observe = fun, st, observe
        self.value = getattr(fun, "value", lambda x, lam: fun(x, lam)[0])
        self.w = np.asarray(st.weights, dtype=float)

    def evaluate(self, z: np.ndarray):
        """(scaled residual G, scaled G_z (m x m+1), DP) at scaled z; MapFailed if it fails."""
        u = z / self.w
        x, lam = u[:-1], float(u[-1])
        px, dp = self.fun(x, lam)
        d = self.st.fd_step * max(abs(lam), 1.0)
        dlam = (self.value(x, lam + d) - self.value(x, lam - d)) / (2.0 * d)
        jac = np.column_stack([dp - np.eye(len(x)), dlam])
        g = (px - x) * self.w[:-1]
        if not (np.isfinite(g).all() and np.isfinite(jac).all()):
            raise MapFailed("the map returned NaN")
        return g, self.w[:-1, None] * jac / self.w[None, :], dp

    def correct(self, z0: np.ndarray, t0: np.ndarray, h: float) -> MapPoint | None:
        """Newton on ``(G(z), t0·(z - z0) - h) = 0`` from the predictor ``z0 + h t0``: the
        point (its tangent oriented along t0), or None when it does not converge."""
        z = z0 + h * t0
        for it in range(self.st.max_iter + 1):
            try:
                g, jz, dp = self.evaluate(z)
            except MapFailed:
                return None
            res = float(np.linalg.norm(g))
            if res <= self.st.tol and it > 0 or res <= 0.01 * self.st.tol:
                t = null_vector(jz)
                norm = float(np.linalg.norm(t))
                if not norm > 0.0:
                    return None
                t = t / norm * (1.0 if t @ t0 >= 0.0 else -1.0)
                return MapPoint(z / self.w, t, dp, res, it)
            if it == self.st.max_iter:
                return None
            ext = np.vstack([jz, t0])
            rhs = -np.append(g, t0 @ (z - z0) - h)
            try:
                z = z + np.linalg.solve(ext, rhs)
            except np.linalg.LinAlgError:
                return None
        return None

    def at(self, a: MapPoint, s: float) -> MapPoint | None:
        """The point at arclength ``s`` from a along a's tangent, with its observation."""
        b = self.correct(a.u * self.w, a.t, s)
        if b is not None:
            b.s = a.s + s
            b.info = self.observe(b.u[:-1], float(b.u[-1])) if self.observe else {}
        return b

    def locate(self, a: MapPoint, b: MapPoint, kind: str) -> MapPoint:
        """Where test function ``kind`` changes sign between a and b: the Illinois secant on
        the arclength from a, to a bracket of ``event_tol * w_λ``."""
        s_tol = self.st.event_tol * self.w[-1]
        lo, hi = 0.0, b.s - a.s
        f_lo, f_hi = a.test(kind), b.test(kind)
        best, side = b, 0
        while hi - lo > s_tol:
            s = hi - f_hi * (hi - lo) / (f_hi - f_lo) if f_hi != f_lo else lo
            if not lo < s < hi:
                s = 0.5 * (lo + hi)
            p = self.at(a, s)
            if p is None:
                break
            best, f = p, p.test(kind)
            if f == 0.0 or not math.isfinite(f):
                break
            if (f > 0) == (f_hi > 0):
                hi, f_hi = s, f
                f_lo, side = (0.5 * f_lo if side == 1 else f_lo), 1
            else:
                lo, f_lo = s, f
                f_hi, side = (0.5 * f_hi if side == -1 else f_hi), -1
        return best

    def bisect(self, a: MapPoint, b: MapPoint, same: Callable) -> MapPoint:
        """The first point past a where ``same(a, p)`` fails, bisected on the arclength to a
        bracket of ``event_tol * w_λ`` (a change of the impact or sticking pattern)."""
        s_tol = self.st.event_tol * self.w[-1]
        lo, hi, best = 0.0, b.s - a.s, b
        while hi - lo > s_tol:
            mid = 0.5 * (lo + hi)
            p = self.at(a, mid)
            if p is None:
                break
            if same(a, p):
                lo = mid
            else:
                hi, best = mid, p
        return best


def _stable(p: MapPoint) -> bool:
    return bool(np.max(np.abs(p.multipliers)) < 1.0)


def _jumped(br: _Branch, a: MapPoint, b: MapPoint, h: float) -> bool:
    """Whether b lies farther than ``max_jump * h`` from a's predictor (scaled)."""
    return float(np.linalg.norm(b.u * br.w - (a.u * br.w + h * a.t))) > br.st.max_jump * h


def null_vector(jac: np.ndarray) -> np.ndarray:
    """The null vector of an m x (m + 1) matrix: t_i = (-1)^i det(jac without column i), the
    cross product of its rows when m = 2; its last component is det of the first m columns."""
    cols = range(jac.shape[1])
    return np.array([(-1) ** i * np.linalg.det(np.delete(jac, i, axis=1)) for i in cols])


def _crossings(br: _Branch, a: MapPoint, b: MapPoint, kinds) -> list[tuple[str, MapPoint, str]]:
    """The events between consecutive points a and b: (kind, located point, detail)."""
    found = []
    for kind in kinds:
        fa, fb = a.test(kind), b.test(kind)
        if fa * fb < 0.0:  # NaN (no complex pair) and an exact zero (a switch's start) pass
            p = br.locate(a, b, kind)
            if abs(p.test(kind)) <= JUMP * max(abs(fa), abs(fb)):
                found.append((kind, p, ""))
            elif kind in CONTINUOUS and _stable(a) != _stable(b):
                found.append((kind, p, f"the test function jumps across 0 between "
                              f"{float(a.u[-1]):.8g} and {float(b.u[-1]):.8g} (the map is not "
                              "smooth there): not located"))  # fmt: skip
    for kind, key in (("impact_change", "n_macro_impacts"), ("sticking", "sticks")):
        if key in a.info and a.info[key] != b.info.get(key):
            p = br.bisect(a, b, lambda a_, p_, key=key: p_.info.get(key) == a_.info[key])
            found.append((kind, p, f"{key} {a.info[key]} -> {p.info.get(key)}"))
    return sorted(found, key=lambda e: e[1].s)


def follow(fun: Callable, u0, st: Settings, *, t0=None, direction=1.0,
           observe: Callable | None = None, kinds=CONTINUOUS,
           on_point: Callable | None = None, resume=None,
           prior=None) -> tuple[list[MapPoint], list[tuple]]:  # fmt: skip
    """Follow the branch of fixed points of ``fun`` from u0 = (x, λ), a fixed point.

    Parameters
    ----------
    fun : callable
        ``fun(x, lam) -> (P(x; lam), DP(x; lam))``, x in R^m (m = 2 for an orbit, 3 for a
        bifurcation curve's extended system), raising :class:`MapFailed` where it cannot;
        ``fun.value(x, lam) -> P(x; lam)``, when it has one, serves the λ difference.
    u0 : array of m + 1
        A fixed point (corrected first, at λ fixed) and its parameter.
    st : Settings
        Steps, tolerances, the λ interval.
    t0 : array of m + 1, optional
        The first tangent (scaled); by default the branch's, oriented so that λ moves with
        the sign of ``direction`` (a float), or along ``direction`` (an array of m + 1,
        scaled). A branch switch gives the new branch's direction here.
    observe : callable, optional
        ``observe(x, lam) -> dict`` of the orbit's discrete features (``n_macro_impacts``,
        ``sticks``): a change between points is an event, bisected.
    kinds : tuple of str
        The test functions (:data:`CONTINUOUS`) located along the branch.
    on_point : callable, optional
        ``on_point(points, events)`` after each new point (a checkpoint).
    resume : (points, events), optional
        An interrupted branch: followed on from its last point and tangent (u0 unused).
    prior : (points, events), optional
        The branch so far in other coordinates (another Poincaré section): the new points
        follow them in the lists returned, the arclength going on from their last.

    Returns
    -------
    (points, events) : list of MapPoint, list of (kind, MapPoint, detail)
        Events in order along the branch; the last is ``end`` with its reason.
    """
    br = _Branch(fun, st, observe)
    z0 = np.asarray(u0, dtype=float) * br.w
    if resume is not None:
        points, events, h = list(resume[0]), list(resume[1]), st.h0
        a = points[-1]
        if len(points) > 1 and a.s > points[-2].s:  # the step that follows a's, as it was
            h = min((a.s - points[-2].s) * (st.grow if a.iterations <= st.easy else 1.0),
                    st.h_max)  # fmt: skip
    elif t0 is None:
        a = br.correct(z0, np.eye(len(z0))[-1], 0.0)  # λ fixed: plain Newton on x
        if a is None:
            raise MapFailed("no fixed point near the start: the corrector did not converge")
        along = a.t @ direction if np.ndim(direction) else a.t[-1] * direction
        a.t = a.t if along >= 0 else -a.t
    else:  # a branch point (its Jacobian singular): taken as it is, left along t0
        g, _, dp = br.evaluate(z0)
        t0 = np.asarray(t0, dtype=float)
        a = MapPoint(z0 / br.w, t0 / np.linalg.norm(t0), dp, float(np.linalg.norm(g)), 0)
    if resume is None:
        a.info = observe(a.u[:-1], float(a.u[-1])) if observe else {}
        points, events = (list(prior[0]), list(prior[1])) if prior else ([], [])
        a.s = points[-1].s if points else 0.0
        points, h = [*points, a], st.h0
    reason = f"max_points = {st.max_points} reached"
    while len(points) < st.max_points:
        b = br.at(a, h)
        if b is None or b.t @ a.t < st.min_cos or _jumped(br, a, b, h):
            if h <= st.h_min:
                reason = (
                    f"{CORRECTOR_FAILED} (h_min = {st.h_min:g}): the "
                    "branch ends, or the map is not smooth here (grazing, chattering)"
                )
                break  # fmt: skip
            h = max(0.5 * h, st.h_min)
            continue
        events.extend(_crossings(br, a, b, kinds))
        points.append(b)
        a = b
        if on_point is not None:
            on_point(points, events)
        if not st.lo <= float(b.u[-1]) <= st.hi:
            reason = f"left the interval [{st.lo:g}, {st.hi:g}]"
            break
        if b.iterations <= st.easy:
            h = min(h * st.grow, st.h_max)
    events.append(("end", points[-1], reason))
    return points, events
