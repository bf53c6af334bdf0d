"""Classify map iterates or Poincaré-section points into a `Verdict`; its pass-through options."""

from __future__ import annotations

import dataclasses
import inspect
import math
from collections.abc import Sequence

from ._evidence import exponent_votes, section_evidence
from ._thresholds import Thresholds, resolve
from ._validate import as_points, check_atol, check_settings
from ._verdict import Verdict, combine

__all__ = ["SECTION_OPTIONS", "check_options", "classify_section", "section_options"]

_DECISIVE = ("exponent", "lyapunov")


def _undetermined(v: Verdict, reason: str) -> Verdict:
    return dataclasses.replace(v, label="undetermined", period=None, reasons=(*v.reasons, reason))


def unsupported_chaos(evidence, need: int) -> list[str] | None:
    """The names voting chaotic when fewer than ``need`` and none is decisive, else None."""
    chaotic = [e.name for e in evidence if e.vote == "chaotic"]
    if any(name in _DECISIVE for name in chaotic) or len(chaotic) >= need:
        return None
    return chaotic


def _decide(
    v: Verdict, n: int, thr: Thresholds, zero_one: bool, given: bool, upper: float
) -> Verdict:
    """The rules `combine` does not know; `upper` is the exponent interval's top (NaN: none)."""
    by_name = {e.name: e for e in v.evidence}
    expo = by_name.get("exponent")
    if v.label == "chaotic":
        chaotic = unsupported_chaos(v.evidence, thr.min_chaotic_votes)
        if chaotic is not None:
            v = _undetermined(
                v,
                f"only {', '.join(chaotic)} votes chaotic; {thr.min_chaotic_votes} independent "
                "methods or a positive exponent are needed",
            )
    elif v.label == "quasiperiodic" and upper < -thr.exponent_zero:
        v = _undetermined(
            v,
            "the exponent is negative (a stable periodic orbit, not a torus) but no period "
            "was found: run longer or raise max_period",
        )
    if v.label != "undetermined":
        return v
    need = [thr.min_points_aperiodic, thr.birkhoff_min_points]
    if zero_one:
        need.append(thr.zero_one_min_points)
    todo = []
    if n < max(need):
        todo.append(
            f"run ~{math.ceil(max(need) / n)}x longer ({n} section points, {max(need)} wanted)"
        )
    if not given:
        todo.append("pass the tangent exponent, exponent=(λ per iterate, stderr)")
    elif expo is not None and expo.vote is None:
        todo.append("run the exponent longer (see its evidence)")
    if todo:
        v = _undetermined(v, "to decide: " + "; ".join(todo))
    return v


def classify_section(
    points,
    *,
    lyapunov: float | None = None,
    lyapunov_tol: float = 0.02,
    exponent=None,
    exponent_time: float = 1.0,
    angle_periods: Sequence[float | None] | None = None,
    rtol: float | None = None,
    atol=None,
    max_period: int | None = None,
    min_points_aperiodic: int | None = None,
    zero_one: bool = True,
    seed: int = 0,
    thresholds: Thresholds | None = None,
) -> Verdict:
    """Classify map iterates or Poincaré-section points as periodic, quasiperiodic or chaotic.

    Evidence (numbers from `Thresholds`):

    * ``section_period`` (`section_period`): periodic with the smallest lag whose bands are
      all narrow, else "not_periodic"; abstains while the points have not settled
      (`Thresholds.stationary_low`, `stationary_high`). On a periodic section the expansion,
      Birkhoff and 0–1 tests abstain (only jitter is left).
    * ``section_rotation`` (`rotation_order`) and ``section_birkhoff`` (`weighted_birkhoff`,
      not near a rational): quasiperiodic votes.
    * ``section_expansion`` (`neighbour_expansion`) and ``section_dimension``
      (`correlation_dimension`, d >= 2): chaotic votes.
    * ``section_zero_one``: `zero_one_evidence` on the first coordinate.
    * ``exponent`` (`exponent_evidence`), and ``lyapunov``: > `lyapunov_tol` chaotic, else not.

    A scalar (shape (N,)) has its period and expansion judged on its 3-delay vectors, its
    rotation by value or by delay pairs (`delays`): a torus seen through cos θ stays a curve.

    The votes are combined by `combine`; then a chaotic label needs a chaotic exponent or
    `Thresholds.min_chaotic_votes`, and a quasiperiodic one with a negative exponent (a
    period not found) is undetermined. An "undetermined" verdict says in `reasons` what to run.

    Raises ValueError on NaN or infinite points, or points of the wrong shape. Limits: on
    the ~90 points of a 20 s cam run a period is called reliably, but only the exponent
    separates quasiperiodic from chaotic.

    Parameters
    ----------
    points : array_like, shape (N,) or (N, d)
        Section points in time order, after the transient. N >= 8, else "undetermined".
    lyapunov, lyapunov_tol : float
        A largest exponent per iterate without error bar (optional), and ``|λ₁|`` counted as zero.
    exponent : float, (float, float), (float, float, int) or object, optional
        Largest exponent with its standard error (forms of `as_exponent`), e.g. the tangent's.
    exponent_time : float
        Factor making λ and stderr per iterate (the forcing period T [s] for λ in 1/s).
    angle_periods : sequence of float or None, optional
        Period of each angular coordinate (None for ordinary ones), see `embed_angles`.
    rtol, min_points_aperiodic : optional
        Override `Thresholds.period_rtol` and `Thresholds.min_points_aperiodic`.
    atol, max_period
        Passed to `section_period` (atol in the units of the embedded points).
    zero_one, seed : bool, int
        Run the 0–1 test, with this seed for its c values.
    thresholds : Thresholds, optional
        The decision thresholds; default `Thresholds()`.

    Returns
    -------
    Verdict
        Period in iterates of the section map (forcing periods for a stroboscopic section);
        identical points are period 1 (a fixed point of the map).
    """
    x = as_points(points)
    check_atol("classify_section", atol, x.shape[1])
    check_settings(
        "classify_section",
        lyapunov=(lyapunov, "number?"),
        lyapunov_tol=(lyapunov_tol, "real>=0"),
        exponent_time=(exponent_time, "real>0"),
        max_period=(max_period, "int>=1?"),
        min_points_aperiodic=(min_points_aperiodic, "int>=1?"),
        seed=(seed, "int>=0"),
    )
    thr = resolve(thresholds, rtol, min_points_aperiodic)
    settings = dict(
        rtol=thr.period_rtol,
        atol=atol,
        max_period=max_period,
        lyapunov_tol=lyapunov_tol,
        exponent_time=exponent_time,
        angle_periods=None if angle_periods is None else list(angle_periods),
        min_points_aperiodic=thr.min_points_aperiodic,
        zero_one=zero_one,
        seed=seed,
        thresholds=thr.to_dict(),
    )
    ev, periods, reasons = section_evidence(x, thr, angle_periods=angle_periods, atol=atol,
                                            max_period=max_period, zero_one=zero_one,
                                            seed=seed)  # fmt: skip
    votes, expo = exponent_votes(thr, exponent, exponent_time, lyapunov, lyapunov_tol,
                                 "per iterate")  # fmt: skip
    if expo is not None:
        settings["exponent"] = expo
    upper = math.nan if expo is None else expo["exponent"] + thr.exponent_z * expo["stderr"]
    verdict = combine(ev + votes, periods, reasons, settings)
    given = exponent is not None or lyapunov is not None
    return _decide(verdict, x.shape[0], thr, zero_one, given, upper)


_BUILT_BY_THE_CALLER = {"points", "lyapunov", "lyapunov_tol", "exponent", "exponent_time"}

SECTION_OPTIONS = frozenset(inspect.signature(classify_section).parameters) - _BUILT_BY_THE_CALLER
"""The settings a model verdict (:func:`chaoscam.classify`) may pass to `classify_section`."""


def check_options(options: dict, caller: str) -> None:
    """TypeError for an option `classify_section` does not take here; ValueError for a bad atol."""
    check_atol(caller, options.get("atol"), 2)
    unknown = sorted(set(options) - SECTION_OPTIONS)
    if unknown:
        raise TypeError(
            f"{caller} got an unknown option {unknown[0]!r}; the options are "
            f"classify_section's: {', '.join(sorted(SECTION_OPTIONS))}"
        )


def section_options(options: dict) -> dict:
    """``options`` less those :func:`classify_section` does not take."""
    return {k: v for k, v in options.items() if k in SECTION_OPTIONS}
