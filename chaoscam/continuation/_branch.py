"""Continuation of the model's period-n orbits in one parameter (:func:`continuation`) and the
branch it returns (:class:`Branch`): the points, the events, a drawing and the files."""

from __future__ import annotations

import dataclasses
import json
import math
import time
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd

from .._util import ParameterError, freeze_fields, real, unknown_message, whole
from ..model import Params, field_names, params_arg
from ..numerics import Numerics
from ..simulation import numerics_arg, simulate
from ..verdict import map_runner, periodic_orbit
from ._core import MapFailed, MapPoint, Settings, follow

__all__ = ["Branch", "NoOrbitError", "continuation", "events_path"]

EVENT_KINDS = ("fold", "period_doubling", "neimark_sacker", "grazing", "sticking",
               "impact_change", "end")  # fmt: skip
"""The ``kind`` values of :attr:`Branch.events`. ``grazing`` is reserved: the kernel keeps no
flight gap to test, so a grazing shows as the ``impact_change`` it causes."""

SWITCH_EPS = 1e-4
"""Length of the first step [scaled arclength] onto the doubled branch, along the
eigenvector of the multiplier -1."""


class NoOrbitError(ValueError):
    """The start converges to no periodic orbit of the period asked for."""


@dataclass(frozen=True)
class Branch:
    """A followed branch of periodic orbits (:func:`continuation`).

    Attributes
    ----------
    points : pandas.DataFrame
        One row per section point of each orbit on the branch: ``branch`` (0 the one followed,
        1, 2, ... those switched onto at period doublings), ``point`` (its index along the
        branch), ``j`` (section point j = 0..n-1 of the orbit), ``period`` n [cam periods],
        ``param``, ``value`` (the parameter), ``s`` (scaled arclength), ``theta_f`` [rad],
        ``omega_f`` [rad/s], the multipliers of DP^n at the orbit's x_0 (``mu1_re``,
        ``mu1_im``, ``mu2_re``, ``mu2_im``, ``|mu1| >= |mu2|``), ``abs_mu`` (``|mu1|``),
        ``stable`` (``|mu1| < 1``), ``n_macro_impacts``, ``n_micro_impacts``, ``n_chatter_ends``
        (counted over the orbit's n cam periods), ``contact_fraction``, ``sticks``
        (persistent contact: a complete chattering or grid steps in contact), ``residual``
        (scaled, rad) and ``iterations`` (the corrector's).
    events : pandas.DataFrame
        ``branch``, ``kind`` (:data:`EVENT_KINDS`), ``param``, ``value``, ``s``, ``theta_f``,
        ``omega_f``, the multipliers there, and ``detail``.
    settings : dict
        Everything the continuation used (the model, the numerics, the steps, tolerances).
    """

    points: pd.DataFrame
    events: pd.DataFrame
    settings: dict[str, Any] = field(default_factory=dict)

    def __post_init__(self) -> None:
        freeze_fields(self, "settings")

    def plot(self, ax=None):
        """The branch diagram on ``ax`` (a new figure's when None): the parameter against
        the section's θ_f, stable orbits solid, unstable dashed, events marked; the Axes."""
        from ..plot import plot_branch

        return plot_branch(self.points, self.events, ax=ax)

    def to_parquet(self, path: str | Path, *, replace: bool = False) -> tuple[Path, Path]:
        """The points to ``path`` and the events to :func:`events_path` of it (Parquet with
        checksums, written whole, an existing file refused unless ``replace``); the paths."""
        import pyarrow as pa

        from ..io import write_new_parquet

        meta = {b"chaoscam.continuation": json.dumps(self.settings, default=str).encode()}
        paths = (Path(path), events_path(path))
        for frame, where in zip((self.points, self.events), paths, strict=True):
            table = pa.Table.from_pandas(frame, preserve_index=False)
            table = table.replace_schema_metadata({**(table.schema.metadata or {}), **meta})
            write_new_parquet(table, where, replace=replace)
        return paths


def events_path(path: str | Path) -> Path:
    """Where a branch written to ``path`` keeps its events: ``NAME.events.parquet``."""
    path = Path(path)
    return path.with_name(f"{path.stem}.events{path.suffix or '.parquet'}")


class _ModelMap:
    """P^n of the model with one field set to λ: ``(x, λ) -> (P^n(x), DP^n(x))`` and the
    orbit's observation, the runners kept for the last few λ."""

    def __init__(self, params: Params, name: str, n: int, num: Numerics) -> None:
        self.params, self.name, self.n, self.num = params, name, n, num
        self.runners: dict[float, Any] = {}

    def runner(self, lam: float):
        if lam not in self.runners:
            if len(self.runners) > 8:
                self.runners.pop(next(iter(self.runners)))
            try:
                p = self.params.replace(**{self.name: lam})
            except (ParameterError, ValueError) as err:
                raise MapFailed(str(err)) from None
            self.runners[lam] = map_runner(p, self.n, self.num)
        return self.runners[lam]

    def __call__(self, x: np.ndarray, lam: float):
        px, dp, code = self.runner(lam)(x)
        if code != 0:
            raise MapFailed(f"the run from x = {x} stopped (status {code})")
        return px, dp

    def observe(self, x: np.ndarray, lam: float) -> dict[str, Any]:
        info = self.runner(lam).counts(x)
        info["sticks"] = bool(info["n_chatter_ends"] > 0 or info["contact_fraction"] > 0)
        info["cam_period"] = self.runner(lam).p.cam_period
        return info


def _check_param(params: Params, param: str) -> None:
    if param not in field_names():
        raise ParameterError(unknown_message(param, field_names()))
    value = getattr(params, param)
    if isinstance(value, bool) or not isinstance(value, int | float):
        raise ParameterError(f"param = {param!r}: not a numeric field of Params ({value!r})")


def find_start(params: Params, x0, period: int, num: Numerics, *, transient: float = 20.0):
    """A period-n orbit to start from: Newton shooting (:func:`chaoscam.periodic_orbit`) from
    x0, or from the last section point of a ``transient`` [s] run from the model's initial
    state when x0 is None; :class:`NoOrbitError` where it converges to none of period n."""
    if x0 is None:
        run = simulate(params, num, duration=transient, transient=0.0, series=False)
        if not run.ok or len(run.section) < 2:
            raise NoOrbitError(f"the start run ended {run.status.name}: {run.message}")
        x0 = run.section[["theta_f", "omega_f"]].to_numpy()[-1]
    orbit = periodic_orbit(params, x0, period, numerics=num)
    if not orbit.converged or orbit.period != period:
        got = (f"converged to period {orbit.period}, not {period}" if orbit.converged
               else f"Newton did not converge (residual {orbit.residual:.3g} rad)")  # fmt: skip
        raise NoOrbitError(
            f"no period-{period} orbit from the start x0 = {np.asarray(x0).tolist()}: {got}; "
            "give another --x0 or --period, or a parameter value where the orbit attracts"
        )
    return orbit


def continuation(params: Params | None = None, x0=None, *, param: str = "omega", to: float,
                 period: int = 1, numerics: Numerics | None = None, ds: float = 0.005,
                 ds_min: float = 1e-6, ds_max: float = 0.02, tol: float = 1e-7,
                 event_tol: float = 1e-6, max_points: int = 500, switch: bool = False,
                 transient: float = 20.0,
                 checkpoint: str | Path | None = None) -> Branch:  # fmt: skip
    """Pseudo-arclength continuation of a period-n orbit of the stroboscopic map in one
    parameter, with its Floquet multipliers, impacts, sticking and bifurcations.

    The branch ``P^n(x; λ) = x`` (x = (θ_f, θ̇_f) at the section t = 0, cam phase 0; P the
    map over n cam periods 2π/ω, whose length follows ω when ω is the parameter) is followed
    from ``params`` (λ = ``params.<param>``) towards ``to`` in the scaled coordinates
    ``z = (θ_f, T θ̇_f, λ / |to - λ0|)`` [rad, rad, -]: a predictor along the tangent, a
    Newton corrector on the extended system with the arclength condition (Keller; Kuznetsov
    2004, *Elements of Applied Bifurcation Theory*, sec. 10.2), DP^n from the tangent
    dynamics with saltation through the impacts (di Bernardo et al. 2008, *Piecewise-smooth
    Dynamical Systems*, ch. 2), ∂P/∂λ by a central difference (step ``1e-5 max(|λ|, 1)``: see
    :class:`chaoscam.continuation.Settings`). Steps: ``ds`` first, halved on a failed
    corrector down to ``ds_min`` (then the branch ends), 1.5 times longer after one that
    converged in at most 3 iterations, up to ``ds_max`` (scaled arclength; the whole λ
    interval is 1).

    Events (:data:`EVENT_KINDS`), located along the arclength to λ within ``event_tol``:
    ``fold`` (the tangent's λ component changes sign: a multiplier through +1; the branch is
    followed round it onto the unstable side), ``period_doubling`` (det(DP + I) changes
    sign: a multiplier through -1; with ``switch`` the period-2n branch is followed from
    there, its first step along the eigenvector of -1), ``neimark_sacker`` (a complex pair
    through ``|μ1 μ2| = 1``: under the default Hunt–Crossley damping ``|μ1 μ2| ≤ ξ² < 1`` after a
    jump and < 1 in persistent contact, which forbids it: docs/continuation.md), and changes
    of the orbit's pattern, bisected: ``impact_change`` (the number of macro impacts over the
    n periods changes: a grazing impact, for which the kernel has no cheaper test function)
    and ``sticking`` (persistent contact begins or ends). ``end`` says why the branch stops.

    Parameters
    ----------
    params : Params, optional
        The model (deterministic: l_lambda_sigma = 0) at the start.
    x0 : (θ_f [rad], θ̇_f [rad/s]), optional
        A point near the start orbit; by default the last section point of a ``transient``
        [s] run from the model's initial state.
    param, to : str, float
        The numeric field of :class:`Params` followed, and the value to follow it to.
    period : int
        n, in cam periods.
    tol : float
        Corrector tolerance [rad] on the scaled residual ``|(Δθ, T Δθ̇)|`` (residuals stall at
        1e-9 to 1e-8 rad on orbits with chattering: see :func:`chaoscam.periodic_orbit`).
    max_points : int
        Most points of each branch.
    checkpoint : path, optional
        A JSON file that keeps the followed branch's points and events so far (written whole
        at most once every :data:`CHECKPOINT_S`): one left by an interrupted call with the same
        settings is followed on from its last point and tangent; removed once done.

    Raises
    ------
    NoOrbitError
        The start converges to no period-n orbit.

    Limits: the map is piecewise smooth; at a grazing or at the onset of chattering the
    corrector may fail even at ``ds_min`` and the branch ends there (``end``, with the
    reason). Only the branch followed is switched at a period doubling, not the doubled ones.
    """
    t_start = time.perf_counter()
    params, num = params_arg(params), numerics_arg(numerics)
    _check_param(params, param)
    n = whole("period", period, low=1)
    lam0 = float(getattr(params, param))
    to = real("to", to)
    if to == lam0:
        raise ParameterError(f"to = {to}: equal to the start {param} = {lam0}; give another")
    model = _ModelMap(params, param, n, num)
    span = abs(to - lam0)
    st = Settings(weights=(1.0, params.cam_period, 1.0 / span), lo=min(lam0, to),
                  hi=max(lam0, to), h0=real("ds", ds, low=0.0, strict=True),
                  h_min=real("ds_min", ds_min, low=0.0, strict=True),
                  h_max=real("ds_max", ds_max, low=0.0, strict=True),
                  tol=real("tol", tol, low=0.0, strict=True),
                  event_tol=real("event_tol", event_tol, low=0.0, strict=True),
                  max_points=whole("max_points", max_points, low=2))  # fmt: skip
    config = {"params": dataclasses.asdict(params), "numerics": dataclasses.asdict(num),
              "param": param, "from": lam0, "to": to, "period": n,
              "x0": None if x0 is None else [float(v) for v in x0], "transient": transient,
              **{f.name: getattr(st, f.name) for f in dataclasses.fields(st)}}  # fmt: skip
    ckpt = _Checkpoint(checkpoint, config)
    resume = ckpt.restore()
    if resume is None:
        u0 = np.array([*find_start(params, x0, n, num, transient=transient).points[0], lam0])
    else:
        u0 = resume[0][-1].u
    try:
        done = resume is not None and any(e[0] == "end" for e in resume[1])
        found = [(0, n, *(resume if done else follow(
            model, u0, st, direction=math.copysign(1.0, to - lam0),
            observe=model.observe, on_point=ckpt.save, resume=resume)))]  # fmt: skip
    except MapFailed as err:
        raise NoOrbitError(f"the start orbit could not be continued: {err}") from None
    ckpt.save(found[0][2], found[0][3], now=True)
    _section_hint(found[0][3], n)
    if switch:
        found += _switched(params, param, n, num, st, found[0][3])
    settings = {**config, "switch": switch, "resumed": resume is not None,
                "wall_time": time.perf_counter() - t_start}  # fmt: skip
    branch = Branch(_points_frame(found, param), _events_frame(found, param), settings)
    ckpt.remove()
    return branch


CHECKPOINT_S = 1.0
"""Least time [s] between two writes of a branch's checkpoint."""


class _Checkpoint:
    """A branch's points and events so far in one JSON file (the settings, then each
    MapPoint's fields), written whole; None: no file."""

    def __init__(self, path, config: dict) -> None:
        self.path, self.config, self.last = (Path(path) if path else None), config, 0.0

    def restore(self):
        """(points, events) from the file, or None when there is none."""
        if self.path is None or not self.path.exists():
            return None
        try:
            saved = json.loads(self.path.read_text())
            saved["config"], saved["points"], saved["events"]  # noqa: B018
        except (ValueError, TypeError, KeyError):
            raise ParameterError(f"the checkpoint {self.path} is damaged: remove it") from None
        same = (
            json.dumps(c, sort_keys=True, default=_plain) for c in (saved["config"], self.config)
        )
        if len(set(same)) > 1:
            keys = sorted(k for k in self.config if saved["config"].get(k) != self.config[k])
            raise ParameterError(f"the checkpoint {self.path} was made with other settings "
                                 f"({', '.join(keys) or 'its format'}): remove it, or resume "
                                 "with the same settings")  # fmt: skip
        pts = [_point(d) for d in saved["points"]]
        return pts, [(k, pts[i] if i >= 0 else _point(d), detail)
                     for k, i, d, detail in saved["events"]]  # fmt: skip

    def save(self, points, events, now: bool = False) -> None:
        if self.path is None or not now and time.monotonic() - self.last < CHECKPOINT_S:
            return
        from ..io import atomic_write_bytes

        index = {id(p): i for i, p in enumerate(points)}
        data = {"config": self.config, "points": [_fields(p) for p in points],
                "events": [(k, index.get(id(p), -1), None if id(p) in index else _fields(p),
                            detail) for k, p, detail in events]}  # fmt: skip
        atomic_write_bytes(self.path, json.dumps(data, default=_plain).encode())
        self.last = time.monotonic()

    def remove(self) -> None:
        if self.path is not None:
            self.path.unlink(missing_ok=True)


def _plain(value):
    return value.tolist() if isinstance(value, np.ndarray | np.generic) else str(value)


def _fields(p: MapPoint) -> dict:
    return {f.name: getattr(p, f.name) for f in dataclasses.fields(p)}


def _point(d: dict) -> MapPoint:
    info = {k: np.asarray(v) if isinstance(v, list) else v for k, v in d["info"].items()}
    arrays = {k: np.asarray(d[k], dtype=float) for k in ("u", "t", "dp")}
    return MapPoint(**{**d, **arrays, "info": info})


SECTION_NEAR = 0.01
"""An impact within this fraction of the cam period of the section t = 0 (mod n T): P^n is
discontinuous where an impact crosses the section."""


def _section_hint(events: list, n: int) -> None:
    """Say so in the ``end`` event when the branch ended at an impact crossing the section."""
    kind, p, detail = events[-1]
    times = p.info.get("macro_times", ())
    period = p.info.get("cam_period", math.nan)
    phase = np.mod(np.asarray(times) / period, float(n))
    if len(phase) and np.min(np.minimum(phase, n - phase)) < SECTION_NEAR:
        events[-1] = (kind, p, detail + "; an impact lies at the section time, where P^n jumps: "
                      "move the section (another theta_c0) to follow on")  # fmt: skip


def _switched(params, param, n, num, st, events) -> list:
    """The period-2n branches from each period doubling of a branch's events."""
    out = []
    model = _ModelMap(params, param, 2 * n, num)
    for kind, p, _ in events:
        if kind != "period_doubling":
            continue
        mu, vec = np.linalg.eig(p.dp)
        v = np.real(vec[:, int(np.argmin(np.abs(mu + 1.0)))]) * np.asarray(st.weights[:2])
        t0 = np.append(v / np.linalg.norm(v), 0.0)
        sw = dataclasses.replace(st, h0=SWITCH_EPS)
        try:
            pts, evs = follow(model, p.u, sw, t0=t0, observe=model.observe)
        except MapFailed:
            continue
        out.append((len(out) + 1, 2 * n, pts, evs))
    return out


def _mu_columns(dp: np.ndarray) -> dict[str, float]:
    mu = np.linalg.eigvals(dp).astype(complex)
    mu = mu[np.argsort(-np.abs(mu), kind="stable")]
    return {"mu1_re": mu[0].real, "mu1_im": mu[0].imag, "mu2_re": mu[1].real,
            "mu2_im": mu[1].imag}  # fmt: skip


_INFO = ("n_macro_impacts", "n_micro_impacts", "n_chatter_ends", "contact_fraction", "sticks")


def _points_frame(found, param: str) -> pd.DataFrame:
    rows = []
    for b, n, points, _ in found:
        for i, p in enumerate(points):
            mu = _mu_columns(p.dp)
            common = {"branch": b, "point": i, "period": n, "param": param,
                      "value": float(p.u[2]), "s": p.s}  # fmt: skip
            info = {key: p.info.get(key) for key in _INFO}
            section = p.info.get("points", np.full((n, 2), np.nan))
            for j in range(n):
                rows.append({**common, "j": j, "theta_f": section[j, 0],
                             "omega_f": section[j, 1], **mu,
                             "abs_mu": math.hypot(mu["mu1_re"], mu["mu1_im"]),
                             "stable": math.hypot(mu["mu1_re"], mu["mu1_im"]) < 1.0, **info,
                             "residual": p.residual, "iterations": p.iterations})  # fmt: skip
    return pd.DataFrame(rows)


def _events_frame(found, param: str) -> pd.DataFrame:
    rows = [{"branch": b, "kind": kind, "param": param, "value": float(p.u[2]), "s": p.s,
             "theta_f": float(p.u[0]), "omega_f": float(p.u[1]), **_mu_columns(p.dp),
             "detail": detail}
            for b, _, _, events in found for kind, p, detail in events]  # fmt: skip
    return pd.DataFrame(rows)
