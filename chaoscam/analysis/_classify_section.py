"""Classify map iterates or Poincaré-section points into a `Verdict`."""

from __future__ import annotations

import math
from collections.abc import Sequence

from ._evidence import lyapunov_evidence, section_evidence
from ._exponent import as_exponent, exponent_evidence
from ._thresholds import Thresholds, resolve
from ._validate import as_points, check_atol, check_settings
from ._verdict import Verdict, combine

__all__ = ["classify_section"]

_DECISIVE = ("exponent", "lyapunov")


def _undetermined(v: Verdict, reason: str) -> Verdict:
    return Verdict("undetermined", None, v.evidence, (*v.reasons, reason), v.settings)


def unsupported_chaos(evidence, need: int) -> list[str] | None:
    """The names voting chaotic when they are fewer than ``need`` and none is decisive (the
    exponent's): a chaotic label they alone cannot carry; None when it is supported."""
    chaotic = [e.name for e in evidence if e.vote == "chaotic"]
    if any(name in _DECISIVE for name in chaotic) or len(chaotic) >= need:
        return None
    return chaotic


def _decide(
    v: Verdict, n: int, thr: Thresholds, zero_one: bool, given: bool, upper: float
) -> Verdict:
    """The rules `combine` does not know: two chaotic votes, a negative exponent, what to run.

    `upper` is the upper end of the exponent's confidence interval (NaN without one).
    """
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
        v = Verdict(
            v.label, None, v.evidence, (*v.reasons, "to decide: " + "; ".join(todo)), v.settings
        )
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

    Evidence gathered (each an `Evidence` in the verdict; `Thresholds` holds every number):

    * ``section_period`` — bands at a fixed lag (`section_period`): periodic with the
      smallest lag n whose n bands are each narrower than ``max(atol, period_rtol ·
      extent)``; otherwise "not_periodic", unless the points have not settled (spread of
      the second half over the first outside [stationary_low, stationary_high]: abstains).
      On a periodic section the expansion, Birkhoff and 0–1 tests abstain (only jitter is
      left).
    * ``section_rotation`` — rank-shift consistency R (`rotation_order`): R >=
      rotation_quasi votes quasiperiodic.
    * ``section_birkhoff`` — converged digits of weighted Birkhoff averages
      (`weighted_birkhoff`, N >= birkhoff_min_points): >= birkhoff_quasi_digits votes
      quasiperiodic, unless the rotation number is within birkhoff_rational_tol of p/q.
    * ``section_expansion`` — mean one-step log growth of nearest-neighbour distances
      beyond the noise floor (`neighbour_expansion`): > expansion_chaotic votes chaotic.
    * ``section_dimension`` — correlation dimension (d >= 2, N >= dimension_min_points):
      >= dimension_chaotic votes chaotic (not a curve).
    * ``section_zero_one`` — 0–1 test on the first coordinate, where valid
      (`zero_one_evidence`).
    * ``exponent`` — a largest exponent with its standard error (`exponent_evidence`):
      chaotic when its confidence interval lies above exponent_zero, not chaotic when
      below (always for -inf), else abstains with the run length that would decide.
    * ``lyapunov`` — a bare exponent per iterate: > `lyapunov_tol` chaotic, else not.

    The votes are combined by `combine`; then a chaotic label needs a chaotic exponent or
    at least min_chaotic_votes chaotic votes, and a quasiperiodic label with a negative
    exponent is a conflict (a stable periodic orbit whose period was not found). An
    "undetermined" verdict says in `reasons` what to run (longer, the tangent exponent).

    Parameters
    ----------
    points : array_like, shape (N,) or (N, d)
        Section points in time order, after the transient. N >= 8.
    lyapunov : float, optional
        Largest Lyapunov exponent per iterate of the section map, without error bar.
    lyapunov_tol : float
        |λ₁| below this counts as zero (for `lyapunov` only).
    exponent : float, (float, float), (float, float, int) or object, optional
        Largest exponent with its standard error (e.g. the model's tangent exponent; the
        forms are those of `as_exponent`). λ = -inf (a zero Floquet multiplier) is
        decisively not chaotic.
    exponent_time : float
        Multiplies λ and stderr to give them per iterate (the forcing period T for an
        exponent in 1/s and a stroboscopic section); 1 when they already are.
    angle_periods : sequence of float or None, optional
        Period of each angular coordinate (None for ordinary ones), see `embed_angles`.
    rtol : float, optional
        Overrides `Thresholds.period_rtol`.
    atol, max_period
        Passed to `section_period` (atol in the units of the embedded points).
    min_points_aperiodic : int, optional
        Overrides `Thresholds.min_points_aperiodic`.
    zero_one : bool
        Run the 0–1 test.
    seed : int
        Seed of the 0–1 test's c values.
    thresholds : Thresholds, optional
        The decision thresholds; default `Thresholds()`.

    Returns
    -------
    Verdict
        Period in iterates of the section map (forcing periods for a stroboscopic section).

    Raises
    ------
    ValueError
        NaN or infinite points, or points of the wrong shape.

    Notes
    -----
    A set of identical points is a fixed point of the section map: periodic with period 1
    (for a stroboscopic section, a response with the forcing's period). Fewer than 8
    points: "undetermined".

    Limits: with the ~90 points of a 20 s cam run a period is called reliably, but only
    the exponent separates quasiperiodic from chaotic.
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
    upper = math.nan
    if exponent is not None:
        lam, se, n_int = as_exponent(exponent, exponent_time)
        upper = lam + thr.exponent_z * se
        settings["exponent"] = dict(exponent=lam, stderr=se, n_intervals=n_int)
        ev.append(exponent_evidence(lam, se, n_int, thresholds=thr))
    if lyapunov is not None:
        ev.append(lyapunov_evidence(lyapunov, lyapunov_tol, "per iterate"))
    verdict = combine(ev, periods, reasons, settings)
    given = exponent is not None or lyapunov is not None
    return _decide(verdict, x.shape[0], thr, zero_one, given, upper)
