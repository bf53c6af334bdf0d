"""Monte Carlo regime maps: a grid of two parameters, N classified realizations per cell.

Paper section 2.5 and Figs. 7-10: over a grid of the line length's mean mu (``l_lambda``)
and spread sigma (``l_lambda_sigma``), each cell's realizations are simulated and
classified; the map shows the fraction of each label with its Wilson interval. The same
machinery serves any two numeric parameters (``omega`` x ``xi`` for the deterministic
model: with sigma = 0 every realization of a cell is the same, so one per cell suffices).
"""

from __future__ import annotations

import numbers
from collections import Counter
from collections.abc import Callable, Iterator
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, ClassVar

import numpy as np
import pandas as pd

from .._util import ParameterError, flag, freeze_fields, whole
from .._version import __version__
from ..io import code_identity
from ..kernel import by_size
from ..model import Params, params_arg, realizations_identical
from ..numerics import Numerics
from ..simulation import numerics_arg
from ..verdict import EXTEND_TO
from ._common import (
    TwoTables,
    as_axis,
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
from ._stats import max_halfwidth, summarize_cells

__all__ = ["RegimeMap", "regime_map", "read_regime_map"]

DEFAULT_CAP = 1000
"""Realizations per cell at most under adaptive sampling, unless told otherwise."""


@dataclass(frozen=True)
class RegimeMap(TwoTables):
    """A regime map: one row per realization and one per cell, with the settings used.

    Attributes
    ----------
    realizations : DataFrame
        One row per realization, sorted by (cell, index): ``cell``, ``index`` (the
        realization in its cell), the two axis values (columns named by the parameters),
        ``seed``, ``sim_index`` (the :func:`chaoscam.simulate` index, see
        :func:`realization_index`), ``status``, ``label``, ``period``, ``n_section``,
        ``recorded_s`` (seconds of section recording behind the label: duration - transient,
        or the extension's when the verdict was extended), ``n_impacts``,
        ``contact_fraction``, ``truncated_mass``, ``reasons``, ``warnings``, ``fate``,
        ``left_at``, ``fate_label`` and ``fate_period`` (with a ``fate`` horizon: the status
        there, when the run stopped, and the verdict at the end of one that stayed; None /
        NaN for runs not continued) and one ``ev_<name>`` column per evidence value
        (NaN where a run has none; ``ev_exponent`` is the tangent exponent per iterate of
        the section map, λ₁·T; with ``lyapunov``, ``ev_lyapunov_1`` is λ₁ in 1/s).
    cells : DataFrame
        The per-cell summary of :func:`summarize_cells`.
    config : dict
        Everything that fixes the result (base parameters and numerics, axes, seed,
        realizations, duration, transient, classifier, adaptive settings, code).
    """

    _tables: ClassVar[tuple[str, str]] = ("realizations", "cells")
    realizations: pd.DataFrame
    cells: pd.DataFrame
    config: dict[str, Any] = field(default_factory=dict)

    def __post_init__(self) -> None:
        freeze_fields(self, "config")

    @property
    def x(self) -> str:
        return self.config["x"]["name"]

    @property
    def y(self) -> str:
        return self.config["y"]["name"]


def read_regime_map(path: str | Path) -> RegimeMap:
    """Read a map written by :func:`regime_map` (``FILE.parquet`` and ``FILE.cells.parquet``)."""
    return RegimeMap(*read_tables(path, "cells", "regime_map"))


class _RegimePlan:
    """The realizations of each cell, and when adaptive sampling asks for more.

    Adaptive rule (deterministic): a cell starts with ``n0`` realizations; each time all of
    its first n are finished, if the widest Wilson interval of its labels is wider than
    ``target`` (half-width) and n < ``cap``, the next ``batch`` indices are added. The
    decision uses exactly the realizations 0..n-1, so it does not depend on their order.
    """

    def __init__(
        self,
        make_task: Callable,
        ncells: int,
        n0: int,
        batch: int,
        cap: int,
        target: float | None,
        confidence: float,
        once: frozenset[int] = frozenset(),
    ) -> None:
        self.make_task = make_task
        self.n0, self.batch, self.target = n0, batch, target
        # cells in `once` are deterministic (sigma = 0): every realization would be the same
        self.caps = [1 if c in once else cap for c in range(ncells)]
        self.confidence = confidence
        self.n_target = [1 if c in once else n0 for c in range(ncells)]
        self.finished: list[set[int]] = [set() for _ in range(ncells)]
        self.counts: list[Counter] = [Counter() for _ in range(ncells)]
        self.done = 0

    @property
    def total(self) -> int:
        return sum(self.n_target)

    def _add(self, record: dict[str, Any]) -> bool:
        c, i = record["cell"], record["index"]
        if i in self.finished[c]:
            return False
        self.finished[c].add(i)
        self.counts[c][record["label"]] += 1
        self.done += 1
        return True

    def _wants_more(self, c: int) -> bool:
        if self.target is None or self.n_target[c] >= self.caps[c]:
            return False
        return max_halfwidth(self.counts[c], self.n_target[c], self.confidence) > self.target

    def restore(self, record: dict[str, Any]) -> bool:
        return self._add(record)

    def _settle(self, c: int) -> None:
        """Replay the adaptive decisions of a resumed cell from its finished indices."""
        while self.n_target[c] < self.caps[c]:
            n = len(self.finished[c])
            if n < self.n_target[c] or (n == self.n_target[c] and not self._wants_more(c)):
                return
            # n > n_target: the earlier run already decided to extend.
            self.n_target[c] = min(self.n_target[c] + self.batch, self.caps[c])

    def start(self) -> Iterator[Realization]:
        if self.target is not None:
            for c in range(len(self.n_target)):
                self._settle(c)
        return self._initial()

    def _initial(self) -> Iterator[Realization]:
        for c, n in enumerate(self.n_target):
            for i in range(n):
                if i not in self.finished[c]:
                    yield self.make_task(c, i)

    def on_record(self, record: dict[str, Any]) -> list[Realization]:
        if not self._add(record):
            return []
        c = record["cell"]
        if len(self.finished[c]) == self.n_target[c] and self._wants_more(c):
            old = self.n_target[c]
            self.n_target[c] = min(old + self.batch, self.caps[c])
            return [self.make_task(c, i) for i in range(old, self.n_target[c])]
        return []


def _cells_frame(x: Axis, y: Axis) -> pd.DataFrame:
    ix, iy = np.meshgrid(np.arange(len(x)), np.arange(len(y)), indexing="ij")
    ix, iy = ix.ravel(), iy.ravel()
    return pd.DataFrame(
        {
            "cell": np.arange(ix.size, dtype=np.int64),
            "ix": ix.astype(np.int64),
            "iy": iy.astype(np.int64),
            x.name: np.asarray(x.values)[ix],
            y.name: np.asarray(y.values)[iy],
        }
    )


def _rows(records: list[dict], cells: pd.DataFrame, x: Axis, y: Axis) -> pd.DataFrame:
    cell = np.array([r["cell"] for r in records], dtype=np.int64)
    head = pd.DataFrame(
        {
            "cell": cell,
            "index": np.array([r["index"] for r in records], dtype=np.int64),
            x.name: cells[x.name].to_numpy()[cell],
            y.name: cells[y.name].to_numpy()[cell],
            "seed": np.array([r["seed"] for r in records], dtype=np.int64),
            "sim_index": np.array([r["sim_index"] for r in records], dtype=np.int64),
            "status": [r["status"] for r in records],
            "label": [r["label"] for r in records],
            "period": period_column(records),
        }
    )
    for name, dtype in (
        ("n_section", np.int64),
        ("recorded_s", float),
        ("n_impacts", np.int64),
        ("contact_fraction", float),
        ("truncated_mass", float),
    ):
        head[name] = np.array([r[name] for r in records], dtype=dtype)
    head["reasons"] = [r["reasons"] for r in records]
    head["warnings"] = [r["warnings"] for r in records]
    head = head.assign(**fate_columns(records))
    return pd.concat([head, evidence_columns(records)], axis=1)


def regime_map(
    x: Axis | str | tuple,
    y: Axis | str | tuple,
    *,
    base: Params | None = None,
    numerics: Numerics | None = None,
    realizations: int | None = None,
    seed: int = 0,
    duration: float = 20.0,
    transient: float | None = None,
    classify: Callable | None = None,
    lyapunov: bool = False,
    check_step: bool = False,
    extend_to: float | None = EXTEND_TO,
    target_halfwidth: float | None = None,
    max_realizations: int | None = None,
    confidence: float = 0.95,
    workers: int | None = None,
    scheduler: Any = None,
    out: str | Path | None = None,
    resume: bool = False,
    progress: bool | None = None,
    flush_interval: float = 1.0,
    force: bool = False,
    device: str = "cpu",
    fate: float | None = None,
) -> RegimeMap:
    """Monte Carlo regime map over two parameters: classify N realizations in every cell.

    Parameters
    ----------
    x, y : Axis, str or (name, values)
        The axes, e.g. ``Axis.linspace("l_lambda", 0.004, 0.016, 7)`` (mu [m]) and
        ``"l_lambda_sigma=0:0.004:5"`` (sigma [m]). Cell ``c = ix * len(y) + iy``.
    base : Params, optional
        The model for everything not swept (Table 1 defaults).
    numerics : Numerics, optional
        The integrator and its settings for everything not swept (an axis may be one of its
        fields, e.g. ``dt``).
    realizations : int, optional
        N, realizations per cell (the first batch under adaptive sampling); default 20 when
        some cell has a random line length, else 1 (a deterministic cell runs once anyway).
    seed : int
        Master seed. Realization ``i`` of cell ``c`` is ``solve(params_c, seed=seed,
        indices=[realization_index(c, i)])``: its line-length stream is
        ``SeedSequence(seed, spawn_key=(realization_index(c, i),))``, whatever the backend,
        the worker count or an interruption.
    duration, transient : float
        Simulated time and the discarded start [s]; transient None = duration / 2.
    classify : callable, optional
        A classifier of one's own, ``classify(solution) -> verdict`` (``label``, ``period``,
        ``evidence``, ``reasons``) on each run as a one-member solution (with its series
        unless it declares ``needs_series = False``); picklable for Dask. Default: the
        package's verdict, :func:`chaoscam.classify`. Runs that did not end normally are not
        classified: their label is the status's (``left_reach``, ``diverged``).
    lyapunov : bool
        Also record each run's tangent Lyapunov spectrum (evidence ``lyapunov_1`` with
        ``lyapunov_1_stderr``, and ``lyapunov_2``, in 1/s), summarised per cell as
        ``lyapunov_mean`` / ``lyapunov_std``: the random system's top exponent.
    check_step : bool
        Judge each realization at half the step too and call it undetermined when the
        verdict changes (twice the cost; the package's verdict only).
    extend_to : float or None
        Longest recorded time [s] an undetermined verdict is extended to (default 120 s).
    target_halfwidth : float, optional
        Adaptive sampling: add ``realizations`` more to a cell while the widest Wilson
        half-width (at ``confidence``) of its label fractions exceeds this, up to
        ``max_realizations``.
    max_realizations : int, optional
        Cap of adaptive sampling (default 1000).
    confidence : float
        Level of the Wilson intervals, in (0, 1) (default 0.95); the report and the figures
        name it.
    workers : int, optional
        Local threads, one batch each (default: every core), or the worker count of a local
        Dask cluster when ``scheduler="local"``.
    scheduler : str or distributed.Client, optional
        Run the batches on Dask: ``"tcp://HOST:PORT"``, ``"local"`` (a LocalCluster on
        127.0.0.1) or a client.
    out : path, optional
        ``FILE.parquet``: realizations there, cells in ``FILE.cells.parquet``, and a
        checkpoint ``FILE.parquet.ckpt/`` while running (removed at the end).
    resume : bool
        Continue an interrupted run of the same configuration (or reuse a finished one).
        Without it an existing output or checkpoint is an error; nothing is overwritten.
    progress : bool, optional
        Show a progress bar with ETA on stderr; default: when stderr is a terminal.
    flush_interval : float
        Seconds between checkpoint parts [s].
    device : {"cpu", "gpu", "auto"}
        Where the batches run: ``"gpu"`` uses an NVIDIA GPU (numba-cuda), equal to the CPU
        only within ``GPU_TOLERANCE`` (chaotic members part after a few periods); default
        ``"cpu"``, bit-identical everywhere; ``"auto"``: the GPU where one runs and the map
        has ``AUTO_GPU_MIN`` (4,096) runs or more.
    fate : float, optional
        Horizon [s]: each realization labelled chaotic, quasiperiodic or undetermined is
        run on to this time, with the tangent (the same motion, bit for bit), to see whether
        it stays in the cam's reach and what it is at the end: transient chaos, which a label
        over ``duration`` cannot see (at (omega, xi) = (42.5 rad/s, 0.40) the motion is
        chaotic for 174 s and then leaves; at xi = 0.3459 a period-6 orbit in bands of ~5e-7
        rad reads chaotic over 10-20 s and periodic 6 over 50-100 s). Its row gets ``fate``
        (the status at the horizon: ``"OK"``, ``"LEFT_REACH"``, ...), ``left_at`` (the last
        section time before it stopped, NaN if it stayed) and, if it stayed, ``fate_label``
        and ``fate_period`` (the model's verdict on the continued run's last half,
        certificate included), and each cell ``n_transient`` (how many left before the
        horizon), ``n_settled`` and ``settled_period`` (how many were periodic there, and
        their period). Labels are not changed: they describe the recorded window. Must
        exceed ``duration``; None (default) continues nothing.

    Returns
    -------
    RegimeMap

    Raises
    ------
    ParameterError
        A grid point outside a parameter's range (sigma < 0, mu <= 0, ...), named.
    SweepError
        Bad settings, or a checkpoint or output of another configuration.
    FileExistsError
        An existing output or checkpoint without ``resume``.
    SweepInterrupted
        Ctrl-C; the message says how to resume.
    """
    x, y = as_axis(x), as_axis(y)
    base, num = params_arg(base, "base"), numerics_arg(numerics)
    duration, transient = run_settings(duration, transient, seed)
    fate = check_fate(fate, duration)
    resume, force = flag("resume", resume), flag("force", force)
    validate_grid(base, num, [x, y])
    cells = _cells_frame(x, y)
    once = _deterministic_cells(base, num, cells, x, y)
    realizations = _realizations(realizations, len(once) < len(cells))
    adaptive = _adaptive(target_halfwidth, max_realizations, realizations)
    _check_confidence(confidence)
    judge = make_judge(classify, flag("lyapunov", lyapunov), flag("check_step", check_step),
                       extend_to)  # fmt: skip
    runs = len(cells) * (adaptive["max_realizations"] if adaptive else realizations)
    eng = resolve_engine(judge, by_size(device, runs), base, num, (duration, transient),
                         workers, scheduler)  # fmt: skip
    check_sweep_budget(base, num, runs=runs, duration=duration, transient=transient,
                       judge=judge, workers=workers, keeps_sections=False,
                       what="this regime map", fate=fate,
                       reduce="the grid, the realizations or the duration")  # fmt: skip
    config = {
        "kind": "regime_map", "version": __version__, "base": base.to_dict(),
        "numerics": num.to_dict(), "x": x.to_dict(), "y": y.to_dict(),
        "realizations": realizations, "seed": int(seed), "duration": duration,
        "transient": transient, "classifier": judge.identity(), "device": eng.device,
        "code": code_identity(), "adaptive": adaptive, "confidence": float(confidence),
        "index_scheme": "cantor(cell, index)",
        "deterministic_cells": "run once (sigma = 0, or the fractal stiffness)", "fate": fate,
    }  # fmt: skip
    cells["deterministic"] = [c in once for c in range(len(cells))]
    xs, ys = cells[x.name].to_numpy(), cells[y.name].to_numpy()

    def make_task(c: int, i: int) -> Realization:
        p, n = cell_params(base, num, {x.name: float(xs[c]), y.name: float(ys[c])})
        return Realization((c, i), p, n, int(seed), realization_index(c, i), duration,
                           transient, fate, {"cell": c, "index": i})  # fmt: skip

    def build(records: list[dict[str, Any]]) -> RegimeMap:
        rows = _rows(records, cells, x, y)
        return RegimeMap(rows, summarize_cells(rows, cells, confidence=confidence), config)

    cap = adaptive["max_realizations"] if adaptive else realizations
    target = adaptive["target_halfwidth"] if adaptive else None
    plan = _RegimePlan(make_task, len(cells), realizations, realizations, cap, target,
                       confidence, once)  # fmt: skip
    return run_sweep(
        plan, eng, out=None if out is None else Path(out), second="cells", config=config,
        keys=("cell", "index"), read=read_regime_map, build=build, resume=resume,
        force=force, flush_interval=flush_interval, workers=workers, scheduler=scheduler,
        progress=show_progress(progress), desc="regime map",
    )  # fmt: skip


RANDOM_REALIZATIONS = 20
"""Realizations per cell by default when some cell has a random line length."""


def _realizations(given, random: bool) -> int:
    if given is None:
        return RANDOM_REALIZATIONS if random else 1
    return whole("realizations", given, low=1)


def _deterministic_cells(base, num, cells, x: Axis, y: Axis) -> frozenset[int]:
    """Cells whose realizations are all the same run (sigma = 0, or the fractal stiffness,
    which the line length does not change): computed once and reported as such."""
    xs, ys = cells[x.name].to_numpy(), cells[y.name].to_numpy()
    return frozenset(
        c
        for c in range(len(cells))
        if realizations_identical(
            cell_params(base, num, {x.name: float(xs[c]), y.name: float(ys[c])})[0]
        )
    )


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
    cap = (
        DEFAULT_CAP
        if max_realizations is None
        else whole("max realizations", max_realizations, low=1)
    )
    if cap < realizations:
        raise SweepError(f"max realizations = {cap} is below realizations = {realizations}")
    return {"target_halfwidth": float(target_halfwidth), "max_realizations": cap,
            "batch": realizations}  # fmt: skip


def _check_confidence(confidence) -> None:
    if isinstance(confidence, bool) or not (
        isinstance(confidence, numbers.Real) and 0.0 < confidence < 1.0
    ):  # before any run: summarize_cells would refuse it only at the end
        raise SweepError(f"confidence = {confidence!r}: the intervals' level, in (0, 1), e.g. 0.95")


def mu_sigma_axes(mu: str, sigma: str) -> tuple[Axis, Axis]:
    """The paper's axes from ``START:STOP:NUM`` texts: mean and spread of l_lambda [m]."""
    x, y = Axis.parse(mu, name="l_lambda"), Axis.parse(sigma, name="l_lambda_sigma")
    if min(x.values) <= 0:
        raise ParameterError(f"mu = {min(x.values)!r} m: the mean line length must be > 0")
    if min(y.values) < 0:
        raise ParameterError(f"sigma = {min(y.values)!r} m: the spread must be >= 0")
    return x, y
