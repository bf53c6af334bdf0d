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
from ._branch import Branch, _check_param, _ModelMap, _mu_columns
from ._core import MapFailed, Settings, follow

__all__ = ["CURVE_KINDS", "Curve", "CurveMap", "curve"]

CURVE_KINDS = {"fold": 1.0, "period_doubling": -1.0}
"""The events a curve continues and σ of their test function det(DP^n - σ I)."""


@dataclasses.dataclass(frozen=True)
class Curve(Branch):
    """A continued bifurcation curve (:func:`curve`): the points, events (``impact_change``,
    ``sticking``, ``end``) and settings, as :class:`Branch` keeps them.

    ``points``: one row per point: ``curve``, ``point``, ``kind`` (:data:`CURVE_KINDS`),
    ``period``, ``param``, ``value`` (λ1), ``param2``, ``value2`` (λ2), ``s`` (scaled
    arclength), ``theta_f`` [rad], ``omega_f`` [rad/s] (the orbit's x_0), its multipliers
    (``mu1_re`` ... ``mu2_im``, ``abs_mu``), ``test`` (det(DP^n - σ I) there, ~0),
    ``n_macro_impacts``, ``sticks``, ``residual``, ``iterations``."""

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
    """Pseudo-arclength continuation of a fold or period doubling of a period-n orbit in two
    parameters: the curve of (λ1, λ2) = (``param``, ``second``) on which P^n has a
    multiplier σ = +1 (fold) or -1 (period doubling).

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
    w = (1.0, p0.cam_period, 1.0 / span, 1.0 / abs(to - lam2))
    st = Settings(weights=w, lo=min(lam2, to), hi=max(lam2, to), h0=ds, h_min=ds_min,
                  h_max=ds_max, tol=tol,
                  max_points=whole("max_points", max_points, low=2))  # fmt: skip
    qmap = CurveMap(_ModelPair(p0, (param, second), n, num), CURVE_KINDS[kind], w, st.fd_step)
    u0 = (float(start["theta_f"]), float(start["omega_f"]), lam1, lam2)
    try:
        points, events = follow(qmap, u0, st, direction=math.copysign(1.0, to - lam2),
                                observe=qmap.observe, kinds=())  # fmt: skip
    except MapFailed as err:
        msg = f"the {kind} at {param} = {lam1:g} could not be continued: {err}"
        raise ParameterError(msg) from None
    common = {"curve": 0, "kind": kind, "period": n, "param": param, "param2": second}
    rows = [{**common, "point": i, "value": float(p.u[2]), "value2": float(p.u[3]), "s": p.s,
             "theta_f": float(p.u[0]), "omega_f": float(p.u[1]), **_mu_columns(p.info["dp"]),
             "test": p.info["test"], "n_macro_impacts": p.info["n_macro_impacts"],
             "sticks": p.info["sticks"], "residual": p.residual, "iterations": p.iterations}
            for i, p in enumerate(points)]  # fmt: skip
    for r in rows:
        r["abs_mu"] = math.hypot(r["mu1_re"], r["mu1_im"])
    ev = pd.DataFrame([{**common, "kind": k, "value": float(p.u[2]), "value2": float(p.u[3]),
                        "s": p.s, "detail": detail} for k, p, detail in events])  # fmt: skip
    settings = {"params": dataclasses.asdict(p0), "numerics": dataclasses.asdict(num),
                "kind": kind, "param": param, "second": second, "from": lam2, "to": to,
                "period": n, **{f.name: getattr(st, f.name) for f in dataclasses.fields(st)},
                "wall_time": time.perf_counter() - t_start}  # fmt: skip
    return Curve(pd.DataFrame(rows), ev, settings)
