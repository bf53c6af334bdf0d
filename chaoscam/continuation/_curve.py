"""Two-parameter continuation of a fold or period-doubling point (:func:`curve`): the curve of
(λ1, λ2) where a period-n orbit has a multiplier +1 or -1, followed through the same core."""

from __future__ import annotations

import dataclasses
import math
import time

import numpy as np
import pandas as pd

from .._util import ParameterError, real, whole
from ..model import Params, params_arg
from ..numerics import Numerics
from ..simulation import numerics_arg
from ._branch import (
    Branch,
    _advance,
    _check_param,
    _fixed_point,
    _locate_grazing,
    _ModelMap,
    _mu_columns,
    _phase0,
)
from ._core import MapFailed, Settings, follow

__all__ = ["CURVE_KINDS", "Curve", "CurveMap", "curve"]

_SIGMA = {"fold": 1.0, "period_doubling": -1.0}
"""σ of the test function det(DP^n - σ I) of the events the augmented system continues."""
CURVE_KINDS = (*_SIGMA, "grazing")
"""The events a curve continues."""
GRAZE_TOL = 1e-6
"""The λ1 tolerance each point of a grazing curve is located to (λ1's units)."""
GRAZE_MARGIN = 1e-4
"""First distance [× max(|λ1|, 1)] from a grazing, on the flight side, at which a grazing
curve's next orbit is looked for (4 times more at each of up to 6 tries)."""


@dataclasses.dataclass(frozen=True)
class Curve(Branch):
    """A continued bifurcation curve (:func:`curve`): the points, events (``impact_change``,
    ``sticking``, ``end``) and settings, as :class:`Branch` keeps them.

    ``points``: one row per point: ``curve``, ``point``, ``kind`` (:data:`CURVE_KINDS`),
    ``period``, ``param``, ``value`` (λ1), ``param2``, ``value2`` (λ2), ``s`` (scaled
    arclength; a grazing's: the λ2 fraction), ``theta_f`` [rad], ``omega_f`` [rad/s] (the
    orbit's x_0 at phase 0), its multipliers (``mu1_re`` ... ``mu2_im``, ``abs_mu``),
    ``test`` (det(DP^n - σ I) there, ~0; a grazing's margin ψ [m]), ``n_macro_impacts``,
    ``sticks``, ``residual``, ``iterations``."""

    def plot(self, ax=None):
        """λ1 against λ2 on ``ax`` (a new figure's when None), one line per curve; the Axes."""
        from ..plot import plot_curves

        return plot_curves(self.points, ax=ax)


class _ModelPair:
    """P^n of the model with two fields set: ``(x, λ1, λ2) -> (P^n(x), DP^n(x))``, and the
    orbit's observation, the maps kept for the last few λ2."""

    def __init__(self, params: Params, names, n: int, num: Numerics) -> None:
        self.params, self.names, self.n, self.num = params, names, n, num
        self.maps: dict[float, _ModelMap] = {}

    def model(self, lam2: float) -> _ModelMap:
        if lam2 not in self.maps:
            if len(self.maps) > 4:
                self.maps.pop(next(iter(self.maps)))
            try:
                p = self.params.replace(**{self.names[1]: lam2})
            except (ParameterError, ValueError) as err:
                raise MapFailed(str(err)) from None
            self.maps[lam2] = _ModelMap(p, self.names[0], self.n, self.num)
        return self.maps[lam2]

    def __call__(self, x, lam1, lam2):
        return self.model(lam2)(x, lam1)

    def observe(self, x, lam1, lam2):
        return self.model(lam2).observe(x, lam1)


class CurveMap:
    """The extended system of a bifurcation curve as a map of y = (x1, x2, λ1) at λ2, for
    :func:`chaoscam.continuation.follow`: Q(y) = (P(x; λ1, λ2), λ1 + g / w1),
    g = det(DP - σ I), whose fixed points are the curve's points (σ = +1 a fold, -1 a period
    doubling). ``pmap(x, λ1, λ2) -> (P, DP)``; ``weights`` (w_x1, w_x2, w1, w2) scale the
    unknowns; ``fd_step``: the difference steps of DQ (:meth:`__call__`)."""

    def __init__(self, pmap, sigma: float, weights, fd_step: float = 1e-5) -> None:
        self.pmap, self.sigma = pmap, sigma
        self.w, self.fd = np.asarray(weights, dtype=float), fd_step

    def _pg(self, x, lam1, lam2):
        px, dp = self.pmap(x, lam1, lam2)
        return px, dp, float(np.linalg.det(dp - self.sigma * np.eye(2))) / self.w[2]

    def value(self, y, lam2):
        px, _, g = self._pg(y[:2], float(y[2]), lam2)
        return np.append(px, y[2] + g)

    def __call__(self, y, lam2):
        """Q(y) and DQ(y): ∂g/∂x_i by central differences of step ``fd_step / w_i``, ∂/∂λ1
        of P and g of step ``fd_step max(|λ1|, 1)`` (9 evaluations of P and DP)."""
        x, lam1 = y[:2], float(y[2])
        px, dp, g = self._pg(x, lam1, lam2)
        dq = np.zeros((3, 3))
        dq[:2, :2] = dp
        for i in range(2):
            e = np.eye(2)[i] * self.fd / self.w[i]
            dq[2, i] = (self._pg(x + e, lam1, lam2)[2] - self._pg(x - e, lam1, lam2)[2]) / (
                2 * e[i]
            )
        d = self.fd * max(abs(lam1), 1.0)
        (pp, _, gp), (pm, _, gm) = self._pg(x, lam1 + d, lam2), self._pg(x, lam1 - d, lam2)
        dq[:2, 2], dq[2, 2] = (pp - pm) / (2 * d), 1.0 + (gp - gm) / (2 * d)
        return np.append(px, lam1 + g), dq

    def observe(self, y, lam2):
        """The point's DP and test function, and what ``pmap.observe`` says of its orbit."""
        x, lam1 = y[:2], float(y[2])
        info = self.pmap.observe(x, lam1, lam2) if hasattr(self.pmap, "observe") else {}
        _, dp, g = self._pg(x, lam1, lam2)
        return {**info, "dp": dp, "test": g * self.w[2]}


def curve(params: Params | None, start, *, second: str, to: float, param: str | None = None,
          kind: str | None = None, period: int = 1, numerics: Numerics | None = None,
          span: float | None = None, ds: float = 0.005, ds_min: float = 1e-6,
          ds_max: float = 0.02, tol: float = 1e-7, max_points: int = 300) -> Curve:  # fmt: skip
    """Continuation of a fold, period doubling or grazing of a period-n orbit in two
    parameters: the curve of (λ1, λ2) = (``param``, ``second``) on which P^n has a
    multiplier σ = +1 (fold) or -1 (period doubling), by pseudo-arclength, or on which a
    flight of the orbit touches the cam (grazing), by natural steps in λ2 (below).

    The unknowns u = (θ_f, θ̇_f, λ1, λ2) solve the minimally augmented system
    ``P^n(x; λ1, λ2) - x = 0``, ``g = det(DP^n - σ I) = 0`` (Kuznetsov 2004, *Elements of
    Applied Bifurcation Theory*, sec. 10.2.2; Dankowicz & Schilder 2013, *Recipes for
    Continuation*, ch. 12), 3 equations in 4 unknowns, followed by
    :func:`chaoscam.continuation.follow` as the fixed points of
    ``Q(x, λ1; λ2) = (P^n, λ1 + g / w1)``, scaled to ``z = (θ_f, T θ̇_f, λ1 / span,
    λ2 / |to - λ2_0|)``. DP^n from the tangent dynamics with saltation (di Bernardo et al.
    2008, ch. 2); ∂g/∂x by central differences of DP^n with steps 1e-5 rad in θ_f and
    1e-5 / T rad/s in θ̇_f, ∂/∂λ1 and ∂/∂λ2 with steps ``1e-5 max(|λ|, 1)``. Changes of the
    impact count or of sticking along the curve are bisected into its events.

    Parameters
    ----------
    params : Params
        The model where the branch was followed (λ2 = ``params.<second>``).
    start : mapping
        A row of :attr:`Branch.events` (``kind``, ``param``, ``value``, ``theta_f``,
        ``omega_f``): corrected onto the curve at λ2 fixed first.
    second, to : str, float
        The second parameter and the value to follow it to.
    param, kind : str, optional
        λ1 and the kind (:data:`CURVE_KINDS`), by default the row's.
    span : float, optional
        λ1's unit of scaled arclength, by default ``0.1 max(|λ1|, 1)``.

    A grazing (its row's ``section_phase`` kept) is traced in steps of ``ds_max`` × |to - λ2|
    in λ2: at each the orbit on the flight side of the last grazing (:data:`GRAZE_MARGIN`)
    by Newton at fixed λ1, and the grazing located from it in λ1 to :data:`GRAZE_TOL`, as
    :func:`chaoscam.continuation.continuation` locates one where a branch ends (the map is
    not smooth across a grazing, so the augmented system does not apply); ``test`` is the
    margin ψ there [m]. It cannot turn round a fold of the curve.

    Limits: where the impact pattern changes the map is only piecewise smooth and the curve
    may end there (``end``); a codimension-two point (a cusp, a fold-flip) is not detected.
    """
    t_start = time.perf_counter()
    params, num = params_arg(params), numerics_arg(numerics)
    param = param or str(start["param"])
    kind = kind or str(start["kind"])
    if kind not in CURVE_KINDS:
        raise ParameterError(f"kind = {kind!r}: a curve continues {sorted(CURVE_KINDS)}")
    for name in (param, second):
        _check_param(params, name)
    if param == second:
        raise ParameterError(f"second = {second!r}: the same as param; give another")
    n, lam2 = whole("period", period, low=1), float(getattr(params, second))
    to = real("to", to)
    lam1 = float(start["value"])
    span = real("span", span, low=0.0, strict=True) if span else 0.1 * max(abs(lam1), 1.0)
    p0 = params.replace(**{param: lam1})
    if kind == "grazing":
        points, ends = _grazing_curve(p0, start, (param, second), to, n, num, ds_max,
                                      max_points)  # fmt: skip
        return _curve_frames(points, ends, kind, n, (param, second), p0, num, t_start,
                             {"from": lam2, "to": to, "h_max": ds_max})  # fmt: skip
    w = (1.0, p0.cam_period, 1.0 / span, 1.0 / abs(to - lam2))
    st = Settings(weights=w, lo=min(lam2, to), hi=max(lam2, to), h0=ds, h_min=ds_min,
                  h_max=ds_max, tol=tol,
                  max_points=whole("max_points", max_points, low=2))  # fmt: skip
    qmap = CurveMap(_ModelPair(p0, (param, second), n, num), _SIGMA[kind], w, st.fd_step)
    u0 = (float(start["theta_f"]), float(start["omega_f"]), lam1, lam2)
    try:
        points, events = follow(qmap, u0, st, direction=math.copysign(1.0, to - lam2),
                                observe=qmap.observe, kinds=())  # fmt: skip
    except MapFailed as err:
        msg = f"the {kind} at {param} = {lam1:g} could not be continued: {err}"
        raise ParameterError(msg) from None
    return _curve_frames([(p.u, p.s, p.info, p.residual, p.iterations) for p in points],
                         [(k, p.u, p.s, d) for k, p, d in events], kind, n, (param, second), p0,
                         num, t_start, {"from": lam2, "to": to,
                                        **{f.name: getattr(st, f.name)
                                           for f in dataclasses.fields(st)}})  # fmt: skip


def _curve_frames(points, events, kind, n, names, p0, num, t_start, more) -> Curve:
    """The Curve of ``points`` (u = (θ_f, θ̇_f, λ1, λ2), s, info, residual, iterations) and
    ``events`` (kind, u, s, detail)."""
    common = {"curve": 0, "kind": kind, "period": n, "param": names[0], "param2": names[1]}
    rows = [{**common, "point": i, "value": float(u[2]), "value2": float(u[3]), "s": s,
             "theta_f": float(u[0]), "omega_f": float(u[1]), **_mu_columns(info["dp"]),
             "test": info["test"], "n_macro_impacts": info["n_macro_impacts"],
             "sticks": info["sticks"], "residual": res, "iterations": it}
            for i, (u, s, info, res, it) in enumerate(points)]  # fmt: skip
    for r in rows:
        r["abs_mu"] = math.hypot(r["mu1_re"], r["mu1_im"])
    ev = pd.DataFrame([{**common, "kind": k, "value": float(u[2]), "value2": float(u[3]),
                        "s": s, "detail": detail} for k, u, s, detail in events])  # fmt: skip
    settings = {"params": dataclasses.asdict(p0), "numerics": dataclasses.asdict(num),
                "kind": kind, "param": names[0], "second": names[1], "period": n, **more,
                "wall_time": time.perf_counter() - t_start}  # fmt: skip
    return Curve(pd.DataFrame(rows), ev, settings)


def _grazing_curve(p0: Params, start, names, to: float, n: int, num: Numerics, step: float,
                   max_points: int) -> tuple[list, list]:  # fmt: skip
    """A grazing continued in λ2 by natural steps of ``step`` times |to - λ2|: at each λ2 the
    orbit on the flight side near the last grazing (Newton at fixed λ1) and the grazing
    located from it in λ1 (:func:`~chaoscam.continuation._branch._locate_grazing`), since
    the map is not smooth across a grazing; (points, events) as :func:`_curve_frames`
    takes them."""
    param, second = names
    lam1, lam2 = float(start["value"]), float(getattr(p0, second))
    phase = float(start.get("section_phase", 0.0) or 0.0)
    x = np.array([float(start["theta_f"]), float(start["omega_f"])])
    if phase:
        x = _advance(p0, num, x, phase / p0.omega)
    d2, points, side, track = step * (to - lam2), [], None, [lam1]
    reason = f"max_points = {max_points} reached"
    for k in range(max_points):
        v2 = lam2 + k * d2
        if (v2 - to) * math.copysign(1.0, d2) > 1e-12 * max(abs(to), 1.0):
            reason = f"reached {second} = {to:g}"
            break
        model = _ModelMap(p0.replace(**{second: v2}), param, n, num, phase)
        guess = 2 * track[-1] - track[-2] if len(track) > 1 else track[-1]
        found = _flight_side(model, x, guess, side)
        located = (
            None
            if found is None
            else _locate_grazing(
                model, found[1], found[0], found[2], found[3], GRAZE_TOL, (-math.inf, math.inf)
            )
        )
        if located is None:
            reason = f"no grazing located at {second} = {v2:.6g}"
            break
        x, lam, info = located
        side = math.copysign(1.0, found[0] - lam)
        track.append(lam)
        _, dp = model(x, lam)
        u = (*_phase0(info, x), lam, v2)
        points.append((u, abs(v2 - lam2) / abs(to - lam2), {**info, "dp": dp,
                       "test": info["grazing"]}, math.nan, 0))  # fmt: skip
    end = points[-1][0] if points else (*x, lam1, lam2)
    return points, [("end", end, points[-1][1] if points else 0.0, reason)]


def _flight_side(model: _ModelMap, x, guess: float, side: float | None):
    """An orbit near x on the flight side (ψ > 0) of a grazing near λ1 = ``guess``:
    (λ1, x, info, dψ/dλ1 estimate), or None."""
    margin = GRAZE_MARGIN * max(abs(guess), 1.0)
    for _ in range(6):
        for sgn in (side,) if side else (-1.0, 1.0):
            lam = guess + sgn * margin
            y = _fixed_point(model, x, lam)
            info = model.observe(y, lam) if y is not None else {}
            psi = info.get("grazing", math.nan)
            if psi > 0.0:
                return lam, y, info, -psi / (guess - lam)
        margin *= 4.0
    return None
