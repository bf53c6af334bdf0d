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
from ._core import CONTINUOUS, CORRECTOR_FAILED, JUMP, MapFailed, MapPoint, Settings, follow
from ._grazing import GRAZE_SAMPLES, flight_margin

__all__ = ["Branch", "NoOrbitError", "continuation", "events_path"]

TWO_PI = 2.0 * math.pi
KINDS = (*CONTINUOUS, "grazing")
"""The test functions located along a branch (:func:`chaoscam.continuation.follow`)."""

EVENT_KINDS = ("fold", "period_doubling", "neimark_sacker", "grazing", "sticking",
               "impact_change", "section", "end")  # fmt: skip
"""The ``kind`` values of :attr:`Branch.events` (:func:`continuation` says what each
means)."""

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
        ``omega_f`` [rad/s] (the orbit's state at t = 0 mod T of the model as given: the
        section of its stroboscopic diagrams), ``section_phase`` [rad] (the cam phase, past
        ``theta_c0``, of the section the branch was solved on there: 0 unless an impact
        crossing the section moved it), the multipliers of DP^n at the orbit's x_0 (``mu1_re``,
        ``mu1_im``, ``mu2_re``, ``mu2_im``, ``|mu1| >= |mu2|``), ``abs_mu`` (``|mu1|``),
        ``stable`` (``|mu1| < 1``: the tangent's verdict, which does not decide where
        chattering ends in sticking; :func:`chaoscam.kick_test` does there),
        ``n_macro_impacts``, ``n_micro_impacts``, ``n_chatter_ends``
        (counted over the orbit's n cam periods), ``contact_fraction``, ``sticks``
        (persistent contact: a complete chattering or grid steps in contact),
        ``flight_margin`` ψ [m] (the grazing test function: the least gap of the flight
        closest to grazing, negative for an impact's virtual penetration; NaN where no flight
        has a minimum), ``residual``
        (scaled, rad) and ``iterations`` (the corrector's).
    events : pandas.DataFrame
        ``branch``, ``kind`` (:data:`EVENT_KINDS`), ``param``, ``value``, ``s``, ``theta_f``,
        ``omega_f`` (at phase 0, as the points), ``section_phase``, the multipliers there,
        and ``detail``.
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
    """P^n of the model with one field set to λ, on the Poincaré section at cam phase
    ``theta_c0 + phase``: ``(x, λ) -> (P^n(x), DP^n(x))`` and the orbit's observation, the
    runners kept for the last few λ."""

    def __init__(self, params: Params, name: str, n: int, num: Numerics,
                 phase: float = 0.0) -> None:  # fmt: skip
        self.params, self.name, self.n, self.num = params, name, n, num
        self.phase = float(phase)
        self.runners: dict[float, Any] = {}

    def model(self, lam: float) -> Params:
        """The model at λ, its cam phase at t = 0 moved by ``phase``."""
        try:
            return self.params.replace(
                **{self.name: lam, "theta_c0": self.params.theta_c0 + self.phase}
            )
        except (ParameterError, ValueError) as err:
            raise MapFailed(str(err)) from None

    def runner(self, lam: float):
        if lam not in self.runners:
            if len(self.runners) > 8:
                self.runners.pop(next(iter(self.runners)))
            self.runners[lam] = map_runner(self.model(lam), self.n, self.num)
        return self.runners[lam]

    def __call__(self, x: np.ndarray, lam: float):
        px, dp, code = self.runner(lam)(x)
        if code != 0:
            raise MapFailed(f"the run from x = {x} stopped (status {code})")
        return px, dp

    def observe(self, x: np.ndarray, lam: float) -> dict[str, Any]:
        """The orbit's counts (:func:`chaoscam.verdict.map_runner`), ``sticks``,
        ``section_phase``, the flights' margin ``grazing`` ψ [m] and its time
        ``grazing_phase`` [cam periods] (:func:`~chaoscam.continuation._grazing.flight_margin`)
        (from phase 0) and, on a moved section, ``points`` at phase 0 (the model's own
        section) and ``section_points`` where the branch is solved."""
        info = self.runner(lam).counts(x)
        info["sticks"] = bool(info["n_chatter_ends"] > 0 or info["contact_fraction"] > 0)
        info["cam_period"] = self.runner(lam).p.cam_period
        info["section_phase"] = self.phase
        run = self.runner(lam)
        every = max(1, round(run.p.cam_period / (GRAZE_SAMPLES * self.num.dt)))
        series, impacts, _ = run.watch(x, every)
        info["grazing"], t_g = flight_margin(run.p, series, impacts)
        info["grazing_phase"] = (t_g / run.p.cam_period + self.phase / TWO_PI) % self.n
        if self.phase:
            p, back = self.model(lam), 2.0 * math.pi - self.phase
            info["section_points"] = info["points"]
            info["points"] = np.array([_advance(p, self.num, y, back / p.omega)
                                       for y in info["points"]])  # fmt: skip
        return info

    def moved(self, phase: float) -> _ModelMap:
        """The same map on the section at ``phase`` (mod 2π)."""
        return _ModelMap(self.params, self.name, self.n, self.num, phase % (2.0 * math.pi))


def _advance(p: Params, num: Numerics, x, tau: float) -> np.ndarray:
    """The state a time ``tau`` [s] after x (at t = 0 of the model p): an RK4 run on the grid
    ``tau / m``, m = round(tau / dt) ≥ 1 (the step changed by at most dt / 2m, so that the run
    ends at tau); NaN where the run stops."""
    m = max(int(round(tau / num.dt)), 1)
    step = num.replace(dt=tau / m)
    run = simulate(p.replace(theta_f0=float(x[0]), omega_f0=float(x[1])), step,
                   duration=m * step.dt, series=False)  # fmt: skip
    return np.array(run.final_state[1:]) if run.ok else np.full(2, np.nan)


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
    jump and < 1 in persistent contact, which forbids it: docs/continuation.md),
    ``grazing`` (a flight just touches the cam: the flights' margin ψ [m], the least gap of
    a flight in flight and an impact's virtual penetration ``-v² / 2a`` past it, changes
    sign, or falls to 0 where the branch ends: there the orbit is then solved by Newton at
    fixed λ up to the λ past which it has none, to ``event_tol``), and changes of the orbit's
    pattern, bisected: ``impact_change`` (the number of macro impacts over the n periods
    changes: a grazing, or an impact's approach speed crossing ``v_micro``) and ``sticking``
    (persistent contact begins or ends). ``section``: an impact crossed the Poincaré section,
    where P^n jumps and the corrector fails; the section moves to the cam phase midway in
    the widest gap between the orbit's impacts (an exact run from the last point there, by
    the grid step adjusted to end at that phase, then Newton) and the branch goes on, its
    ``theta_f`` still given at phase 0. ``end`` says why the branch stops.

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
    switch : bool
        Follow the period-2n branch from each period doubling of the branch (not from the
        doubled branches' own).
    checkpoint : path, optional
        A JSON file that keeps each branch's points and events so far (written whole at most
        once every :data:`CHECKPOINT_S`): one left by an interrupted call with the same
        settings keeps the branches it finished and follows the interrupted one on from its
        last point and tangent; removed once done.

    Raises
    ------
    NoOrbitError
        The start converges to no period-n orbit.

    Limits: the map is piecewise smooth; at a grazing or at the onset of chattering the
    corrector may fail even at ``ds_min`` and the branch ends there (``end``, with the
    reason). The section is not moved when the parameter is ``theta_c0`` itself.
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
    config["switch"] = bool(switch)
    ckpt = _Checkpoint(checkpoint, config)
    saved = ckpt.restore()
    try:
        start = (
            None
            if 0 in saved
            else np.array([*find_start(params, x0, n, num, transient=transient).points[0], lam0])
        )
        found = [(0, n, *_resumed(ckpt, saved, 0, n, model, st, u0=start,
                                  direction=math.copysign(1.0, to - lam0)))]  # fmt: skip
    except MapFailed as err:
        raise NoOrbitError(f"the start orbit could not be continued: {err}") from None
    if switch:
        found += _switched(ckpt, saved, model, st, found[0][3])
    settings = {**config, "resumed": bool(saved), "wall_time": time.perf_counter() - t_start}
    branch = Branch(_points_frame(found, param), _events_frame(found, param), settings)
    ckpt.remove()
    return branch


def _resumed(ckpt, saved: dict, b: int, n: int, model: _ModelMap, st: Settings, *,
             u0=None, t0=None, direction=1.0):  # fmt: skip
    """Branch b: as the checkpoint keeps it when it ended, else followed (on from the
    checkpoint's last point where it has one), its points and events checkpointed."""
    if b in saved and saved[b][1] and saved[b][1][-1][0] == "end":
        return saved[b]
    resume = saved.get(b)
    if resume is not None:
        model = model.moved(resume[0][-1].info.get("section_phase", 0.0))
    points, events = _sectioned(model, u0, st, t0=t0, direction=direction, resume=resume,
                                on_point=lambda p, e: ckpt.save(b, n, p, e))  # fmt: skip
    ckpt.save(b, n, points, events, now=True)
    return points, events


CHECKPOINT_S = 1.0
"""Least time [s] between two writes of a branch's checkpoint."""


class _Checkpoint:
    """The branches' points and events so far in one JSON file (the settings, then each
    branch's MapPoints), written whole; None: no file."""

    def __init__(self, path, config: dict) -> None:
        self.path, self.config, self.last = (Path(path) if path else None), config, 0.0
        self.branches: dict[int, tuple] = {}

    def restore(self) -> dict[int, tuple[list, list]]:
        """{branch: (points, events)} from the file; empty when there is none."""
        if self.path is None or not self.path.exists():
            return {}
        try:
            saved = json.loads(self.path.read_text())
            saved["config"], saved["branches"]  # noqa: B018
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
        out = {}
        for b, n, points, events in saved["branches"]:
            pts = [_point(d) for d in points]
            out[b] = (pts, [(k, pts[i] if i >= 0 else _point(d), detail)
                            for k, i, d, detail in events])  # fmt: skip
            self.branches[b] = (n, *out[b])
        return out

    def save(self, b: int, n: int, points, events, now: bool = False) -> None:
        """Keep branch b's points and events; write them all, at most once a
        :data:`CHECKPOINT_S` unless ``now``."""
        self.branches[b] = (n, points, events)
        if self.path is None or not now and time.monotonic() - self.last < CHECKPOINT_S:
            return
        from ..io import atomic_write_bytes

        data = {
            "config": self.config,
            "branches": [(b, n, *_saved(p, e)) for b, (n, p, e) in self.branches.items()],
        }
        atomic_write_bytes(self.path, json.dumps(data, default=_plain).encode())
        self.last = time.monotonic()

    def remove(self) -> None:
        if self.path is not None:
            self.path.unlink(missing_ok=True)


def _saved(points, events) -> tuple[list, list]:
    """A branch's points as dicts and its events as (kind, index of the point or -1, the
    point's dict when it is not one of the points, detail)."""
    index = {id(p): i for i, p in enumerate(points)}
    return [_fields(p) for p in points], [
        (k, index.get(id(p), -1), None if id(p) in index else _fields(p), detail)
        for k, p, detail in events]  # fmt: skip


def _plain(value):
    return value.tolist() if isinstance(value, np.ndarray | np.generic) else str(value)


def _fields(p: MapPoint) -> dict:
    return {f.name: getattr(p, f.name) for f in dataclasses.fields(p)}


def _point(d: dict) -> MapPoint:
    info = {k: np.asarray(v) if isinstance(v, list) else v for k, v in d["info"].items()}
    arrays = {k: np.asarray(d[k], dtype=float) for k in ("u", "t", "dp")}
    return MapPoint(**{**d, **arrays, "info": info})


SECTION_NEAR = 0.01
"""An impact within this fraction of the cam period of the section (mod n T) ends a branch
whose corrector fails by moving the section: P^n is discontinuous where an impact crosses
the section."""
SECTION_MOVES = 8
"""Most moves of the section along one branch."""


def _sectioned(model: _ModelMap, u0, st: Settings, *, t0=None, direction=1.0, resume=None,
               on_point=None) -> tuple[list, list]:  # fmt: skip
    """:func:`follow` through impacts that cross the section: where the corrector fails with
    an impact within :data:`SECTION_NEAR` of the section, the section moves to the middle of
    the widest gap between the orbit's impact phases (a ``section`` event) and the branch goes
    on there, up to :data:`SECTION_MOVES` times."""
    points, events = follow(model, u0, st, t0=t0, direction=direction, observe=model.observe,
                            kinds=KINDS, on_point=on_point, resume=resume)  # fmt: skip
    for _ in range(SECTION_MOVES):
        end = events[-1]
        if not end[2].startswith(CORRECTOR_FAILED) or not _near_section(end[1], model.n):
            break
        if model.name == "theta_c0" or len(points) < 3:
            break
        moved = _moved(model, points, st.weights)
        if moved is None:
            break
        model, u, orient = moved
        prior = (points, [*events[:-1]])
        try:
            points, events = follow(model, u, st, direction=orient, observe=model.observe,
                                    kinds=KINDS, on_point=on_point, prior=prior)  # fmt: skip
        except MapFailed:
            points, events = prior[0], [*prior[1], end]
            break
        first = points[len(prior[0])]
        events.insert(len(prior[1]), ("section", first, f"an impact crossed the section: moved "
                                      f"to phase {model.phase:.6g} rad"))  # fmt: skip
    kind, p, detail = events[-1]
    if not detail.startswith(CORRECTOR_FAILED):
        return points, events
    if _near_section(p, model.n):
        events[-1] = (kind, p, detail + "; an impact lies at the section time, where P^n "
                      "jumps, and moving the section did not help")  # fmt: skip
    elif (graze := _graze_end(model, points, st)) is not None:
        events[-1:] = [("grazing", graze, f"a flight touches the cam at "
                        f"{graze.info['grazing_phase']:.4f} cam periods: no period-"
                        f"{model.n} orbit past it"),
                       (kind, p, "the branch ends at a grazing")]  # fmt: skip
    return points, events


GRAZE_ITER = 60
"""Most fixed-λ Newton solves spent locating a grazing at a branch's end."""


def _graze_end(model: _ModelMap, points: list, st: Settings) -> MapPoint | None:
    """The grazing a branch ends at (:func:`_locate_grazing` from its last point), where the
    margin ψ of its last two points falls towards 0; None where it does not."""
    if len(points) < 2:
        return None
    a, b = points[-2], points[-1]
    psi_a, psi_b = a.info.get("grazing", math.nan), b.info.get("grazing", math.nan)
    lam_a, lam_b = float(a.u[-1]), float(b.u[-1])
    if not (0.0 < psi_b < psi_a and lam_a != lam_b):
        return None
    found = _locate_grazing(model, b.u[:-1], lam_b, b.info, (psi_b - psi_a) / (lam_b - lam_a),
                            st.event_tol, (st.lo, st.hi))  # fmt: skip
    if found is None:
        return None
    x, lam, info = found
    _, dp = model(x, lam)
    return MapPoint(np.append(x, lam), b.t, dp, 0.0, 0, b.s + abs(lam - lam_b) * st.weights[-1],
                    info)  # fmt: skip


def _locate_grazing(model: _ModelMap, x, lam: float, info: dict, slope: float, tol: float,
                    bounds) -> tuple | None:  # fmt: skip
    """The grazing near the orbit x at λ (margin ψ = ``info["grazing"]`` > 0 falling at
    ``slope`` = dψ/dλ), located to ``tol`` in λ within ``bounds``: the orbit by Newton at
    fixed λ (no ∂P/∂λ, whose difference would straddle the grazing), stepped past the
    linear estimate of ψ = 0 and then bisected between the last λ with an orbit of ψ > 0 and
    the first without; (x, λ, info) at the last, or None where ψ does not fall to 0 there
    (the orbit ends for another reason)."""
    psi0, lo, hi = info["grazing"], (lam, np.asarray(x, dtype=float), info), None
    for _ in range(GRAZE_ITER):
        if hi is not None and abs(hi - lo[0]) <= tol:
            break
        trial = lo[0] - 2.0 * lo[2]["grazing"] / slope if hi is None else 0.5 * (lo[0] + hi)
        if not bounds[0] <= trial <= bounds[1]:
            return None
        y = _fixed_point(model, lo[1], trial)
        seen = model.observe(y, trial) if y is not None else {}
        if seen.get("grazing", math.nan) > 0.0:
            lo = (trial, y, seen)
        else:
            hi = trial
    if hi is None or not lo[2]["grazing"] <= JUMP * psi0:
        return None
    return lo[1], lo[0], lo[2]


def _fixed_point(model: _ModelMap, x, lam: float) -> np.ndarray | None:
    """The period-n orbit's point near x at λ by Newton shooting; None where none is."""
    orbit = periodic_orbit(model.model(lam), x, model.n, numerics=model.num)
    return orbit.points[0] if orbit.converged and orbit.period == model.n else None


def _near_section(p: MapPoint, n: int) -> bool:
    """Whether an impact of the orbit at p lies within :data:`SECTION_NEAR` of its section."""
    times = p.info.get("impact_times", p.info.get("macro_times", ()))
    phase = np.mod(np.asarray(times, dtype=float) / p.info.get("cam_period", math.nan), n)
    return bool(len(phase) and np.min(np.minimum(phase, n - phase)) < SECTION_NEAR)


def _moved(model: _ModelMap, points: list, weights):
    """The map on a section away from the impacts of the last point's orbit, that point on
    it, and the direction to go on in (scaled): (map, u, orient); None where it fails."""
    a = points[-1]
    times = np.asarray(a.info.get("impact_times", ()), dtype=float)
    period = a.info["cam_period"]
    psi = np.sort(np.mod(times / period, 1.0))
    gaps = np.diff(np.append(psi, psi[0] + 1.0))
    delta = 2.0 * math.pi * (psi[int(np.argmax(gaps))] + 0.5 * float(np.max(gaps)))
    new = model.moved(model.phase + delta)
    ends = []
    for p in (points[-3], a):
        lam = float(p.u[-1])
        q = model.model(lam)
        ends.append(np.append(_advance(q, model.num, p.u[:-1], delta / q.omega), lam))
    if not np.isfinite(ends).all():
        return None
    return new, ends[1], (ends[1] - ends[0]) * np.asarray(weights, dtype=float)


def _switched(ckpt, saved: dict, model: _ModelMap, st: Settings, events) -> list:
    """The period-2n branches from each period doubling of a branch's events."""
    out = []
    for kind, p, _ in events:
        if kind != "period_doubling":
            continue
        mu, vec = np.linalg.eig(p.dp)
        v = np.real(vec[:, int(np.argmin(np.abs(mu + 1.0)))]) * np.asarray(st.weights[:2])
        t0 = np.append(v / np.linalg.norm(v), 0.0)
        sw = dataclasses.replace(st, h0=SWITCH_EPS)
        doubled = _ModelMap(model.params, model.name, 2 * model.n, model.num,
                            p.info.get("section_phase", 0.0))  # fmt: skip
        b = len(out) + 1
        try:
            pts, evs = _resumed(ckpt, saved, b, doubled.n, doubled, sw, u0=p.u, t0=t0)
        except MapFailed:
            continue
        out.append((b, doubled.n, pts, evs))
    return out


def _mu_columns(dp: np.ndarray) -> dict[str, float]:
    mu = np.linalg.eigvals(dp).astype(complex)
    mu = mu[np.argsort(-np.abs(mu), kind="stable")]
    return {"mu1_re": mu[0].real, "mu1_im": mu[0].imag, "mu2_re": mu[1].real,
            "mu2_im": mu[1].imag}  # fmt: skip


_INFO = {
    "n_macro_impacts": "n_macro_impacts",
    "n_micro_impacts": "n_micro_impacts",
    "n_chatter_ends": "n_chatter_ends",
    "contact_fraction": "contact_fraction",
    "sticks": "sticks",
    "flight_margin": "grazing",
    "section_phase": "section_phase",
}
"""The points' columns from each orbit's observation: column -> key."""


def _points_frame(found, param: str) -> pd.DataFrame:
    rows = []
    for b, n, points, _ in found:
        for i, p in enumerate(points):
            mu = _mu_columns(p.dp)
            common = {"branch": b, "point": i, "period": n, "param": param,
                      "value": float(p.u[2]), "s": p.s}  # fmt: skip
            info = {col: p.info.get(key) for col, key in _INFO.items()}
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
             **dict(zip(("theta_f", "omega_f"), _phase0(p.info, p.u[:2]), strict=True)),
             "section_phase": p.info.get("section_phase", 0.0), **_mu_columns(p.dp),
             "detail": detail}
            for b, _, _, events in found for kind, p, detail in events]  # fmt: skip
    return pd.DataFrame(rows)


def _phase0(info: dict, x) -> tuple[float, float]:
    """The orbit's state at the model's own section (phase 0), from its observation ``info``
    and its point x on the section it was solved on."""
    y = info["points"][0] if info.get("section_phase") and "points" in info else x
    return float(y[0]), float(y[1])
