"""Bifurcation diagrams (paper Figs. 4, 6: l_lambda over [0.001, 0.018] m; D over [1.36, 1.56],
fractal stiffness): section points after the transient and verdicts over one parameter; several
initial conditions show coexisting attractors, continuation follows one branch."""

from __future__ import annotations

import math
import numbers
from collections.abc import Callable, Iterator, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, ClassVar

import numpy as np
import pandas as pd

from .._util import ParameterError, flag, whole
from ..io import code_identity
from ..model import Params, contact_angle
from ..numerics import Numerics
from ..verdict import EXTEND_TO
from ._common import TwoTables, dataset, make_judge, record_table, section_table, settings
from ._engine import Plan, plan_engine, run_sweep
from ._grid import Axis, SweepError, cell_params, realization_index, validate_grid
from ._runs import Realization

IC_BOX = (0.3, 3.0)
"""Extra initial conditions: theta_f0 - theta_fc(0) in [0, 0.3] rad (off the cam) and omega_f0
in [-3, 3] rad/s, the extent of the default model's section."""


@dataclass(frozen=True)
class Bifurcation(TwoTables):
    """A bifurcation diagram: section points and verdicts, with the settings used.

    Attributes
    ----------
    points : DataFrame
        One row per section point after the transient, sorted by (value_index, ic, k):
        ``param``, ``value``, ``value_index``, ``ic``, ``k``, ``t`` [s], ``theta_f`` [rad],
        ``omega_f`` [rad/s], ``l_lambda`` [m], and the run's ``status``, ``label``, ``period``.
    verdicts : DataFrame
        One row per (value, initial condition): ``param``, ``value``, ``value_index``,
        ``ic``, ``seed``, ``sim_index``, ``theta_f0``, ``omega_f0`` (NaN = in contact),
        ``continued``, then as :class:`RegimeMap` (``n_points`` for ``n_section``).
    config : dict
        The settings that fix the result.
    """

    _tables: ClassVar[tuple[str, str]] = ("points", "verdicts")
    _kind: ClassVar[str] = "bifurcation"
    points: pd.DataFrame
    verdicts: pd.DataFrame
    config: dict[str, Any] = field(default_factory=dict)

    @property
    def param(self) -> str:
        return self.config["axis"]["name"]

    def plot(self, ax=None, *, coordinate: str = "theta_f", color_by: str | None = "label"):
        """The diagram on ``ax`` (None: a new pyplot figure's); returns the Axes.

        The section's ``coordinate`` ("theta_f" [rad] or "omega_f" [rad/s]) over the swept
        value, coloured by ``color_by`` ("label", "ic" or None); a run without a section
        point after the transient (out of the cam's reach, diverged) is an x on the top edge.
        """
        from ..plot import axes, plot_diagram

        return plot_diagram(self.points, axes(ax), verdicts=self.verdicts,
                            coordinate=coordinate, color_by=color_by)  # fmt: skip

    def to_xarray(self):
        """The diagram as an ``xarray.Dataset`` over (the swept parameter, ``ic``, ``point``)
        (optional extra ``chaoscam[xarray]``).

        ``k``, ``t`` [s], ``theta_f`` [rad], ``omega_f`` [rad/s] and ``l_lambda_used`` [m] (the
        line length in force) of each section point are variables over all three dims
        (``point`` numbers a run's points from 0; NaN past its last); each column of
        :attr:`verdicts` (``label``, ``period``, ``status``, evidence, ...) is one over
        (parameter, ``ic``). ``attrs``: ``kind`` and ``config`` (the record, JSON).
        Round-trips through ``to_netcdf``.
        """
        from ..plot import axis_label

        name, pts = self.param, self.points.drop(columns=["param", "status", "label", "period"])
        pts = pts.rename(columns={"l_lambda": "l_lambda_used"})  # the swept field may be l_lambda
        pts = pts.assign(point=pts.groupby(["value", "ic"]).cumcount())
        points = dataset(pts, ["value", "ic", "point"], self.config, value=name)
        runs = dataset(self.verdicts.drop(columns="param"), ["value", "ic"], {}, value=name)
        ds = points.drop_vars("value_index").merge(runs)
        ds[name].attrs["long_name"] = axis_label(name)
        return ds


def read_bifurcation(path: str | Path) -> Bifurcation:
    """Read a diagram written by :func:`bifurcation`."""
    return Bifurcation.read(path)


def initial_offsets(n: int) -> list[tuple[float, float]]:
    """Offsets (d theta [rad], omega_f0 [rad/s]) of initial conditions 1 .. n-1: the unscrambled
    2-D Halton sequence (bases 2, 3; ``scipy.stats.qmc.Halton``'s bits, without a second of
    importing scipy.stats) without its origin, mapped onto `IC_BOX`."""
    if whole("n", n, low=0) <= 1:
        return []
    d_theta, omega = IC_BOX
    return [
        (_radical_inverse(i, 2) * d_theta, (2.0 * _radical_inverse(i, 3) - 1.0) * omega)
        for i in range(1, n)
    ]


def _radical_inverse(i: int, base: int) -> float:
    """The van der Corput point ``sum_k d_k base^-(k+1)`` of ``i = sum_k d_k base^k``."""
    x, scale = 0.0, 1.0 / base
    while i > 0:
        i, digit = divmod(i, base)
        x += digit * scale
        scale /= base
    return x


class _BranchPlan(Plan):
    """Every (value, initial condition); with continuation, one chain per condition."""

    keys = ("value_index", "ic")

    def __init__(self, make_task: Callable, nvalues: int, nics: int, continuation: bool):
        super().__init__()
        self.make_task, self.nvalues, self.nics = make_task, nvalues, nics
        self.continuation, self.total = continuation, nvalues * nics
        self.last: dict[int, tuple[int, Any]] = {}  # chain -> (value index, next state)

    def counted(self, record: dict[str, Any]) -> None:
        v, j = record["value_index"], record["ic"]
        if v >= self.last.get(j, (-1, None))[0]:
            self.last[j] = (v, next_state(record))

    def start(self) -> Iterator[Realization]:
        if not self.continuation:
            return (self.make_task(v, j, None) for v in range(self.nvalues)
                    for j in range(self.nics) if (v, j) not in self.finished)  # fmt: skip
        tasks = []
        for j in range(self.nics):
            v, state = self.last.get(j, (-1, None))
            if v + 1 < self.nvalues:
                tasks.append(self.make_task(v + 1, j, state))
        return iter(tasks)

    def follow(self, record: dict[str, Any]) -> list[Realization]:
        v, j = record["value_index"], record["ic"]
        if self.continuation and v + 1 < self.nvalues:
            return [self.make_task(v + 1, j, next_state(record))]
        return []


def next_state(record: dict[str, Any]) -> list[float] | None:
    """A continued chain's next start: the run's last section point; None for a failed run."""
    sec = record.get("section") or {}
    if record["status"] != "OK" or not sec.get("theta_f"):
        return None
    return [float(sec["theta_f"][-1]), float(sec["omega_f"][-1])]


def _tables(records: list[dict], axis: Axis) -> tuple[pd.DataFrame, pd.DataFrame]:
    param = ("param", np.array([axis.name] * len(records), dtype=object))
    verdicts = record_table(records, [
        param, "value", "value_index", "ic", "seed", "sim_index", "theta_f0", "omega_f0",
        "continued", "status", "label", "period", "n_section", "recorded_s", "reasons",
        "warnings",
    ]).rename(columns={"n_section": "n_points"})  # fmt: skip
    lead = dict([param, *((c, verdicts[c].to_numpy()) for c in ("value", "value_index", "ic"))])
    trail = {c: verdicts[c].to_numpy() for c in ("status", "label")}
    points = section_table(records, lead, {**trail, "period": verdicts["period"].array})
    return points, verdicts


def _check_state_axis(name: str, counted: int | None, continuation) -> None:
    """Refuse other initial conditions and continuation over a swept initial state."""
    if name not in ("theta_f0", "omega_f0"):
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
    param: str | Axis, values: Sequence[float] | str | None = None, *, base: Params | None = None,
    numerics: Numerics | None = None, duration: float = 20.0, transient: float | None = None,
    seed: int = 0, initial_conditions: int | Sequence[tuple[float, float]] = 1,
    continuation: bool = False, classify: Callable | None = None, lyapunov: bool = False,
    check_step: bool = False, extend_to: float | None = EXTEND_TO, workers: int | None = None,
    scheduler: Any = None, out: str | Path | None = None, resume: bool = False,
    progress: bool | None = None, flush_interval: float = 1.0, force: bool = False,
    device: str = "cpu", fate: float | None = None,
) -> Bifurcation:  # fmt: skip
    """Bifurcation diagram of the stroboscopic section over one parameter (paper Figs. 4, 6).

    Parameters
    ----------
    param : str or Axis
        The swept Params or Numerics field (``l_lambda``, ``D``, ``dt``, ...), or an Axis.
    values : sequence of float or str
        The values, or ``"START:STOP:NUM"`` (ends included); Fig. 4:
        ``bifurcation("l_lambda", "0.001:0.018:69")``.
    base, numerics : Params, Numerics, optional
        Not swept; Fig. 6: ``Params(stiffness="fractal", G=1e-9)`` (warned if ``dt`` is coarse).
    seed : int
        Seed of the line-length process; value ``v``, condition ``j`` is solve index
        ``realization_index(v, j)``.
    initial_conditions : int or sequence of (theta_f0, omega_f0)
        An int n: condition 0 is the base's state, 1 .. n-1 :func:`initial_offsets`; or explicit
        states [rad, rad/s]. Over ``theta_f0`` or ``omega_f0``: 1 condition, no continuation.
    continuation : bool
        Start value v+1 of each condition from value v's last section point (after a failed
        run: the condition's own state); only the conditions run in parallel.
    duration, transient, classify, lyapunov, check_step, extend_to, workers, scheduler, out,
    resume, progress, flush_interval, force, device, fate
        As for :func:`regime_map`; the verdicts go to ``FILE.verdicts.parquet``, and a
        continued chain starts its next value from the recorded run, not the fate run.

    Returns
    -------
    Bifurcation
    """
    axis = _axis(param, values)
    base, num, duration, transient, fate, resume, force = settings(
        base, numerics, duration, transient, seed, fate, resume, force
    )
    continuation = flag("continuation", continuation)
    validate_grid(base, num, [axis], points=False)  # its points after the budget check
    counted = isinstance(initial_conditions, numbers.Integral) and not isinstance(
        initial_conditions, bool
    )
    _check_state_axis(axis.name, initial_conditions if counted else None, continuation)
    n_specs, specs = _conditions(base, initial_conditions, counted)
    judge = make_judge(classify, lyapunov, check_step, extend_to)
    eng = plan_engine(judge, device, len(axis) * n_specs, base, num, duration, transient,
                      workers, scheduler, what="this bifurcation diagram", sections=True, fate=fate,
                      reduce="the values, the initial conditions or the duration")  # fmt: skip
    validate_grid(base, num, [axis])
    if counted:  # built after the budget check: a huge count is refused first
        specs = [("base", base.theta_f0, base.omega_f0)] + [
            ("offset", a, b) for a, b in initial_offsets(initial_conditions)
        ]
    config = eng.config(
        "bifurcation", code_identity(), base=base.to_dict(), numerics=num.to_dict(),
        axis=axis.to_dict(), seed=int(seed), duration=duration, transient=transient,
        initial_conditions=[list(s) for s in specs], continuation=continuation,
        index_scheme="cantor(value_index, ic)", fate=fate,
    )  # fmt: skip

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

    plan = _BranchPlan(make_task, len(axis), len(specs), continuation)
    return run_sweep(
        plan, eng, Bifurcation, config, lambda r: Bifurcation(*_tables(r, axis), config),
        out=out, resume=resume, force=force, flush_interval=flush_interval, workers=workers,
        scheduler=scheduler, progress=progress, desc=f"bifurcation {axis.name}",
    )  # fmt: skip


def _axis(param, values) -> Axis:
    if isinstance(param, Axis) and values is not None:  # the values were ignored
        raise SweepError(f"the Axis {param.name} has its values: give values=None")
    if isinstance(param, Axis):
        return param
    if values is None:
        raise SweepError(f"give the values of {param} to sweep (or an Axis)")
    return Axis.parse(values, name=param) if isinstance(values, str) else Axis(param, values)


def _conditions(base: Params, given, counted: bool) -> tuple[int, list]:
    """(how many initial conditions, the explicit ones as specs), checked before any run."""
    if counted:
        return whole("initial conditions", given, low=1), []
    if isinstance(given, str | bytes | dict) or not hasattr(given, "__iter__"):
        raise SweepError(
            "initial_conditions must be a count (an int >= 1) or a list of (theta_f0, "
            f"omega_f0) states [rad, rad/s], got {type(given).__name__} {given!r}"
        )
    specs = []
    for state in given:
        try:
            th, om = (float(x) for x in state)
        except (TypeError, ValueError):
            th = om = math.nan
        if not (math.isfinite(th) and math.isfinite(om)):
            raise SweepError(
                f"initial_conditions: each state is (theta_f0 [rad], omega_f0 [rad/s]), two "
                f"finite numbers, got {state!r}"
            )
        specs.append(("absolute", th, om))
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
    """A condition's initial state: carried, the base's, an offset from contact, or given."""
    kind, a, b = spec
    if state is not None:
        return state
    if kind == "offset":
        return float(contact_angle(p, 0.0)) + a, b
    if kind == "base":
        return p.theta_f0, p.omega_f0
    return a, b
