"""classify(solution): a verdict per member from its stroboscopic section and tangent
exponent, the model-level rules, the extension of undetermined runs and the step check
(shared/MODEL.md: a result must not change when the step is halved)."""

from __future__ import annotations

import contextvars
import dataclasses
import time
from collections.abc import Callable
from concurrent.futures import ThreadPoolExecutor
from typing import Any

import numpy as np

from .._util import ParameterError, flag, real, warn
from ..analysis import (
    Evidence,
    Verdict,
    check_options,
    classify_section,
    section_options,
    spectrum_from_jacobians,
)
from ..kernel import Status, check_stop
from ..model import realizations_identical
from ..numerics import Numerics
from ..simulation import Solution, extend, solve
from ._certificate import MODEL_ATOL
from ._rules import (
    STEP_MARGINAL,
    Context,
    apply_rules,
    extensible,
    extension_stopped,
    overflow_evidence,
)

__all__ = ["EXTEND_TO", "classify", "judge_member", "judge_points"]

EXTEND_TO = 120.0
"""Longest recorded time [s] an undetermined verdict is extended to: the labelled sets are
settled from 120 s runs, and the tangent exponent's standard error falls as the inverse
square root of the run (~0.15 1/s after 60 s on the default model)."""

_COORDS = ["theta_f", "omega_f"]


def classify(solution: Solution, *, extend_to: float | None = EXTEND_TO, check_step: bool = False,
             discard: float = 0.0, progress: Callable | None = None,
             **options: Any) -> list[Verdict]:  # fmt: skip
    """The verdict of every member of ``solution``, in the order of its ``members``.

    A member is judged from its stroboscopic section (theta_f, theta_f') at t = k 2 pi / omega
    with its tangent exponent lambda_1 +- its standard error by
    :func:`chaoscam.analysis.classify_section`, then by the model-level :data:`RULES`; an
    undetermined member is continued bit for bit, 4x its recorded time a round, until its
    verdict settles.

    Parameters
    ----------
    solution : Solution
        The runs (from :func:`chaoscam.solve`, :func:`chaoscam.simulate` or
        :func:`chaoscam.load_trajectory`). Without its Jacobians (solved without
        ``tangent=True``) the same realizations are solved again with the tangent, on the
        RK4 grid at the solution's ``dt`` (for an adaptive run a RuntimeWarning says so).
    extend_to : float or None
        Longest recorded time [s] an undetermined verdict is extended to (not one whose
        tangent overflowed, nor one whose periodic orbit is the step's); None: never.
        ``settings["extended"]`` records the time used.
    check_step : bool
        Judge the same realizations at half the step (:meth:`Numerics.refined`), with the
        same extension; a verdict that changes becomes "undetermined" with the reason
        (evidence ``step_check``: 1 unchanged, 0 changed; not a vote). Without it, the members
        whose verdict the step may decide (evidence ``step_marginal``: n-band chaos on an orbit
        unstable only at the run's step) are checked so all the same.
    discard : float
        Extra time after the transient left out of the classification [s].
    progress : callable, optional
        Called as ``progress(0, extending=m, recorded_s=r)`` before each extension round and
        ``progress(n)`` after each of its batches (a progress bar's total can grow).
    **options
        Passed to :func:`chaoscam.analysis.classify_section` (``rtol``, ``atol``,
        ``thresholds``, ``seed``, ...).

    Returns
    -------
    list of Verdict
        One per member. A member whose run did not end normally (it left the cam's reach,
        diverged) is "undetermined" with a ``status`` evidence item and the reason.
        ``settings`` records the options, the member's run, the tangent spectrum and the
        certificate's shootings.
    """
    if not isinstance(solution, Solution):
        raise TypeError(
            f"solution must be a chaoscam Solution (from chaoscam.solve or simulate), got "
            f"{type(solution).__name__}"
        )
    check_options(options, "classify")
    check_step = flag("check_step", check_step)
    discard = real("discard", discard, low=0.0, unit="s")
    if extend_to is not None:
        extend_to = real("extend_to", extend_to, low=0.0, unit="s")
    s = solution.settings
    recorded = s["duration"] - s["transient"]
    if discard >= recorded:
        raise ParameterError(
            f"discard = {discard!r} s must be in [0, {recorded:g}) s: the run records "
            f"{recorded:g} s after its transient"
        )
    how = {"check_step": check_step, "discard": discard, "extend_to": extend_to, **options}
    run = _tangent_solution(solution)
    verdicts = _settled(run, extend_to, discard, options, progress)
    marginal = {j for j, v in enumerate(verdicts) if STEP_MARGINAL in {e.name for e in v.evidence}}
    if check_step or marginal:
        only = None if check_step else marginal
        verdicts = _step_checked(run, verdicts, extend_to, discard, options, only)
    return [_with_run(v, solution, j, how) for j, v in enumerate(verdicts)]


def _with_run(v: Verdict, sol: Solution, j: int, how: dict) -> Verdict:
    """``v`` with the options and member ``j``'s run recorded in its settings."""
    row = sol.members.iloc[j]
    record = {"params": sol.models[j].to_dict(), "numerics": sol.numerics.to_dict(),
              "settings": {**sol.settings, "index": int(row["index"])},
              "status": str(row["status"])}  # fmt: skip
    return dataclasses.replace(v, settings={**v.settings, "classify": how, "trajectory": record})


def _tangent_solution(sol: Solution) -> Solution:
    """``sol`` when solved with the tangent, else the same realizations on the RK4 grid."""
    if sol.jacobians is not None:
        return sol
    num = sol.numerics
    if num.integrator != "rk4":
        warn(
            f"the verdict of this {num.describe_step()} run is taken on the same realization "
            f"on the RK4 grid at dt = {num.dt:g} s (its tangent exponent, the orbit "
            "certificate and any extension), which the adaptive tolerances do not refine: to "
            "converge the verdict, refine dt"
        )
    return _solved_again(sol, range(len(sol)), num.replace(integrator="rk4"))


def _solved_again(sol: Solution, members, num: Numerics) -> Solution:
    """The realizations of ``members`` of ``sol`` solved again at ``num`` with the tangent,
    resumable (an extension goes on from it)."""
    s = sol.settings
    return solve(
        [sol.models[j] for j in members], num,
        indices=[int(sol.members["index"].iat[j]) for j in members], seed=s["seed"],
        duration=s["duration"], transient=s["transient"], tangent=True, resumable=True,
    )  # fmt: skip


def _judge_all(sol: Solution, discard: float, options: dict) -> list[Verdict]:
    """Each member's verdict: those of a deterministic model on the solution's threads (their
    shootings run compiled, without the GIL), the others on this thread meanwhile (numpy
    under the GIL, which threads would only contend for)."""
    transient = float(sol.settings["transient"]) + discard
    rows_of = sol.sections.groupby("member").indices
    sec, empty = sol.sections, np.empty(0, dtype=np.int64)
    t, kk, xy = sec["t"].to_numpy(), sec["k"].to_numpy(), sec[_COORDS].to_numpy(dtype=float)

    def verdict(m: int) -> Verdict:
        check_stop()  # before each member: a prompt Ctrl-C
        pick = rows_of.get(m, empty)
        status = Status[sol.members["status"].iat[m]]
        noise = {"seed": int(sol.settings["seed"]), "index": int(sol.members["index"].iat[m])}
        return judge_member(status, t[pick], kk[pick], xy[pick], sol.jacobians[pick],
                            sol.models[m], sol.numerics, transient, options, **noise)  # fmt: skip

    order = list(range(len(sol)))
    shoot = [realizations_identical(sol.models[m]) for m in order]
    pooled = [m for m, s in zip(order, shoot, strict=True) if s]
    here = [m for m, s in zip(order, shoot, strict=True) if not s]
    a, b = _threaded(verdict, pooled, int(sol.settings.get("threads", 1)), here)
    done_a, done_b = iter(a), iter(b)
    return [next(done_a) if s else next(done_b) for s in shoot]


def judge_member(status, t, kk, xy, jac, p, num, transient: float, options: dict, *,
                 seed: int = 0, index: int = 0) -> Verdict:  # fmt: skip
    """One member's verdict from its status, section rows (times ``t``, indices ``kk``,
    points ``xy``) and their Jacobians, recording from ``transient`` [s]; realization
    (``seed``, ``index``) for the common-noise twins."""
    if status is not Status.OK:
        return _status_verdict(status, float(t[-1]) if len(t) else float("nan"))
    period = p.cam_period
    keep = (t >= transient - 1e-9 * period) & (kk > 0)
    if keep.sum() < 2:
        why = (f"{int(keep.sum())} section point(s) after the transient: too few to judge; "
               "run longer than the transient by several cam periods")  # fmt: skip
        return Verdict("undetermined", None, (), (why,))
    return judge_points(xy[keep], jac[keep], p, num, options, seed=seed, index=index)


def judge_points(points, jacobians, p, num, options: dict, *, seed: int = 0,
                 index: int = 0) -> Verdict:  # fmt: skip
    """The verdict on section ``points`` (theta_f, theta_f') and the Jacobians of the periods
    ending at them (one per point) of realization (``seed``, ``index``) of model ``p``: the
    section with the tangent exponent, then the model-level rules."""
    period = p.cam_period
    opts = section_options(options)
    opts.setdefault("atol", (MODEL_ATOL, MODEL_ATOL / period))
    ev = overflow_evidence(jacobians, p, num)
    if ev is not None:
        v = classify_section(points, **opts)
        return Verdict("undetermined", None, v.evidence + (ev,), (ev.detail,))
    spec = spectrum_from_jacobians(jacobians, period)
    exponent = (spec.exponent, float(spec.stderr[0]), spec.n_periods)
    v = classify_section(points, exponent=exponent, exponent_time=period, **opts)
    method = "tangent dynamics through the impacts, QR (chaoscam.lyapunov_spectrum)"
    tangent = {"exponents": [float(x) for x in spec.exponents],
               "stderr": [float(x) for x in spec.stderr], "n_periods": spec.n_periods,
               "method": method}  # fmt: skip
    extra = {"tangent": tangent}
    ctx = Context(p, num.replace(integrator="rk4"), points, extra, seed, index)
    v = apply_rules(v, ctx)
    return dataclasses.replace(v, settings={**v.settings, **extra})


def _status_verdict(st: Status, t_end: float) -> Verdict:
    label = st.label or st.name.lower()
    ended = f"the run ended with status {st.name} at t = {t_end:.6g} s: {st.message}"
    e = Evidence("status", int(st), None, ended)
    why = (f"the run did not end normally ({label}, t = {t_end:.6g} s): the motion is not "
           "described by the model after that, so it is not classified")  # fmt: skip
    return Verdict("undetermined", None, (e,), (why,), {"status": st.name})


def _settled(sol, extend_to, discard, options, progress) -> list[Verdict]:
    """The members' verdicts, the undetermined ones continued 4x longer a round (all in one
    call) until their verdicts settle or the recorded time reaches ``extend_to``."""
    verdicts = _judge_all(sol, discard, options)
    s = sol.settings
    start = s["transient"] + discard
    recorded = s["duration"] - start
    t_wall = time.perf_counter()
    pending = [j for j, v in enumerate(verdicts) if extensible(v)]
    last, at = sol, list(range(len(sol)))  # the latest run, and whose members it holds
    while pending and extend_to is not None and recorded < extend_to:
        recorded = min(extend_to, 4.0 * recorded)
        if progress is not None:
            progress(0, extending=len(pending), recorded_s=recorded)
        where = {j: i for i, j in enumerate(at)}
        # a CPU run's extension on the CPU (its bits), a GPU run's by size ("auto": a few
        # hundred members run sooner on the host's cores than on the GPU)
        backend = "cpu" if last.settings["backend"] == "cpu" else "auto"
        longer = extend(last, start + recorded, members=[where[j] for j in pending],
                        resumable=True, progress=progress, backend=backend)  # fmt: skip
        note = {"recorded_s": recorded, "wall_time_s": time.perf_counter() - t_wall,
                "why": "the verdict on the run as given was undetermined",
                "backend": longer.settings["backend"]}  # fmt: skip
        judged = _judge_all(longer, discard, options)
        for i, j in enumerate(pending):
            verdicts[j] = _after_extension(verdicts[j], judged[i], longer, i, note, recorded)
        last, at = longer, list(pending)
        pending = [j for j in pending if extensible(verdicts[j])]
    return verdicts


def _after_extension(before: Verdict, after: Verdict, longer: Solution, i, note, recorded):
    """The longer run's verdict, or, when that run ended early, the first one, saying so."""
    status = Status[longer.members["status"].iat[i]]
    if status is Status.OK:
        return dataclasses.replace(after, settings={**after.settings, "extended": note})
    t = longer.sections["t"].to_numpy()[longer.sections["member"].to_numpy() == i]
    return extension_stopped(before, status, float(t.max()) if len(t) else np.nan, recorded)


def _step_checked(sol, verdicts, extend_to, discard, options, only=None) -> list[Verdict]:
    """The verdicts (of the members in ``only``; None: all) checked against the same
    realizations at :meth:`Numerics.refined` (dt / 2; the adaptive tolerances / 32), judged the
    same way (extension included). An undetermined verdict is not re-run: no half-step verdict
    can change it."""
    fine = sol.numerics.refined()
    asked = [j for j, v in enumerate(verdicts)
             if v.label != "undetermined" and (only is None or j in only)]  # fmt: skip
    out = [_skipped(v, fine) if v.label == "undetermined" and only is None else v for v in verdicts]
    if not asked:
        return out
    fine_verdicts = _settled(_solved_again(sol, asked, fine), extend_to, discard, options, None)
    s = sol.settings
    recorded = s["duration"] - s["transient"] - discard
    for i, j in enumerate(asked):
        hv = fine_verdicts[i]
        seconds = hv.settings.get("extended", {}).get("recorded_s", recorded)
        out[j] = _compared(verdicts[j], hv, sol.numerics, fine, seconds)
    return out


def _step_record(v: Verdict, item: Evidence, record: dict) -> Verdict:
    """``v`` with the step check's evidence ``item`` and ``settings["step_check"]``."""
    record = {**record, "grid_label": v.label, "grid_period": v.period}
    settings = {**v.settings, "step_check": record}
    return dataclasses.replace(v, evidence=(*v.evidence, item), settings=settings)


def _skipped(v: Verdict, fine: Numerics) -> Verdict:
    """An undetermined verdict with evidence ``step_check`` (no value) saying why the
    realization was not re-run at ``fine``'s step."""
    why = (f"not re-run at {fine.describe_step()}: the verdict is undetermined already, "
           "which a half step cannot change")  # fmt: skip
    record = {"dt_half": fine.dt, "skipped": True}
    return _step_record(v, Evidence("step_check", None, None, why), record)


def _compared(v: Verdict, half: Verdict, coarse: Numerics, fine: Numerics, seconds) -> Verdict:
    """The grid verdict ``v`` checked against ``half``, the same realization's at ``fine``'s
    step (on ``seconds`` recorded): kept with evidence ``step_check`` = 1 when label and period
    agree, else "undetermined" with the reason and ``step_check`` = 0."""
    same = half.label == v.label and half.period == v.period
    what = f"{coarse.describe_step()}: {_described(v)}; {fine.describe_step()}: {_described(half)}"
    changed = f"{'unchanged' if same else 'changed'} when the step is halved ({what})"
    record = {"dt_half": fine.dt, "refined": fine.describe_step(), "label": half.label,
              "period": half.period, "reasons": list(half.reasons),
              "recorded_s": seconds}  # fmt: skip
    checked = _step_record(v, Evidence("step_check", int(same), None, changed), record)
    if same:
        return checked
    why = (f"halving the step changes the verdict ({what}): rerun at "
           f"{fine.refined().describe_step()} to see which holds")  # fmt: skip
    return Verdict("undetermined", None, checked.evidence, (*v.reasons, why), checked.settings)


def _described(v: Verdict) -> str:
    return v.label + (f" (period {v.period})" if v.period is not None else "")


def _threaded(fn: Callable, items: list, threads: int, here: list = ()) -> tuple[list, list]:
    """``([fn(x) for x in items], [fn(x) for x in here])``, ``items`` on up to ``threads``
    threads and ``here`` on this one meanwhile; an exception (a Ctrl-C too) cancels the rest."""
    if threads <= 1 or len(items) <= 1:
        return [fn(x) for x in items], [fn(x) for x in here]
    # each call in a copy of this thread's context: its warnings are recorded with this one's
    ctx = contextvars.copy_context()
    pool = ThreadPoolExecutor(min(threads, len(items)), thread_name_prefix="chaoscam-verdict")
    try:
        futures = [pool.submit(ctx.copy().run, fn, x) for x in items]
        mine = [fn(x) for x in here]
        return [f.result() for f in futures], mine
    finally:
        pool.shutdown(wait=True, cancel_futures=True)
