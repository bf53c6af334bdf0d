"""classify_ensemble(ens, params): a verdict per ensemble member, from arrays only.

An ensemble (:func:`chaoscam.integrate.simulate_ensemble` with ``tangent=True``) keeps no
time series: each member has its stroboscopic section and the Jacobian of the section map
over each period. That is what :func:`chaoscam.classify.classify_section_run` needs, the
verdict :func:`chaoscam.classify_trajectory` gives a run kept without its series: the
section's structure, the tangent exponent λ₁ ± its standard error, n-band chaos, and for a
deterministic member (σ = 0) the certificate of a periodic orbit (Newton shooting). The
regime maps and bifurcation diagrams of :mod:`chaoscam.sweep` label their members here too,
so a member's verdict is the same whichever driver ran it.
"""

from __future__ import annotations

import contextvars
import dataclasses
import time
from collections.abc import Callable, Sequence
from concurrent.futures import ThreadPoolExecutor

import numpy as np
import pandas as pd

from ._checks import of_type, real
from ._model_rules import extensible, extension_stopped
from .analysis import Verdict
from .classify import EXTEND_TO, _with_settings, classify_section_run
from .integrate import Ensemble, Status, extend_ensemble, simulate_ensemble
from .integrate._driver import check_stop
from .model import Params, realizations_identical

__all__ = ["MemberVerdict", "classify_ensemble", "member_verdicts"]

_COORDS = ["theta_f", "omega_f"]

EXTEND_BACKEND = {"cpu": "cpu", "gpu": "auto"}
"""Where the extensions of an ensemble run, by where it ran. A CPU run stays on the CPU (its
verdicts are then the same bits as a longer CPU run's). A GPU run's extensions settle by size
(``"auto"``: the GPU from ``_gpu.AUTO_GPU_MIN`` members), because one GPU thread is slow: on
an H200 (2026-11-27) 64 members of 0.25 s took a 1.09 s launch, about 0.23 simulated seconds
a second a thread, where one CPU core runs a default member at about 150 (0.13 s for 20 s).
A few hundred undetermined members extended by 60 s would hold the device for minutes that
the host's cores finish in seconds."""


@dataclasses.dataclass(frozen=True)
class MemberVerdict:
    """One member's label, period and reasons; ``verdict`` is None for a run that did not
    end normally (labelled by its status: ``left_reach``, ``diverged``). A run with too few
    section points to judge has an undetermined verdict without evidence, and is extended
    like any undetermined one."""

    label: str
    period: int | None
    reasons: str
    verdict: Verdict | None


def _member(status: str, t, k, xy, jac: np.ndarray, p: Params, transient: float):
    """One member's verdict from its section rows as arrays (times ``t``, indices ``k``,
    points ``xy`` = (theta_f, omega_f)) and their Jacobians; arrays, not a DataFrame slice
    a member (pandas indexing was a quarter of a random member's verdict time)."""
    st = Status[status]
    if st is not Status.OK:
        return MemberVerdict(st.label or "undetermined", None, st.message, None)
    keep = (t >= transient - 1e-9 * p.cam_period) & (k > 0)
    if keep.sum() < 2:
        why = (
            f"{int(keep.sum())} section point(s) after the transient: too few to judge; "
            "run longer than the transient by several cam periods"
        )
        # An undetermined verdict like any other, so that the member is extended as
        # classify_trajectory extends such a run (the engines' labels agree).
        return MemberVerdict("undetermined", None, why, Verdict("undetermined", None, (), (why,)))
    v = classify_section_run(xy[keep], jac[keep], p)
    return MemberVerdict(v.label, v.period, "; ".join(v.reasons), v)


def member_verdicts(
    ens: Ensemble,
    params: Params | Sequence[Params],
    *,
    extend_to: float | None = EXTEND_TO,
    progress=None,
) -> list[MemberVerdict]:
    """The verdict of every member of ``ens``, in the order of ``ens.members``.

    ``params`` is the model of the run (one for all members, or one per member, as given to
    ``simulate_ensemble``); other models are refused (ValueError), as the verdicts would
    judge the members with them. As :func:`chaoscam.classify_trajectory` does, an undetermined
    member (but not one whose tangent overflowed) is run again longer (4x the recorded time
    each round, at most ``extend_to`` seconds recorded; None: never), all such members in
    one ensemble call on the backend of ``ens``, until its verdict settles; its verdict's
    ``settings["extended"]`` records the time used. A run made with ``resumable=True`` is
    continued from where it stopped (:func:`chaoscam.integrate.extend_ensemble`: the same
    bits as running it again from t = 0, without repeating the transient and the time
    already recorded). A CPU run's extensions run on the CPU; a GPU run's where
    ``backend="auto"`` puts them (:data:`EXTEND_BACKEND`: on the CPU for fewer than
    ``_gpu.AUTO_GPU_MIN`` members, continued from the GPU's state). Raises ValueError when
    ``ens`` was run without ``tangent=True``.

    ``progress``, optional, is called as ``progress(0, extending=m, recorded_s=r)`` before
    each extension round (m members, to r seconds recorded) and as ``progress(n)`` after
    each batch of it (n members just run), so that a progress bar can grow its total.
    """
    of_type("ens", ens, Ensemble, "from chaoscam.integrate.simulate_ensemble")
    if extend_to is not None:  # as classify_trajectory checks it
        extend_to = real("extend_to", extend_to, low=0.0, unit="s")
    if ens.jacobians is None:
        raise ValueError("classify_ensemble needs an ensemble run with tangent=True")
    members = ens.members
    plist = list(params) if isinstance(params, list | tuple) else [params] * len(members)
    _check_models(ens, plist)
    verdicts = _verdicts(ens, plist)
    s = ens.settings
    recorded = s["duration"] - s["transient"]
    t_wall = time.perf_counter()
    pending = [j for j, v in enumerate(verdicts) if _unsettled(v)]
    last, at = ens, list(range(len(members)))  # the latest run, and whose members it holds
    more = EXTEND_BACKEND[s["backend"]]
    while pending and extend_to is not None and recorded < extend_to:
        recorded = min(extend_to, 4.0 * recorded)
        sub = [plist[j] for j in pending]
        if progress is not None:
            progress(0, extending=len(pending), recorded_s=recorded)
        if last.resume is not None:  # continued from its last run: the same bits, sooner
            where = {j: i for i, j in enumerate(at)}
            longer = extend_ensemble(
                last,
                [plist[j] for j in at],
                s["transient"] + recorded,
                members=[where[j] for j in pending],
                resumable=True,
                progress=progress,
                backend=more,
            )
        else:
            longer = simulate_ensemble(
                sub,
                [int(members["index"].iat[j]) for j in pending],
                seed=s["seed"],
                duration=s["transient"] + recorded,
                transient=s["transient"],
                backend=more,
                tangent=True,
                progress=progress,
            )
        last, at = longer, list(pending)
        note = {
            "recorded_s": recorded,
            "wall_time_s": time.perf_counter() - t_wall,
            "why": "the verdict on the run as given was undetermined",
            "backend": longer.settings["backend"],
        }
        last_t = longer.sections.groupby("member")["t"].max()
        for i, (j, v) in enumerate(zip(pending, _verdicts(longer, sub), strict=True)):
            if v.verdict is not None:
                extended = _with_settings(v.verdict, extended=note)
                verdicts[j] = dataclasses.replace(v, verdict=extended)
            else:  # the longer run ended early: the first verdict stays, and says so
                m, status = longer.members["member"].iat[i], longer.members["status"].iat[i]
                kept = extension_stopped(
                    verdicts[j].verdict, Status[status], float(last_t.get(m, np.nan)), recorded
                )
                verdicts[j] = dataclasses.replace(
                    verdicts[j], reasons="; ".join(kept.reasons), verdict=kept
                )
        pending = [j for j in pending if _unsettled(verdicts[j])]
    return verdicts


def _check_models(ens: Ensemble, plist: list) -> None:
    """``params`` must be the models the members ran with: each verdict judges its member
    with them (the certificate of a periodic orbit runs the model again)."""
    from .integrate._ensemble import models_digest

    if len(plist) != len(ens.members):
        raise ValueError(
            f"params: {len(plist)} parameter sets for an ensemble of {len(ens.members)} "
            "members; give one Params for all, or one per member"
        )
    bad = next((q for q in plist if not isinstance(q, Params)), None)
    if bad is not None:
        raise ValueError(f"params: expected chaoscam.Params, got {type(bad).__name__}")
    ran = ens.settings.get("models")
    if ran is not None and models_digest(plist) != ran:
        raise ValueError(
            "params are not the models this ensemble was run with; pass the Params (or the "
            "list) given to simulate_ensemble"
        )


def _unsettled(v: MemberVerdict) -> bool:
    return v.verdict is not None and extensible(v.verdict)


def _verdicts(ens: Ensemble, plist: list[Params]) -> list[MemberVerdict]:
    """Each member's verdict; those of a deterministic model on as many threads as the
    ensemble ran on, the others on the calling thread meanwhile.

    A verdict is a pure function of its member, so the threads change nothing but the time.
    A deterministic member that looks periodic is certified by Newton shooting, whose map
    iterates run compiled without the GIL (:func:`chaoscam.integrate._driver.run_alone`),
    about two thirds of the verdicts' time in a regime map with a sigma = 0 row: threads
    help there. A random member's verdict (no certificate) is numpy and Python under the GIL,
    which threads only contend for: 128 members of sigma = 2 mm, 20 s recorded, took 3.3-3.6
    ms each on one thread and 4.1-4.2, 4.5 and 4.7-5.6 ms on 2, 4 and 8 threads (2-core
    machine, 2026-11-28).
    """
    transient = float(ens.settings["transient"])
    rows_of = ens.sections.groupby("member").indices  # member -> positions of its rows
    empty = np.empty(0, dtype=np.int64)
    sec = ens.sections
    t, k, xy = sec["t"].to_numpy(), sec["k"].to_numpy(), sec[_COORDS].to_numpy(dtype=float)

    def verdict(item: tuple[int, str]) -> MemberVerdict:
        check_stop()  # a labelling thread asked to stop: before each member (a prompt Ctrl-C)
        m, status = item
        pick = rows_of.get(m, empty)
        return _member(
            status, t[pick], k[pick], xy[pick], ens.jacobians[pick], plist[int(m)], transient
        )

    items = list(zip(ens.members["member"], ens.members["status"], strict=True))
    shoot = [realizations_identical(plist[int(m)]) for m, _ in items]
    pooled = [x for x, s in zip(items, shoot, strict=True) if s]
    here = [x for x, s in zip(items, shoot, strict=True) if not s]
    a, b = _threaded(verdict, pooled, int(ens.settings.get("threads", 1)), here)
    done_a, done_b = iter(a), iter(b)
    return [next(done_a) if s else next(done_b) for s in shoot]


def _threaded(
    fn: Callable, items: list, threads: int, here: list = (), prefix: str = "chaoscam-verdict"
) -> tuple[list, list]:
    """``([fn(x) for x in items], [fn(x) for x in here])``: ``items`` on up to ``threads``
    threads (named ``prefix``), ``here`` on the calling thread meanwhile, each in order. An
    exception (a Ctrl-C in the waiting thread too) cancels the calls not yet started."""
    if threads <= 1 or len(items) <= 1:
        return [fn(x) for x in items], [fn(x) for x in here]
    # each call in a copy of this thread's context: a warning it raises is recorded where
    # this thread's are (:func:`chaoscam._warn.recorded`, the sweeps' batches)
    ctx = contextvars.copy_context()
    pool = ThreadPoolExecutor(min(threads, len(items)), thread_name_prefix=prefix)
    try:
        futures = [pool.submit(ctx.copy().run, fn, x) for x in items]
        mine = [fn(x) for x in here]
        return [f.result() for f in futures], mine
    finally:
        pool.shutdown(wait=True, cancel_futures=True)


def classify_ensemble(
    ens: Ensemble,
    params: Params | Sequence[Params],
    *,
    extend_to: float | None = EXTEND_TO,
    progress=None,
) -> Ensemble:
    """``ens`` with each member's verdict: columns ``label``, ``period`` and ``reasons``
    (why, in words; for an undetermined member, what is missing) added to ``members``.
    ``extend_to``, ``progress``: see :func:`member_verdicts`."""
    verdicts = member_verdicts(ens, params, extend_to=extend_to, progress=progress)
    members = ens.members.assign(
        label=[v.label for v in verdicts],
        period=pd.array([v.period for v in verdicts], dtype="Int64"),
        reasons=[v.reasons for v in verdicts],
    )
    return dataclasses.replace(ens, members=members)
