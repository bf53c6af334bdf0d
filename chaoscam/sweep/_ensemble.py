"""Ensembles: realizations of one model with their sections, statuses and verdicts; member
``i`` is ``solve(params, numerics, seed=seed, indices=[first + i])`` bit for bit."""

from __future__ import annotations

from collections.abc import Callable, Iterator
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, ClassVar

import numpy as np
import pandas as pd

from .._util import COUNT_MAX, whole
from ..io import code_identity
from ..model import Params
from ..numerics import Numerics
from ..verdict import EXTEND_TO
from ._common import RUN_COLUMNS, TwoTables, make_judge, record_table, section_table, settings
from ._engine import Plan, plan_engine, run_sweep
from ._runs import Realization


@dataclass(frozen=True)
class Ensemble(TwoTables):
    """An ensemble: one row per member and one per section point, with the settings used.

    Attributes
    ----------
    members : DataFrame
        One row per member: ``member``, ``index`` (its realization), ``seed``, then as
        :class:`RegimeMap` from ``status`` (no fate columns; no label without ``classify``).
    sections : DataFrame
        member, k, t, theta_f, omega_f, l_lambda: each member's section after the transient.
    config : dict
        Everything that fixes the result.
    """

    _tables: ClassVar[tuple[str, str]] = ("members", "sections")
    _kind: ClassVar[str] = "ensemble"
    members: pd.DataFrame
    sections: pd.DataFrame
    config: dict[str, Any] = field(default_factory=dict)


def read_ensemble(path: str | Path) -> Ensemble:
    """Read an ensemble written by :func:`ensemble` (FILE.parquet, FILE.sections.parquet)."""
    return Ensemble.read(path)


class _Members(Plan):
    """Every member once; nothing follows up."""

    keys = ("member",)

    def __init__(self, make_task: Callable, n: int) -> None:
        super().__init__()
        self.make_task, self.total = make_task, n

    def start(self) -> Iterator[Realization]:
        return (self.make_task(i) for i in range(self.total) if (i,) not in self.finished)


def ensemble(
    params: Params | None = None, numerics: Numerics | None = None, *, members: int,
    first: int = 0, seed: int = 0, duration: float = 20.0, transient: float | None = None,
    classify: bool | Callable = True, lyapunov: bool = False, check_step: bool = False,
    extend_to: float | None = EXTEND_TO, workers: int | None = None, scheduler: Any = None,
    out: str | Path | None = None, resume: bool = False, progress: bool | None = None,
    flush_interval: float = 1.0, force: bool = False, device: str = "cpu",
) -> Ensemble:  # fmt: skip
    """Realizations ``first .. first + members - 1`` of one model, with their verdicts.

    Parameters
    ----------
    params, numerics : Params, Numerics, optional
        The model and its integrator settings.
    members, first : int
        How many realizations, and the first one's index under ``seed``.
    classify : bool or callable
        True: each member's verdict (:func:`chaoscam.classify`); False: none (statuses,
        counts and sections only); or a classifier of one's own, as for :func:`regime_map`.
    duration, transient, lyapunov, check_step, extend_to, workers, scheduler, out, resume,
    progress, flush_interval, force, device
        As for :func:`regime_map`; the sections go to ``FILE.sections.parquet``.

    Returns
    -------
    Ensemble
    """
    p, num, duration, transient, _, resume, force = settings(
        params, numerics, duration, transient, seed, None, resume, force, name="params"
    )
    members = whole("members", members, low=1)
    first = whole("first", first, high=COUNT_MAX - (members - 1))  # every index fits int64
    labels = classify is not False
    if not labels and (lyapunov or check_step):
        raise ValueError("lyapunov and check_step need classify (a verdict to adapt)")
    judge = make_judge(classify if callable(classify) else None, lyapunov, check_step,
                       extend_to if labels else None, labels=labels)  # fmt: skip
    eng = plan_engine(judge, device, members, p, num, duration, transient, workers, scheduler,
                      what=f"an ensemble of {members} members", sections=True,
                      reduce="the members or the duration")  # fmt: skip
    config = eng.config(
        "ensemble", code_identity(), params=p.to_dict(), numerics=num.to_dict(),
        seed=int(seed), first=first, members=members, duration=duration, transient=transient,
    )  # fmt: skip

    def make_task(i: int) -> Realization:
        return Realization((i, 0), p, num, int(seed), first + i, duration, transient, None,
                           {"member": i, "index": first + i}, sections=True)  # fmt: skip

    def build(records: list[dict[str, Any]]) -> Ensemble:
        head = record_table(records, ["member", "index", "seed", *RUN_COLUMNS], fate=False)
        sections = section_table(records, {"member": head["member"].to_numpy(np.int64)})
        return Ensemble(head, sections, config)

    return run_sweep(_Members(make_task, members), eng, Ensemble, config, build, out=out,
                     resume=resume, force=force, flush_interval=flush_interval, workers=workers,
                     scheduler=scheduler, progress=progress, desc="ensemble")  # fmt: skip
