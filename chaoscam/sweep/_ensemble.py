"""Ensembles: many realizations of one model, each with its section, status and verdict.

A plan over the one sweep engine, like the maps and diagrams: members run in batches (the
CPU's threads, a GPU or Dask), each record is checkpointed as it completes, and an
interrupted run resumes to the same tables. Member ``i`` is realization ``first + i`` of
``seed``: ``solve(params, numerics, seed=seed, indices=[first + i])`` bit for bit.
"""

from __future__ import annotations

from collections.abc import Callable, Iterator
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, ClassVar

import numpy as np
import pandas as pd

from .._util import COUNT_MAX, flag, freeze_fields, whole
from .._version import __version__
from ..io import code_identity
from ..kernel import by_size
from ..model import Params, params_arg
from ..numerics import Numerics
from ..simulation import numerics_arg
from ..verdict import EXTEND_TO
from ._common import (
    TwoTables,
    check_sweep_budget,
    evidence_columns,
    make_judge,
    period_column,
    read_tables,
    run_settings,
    show_progress,
)
from ._engine import resolve_engine, run_sweep
from ._runs import Realization, section_arrays

__all__ = ["Ensemble", "ensemble", "read_ensemble"]


@dataclass(frozen=True)
class Ensemble(TwoTables):
    """An ensemble: one row per member and one per section point, with the settings used.

    Attributes
    ----------
    members : DataFrame
        One row per member, sorted: ``member``, ``index`` (its realization), ``seed``,
        ``status``, ``label``, ``period`` (None without ``classify``), ``n_section``,
        ``recorded_s``, ``n_impacts``, ``contact_fraction``, ``truncated_mass``,
        ``reasons``, ``warnings`` and the ``ev_<name>`` evidence values.
    sections : DataFrame
        member, k, t, theta_f, omega_f, l_lambda: every member's stroboscopic section after
        the transient.
    config : dict
        Everything that fixes the result.
    """

    _tables: ClassVar[tuple[str, str]] = ("members", "sections")
    members: pd.DataFrame
    sections: pd.DataFrame
    config: dict[str, Any] = field(default_factory=dict)

    def __post_init__(self) -> None:
        freeze_fields(self, "config")


def read_ensemble(path: str | Path) -> Ensemble:
    """Read an ensemble written by :func:`ensemble` (FILE.parquet, FILE.sections.parquet)."""
    return Ensemble(*read_tables(path, "sections", "ensemble"))


class _Members:
    """Every member once; nothing follows up."""

    def __init__(self, make_task: Callable, n: int) -> None:
        self.make_task, self.total, self.done = make_task, n, 0
        self.finished: set[int] = set()

    def restore(self, record: dict[str, Any]) -> bool:
        if record["member"] in self.finished:
            return False
        self.finished.add(record["member"])
        self.done += 1
        return True

    def start(self) -> Iterator[Realization]:
        return (self.make_task(i) for i in range(self.total) if i not in self.finished)

    def on_record(self, record: dict[str, Any]) -> list:
        self.restore(record)
        return []


def ensemble(
    params: Params | None = None,
    numerics: Numerics | None = None,
    *,
    members: int,
    first: int = 0,
    seed: int = 0,
    duration: float = 20.0,
    transient: float | None = None,
    classify: bool | Callable = True,
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
) -> Ensemble:
    """Realizations ``first .. first + members - 1`` of one model, with their verdicts.

    Parameters
    ----------
    params, numerics : Params, Numerics, optional
        The model and its integrator settings.
    members, first : int
        How many realizations, and the first one's index under ``seed``.
    duration, transient : float
        Simulated time and the discarded start [s]; transient None = duration / 2.
    classify : bool or callable
        True: each member's verdict (:func:`chaoscam.classify`); False: none (statuses,
        counts and sections only); or a classifier of one's own, as for
        :func:`regime_map`.
    lyapunov, check_step, extend_to, workers, scheduler, out, resume, progress, flush_interval,
    force, device
        As for :func:`regime_map`; the sections go to ``FILE.sections.parquet``.

    Returns
    -------
    Ensemble
    """
    p, num = params_arg(params), numerics_arg(numerics)
    members = whole("members", members, low=1)
    first = whole("first", first, high=COUNT_MAX - (members - 1))  # every index fits int64
    duration, transient = run_settings(duration, transient, seed)
    resume, force = flag("resume", resume), flag("force", force)
    labels = classify is not False
    custom = classify if callable(classify) else None
    if not labels and (lyapunov or check_step):
        raise ValueError("lyapunov and check_step need classify (a verdict to adapt)")
    judge = make_judge(custom, flag("lyapunov", lyapunov), flag("check_step", check_step),
                       extend_to if labels else None, labels=labels)  # fmt: skip
    eng = resolve_engine(judge, by_size(device, members), p, num, (duration, transient),
                         workers, scheduler)  # fmt: skip
    check_sweep_budget(p, num, runs=members, duration=duration, transient=transient,
                       judge=judge, workers=workers, keeps_sections=True,
                       what=f"an ensemble of {members} members",
                       reduce="the members or the duration")  # fmt: skip
    config = {
        "kind": "ensemble", "version": __version__, "params": p.to_dict(),
        "numerics": num.to_dict(), "seed": int(seed), "first": first, "members": members,
        "duration": duration, "transient": transient,
        "classifier": judge.identity(), "device": eng.device,
        "code": code_identity(),
    }  # fmt: skip

    def make_task(i: int) -> Realization:
        return Realization((i, 0), p, num, int(seed), first + i, duration, transient, None,
                           {"member": i, "index": first + i}, sections=True)  # fmt: skip

    return run_sweep(
        _Members(make_task, members), eng, out=None if out is None else Path(out),
        second="sections", config=config, keys=("member", "index"), read=read_ensemble,
        build=lambda records: Ensemble(*_tables(records), config), resume=resume,
        force=force, flush_interval=flush_interval, workers=workers, scheduler=scheduler,
        progress=show_progress(progress), desc="ensemble",
    )  # fmt: skip


def _tables(records: list[dict]) -> tuple[pd.DataFrame, pd.DataFrame]:
    head = pd.DataFrame({
        "member": np.array([r["member"] for r in records], dtype=np.int64),
        "index": np.array([r["index"] for r in records], dtype=np.int64),
        "seed": np.array([r["seed"] for r in records], dtype=np.int64),
        "status": [r["status"] for r in records],
        "label": [r["label"] for r in records],
        "period": period_column(records),
        "n_section": np.array([r["n_section"] for r in records], dtype=np.int64),
        "recorded_s": np.array([r["recorded_s"] for r in records], dtype=float),
        "n_impacts": np.array([r["n_impacts"] for r in records], dtype=np.int64),
        "contact_fraction": np.array([r["contact_fraction"] for r in records], dtype=float),
        "truncated_mass": np.array([r["truncated_mass"] for r in records], dtype=float),
        "reasons": [r["reasons"] for r in records],
        "warnings": [r["warnings"] for r in records],
    })  # fmt: skip
    head = pd.concat([head, evidence_columns(records)], axis=1)
    blocks = [pd.DataFrame(section_arrays(r)).assign(member=r["member"]) for r in records]
    sections = (
        pd.concat(blocks, ignore_index=True)
        if blocks
        else pd.DataFrame(columns=["k", "t", "theta_f", "omega_f", "l_lambda", "member"])
    )
    sections = sections[["member", "k", "t", "theta_f", "omega_f", "l_lambda"]]
    sections[["member", "k"]] = sections[["member", "k"]].astype(np.int64)
    return head, sections
