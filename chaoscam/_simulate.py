"""simulate(params, ...) -> Trajectory: one realization of the cam-follower model.

The driver around the compiled kernel (:mod:`chaoscam.integrate._kernel`): it builds the
initial state (in contact, paper sec. 2), feeds the kernel line-length draws from the
realization's own generator, empties its output buffers, and wraps everything in a frozen
:class:`Trajectory` that records the settings actually used.
"""

from __future__ import annotations

import copy
import dataclasses
import json
import math
import time
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

import numpy as np

from ._frozen import freeze_fields
from ._run_warnings import run_warnings
from ._version import __version__
from ._warn import warn
from .integrate import Status, kernel_constants
from .integrate import _kernel as k
from .integrate._constants import initial_counters, initial_state
from .integrate._driver import Buffers, check_window, contact_fraction, drive
from .integrate._resume import RunCopy, snapshot_step
from .integrate._tangent import section_jacobians
from .model import (
    LineLengthStream,
    ParameterError,
    Params,
    contact_angle,
    contact_period,
    gap,
    normal_force,
    truncated_mass,
)

if TYPE_CHECKING:
    import pandas as pd

__all__ = ["simulate", "Trajectory", "RawRun", "raw_run", "contact_period", "SERIES_COLUMNS"]

SERIES_COLUMNS = ("t", "theta_f", "omega_f", "theta_fc", "gap", "contact", "F_n", "l_lambda")
SECTION_COLUMNS = k.SECTION_NAMES
IMPACT_COLUMNS = k.IMPACT_NAMES
IMPACT_KINDS = k.IMPACT_KINDS
_BLOCK = 4096  # rows per output buffer and draws per refill


@dataclass(frozen=True)
class Trajectory:
    """One simulated realization, with the settings that produced it.

    Attributes
    ----------
    params : Params
        The model used.
    settings : dict
        duration, transient, seed, index, output_dt, solver, package version, wall time;
        read-only, as ``stats`` (a record of the run: :class:`chaoscam._frozen.FrozenDict`).
    status : Status
        How the run ended; ``message`` says what to do about it.
    series : pandas.DataFrame or None
        Time series sampled every ``output_dt`` (``SERIES_COLUMNS``), or None when not kept.
    section : pandas.DataFrame
        Stroboscopic Poincaré section at t = k 2 pi / omega: k, t, theta_f, omega_f, l_lambda.
    impacts : pandas.DataFrame
        The applied restitution jumps: t, theta_f, omega_before, omega_after,
        gap_rate_before, lever_arm, l_lambda, kind ("macro", "micro": slower than
        ``v_micro``, "chatter_end": the plastic closure ending a complete chattering).
    stats : dict
        contact_fraction, n_impacts (of them n_macro_impacts, n_micro_impacts, n_chatter_ends),
        slow_closings, chatter_handovers, truncated_mass, steps_per_contact_period.
    final_state : tuple
        (t, theta_f, omega_f) where the run stopped.
    jacobians : ndarray or None
        With ``tangent=True``: shape (n_sections, 2, 2), the Jacobian of the stroboscopic
        map d(theta_f, theta_f')(t_k) / d(theta_f, theta_f')(t_k - T) over the period that
        ends at each section point (through the impacts' saltation matrices).
    divergence : ndarray or None
        With ``tangent=True``: the integral of the flow's divergence over each such period
        (Liouville: ln|det J_k| = divergence_k + 2 ln(xi) per restitution jump). Read-only.
    resume : RunCopy or None
        With ``resumable=True`` (RK4): the copy :func:`chaoscam.extend_trajectory`
        continues the run from; None otherwise, and for a run read from a file.
    """

    params: Params
    settings: dict[str, Any]
    status: Status
    series: pd.DataFrame | None
    section: pd.DataFrame
    impacts: pd.DataFrame
    stats: dict[str, Any] = field(default_factory=dict)
    final_state: tuple[float, float, float] = (0.0, 0.0, 0.0)
    jacobians: np.ndarray | None = field(default=None, repr=False)
    divergence: np.ndarray | None = field(default=None, repr=False)
    resume: RunCopy | None = field(default=None, repr=False, compare=False)

    def __post_init__(self) -> None:
        freeze_fields(self, "settings", "stats", "jacobians", "divergence")

    @property
    def message(self) -> str:
        return self.status.message

    @property
    def ok(self) -> bool:
        return self.status is Status.OK

    def summary(self) -> str:
        """A few lines for a terminal."""
        return _summary(self)

    def provenance(self) -> dict[str, Any]:
        """Parameters and settings as a JSON-serialisable dict."""
        return {
            "params": self.params.to_dict(),
            "settings": self.settings,
            "status": self.status.name,
            "stats": self.stats,
        }

    def to_parquet(self, path, *, replace: bool = False) -> None:
        """:meth:`parquet_table`, atomically; an existing file is refused unless replace=True."""
        from ._outputs import write_new_parquet

        write_new_parquet(self.parquet_table(), path, replace=replace)

    def parquet_table(self):
        """The series (or the section) as a pyarrow table; section, impacts, provenance: meta."""
        import pyarrow as pa

        from ._parquet import exact_json

        frame = self.series if self.series is not None else self.section
        table = pa.Table.from_pandas(frame, preserve_index=False)
        meta = dict(table.schema.metadata or {})
        meta[b"chaoscam.trajectory"] = json.dumps(self.provenance()).encode()
        for name in ("section", "impacts"):
            meta[f"chaoscam.{name}".encode()] = exact_json(getattr(self, name)).encode()
        return table.replace_schema_metadata(meta)


def _check_run(
    p: Params, duration: float, transient: float, output_dt: float | None, seed, index
) -> tuple[int, int]:
    """Validate the run's settings and refuse a run that cannot fit in memory."""
    from ._budget import check_budget, estimate
    from ._checks import whole

    seed, index = whole("seed", seed), whole("index", index)
    duration, transient = check_window(duration, transient, dt=p.dt)
    if output_dt is not None and not (output_dt >= p.dt and math.isfinite(output_dt)):
        raise ParameterError(
            f"output_dt = {output_dt!r} s (the series' sampling step, --output-dt) must be "
            f">= dt = {p.dt} s: raise output_dt or lower dt"
        )
    series_rows = (duration - transient) / output_dt if output_dt is not None else 0.0
    job = estimate(
        p,
        duration=duration,
        transient=transient,
        series=output_dt is not None,
        output_dt=output_dt or 1.0,
    )
    check_budget(
        job,
        what="this run",
        reduce="duration (or raise output_dt)",
        run=dict(params=p, duration=duration, what="this run", series_rows=series_rows),
    )
    return seed, index


def simulate(
    params: Params | None = None,
    *,
    duration: float = 20.0,
    transient: float = 0.0,
    seed: int = 0,
    index: int = 0,
    series: bool = True,
    output_dt: float = 1e-3,
    tangent: bool = False,
    resumable: bool = False,
    **overrides: Any,
) -> Trajectory:
    """Simulate one realization with located impacts: fixed-step RK4 (the paper's method, the
    default) or the adaptive DOP853 path (``integrator="adaptive"``).

    Parameters
    ----------
    params : Params, optional
        The model (Table 1 defaults when omitted); keyword ``overrides`` are applied on top,
        e.g. ``simulate(omega=30.0)``.
    duration : float
        End time [s]; the paper uses 20 s.
    transient : float
        Outputs before this time are discarded [s].
    seed, index : int
        The realization of the random line length: a pure function of (seed, index).
    series : bool
        Keep the time series; False keeps sections and impacts only (long runs, sweeps).
    output_dt : float
        Sampling interval of the series [s], rounded to a whole number of steps.
    tangent : bool
        Also integrate the tangent dynamics through the impacts (:mod:`chaoscam.integrate.
        _tangent`; both integrators) and keep the stroboscopic map's Jacobian over each
        recorded period (``Trajectory.jacobians``, for :func:`chaoscam.lyapunov_spectrum` and
        :func:`chaoscam.periodic_orbit`). The motion is the same with and without it.
    resumable : bool
        Keep a copy of the run's state near its end (``Trajectory.resume``; RK4 only), from
        which :func:`chaoscam.extend_trajectory` makes the run longer without repeating it,
        to the same bits as a run made that long from t = 0. The run is the same.

    Returns
    -------
    Trajectory
        Frozen; ``status`` says how the run ended (it never raises for a run that leaves the
        cam or diverges).

    Notes
    -----
    The follower starts in contact with the cam (``theta_f0``, ``omega_f0`` None). From a
    section point ``(theta_f, omega_f)`` of an earlier run (at t = k 2π/ω the cam is back at
    ``theta_c0``), ``simulate(theta_f0=theta_f, omega_f0=omega_f)`` is a new run, not the
    earlier one's continuation to the bit (:func:`chaoscam.extend_trajectory` is that).
    """
    return raw_run(
        params,
        duration=duration,
        transient=transient,
        seed=seed,
        index=index,
        series=series,
        output_dt=output_dt,
        tangent=tangent,
        resumable=resumable,
        **overrides,
    ).trajectory()


@dataclass(frozen=True)
class RawRun:
    """A run's outputs as the kernel wrote them, before they become a :class:`Trajectory`'s
    tables: what a caller that only prints a summary needs, without importing pandas.

    ``series`` (t, theta_f, omega_f, l_lambda samples, or None), ``section`` (the kernel's
    ``SECTION_COLS`` columns, tangent slots included) and ``impacts`` (``IMPACT_COLS``) are
    arrays; the other attributes are those of :class:`Trajectory`.
    """

    params: Params
    settings: dict[str, Any]
    status: Status
    stats: dict[str, Any]
    final_state: tuple[float, float, float]
    series: np.ndarray | None
    section: np.ndarray
    impacts: np.ndarray
    resume: RunCopy | None = field(default=None, repr=False, compare=False)

    @property
    def message(self) -> str:
        return self.status.message

    def summary(self) -> str:
        """A few lines for a terminal (:meth:`Trajectory.summary`)."""
        return _summary(self)

    def trajectory(self) -> Trajectory:
        """The run as a :class:`Trajectory` (its tables as pandas DataFrames)."""
        import pandas as pd

        n_sec = len(SECTION_COLUMNS)
        sec = pd.DataFrame(self.section[:, :n_sec], columns=list(SECTION_COLUMNS))
        sec["k"] = sec["k"].astype(np.int64)
        imp = pd.DataFrame(self.impacts, columns=list(IMPACT_COLUMNS))
        imp["kind"] = pd.Categorical.from_codes(
            imp["kind"].to_numpy(dtype=np.int64), categories=list(IMPACT_KINDS)
        )
        tangent = self.settings["tangent"]
        return Trajectory(
            params=self.params,
            settings=self.settings,
            status=self.status,
            series=None if self.series is None else _series_frame(self.params, self.series),
            section=sec,
            impacts=imp,
            stats=self.stats,
            final_state=self.final_state,
            jacobians=section_jacobians(self.section) if tangent else None,
            divergence=self.section[:, n_sec + 4].copy() if tangent else None,
            resume=self.resume,
        )


def raw_run(
    params: Params | None = None,
    *,
    duration: float = 20.0,
    transient: float = 0.0,
    seed: int = 0,
    index: int = 0,
    series: bool = True,
    output_dt: float = 1e-3,
    tangent: bool = False,
    resumable: bool = False,
    **overrides: Any,
) -> RawRun:
    """:func:`simulate` up to its arrays (same arguments, same checks and warnings)."""
    from ._checks import flag, params_arg, real, with_overrides

    series, tangent = flag("series", series), flag("tangent", tangent)
    resumable = flag("resumable", resumable)
    p = params_arg(params)
    if overrides:
        p = with_overrides(p, overrides, simulate)
    # output_dt is checked even without a series: a bad value is a mistake either way.
    output_dt = real("output_dt", output_dt, low=0.0, strict=True, unit="s")
    seed, index = _check_run(p, duration, transient, output_dt if series else None, seed, index)
    t0 = time.perf_counter()
    n_stop = int(round(duration / p.dt))
    stride = max(1, int(round(output_dt / p.dt))) if series else 0
    for text in run_warnings(p):
        warn(text)

    stream = LineLengthStream(p, seed, index)
    lam = stream.draw(output_block(p))
    y = initial_state(p)
    th0, om0 = y[k.Y_THETA], y[k.Y_OMEGA]
    cnt = initial_counters(p, transient=transient)
    c = kernel_constants(p, t_record=transient, stride=stride, tangent=tangent)
    parts: dict[str, list[np.ndarray]] = {"series": [], "section": [], "impacts": []}
    if series and transient == 0.0:
        parts["series"].append(np.array([[0.0, th0, om0, lam[0]]]))
    run = KernelRun(p, y, cnt, c, lam, stream, parts)
    code = run.go(n_stop, resumable)
    settings = {
        "duration": float(duration),
        "transient": float(transient),
        "seed": int(seed),
        "index": int(index),
        "output_dt": stride * p.dt if series else None,
        "solver": (
            "dop853-adaptive+interpolant-events"
            if p.integrator == "adaptive"
            else "rk4-fixed-step+newton-events"
        ),
        "version": __version__,
        "tangent": bool(tangent),
        "wall_time_s": time.perf_counter() - t0,
    }
    return run.result(code, settings)


def output_block(p: Params) -> int:
    """Rows per output buffer and draws per refill: at least a few steps' worth of the most
    a step can produce."""
    per_step = p.max_events_per_step + p.flight_merge + 2
    if p.resample == "interval":
        per_step += int(p.dt / p.resample_dt) + 2
    step = p.h_max if p.integrator == "adaptive" else p.dt  # the longest step
    return max(_BLOCK, 4 * per_step, 4 * (int(step / p.cam_period) + 2))


class KernelRun:
    """One trajectory's arrays on their way through the kernel (:func:`drive`), the rows
    recorded so far (``parts``) and its draws; for a resumable run also the copy taken on
    the way (:mod:`chaoscam.integrate._resume`)."""

    def __init__(self, p: Params, y, cnt, c, lam, stream, parts) -> None:
        self.p, self.y, self.cnt, self.c, self.lam, self.stream = p, y, cnt, c, lam, stream
        self.parts = parts
        self.block = output_block(p)
        rows = self.block if c[k.C_STRIDE] > 0 else 1  # series: an adaptive step's samples too
        if p.integrator == "adaptive" and c[k.C_STRIDE] > 0:
            rows = max(rows, 4 * (int(p.h_max / (c[k.C_STRIDE] * p.dt)) + 2))
        self.buffers = Buffers.empty(rows, self.block, self.block)
        self.kept: RunCopy | None = None  # its rows are attached by result()
        self.rows_at_copy: dict[str, int] = {}

    def _more_draws(self, lam: np.ndarray) -> np.ndarray:
        pos = self.cnt[k.I_LAM_POS]
        self.cnt[k.I_LAM_POS] = 0
        self.lam = np.concatenate([lam[pos:], self.stream.draw(self.block)])
        return self.lam

    def _to(self, n_stop: int) -> int:
        return drive(
            self.y,
            self.cnt,
            self.c,
            n_stop,
            self.lam,
            self.buffers,
            on_rows=lambda name, rows: self.parts[name].append(rows.copy()),
            more_draws=self._more_draws,
        )

    def go(self, n_stop: int, resumable: bool) -> int:
        """Drive to grid step ``n_stop``; resumable (RK4 only), stop once on the way at
        :func:`snapshot_step` and keep a copy there. Returns the final status code."""
        step = snapshot_step(self.p, n_stop) if resumable else None
        if step is None:
            return self._to(n_stop)
        code = self._to(step)
        cnt = self.cnt.copy()
        draws = self.lam[cnt[k.I_LAM_POS] :].copy()
        cnt[k.I_LAM_POS] = 0
        stream = copy.deepcopy(self.stream)
        none = np.empty((0, 0))
        self.kept = RunCopy(
            step, self.y.copy(), cnt, self.c.copy(), draws, stream, None, none, none, code
        )
        self.rows_at_copy = {name: sum(map(len, part)) for name, part in self.parts.items()}
        return self._to(n_stop) if code == k.OK else code

    def result(self, code: int, settings: dict[str, Any]) -> RawRun:
        """The run's :class:`RawRun` (its copy attached when one was kept)."""
        p, y, cnt, c = self.p, self.y, self.cnt, self.c

        def stack(name: str, ncol: int) -> np.ndarray:
            part = self.parts[name]
            return np.concatenate(part) if part else np.empty((0, ncol))

        series = stack("series", k.SERIES_COLS) if c[k.C_STRIDE] > 0 else None
        section = stack("section", k.SECTION_COLS)
        imp = stack("impacts", k.IMPACT_COLS)
        kinds = imp[:, IMPACT_COLUMNS.index("kind")]
        stats = {
            "contact_fraction": contact_fraction(y, cnt, c),
            "n_impacts": len(imp),
            "n_macro_impacts": int((kinds == k.IMPACT_MACRO).sum()),
            "n_micro_impacts": int((kinds == k.IMPACT_MICRO).sum()),
            "n_chatter_ends": int((kinds == k.IMPACT_CHATTER_END).sum()),
            "slow_closings": int(cnt[k.I_SLOW_CLOSINGS]),
            "chatter_handovers": int(cnt[k.I_CHATTER]),
            "truncated_mass": truncated_mass(p.l_lambda, p.l_lambda_sigma, p.l_min),
            "steps_per_contact_period": contact_period(p) / p.dt,
        }
        resume = None
        if self.kept is not None:  # the rows before it: views of the run's own
            n = self.rows_at_copy
            resume = dataclasses.replace(
                self.kept,
                series=None if series is None else series[: n["series"]],
                section=section[: n["section"]],
                impacts=imp[: n["impacts"]],
            )
        return RawRun(
            params=p,
            settings=settings,
            status=Status(code),
            stats=stats,
            final_state=(float(y[k.Y_TIME]), float(y[k.Y_THETA]), float(y[k.Y_OMEGA])),
            series=series,
            section=section,
            impacts=imp,
            resume=resume,
        )


def _summary(run: Trajectory | RawRun) -> str:
    """The terminal lines of :meth:`Trajectory.summary` (and :meth:`RawRun.summary`)."""
    s = run.stats
    fraction = s["contact_fraction"]
    contact = "n/a (no step recorded)" if math.isnan(fraction) else f"{fraction:.4f}"
    end = run.final_state[0]  # NaN for a run read from a file that kept no section row
    reached = "an end time not recorded in the file" if math.isnan(end) else f"{end:.4g} s"
    return (
        f"status: {run.status.name} - {run.message}\n"
        f"simulated: {reached} of {run.settings['duration']:.4g} s "
        f"(transient {run.settings['transient']:.4g} s discarded), dt = {run.params.dt:g} s\n"
        f"impacts: {s['n_impacts']} applied ({s['n_macro_impacts']} macro, "
        f"{s['n_micro_impacts']} micro, {s['n_chatter_ends']} chattering ends), "
        f"{s['slow_closings']} slow closings left to the compliant contact, "
        f"{s['chatter_handovers']} chattering-guard hand-overs\n"
        f"contact fraction: {contact}\n"
        f"section points: {len(run.section)}"
    )


def _series_frame(p: Params, a: np.ndarray) -> pd.DataFrame:
    """The tidy series: kernel samples plus the observables derived from them."""
    import pandas as pd

    t, th, om, lam = a[:, 0], a[:, 1], a[:, 2], a[:, 3]
    d = gap(p, t, th)
    force = normal_force(p, t, th, om, lam)
    columns = (t, th, om, contact_angle(p, t), d, d <= 0.0, force, lam)
    return pd.DataFrame(dict(zip(SERIES_COLUMNS, columns, strict=True)))
