"""Monte Carlo regime maps (paper sec. 2.5, Figs. 7-10): N classified realizations per cell of a
grid of two numeric fields (the line length's mean mu ``l_lambda`` and spread sigma
``l_lambda_sigma``, or ``omega`` x ``xi``), each label's fraction with its Wilson interval."""

from __future__ import annotations

import numbers
from collections import Counter
from collections.abc import Callable, Iterator
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, ClassVar

import numpy as np
import pandas as pd

from .._util import ParameterError, whole
from ..io import code_identity
from ..model import Params, realizations_identical
from ..numerics import Numerics
from ..verdict import EXTEND_TO
from ._common import (
    RUN_COLUMNS,
    TwoTables,
    as_axis,
    dataset,
    make_judge,
    record_table,
    settings,
)
from ._engine import Plan, plan_engine, run_sweep
from ._grid import Axis, SweepError, cell_params, realization_index, validate_grid
from ._runs import Realization
from ._stats import max_halfwidth, summarize_cells

DEFAULT_CAP = 1000
"""Realizations per cell at most under adaptive sampling, unless told otherwise."""

RANDOM_REALIZATIONS = 20
"""Realizations per cell by default when some cell has a random line length."""


@dataclass(frozen=True)
class RegimeMap(TwoTables):
    """A regime map: one row per realization and one per cell, with the settings used.

    Attributes
    ----------
    realizations : DataFrame
        Sorted by (cell, index): ``cell``, ``index``, the axis values (named by the fields),
        ``seed``, ``sim_index`` (:func:`realization_index`), ``status``, ``label``,
        ``period``, ``n_section``, ``recorded_s`` (section time behind the label),
        ``n_impacts``, ``contact_fraction``, ``truncated_mass``, ``reasons``, ``warnings``,
        the fate columns and ``ev_<name>`` evidence values (NaN where absent;
        ``ev_exponent`` is λ₁·T per section iterate, ``ev_lyapunov_1`` λ₁ [1/s] and
        ``ev_lyapunov_1_stderr`` its standard error, ``ev_twins`` the common-noise twins'
        finite-time rate [1/s] and ``ev_synchronised`` 1 or 0 where they ran,
        ``ev_section_q0`` .. ``ev_section_q20`` the recorded section's theta_f quantiles
        [rad]).
    cells : DataFrame
        The per-cell summary of :func:`summarize_cells`.
    config : dict
        Everything that fixes the result (model, numerics, axes, seed, window, code, ...).
    """

    _tables: ClassVar[tuple[str, str]] = ("realizations", "cells")
    _kind: ClassVar[str] = "regime_map"
    realizations: pd.DataFrame
    cells: pd.DataFrame
    config: dict[str, Any] = field(default_factory=dict)

    @property
    def x(self) -> str:
        return self.config["x"]["name"]

    @property
    def y(self) -> str:
        return self.config["y"]["name"]

    def plot(self, ax=None, *, kind: str = "dominant", label: str = "chaotic"):
        """The map on ``ax`` (None: a new pyplot figure's) as a heatmap over its x and y
        fields; returns the Axes.

        ``kind`` = "dominant": each cell's dominant label (periodic cells marked Pn);
        "probability": P(``label``) per cell, with its Wilson interval at the map's
        confidence written in on grids of at most 64 cells; "width": that interval's width.
        """
        from .. import plot

        draw = {"dominant": plot.plot_dominant, "probability": plot.plot_probability,
                "width": plot.plot_interval_width}  # fmt: skip
        if kind not in draw:
            raise ValueError(f"kind = {kind!r}: one of {', '.join(map(repr, draw))}")
        kw = {"label": label, "confidence": self.config.get("confidence", 0.95)}
        ax = plot.axes(ax)
        draw[kind](self.cells, self.x, self.y, ax, **({} if kind == "dominant" else kw))
        return ax

    def to_xarray(self):
        """The map as an ``xarray.Dataset`` over its axes (dims named by their fields, the
        swept values as coordinates; optional extra ``chaoscam[xarray]``).

        Each column of :attr:`cells` is a variable over (x, y): ``dominant`` (the dominant
        label, text), ``n`` (realizations in the cell), ``n_L``/``p_L`` with ``p_L_lo``,
        ``p_L_hi`` (count and share of each label L, Wilson interval), period, exponents and
        the fate counts; each realization's ``label``, ``status`` and ``ev_*`` evidence is a
        variable over (x, y, ``realization``), "" or NaN past a cell's last one. ``attrs``:
        ``kind`` and ``config`` (the record, JSON). Round-trips through ``to_netcdf``.
        """
        from ..plot import axis_label

        x, y = self.x, self.y
        runs = [c for c in self.realizations if c in ("label", "status") or c[:3] == "ev_"]
        cells = dataset(self.cells.drop(columns=["cell", "ix", "iy"]), [x, y], self.config)
        real = dataset(self.realizations[[x, y, "index", *runs]], [x, y, "index"], {},
                       index="realization")  # fmt: skip
        ds = cells.merge(real)
        for name in (x, y):
            ds[name].attrs["long_name"] = axis_label(name)
        return ds


def read_regime_map(path: str | Path) -> RegimeMap:
    """Read a map written by :func:`regime_map` (``FILE.parquet`` and ``FILE.cells.parquet``)."""
    return RegimeMap.read(path)


class _RegimePlan(Plan):
    """Each cell's realizations: ``batch``, then ``batch`` more once its first n finished while
    its widest Wilson half-width exceeds ``target`` and n < ``cap``; cells in ``once`` run one."""

    keys = ("cell", "index")

    def __init__(self, make_task: Callable, ncells: int, batch: int, cap: int,
                 target: float | None, confidence: float, once=frozenset()) -> None:  # fmt: skip
        super().__init__()
        self.make_task, self.batch = make_task, batch
        self.target, self.confidence = target, confidence
        self.caps = [1 if c in once else cap for c in range(ncells)]
        self.n_target = [1 if c in once else batch for c in range(ncells)]
        self.n_done = [0] * ncells
        self.counts: list[Counter] = [Counter() for _ in range(ncells)]

    @property
    def total(self) -> int:
        return sum(self.n_target)

    def counted(self, record: dict[str, Any]) -> None:
        self.n_done[record["cell"]] += 1
        self.counts[record["cell"]][record["label"]] += 1

    def _grow(self, c: int) -> int:
        """Grow cell ``c``'s target while its finished runs ask for more; the target before."""
        old = self.n_target[c]
        while self.n_target[c] < self.caps[c] and self.n_done[c] >= self.n_target[c]:
            n = self.n_target[c]
            if self.n_done[c] == n and not (
                self.target is not None
                and max_halfwidth(self.counts[c], n, self.confidence) > self.target
            ):
                break
            self.n_target[c] = min(n + self.batch, self.caps[c])
        return old

    def start(self) -> Iterator[Realization]:
        if self.target is not None:
            for c in range(len(self.n_target)):
                self._grow(c)
        return (self.make_task(c, i) for c, n in enumerate(self.n_target) for i in range(n)
                if (c, i) not in self.finished)  # fmt: skip

    def follow(self, record: dict[str, Any]) -> list[Realization]:
        c = record["cell"]
        if self.n_done[c] != self.n_target[c]:  # not all of its first n finished
            return []
        return [self.make_task(c, i) for i in range(self._grow(c), self.n_target[c])]


def _cells_frame(x: Axis, y: Axis) -> pd.DataFrame:
    ix, iy = np.meshgrid(np.arange(len(x)), np.arange(len(y)), indexing="ij")
    ix, iy = ix.ravel(), iy.ravel()
    return pd.DataFrame({"cell": np.arange(ix.size, dtype=np.int64), "ix": ix.astype(np.int64),
                         "iy": iy.astype(np.int64), x.name: np.asarray(x.values)[ix],
                         y.name: np.asarray(y.values)[iy]})  # fmt: skip


def regime_map(
    x: Axis | str | tuple, y: Axis | str | tuple, *, base: Params | None = None,
    numerics: Numerics | None = None, realizations: int | None = None, seed: int = 0,
    duration: float = 20.0, transient: float | None = None, classify: Callable | None = None,
    lyapunov: bool = False, check_step: bool = False, extend_to: float | None = EXTEND_TO,
    target_halfwidth: float | None = None, max_realizations: int | None = None,
    confidence: float = 0.95, workers: int | None = None, scheduler: Any = None,
    out: str | Path | None = None, resume: bool = False, progress: bool | None = None,
    flush_interval: float = 1.0, force: bool = False, device: str = "cpu",
    fate: float | None = None,
) -> RegimeMap:  # fmt: skip
    """Monte Carlo regime map over two parameters: classify N realizations in every cell.

    Parameters
    ----------
    x, y : Axis, str or (name, values)
        The axes (Params or Numerics fields), e.g. ``Axis.linspace("l_lambda", 0.004, 0.016,
        7)`` and ``"l_lambda_sigma=0:0.004:5"`` [m]; cell ``ix * len(y) + iy``.
    base, numerics : Params, Numerics, optional
        Everything not swept.
    realizations : int, optional
        N per cell (adaptive: the first batch); default 20 where some cell has a random line
        length, else 1; a deterministic cell runs once.
    seed : int
        Realization ``i`` of cell ``c`` is ``solve(params_c, seed=seed,
        indices=[realization_index(c, i)])``, whatever the backend or interruptions.
    duration, transient : float
        Simulated time and the discarded start [s]; transient None = duration / 2.
    classify : callable, optional
        ``classify(solution) -> verdict`` (``label``, ``period``, ``evidence``, ``reasons``)
        on each run as a one-member solution (with its series unless ``needs_series =
        False``; picklable for Dask); default :func:`chaoscam.classify`. A run that did not
        end normally is labelled by its status (``left_reach``, ...).
    lyapunov : bool
        Record each run's tangent spectrum (evidence ``lyapunov_1``, ``lyapunov_1_stderr``,
        ``lyapunov_2`` [1/s]).
    check_step, extend_to : bool, float or None
        Judge each run at half the step too (the package's verdict; twice the cost); the
        longest recorded time [s] an undetermined verdict is extended to.
    target_halfwidth, max_realizations : float, int, optional
        Adaptive sampling: ``realizations`` more per cell while its widest Wilson half-width
        exceeds ``target_halfwidth``, up to ``max_realizations`` (default 1000).
    confidence : float
        Level of the Wilson intervals, in (0, 1).
    workers, scheduler : int, str or distributed.Client, optional
        Local threads (default: every core); or Dask: ``"tcp://HOST:PORT"``, ``"local"``
        (``workers`` processes) or a client.
    out : path, optional
        ``FILE.parquet`` and ``FILE.cells.parquet``; ``FILE.parquet.ckpt/`` while running.
    resume, force : bool
        Continue an interrupted run of the same configuration (or reuse a finished one);
        start over, replacing the outputs. Otherwise an existing output is an error.
    progress, flush_interval : bool or None, float
        A progress bar on stderr (None: when it is a terminal); the time between checkpoints [s].
    device : {"cpu", "gpu", "auto"}
        ``"cpu"`` is bit-identical everywhere; ``"gpu"`` agrees within ``GPU_TOLERANCE``;
        ``"auto"``: the GPU where one runs, for ``AUTO_GPU_MIN`` runs or more.
    fate : float, optional
        Horizon [s] > duration to which chaotic, quasiperiodic or undetermined runs go on, for
        transient chaos (at (omega, xi) = (42.5 rad/s, 0.40): chaotic for 174 s, then out of
        reach): columns ``fate`` (status), ``left_at``, ``fate_label``, ``fate_period`` (on its
        last half); per cell ``n_transient``, ``n_settled``, ``settled_period``; labels kept.

    Returns
    -------
    RegimeMap

    Raises
    ------
    ParameterError, SweepError
        A grid point outside a parameter's range; bad settings, or a checkpoint or output
        of another configuration.
    FileExistsError, SweepInterrupted
        An existing output without ``resume``; Ctrl-C (the message says how to resume).
    """
    x, y = as_axis(x), as_axis(y)
    base, num, duration, transient, fate, resume, force = settings(
        base, numerics, duration, transient, seed, fate, resume, force
    )
    validate_grid(base, num, [x, y], points=False)  # its points after the budget check
    cells = _cells_frame(x, y)
    xs, ys = cells[x.name].to_numpy(), cells[y.name].to_numpy()

    def cell(c: int) -> tuple[Params, Numerics]:
        return cell_params(base, num, {x.name: float(xs[c]), y.name: float(ys[c])})

    sigma = cells.get("l_lambda_sigma", np.full(len(cells), base.l_lambda_sigma))
    once = frozenset(np.flatnonzero(realizations_identical(base, sigma)).tolist())
    if realizations is None:
        realizations = RANDOM_REALIZATIONS if len(once) < len(cells) else 1
    realizations = whole("realizations", realizations, low=1)
    adaptive = _adaptive(target_halfwidth, max_realizations, realizations)
    if isinstance(confidence, bool) or not (
        isinstance(confidence, numbers.Real) and 0.0 < confidence < 1.0
    ):  # before any run: summarize_cells would refuse it only at the end
        raise SweepError(f"confidence = {confidence!r}: the intervals' level, in (0, 1), e.g. 0.95")
    judge = make_judge(classify, lyapunov, check_step, extend_to)
    cap = adaptive["max_realizations"] if adaptive else realizations
    eng = plan_engine(judge, device, len(cells) * cap, base, num, duration, transient, workers,
                      scheduler, what="this regime map", sections=False, fate=fate,
                      reduce="the grid, the realizations or the duration")  # fmt: skip
    validate_grid(base, num, [x, y])
    config = eng.config(
        "regime_map", code_identity(), base=base.to_dict(), numerics=num.to_dict(),
        x=x.to_dict(), y=y.to_dict(), realizations=realizations, seed=int(seed),
        duration=duration, transient=transient, adaptive=adaptive, confidence=float(confidence),
        index_scheme="cantor(cell, index)",
        deterministic_cells="run once (sigma = 0, or the fractal stiffness)", fate=fate,
    )  # fmt: skip
    cells["deterministic"] = [c in once for c in range(len(cells))]

    def make_task(c: int, i: int) -> Realization:
        return Realization((c, i), *cell(c), int(seed), realization_index(c, i), duration,
                           transient, fate, {"cell": c, "index": i})  # fmt: skip

    def build(records: list[dict[str, Any]]) -> RegimeMap:
        at = np.array([r["cell"] for r in records], dtype=np.int64)
        rows = record_table(records, ["cell", "index", (x.name, xs[at]), (y.name, ys[at]),
                                      "seed", "sim_index", *RUN_COLUMNS])  # fmt: skip
        return RegimeMap(rows, summarize_cells(rows, cells, confidence=confidence), config)

    target = adaptive["target_halfwidth"] if adaptive else None
    plan = _RegimePlan(make_task, len(cells), realizations, cap, target, confidence, once)
    return run_sweep(plan, eng, RegimeMap, config, build, out=out, resume=resume, force=force,
                     flush_interval=flush_interval, workers=workers, scheduler=scheduler,
                     progress=progress, desc="regime map")  # fmt: skip


def _adaptive(target_halfwidth, max_realizations, realizations: int) -> dict | None:
    """The adaptive sampling settings, checked; None without a target."""
    if target_halfwidth is None:
        if max_realizations is not None:
            raise SweepError(
                "max_realizations (--max-realizations) applies only with target_halfwidth "
                "(--target-halfwidth)"
            )
        return None
    if isinstance(target_halfwidth, bool) or not (
        isinstance(target_halfwidth, numbers.Real) and 0.0 < target_halfwidth < 0.5
    ):
        raise SweepError(f"target half-width = {target_halfwidth!r} must be in (0, 0.5)")
    cap = DEFAULT_CAP if max_realizations is None else whole("max realizations",
                                                             max_realizations, low=1)  # fmt: skip
    if cap < realizations:
        raise SweepError(f"max realizations = {cap} is below realizations = {realizations}")
    return {"target_halfwidth": float(target_halfwidth), "max_realizations": cap,
            "batch": realizations}  # fmt: skip


def mu_sigma_axes(mu: str, sigma: str) -> tuple[Axis, Axis]:
    """The paper's axes from ``START:STOP:NUM`` texts: mean and spread of l_lambda [m]."""
    x, y = Axis.parse(mu, name="l_lambda"), Axis.parse(sigma, name="l_lambda_sigma")
    if min(x.values) <= 0:
        raise ParameterError(f"mu = {min(x.values)!r} m: the mean line length must be > 0")
    if min(y.values) < 0:
        raise ParameterError(f"sigma = {min(y.values)!r} m: the spread must be >= 0")
    return x, y
