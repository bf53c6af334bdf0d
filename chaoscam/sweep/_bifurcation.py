"""Bifurcation diagrams: stroboscopic section points and the verdict over one parameter.

Paper Figs. 4 and 6: for each value of a parameter (l_lambda over [0.001, 0.018] m in steps
of 0.00025 m; D over [1.36, 1.56] with fractal stiffness for G = 1e-9 and 1e-10 m), the
follower's angle at the cam period after the transient. Several initial conditions per
value show coexisting attractors; continuation starts each value from the previous value's
last section point, following one branch.
"""

from __future__ import annotations

import math
import numbers
from collections.abc import Callable, Iterator, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, ClassVar

import numpy as np
import pandas as pd

from .._util import ParameterError, flag, freeze_fields, whole
from .._version import __version__
from ..io import code_identity
from ..kernel import by_size
from ..model import Params, contact_angle, params_arg
from ..numerics import Numerics
from ..simulation import numerics_arg
from ..verdict import EXTEND_TO
from ._common import (
    TwoTables,
    check_fate,
    check_sweep_budget,
    evidence_columns,
    make_judge,
    period_column,
    read_tables,
    run_settings,
    show_progress,
)
from ._engine import resolve_engine, run_sweep
from ._grid import Axis, SweepError, cell_params, realization_index, validate_grid
from ._runs import Realization, fate_columns

__all__ = ["Bifurcation", "bifurcation", "read_bifurcation", "initial_offsets"]

IC_BOX = (0.3, 3.0)
"""Extra initial conditions lie in theta_f0 - theta_fc(0) in [0, 0.3] rad (lifted off the
cam, never into it) and omega_f0 in [-3, 3] rad/s: the extent of the default model's
stroboscopic section (theta_f in [0, 0.31] rad, omega_f within +-3.6 rad/s)."""

POINT_COLUMNS = ("k", "t", "theta_f", "omega_f", "l_lambda")


@dataclass(frozen=True)
class Bifurcation(TwoTables):
    """A bifurcation diagram: section points and verdicts, with the settings used.

    Attributes
    ----------
    points : DataFrame
        One row per stroboscopic section point after the transient, sorted by (value_index,
        ic, k): ``param``, ``value``, ``value_index``, ``ic``, ``k``, ``t`` [s],
        ``theta_f`` [rad], ``omega_f`` [rad/s], ``l_lambda`` (the line length in use [m]),
        and the run's ``status``, ``label``, ``period``.
    verdicts : DataFrame
        One row per (value, initial condition): ``param``, ``value``, ``value_index``,
        ``ic``, ``seed``, ``sim_index``, ``theta_f0``, ``omega_f0`` (NaN = in contact),
        ``continued``, ``status``, ``label``, ``period``, ``n_points``, ``recorded_s``
        (seconds of section recording behind the label: duration - transient, or the
        extension's when the verdict was extended), ``reasons``, ``warnings``, ``fate``,
        ``left_at``, ``fate_label`` and ``fate_period`` (with a ``fate`` horizon, as for
        :class:`RegimeMap`) and
        ``ev_<name>`` evidence values (``ev_exponent``: the tangent exponent per iterate
        of the section map, λ₁·T).
    config : dict
        The settings that fix the result.
    """

    _tables: ClassVar[tuple[str, str]] = ("points", "verdicts")
    points: pd.DataFrame
    verdicts: pd.DataFrame
    config: dict[str, Any] = field(default_factory=dict)

    def __post_init__(self) -> None:
        freeze_fields(self, "config")

    @property
    def param(self) -> str:
        return self.config["axis"]["name"]


def read_bifurcation(path: str | Path) -> Bifurcation:
    """Read a diagram written by :func:`bifurcation`."""
    return Bifurcation(*read_tables(path, "verdicts", "bifurcation"))


def initial_offsets(n: int) -> list[tuple[float, float]]:
    """Offsets (d theta [rad], omega_f0 [rad/s]) of initial conditions 1 .. n-1.

    The points of the unscrambled 2-D Halton sequence (bases 2 and 3), skipping its origin,
    mapped onto `IC_BOX`: spread evenly, and the same for every value and every seed.
    The sequence is computed here (:func:`_radical_inverse`), the same bits as
    ``scipy.stats.qmc.Halton(d=2, scramble=False)`` (tested): importing ``scipy.stats``
    took about a second at the start of every sweep's process.
    """
    if whole("n", n, low=0) <= 1:
        return []
    d_theta, omega = IC_BOX
    return [
        (_radical_inverse(i, 2) * d_theta, (2.0 * _radical_inverse(i, 3) - 1.0) * omega)
        for i in range(1, n)
    ]


def _radical_inverse(i: int, base: int) -> float:
    """The van der Corput point of index ``i`` in ``base``: its digits mirrored about the
    point, ``sum_k d_k base^-(k+1)`` for ``i = sum_k d_k base^k``."""
    x, scale = 0.0, 1.0 / base
    while i > 0:
        i, digit = divmod(i, base)
        x += digit * scale
        scale /= base
    return x


class _BranchPlan:
    """Every (value, initial condition); with continuation, one chain per condition."""

    def __init__(self, make_task: Callable, nvalues: int, nics: int, continuation: bool):
        self.make_task, self.nvalues, self.nics = make_task, nvalues, nics
        self.continuation = continuation
        self.finished: set[tuple[int, int]] = set()
        self.last: dict[int, tuple[int, Any]] = {}  # chain -> (value index, next state)
        self.total = nvalues * nics
        self.done = 0

    def restore(self, record: dict[str, Any]) -> bool:
        key = (record["value_index"], record["ic"])
        if key in self.finished:
            return False
        self.finished.add(key)
        self.done += 1
        v, j = key
        if v >= self.last.get(j, (-1, None))[0]:
            self.last[j] = (v, next_state(record))
        return True

    def start(self) -> Iterator[Realization]:
        if not self.continuation:
            return (
                self.make_task(v, j, None)
                for v in range(self.nvalues)
                for j in range(self.nics)
                if (v, j) not in self.finished
            )
        tasks = []
        for j in range(self.nics):
            v, state = self.last.get(j, (-1, None))
            if v + 1 < self.nvalues:
                tasks.append(self.make_task(v + 1, j, state))
        return iter(tasks)

    def on_record(self, record: dict[str, Any]) -> list[Realization]:
        if not self.restore(record):
            return []
        v, j = record["value_index"], record["ic"]
        if self.continuation and v + 1 < self.nvalues:
            return [self.make_task(v + 1, j, next_state(record))]
        return []


def next_state(record: dict[str, Any]) -> list[float] | None:
    """The state the next value of a continued chain starts from: the run's last section
    point (at cam phase theta_c0, so the cam phase carries over), or None for a run that did
    not end normally (the condition's own initial state is taken)."""
    sec = record.get("section") or {}
    if record["status"] != "OK" or not sec.get("theta_f"):
        return None
    return [float(sec["theta_f"][-1]), float(sec["omega_f"][-1])]


def _tables(records: list[dict], axis: Axis) -> tuple[pd.DataFrame, pd.DataFrame]:
    verdicts = pd.DataFrame(
        {
            "param": axis.name,
            "value": np.array([r["value"] for r in records], dtype=float),
            "value_index": np.array([r["value_index"] for r in records], dtype=np.int64),
            "ic": np.array([r["ic"] for r in records], dtype=np.int64),
            "seed": np.array([r["seed"] for r in records], dtype=np.int64),
            "sim_index": np.array([r["sim_index"] for r in records], dtype=np.int64),
            "theta_f0": np.array([r["theta_f0"] for r in records], dtype=float),
            "omega_f0": np.array([r["omega_f0"] for r in records], dtype=float),
            "continued": np.array([r["continued"] for r in records], dtype=bool),
            "status": [r["status"] for r in records],
            "label": [r["label"] for r in records],
            "period": period_column(records),
            "n_points": np.array([r["n_section"] for r in records], dtype=np.int64),
            "recorded_s": np.array([r["recorded_s"] for r in records], dtype=float),
            "reasons": [r["reasons"] for r in records],
            "warnings": [r["warnings"] for r in records],
            **fate_columns(records),
        }
    )
    verdicts = pd.concat([verdicts, evidence_columns(records)], axis=1)
    n = verdicts["n_points"].to_numpy()
    rep = np.repeat(np.arange(len(records)), n)
    cols = {
        c: np.concatenate([[]] + [r["section"].get(c, []) for r in records]) for c in POINT_COLUMNS
    }
    points = pd.DataFrame(
        {
            "param": axis.name,
            "value": verdicts["value"].to_numpy()[rep],
            "value_index": verdicts["value_index"].to_numpy()[rep],
            "ic": verdicts["ic"].to_numpy()[rep],
            "k": cols["k"].astype(np.int64),
            **{c: cols[c].astype(float) for c in POINT_COLUMNS[1:]},
            "status": verdicts["status"].to_numpy()[rep],
            "label": verdicts["label"].to_numpy()[rep],
            "period": verdicts["period"].array[rep] if len(rep) else pd.array([], "Int64"),
        }
    )
    return points, verdicts


def _states(given) -> list:
    """``initial_conditions`` when it is not a count: a list of states, else a SweepError."""
    if isinstance(given, str | bytes | dict) or not hasattr(given, "__iter__"):
        raise SweepError(
            "initial_conditions must be a count (an int >= 1) or a list of (theta_f0, "
            f"omega_f0) states [rad, rad/s], got {type(given).__name__} {given!r}"
        )
    return list(given)


def _state(given) -> tuple[float, float]:
    """One explicit initial state: two finite numbers, else a SweepError naming it."""
    try:
        th, om = (float(x) for x in given)
    except (TypeError, ValueError):
        th = om = math.nan
    if not (math.isfinite(th) and math.isfinite(om)):
        raise SweepError(
            f"initial_conditions: each state is (theta_f0 [rad], omega_f0 [rad/s]), two "
            f"finite numbers, got {given!r}"
        )
    return th, om


STATE_FIELDS = ("theta_f0", "omega_f0")
"""Fields of the initial state: a diagram over one of them is a slice of the basins."""


def _check_state_axis(name: str, counted: int | None, continuation) -> None:
    """Refuse what would overwrite a swept initial state: the other initial conditions
    (they set the state themselves) and continuation (it carries the state over)."""
    if name not in STATE_FIELDS:
        return
    if counted != 1:
        raise SweepError(
            f"the swept {name} is the initial state: initial_conditions must be 1 "
            "(the other conditions set the state themselves); sweep the other field with "
            "regime_map for a two-dimensional slice"
        )
    if continuation:
        raise SweepError(
            f"the swept {name} is the initial state: continuation (which starts each value "
            "from the last one's state) cannot be used with it"
        )


def bifurcation(
    param: str | Axis,
    values: Sequence[float] | str | None = None,
    *,
    base: Params | None = None,
    numerics: Numerics | None = None,
    duration: float = 20.0,
    transient: float | None = None,
    seed: int = 0,
    initial_conditions: int | Sequence[tuple[float, float]] = 1,
    continuation: bool = False,
    classify: Callable | None = None,
    lyapunov: bool = False,
    check_step: bool = False,
    extend_to: float | None = EXTEND_TO,
    workers: int | None = None,
    scheduler: Any = None,
    out: str | Path | None = None,
    resume: bool = False,
    progress: bool | None = None,
    flush_interval: float = 1.0,
    force: bool = False,
    device: str = "cpu",
    fate: float | None = None,
) -> Bifurcation:
    """Bifurcation diagram of the stroboscopic section over one parameter (paper Figs. 4, 6).

    Parameters
    ----------
    param : str or Axis
        The swept field (``l_lambda``, ``D``, ``G``, ``omega``, ``xi``, ``beta``, ...), or an
        Axis holding the values too.
    values : sequence of float or str
        The values, or ``"START:STOP:NUM"`` (NUM points, ends included). Fig. 4:
        ``bifurcation("l_lambda", "0.001:0.018:69")``.
    base : Params, optional
        Everything not swept; for Fig. 6 ``Params(stiffness="fractal", G=1e-9)`` (the
        fractal stiffness needs a smaller ``dt``: a warning says when it is too coarse).
    numerics : Numerics, optional
        The integrator and its settings (the swept field may be one of its fields).
    duration, transient : float
        Simulated time and the discarded start [s]; transient None = duration / 2.
    seed : int
        Seed of the line-length process (matters only when ``l_lambda_sigma`` > 0); value
        ``v``, condition ``j`` uses index ``realization_index(v, j)``.
    initial_conditions : int or sequence of (theta_f0, omega_f0)
        An int n: condition 0 is the base's initial state (in contact by default) and
        1 .. n-1 are spread over `IC_BOX` by :func:`initial_offsets`; or explicit states
        [rad, rad/s]. A diagram over ``theta_f0`` or ``omega_f0`` (a slice of the basins)
        sets that part of the state itself: it takes 1 condition and no continuation.
    continuation : bool
        Start value v+1 of each condition from the last section point of value v (at cam
        phase theta_c0, so the cam phase carries over); a run that did not end normally
        hands over the condition's own initial state instead. Values run in order along
        each chain, so only the conditions run in parallel.
    classify, lyapunov, check_step, extend_to, workers, scheduler, out, resume, progress
        As for :func:`regime_map`; the verdicts go to ``FILE.verdicts.parquet``.
    flush_interval, device
        As for :func:`regime_map`: the conditions of a value (and, without continuation,
        many values) run as one batch of members; a batch holds members of one omega and
        numerics, so a sweep over ``omega`` or ``dt`` batches the conditions of each value.
    fate : float, optional
        As for :func:`regime_map`: runs labelled chaotic, quasiperiodic or undetermined are
        continued to this time [s] to see whether they stay in the cam's reach and what they
        are at the end (verdict columns ``fate``, ``left_at``, ``fate_label``,
        ``fate_period``); a continued chain still starts its next value from the recorded
        run.

    Returns
    -------
    Bifurcation
    """
    axis = _axis(param, values)
    base, num = params_arg(base, "base"), numerics_arg(numerics)
    duration, transient = run_settings(duration, transient, seed)
    fate = check_fate(fate, duration)
    resume, force = flag("resume", resume), flag("force", force)
    continuation = flag("continuation", continuation)
    validate_grid(base, num, [axis])
    counted = isinstance(initial_conditions, numbers.Integral) and not isinstance(
        initial_conditions, bool
    )
    _check_state_axis(axis.name, initial_conditions if counted else None, continuation)
    n_specs, specs = _conditions(base, initial_conditions, counted)
    judge = make_judge(classify, flag("lyapunov", lyapunov), flag("check_step", check_step),
                       extend_to)  # fmt: skip
    runs = len(axis) * n_specs
    eng = resolve_engine(judge, by_size(device, runs), base, num, (duration, transient),
                         workers, scheduler)  # fmt: skip
    check_sweep_budget(base, num, runs=runs, duration=duration, transient=transient,
                       judge=judge, workers=workers, keeps_sections=True,
                       what="this bifurcation diagram", fate=fate,
                       reduce="the values, the initial conditions or the duration")  # fmt: skip
    if counted:  # built after the budget check: a huge count is refused first
        specs = [("base", base.theta_f0, base.omega_f0)] + [
            ("offset", a, b) for a, b in initial_offsets(initial_conditions)
        ]
    config = {
        "kind": "bifurcation", "version": __version__, "base": base.to_dict(),
        "numerics": num.to_dict(), "axis": axis.to_dict(), "seed": int(seed),
        "duration": duration, "transient": transient,
        "initial_conditions": [list(s) for s in specs], "continuation": bool(continuation),
        "classifier": judge.identity(), "device": eng.device, "code": code_identity(),
        "index_scheme": "cantor(value_index, ic)", "fate": fate,
    }  # fmt: skip

    def make_task(v: int, j: int, state) -> Realization:
        value = axis.values[v]
        p, n = cell_params(base, num, {axis.name: value})
        th, om = _start_state(p, specs[j], state)
        p = p.replace(theta_f0=th, omega_f0=om)
        extra = {"value_index": v, "ic": j, "value": value, "continued": state is not None,
                 "theta_f0": math.nan if th is None else float(th),
                 "omega_f0": math.nan if om is None else float(om)}  # fmt: skip
        return Realization((v, j), p, n, int(seed), realization_index(v, j), duration,
                           transient, fate, extra, sections=True)  # fmt: skip

    return run_sweep(
        _BranchPlan(make_task, len(axis), len(specs), bool(continuation)), eng,
        out=None if out is None else Path(out), second="verdicts", config=config,
        keys=("value_index", "ic"), read=read_bifurcation,
        build=lambda records: Bifurcation(*_tables(records, axis), config), resume=resume,
        force=force, flush_interval=flush_interval, workers=workers, scheduler=scheduler,
        progress=show_progress(progress), desc=f"bifurcation {axis.name}",
    )  # fmt: skip


def _axis(param, values) -> Axis:
    if isinstance(param, Axis) and values is not None:  # the values were ignored
        raise SweepError(f"the Axis {param.name} has its values: give values=None")
    if isinstance(param, Axis):
        return param
    if values is None:
        raise SweepError(f"give the values of {param} to sweep (or an Axis)")
    if isinstance(values, str):
        return Axis.parse(values, name=param)
    return Axis(param, values)


def _conditions(base: Params, given, counted: bool) -> tuple[int, list]:
    """(how many initial conditions, the explicit ones as specs), checked before any run."""
    if counted:
        return whole("initial conditions", given, low=1), []
    specs = [("absolute", *_state(s)) for s in _states(given)]
    if not specs:
        raise SweepError("initial conditions: the list is empty")
    for i, (_, th, om) in enumerate(specs):  # before any run (and any checkpoint)
        try:
            base.replace(theta_f0=th, omega_f0=om)
        except ParameterError as err:
            raise ParameterError(f"initial_conditions[{i}] = ({th}, {om}): {err}") from None
        if specs.index(specs[i]) < i:  # as an axis value twice: the same runs again
            raise SweepError(f"initial_conditions[{i}] = ({th}, {om}) is given twice")
    return len(specs), specs


def _start_state(p: Params, spec, state):
    """The initial state of a condition at a value: the chain's carried state, the base's
    (with the swept value if the axis is one), an offset from contact, or an explicit one."""
    kind, a, b = spec
    if state is not None:
        return state
    if kind == "offset":
        return float(contact_angle(p, 0.0)) + a, b
    if kind == "base":
        return p.theta_f0, p.omega_f0
    return a, b
