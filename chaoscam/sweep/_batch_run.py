"""A batch of sweep tasks through the ensemble engine, in two phases.

:func:`launch_batch` runs the members (one compiled ensemble call per group of tasks that
share the grid, on the CPU's threads or a GPU); :func:`label_batch` judges them
(:func:`chaoscam._ensemble_verdicts.member_verdicts`: section, tangent exponent, orbit
certificate, extensions of undetermined members), runs the fate runs and builds each
task's record (``task.record``, the same fields as on the process engine).
:func:`run_batch` is the two in a row. Apart, they let a GPU sweep launch its next batch
while the host labels the last (:class:`._pipeline.PipelineBackend`).

Bit-identity: an ensemble member equals ``simulate(params, seed=seed, index=sim_index)``
bit for bit, and its verdict uses its own arrays only, so a record does not depend on the
batch it ran in, the thread count, the phases' threads or an interruption.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

from .._run_warnings import run_warnings
from .._warn import quiet, recorded
from ..integrate._members import models_of
from ..model import Params, truncated_mass
from ._tasks import FATE_LABELS, RunSummary, fate_continues, fate_fields, verdict_fields

__all__ = ["Launched", "label_batch", "launch_batch", "run_batch"]


def _group_key(task: Any) -> tuple:
    p = task.params
    return (task.seed, task.duration, task.transient, p.dt, p.omega, task.fate)


@dataclass(frozen=True)
class Launched:
    """One group of a batch after its ensemble call: its key (seed, duration, transient,
    dt, omega, fate), the positions of its tasks in the batch, their models, the ensemble,
    and what the call warned."""

    key: tuple
    picks: list[int]
    plist: list[Params]
    ens: Any
    warned: list[str]


def launch_batch(
    tasks: Sequence[Any], backend: str = "cpu", extend_to: float | None = 120.0
) -> list[Launched]:
    """The ensembles of ``tasks``, one compiled call per group of tasks that share (seed,
    duration, transient, dt, omega, fate), keeping their order within a group; kept
    resumable when undetermined members may be extended (``extend_to`` not None) or fate
    runs continued (a ``fate`` horizon)."""
    from ..integrate import simulate_ensemble

    groups: dict[tuple, list[int]] = {}
    for i, t in enumerate(tasks):
        groups.setdefault(_group_key(t), []).append(i)
    out = []
    for key, picks in groups.items():
        seed, duration, transient = key[:3]
        plist = [tasks[i].params for i in picks]
        with recorded() as caught:  # catch_warnings is not safe on the batch threads
            ens = simulate_ensemble(
                plist,
                [tasks[i].sim_index for i in picks],
                seed=seed,
                duration=duration,
                transient=transient,
                backend=backend,
                tangent=True,
                # undetermined members are extended, and fate runs go on, from the copy
                resumable=extend_to is not None or key[5] is not None,
            )
        out.append(Launched(key, picks, plist, ens, [str(w.message) for w in caught]))
    return out


def _fates(ens, plist, later, seed: int, fate: float) -> list[dict[str, Any]]:
    """The fate fields of members ``later`` of ``ens`` (models ``plist``, every member's)
    run on to ``fate`` seconds with the tangent: continued from the copy a resumable run
    keeps (:func:`chaoscam.integrate.extend_ensemble`, bit-identical to a run made that long,
    without repeating the first run's time: 20 of a 100-s horizon's seconds in the
    report), else run again from t = 0. One ensemble call, as the process engine's one run
    each (:func:`._tasks.fate_fields` on the same rows: a continued run records from the
    first run's transient on, so it is taken only where the run's last half, the rows
    judged, starts after that transient; see :func:`_continues`).

    After a GPU batch they run where ``"auto"`` puts so few
    (:data:`chaoscam._ensemble_verdicts.EXTEND_BACKEND`: the CPU for fewer than
    ``_gpu.AUTO_GPU_MIN``): continued, they go on from the GPU's state; run again, they are
    the same realizations, equal to the GPU's motion within ``GPU_TOLERANCE`` for a while
    and, when chaotic, only in their statistics after."""
    from .._ensemble_verdicts import EXTEND_BACKEND
    from ..integrate import extend_ensemble, simulate_ensemble

    backend = EXTEND_BACKEND[ens.settings["backend"]]
    with quiet():  # the model's warnings came with the first run (quiet: on batch threads)
        if _continues(ens, plist, fate):
            long = extend_ensemble(ens, list(plist), fate, members=later, backend=backend)
        else:
            long = simulate_ensemble(
                [plist[j] for j in later],
                [int(ens.members["index"].iat[j]) for j in later],
                seed=seed, duration=fate, transient=0.0, backend=backend, tangent=True,
            )  # fmt: skip
    rows_of = long.sections.groupby("member").indices
    out = []
    for i, j in enumerate(later):
        rows = rows_of.get(i, [])
        sec = long.sections.iloc[rows].reset_index(drop=True)
        out.append(
            fate_fields(str(long.members["status"].iat[i]), sec, long.jacobians[rows], plist[j])
        )
    return out


def _continues(ens, plist, fate: float) -> bool:
    """Whether ``ens`` can go on to ``fate`` with the fate fields of a run made from t = 0
    (:func:`._tasks.fate_continues`: it kept a copy, and the judged last half starts after
    the transient, from which a continued run records)."""
    period = max(p.cam_period for p in plist)
    return fate_continues(ens.resume is not None, ens.settings["transient"], fate, period)


def label_batch(
    tasks: Sequence[Any], launched: list[Launched], extend_to: float | None = 120.0
) -> list[dict[str, Any]]:
    """The records of ``tasks`` from their launched groups: each member's verdict (the
    undetermined extended up to ``extend_to`` s recorded, see
    :func:`chaoscam.classify_ensemble`), its fate where the sweep asks one, its warnings."""
    from .._ensemble_verdicts import member_verdicts

    records: list[dict[str, Any] | None] = [None] * len(tasks)
    for group in launched:
        seed, fate = group.key[0], group.key[5]
        picks, plist, ens = group.picks, group.plist, group.ens
        with recorded() as caught:
            verdicts = member_verdicts(ens, plist, extend_to=extend_to)
        # What the batch warned, less the models' own warnings (simulate_ensemble warns those
        # once for every model in the group; each record adds its own model's below, as on
        # the process engine, not its neighbours')
        models = {w for q in models_of(plist) for w in run_warnings(q)}
        said = [*group.warned, *(str(w.message) for w in caught)]
        shared = [w for w in said if w not in models]
        later = [
            j for j, v in enumerate(verdicts) if v.verdict is not None and v.label in FATE_LABELS
        ]
        fates: dict[int, dict[str, Any]] = {}
        if fate is not None and later:
            fates = dict(zip(later, _fates(ens, plist, later, seed, fate), strict=True))
        rows_of = ens.sections.groupby("member").indices
        members = ens.members
        for j, i in enumerate(picks):
            sec = ens.sections.iloc[rows_of.get(j, [])].drop(columns="member")
            status = str(members["status"].iat[j])
            run = RunSummary(
                status,
                sec.reset_index(drop=True),
                int(members["n_impacts"].iat[j]),
                float(members["contact_fraction"].iat[j]),
                truncated_mass(plist[j].l_lambda, plist[j].l_lambda_sigma, plist[j].l_min),
            )
            v = verdicts[j]  # without a verdict: labelled by its status, or too short to judge
            fields = (
                verdict_fields(v.verdict)
                if v.verdict is not None
                else {"label": v.label, "period": None, "reasons": v.reasons, "evidence": {}}
            )
            fields.update(fates.get(j, {}))
            seen = [w for w in (*run_warnings(plist[j]), *shared) if w]
            fields["status"] = status
            fields["warnings"] = " | ".join(dict.fromkeys(seen))
            records[i] = tasks[i].record(run, fields)
    return records  # type: ignore[return-value]


def run_batch(
    tasks: Sequence[Any], backend: str = "cpu", extend_to: float | None = 120.0
) -> list[dict[str, Any]]:
    """The records of ``tasks``, simulated as ensembles of members that share the grid;
    undetermined members are extended up to ``extend_to`` s recorded (see
    :func:`chaoscam.classify_ensemble`): :func:`launch_batch`, then :func:`label_batch`."""
    return label_batch(tasks, launch_batch(tasks, backend, extend_to), extend_to)
