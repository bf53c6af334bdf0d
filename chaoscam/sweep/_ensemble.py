"""Ensembles: realizations of one model with their sections, statuses and verdicts; member
``i`` is ``solve(params, numerics, seed=seed, indices=[first + i])`` bit for bit."""

from __future__ import annotations

import re
from collections import Counter
from collections.abc import Callable, Iterator
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, ClassVar

import numpy as np
import pandas as pd

from .._util import COUNT_MAX, whole
from ..io import code_identity
from ..model import Params, realizations_identical
from ..numerics import Numerics
from ..verdict import EXTEND_TO
from ._common import RUN_COLUMNS, TwoTables, make_judge, record_table, section_table, settings
from ._engine import Plan, plan_engine, run_sweep
from ._runs import Realization
from ._stats import LABEL_ORDER, wilson_interval


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

    @property
    def identical(self) -> bool:
        """Whether every member is the same run (``l_lambda_sigma = 0`` or the fractal
        stiffness: :func:`chaoscam.model.realizations_identical`); False for a record this
        version cannot read."""
        try:
            return realizations_identical(Params(**self.config["params"]))
        except (KeyError, TypeError, ValueError):
            return False

    def plot(self, ax=None, *, kind: str = "shares"):
        """The ensemble on ``ax`` (None: a new pyplot figure's); returns the Axes.

        ``kind`` = "shares": each label's share of the members with its 95 % Wilson interval
        (none when :attr:`identical`); "section": every member's stroboscopic section
        (θ_f [rad], θ̇_f [rad/s]) coloured by its label (its verdict, or its run status).
        """
        from ..plot import axes, plot_section, plot_shares

        shares = label_shares(self.members)
        if kind == "shares":
            return plot_shares(shares, axes(ax), interval=not self.identical)
        if kind != "section":
            raise ValueError(f"kind = {kind!r}: 'shares' or 'section'")
        labels = dict(zip(self.members["member"], member_labels(self.members), strict=True))
        ax = plot_section(self.sections, axes(ax), labels=self.sections["member"].map(labels),
                          order=[r["label"] for r in shares])  # fmt: skip
        ax.set_title(f"stroboscopic section of {self.members['member'].nunique()} members")
        return ax


def read_ensemble(path: str | Path) -> Ensemble:
    """Read an ensemble written by :func:`ensemble` (FILE.parquet, FILE.sections.parquet)."""
    return Ensemble.read(path)


def classified(members: pd.DataFrame) -> bool:
    """Whether an ensemble's members carry verdicts (it was run with ``classify``)."""
    return "label" in members and bool(members["label"].notna().any())


def member_labels(members: pd.DataFrame) -> list[str]:
    """Each member's label: its verdict ("periodic (period 2)" with its period), or its run
    status when the ensemble was not classified."""
    if not classified(members):
        return [str(s) for s in members["status"]]
    return [
        f"periodic (period {int(p)})" if lab == "periodic" and not pd.isna(p) else str(lab)
        for lab, p in zip(members["label"], members["period"], strict=True)
    ]


def _order(label: str) -> tuple[int, int, str]:
    head = label.partition(" ")[0]
    rank = LABEL_ORDER.index(head) if head in LABEL_ORDER else len(LABEL_ORDER)
    period = re.search(r"period (\d+)", label)
    return rank, int(period.group(1)) if period else 0, label


def label_shares(members: pd.DataFrame, *, confidence: float = 0.95) -> list[dict[str, Any]]:
    """One row per label of :func:`member_labels`, in display order: label, count, share,
    and the share's Wilson interval (``lo``, ``hi``) over the members."""
    counts = Counter(member_labels(members))
    n = sum(counts.values())
    rows = []
    for label in sorted(counts, key=_order):
        k = counts[label]
        lo, hi = wilson_interval(k, n, confidence)
        rows.append({"label": label, "count": k, "share": k / n, "lo": float(lo), "hi": float(hi)})
    return rows


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
