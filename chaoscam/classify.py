"""classify_trajectory(traj) -> Verdict: periodic, quasiperiodic or chaotic, for the model.

The glue between a simulated :class:`~chaoscam._simulate.Trajectory` and the array-only
analysis layer (:mod:`chaoscam.analysis`): it picks the observables (the stroboscopic
section (θ_f, θ̇_f) once per cam period and the sampled θ_f(t)), the forcing period
T = 2 pi / omega, and optionally adds the model's own Lyapunov exponent
(:func:`chaoscam.lyapunov.lyapunov_model`) and a step-halving check.
"""

from __future__ import annotations

import dataclasses
import math
import re
import time
from typing import Any

import numpy as np

from . import _step_check as step_check
from ._checks import flag, of_type, real
from ._extend import extend_trajectory
from ._model_rules import (
    MODEL_ATOL,
    extensible,
    extension_stopped,
    overflow_evidence,
    with_model_evidence,
)
from ._simulate import Trajectory, simulate

# the step check's re-simulation under this module's name, which tests replace
from ._step_check import resimulate_half_step as _resimulate_half_step
from ._trajectory_io import load_trajectory
from ._warn import warn
from .analysis import Evidence, Verdict, classify_section, classify_signal
from .analysis._options import check_options, section_options
from .integrate import Status
from .model import ParameterError, Params
from .tangent import spectrum_from_jacobians

__all__ = ["classify_file", "classify_section_run", "classify_trajectory", "load_trajectory"]

_SECTION_COORDS = ["theta_f", "omega_f"]


def _with_settings(v: Verdict, **extra: Any) -> Verdict:
    return dataclasses.replace(v, settings={**v.settings, **extra})


def _rename_lyapunov(v: Verdict, detail_prefix: str, exponent: float) -> Verdict:
    """Call the analysis layer's "lyapunov" evidence "lyapunov_model" (its source).

    Its value is the exponent in 1/s in both modes (the section-only classifier was given
    it per iterate, λ₁ T; its detail says so).
    """
    ev = tuple(
        dataclasses.replace(
            e,
            name="lyapunov_model",
            value=exponent if e.value is not None else None,
            detail=detail_prefix + e.detail,
        )
        if e.name == "lyapunov"
        else e
        for e in v.evidence
    )
    reasons = tuple(re.sub(r"(?<![\w])lyapunov: ", "lyapunov_model: ", r) for r in v.reasons)
    return dataclasses.replace(v, evidence=ev, reasons=reasons)


def _status_verdict(traj: Trajectory, settings: dict) -> Verdict:
    st = traj.status
    label = st.label or st.name.lower()
    t_end = traj.final_state[0]
    e = Evidence(
        "status",
        int(st),
        None,
        f"the run ended with status {st.name} at t = {t_end:.6g} s: {st.message}",
    )
    return Verdict(
        "undetermined",
        None,
        (e,),
        (
            f"the run did not end normally ({label}, t = {t_end:.6g} s): the motion is not "
            "described by the model after that, so it is not classified",
        ),
        settings,
    )


def _evidence_verdict(
    traj: Trajectory, discard: float, lyap: float | None, options: dict
) -> Verdict:
    """The analysis-layer verdict from the section (and the series when kept)."""
    period = traj.params.cam_period
    t0 = traj.settings["transient"] + discard
    sec = traj.section
    points = sec.loc[sec["t"] >= t0 - 1e-9 * period, _SECTION_COORDS].to_numpy(dtype=float)
    if not len(points):  # the analysis layer refuses an empty section
        why = f"no section point after t = {t0:g} s (cam period {period:.4g} s): simulate longer"
        return Verdict("undetermined", None, (), (why,), {"discard": discard})
    opts = dict(options)
    opts.setdefault("atol", (MODEL_ATOL, MODEL_ATOL / period))
    if traj.series is None:
        tol = opts.pop("lyapunov_tol", None)
        if tol is not None:
            opts["lyapunov_tol"] = tol * period  # 1/s -> per iterate
        per_iter = None if lyap is None else lyap * period
        return classify_section(points, lyapunov=per_iter, **opts)
    ser = traj.series
    x = ser.loc[ser["t"] >= t0 - 1e-9 * period, "theta_f"].to_numpy(dtype=float)
    dt = float(traj.settings["output_dt"])
    return classify_signal(x, dt, period, section=points, lyapunov=lyap, **opts)


def _model_options(options: dict, period: float) -> dict:
    """Analysis options for the model's section: the absolute band tolerance by default."""
    opts = {k_: v_ for k_, v_ in options.items() if k_ not in ("lyapunov_tol",)}
    opts.setdefault("atol", (MODEL_ATOL, MODEL_ATOL / period))
    return opts


def classify_section_run(points, jacobians, params: Params, **options: Any) -> Verdict:
    """The model's verdict from a run's section points and its stroboscopic Jacobians.

    What :func:`classify_trajectory` does for a run kept without its series, for callers
    that hold only arrays (ensembles): :func:`chaoscam.analysis.classify_section` with the
    tangent exponent (λ₁ ± stderr by QR on ``jacobians``, one per point, each over the period
    ending at that point) and the model's absolute band tolerance, then the model-level
    rules (n-band chaos, the periodic-orbit certificate for the deterministic model).
    ``settings["tangent"]`` (and ``settings["periodic_orbit"]``) record the numbers.
    """
    v, extra = _section_verdict(
        np.asarray(points, dtype=float),
        np.asarray(jacobians, dtype=float),
        params.replace(integrator="rk4"),
        options,
    )
    return _with_settings(v, **extra)


def _section_verdict(points, jacobians, p: Params, options: dict) -> tuple[Verdict, dict]:
    """Section with the tangent exponent, then the model-level rules; (verdict, settings).
    A series run's signal options have no use here (its extension, an overflow)."""
    period = p.cam_period
    options = section_options(options)
    if (overflow := _overflow_verdict(points, jacobians, p, options)) is not None:
        return overflow, {}
    spec = spectrum_from_jacobians(jacobians, period)
    v = classify_section(
        points,
        exponent=_exponent_of(spec),
        exponent_time=period,
        **_model_options(options, period),
    )
    return with_model_evidence(v, p, points, spec)


def _overflow_verdict(points, jacobians, p: Params, options: dict) -> Verdict | None:
    """Undetermined from the section alone (``options``: classify_section's), with the
    reason, when the tangent overflowed (:func:`chaoscam._model_rules.overflow_evidence`);
    else None."""
    ev = overflow_evidence(jacobians, p)
    if ev is None:
        return None
    v = classify_section(points, **_model_options(options, p.cam_period))
    # Its reasons alone: the section's own ("run longer", "pass the exponent") do not apply.
    return Verdict("undetermined", None, v.evidence + (ev,), (ev.detail,))


def _exponent_of(spec) -> tuple[float, float, int]:
    return (spec.exponent, float(spec.stderr[0]), spec.n_periods)


def _tangent_run(traj: Trajectory) -> Trajectory:
    """The run whose Jacobians a verdict reads: ``traj`` when simulated with the tangent,
    else the same realization on the RK4 grid with it, kept resumable (so that an extension
    goes on from it, :func:`chaoscam.extend_trajectory`)."""
    if traj.jacobians is not None:
        return traj
    return _rk4_tangent_run(traj, traj.settings["duration"])


def _rk4_tangent_run(traj: Trajectory, duration: float) -> Trajectory:
    """The realization of ``traj`` simulated ``duration`` seconds on the RK4 grid (where the
    tangent lives) with the tangent, without series, kept resumable. For a run of the
    adaptive path a RuntimeWarning says so: the verdict then rests on the grid's ``dt``,
    which the adaptive tolerances do not refine."""
    s = traj.settings
    if traj.params.integrator != "rk4":
        warn(
            f"the verdict of this {traj.params.describe_step()} run is taken on the same "
            f"realization on the RK4 grid at dt = {traj.params.dt:g} s (its tangent exponent "
            "unless the run carried one, the orbit certificate, any extension, and the section "
            "unless the run kept a series), which the adaptive tolerances do not refine: to "
            "converge the verdict, refine dt "
            '(docs/findings.md, "The figures\' step")',
        )
    return simulate(
        traj.params.replace(integrator="rk4"),
        duration=duration,
        transient=s["transient"],
        seed=s["seed"],
        index=s["index"],
        series=False,
        tangent=True,
        resumable=True,
    )


def _tangent_verdict(
    traj: Trajectory, discard: float, options: dict, tr: Trajectory | None = None
) -> tuple[Verdict, dict]:
    """The verdict from the section (and series), the tangent exponent of ``tr`` (default
    :func:`_tangent_run`) and, for a periodic section of the deterministic model, a
    certified periodic orbit (:mod:`chaoscam.tangent`)."""
    p = traj.params.replace(integrator="rk4")
    s = traj.settings
    tr = _tangent_run(traj) if tr is None else tr
    period = p.cam_period
    t0 = s["transient"] + discard
    sec = tr.section
    keep = ((sec["t"] >= t0 - 1e-9 * period) & (sec["k"] > 0)).to_numpy()
    if not keep.any():
        # No cam period recorded after the transient: no Jacobian, so no exponent; the
        # other methods abstain on so little data and say so.
        v = _evidence_verdict(traj, discard, None, options)
        reason = (
            f"no cam period (tau = {period:.4g} s) recorded after t = {t0:g} s, so no "
            "tangent exponent: simulate longer"
        )
        return dataclasses.replace(v, reasons=v.reasons + (reason,)), {}
    points = sec.loc[keep, _SECTION_COORDS].to_numpy(dtype=float)
    if traj.series is None or not np.isfinite(tr.jacobians[keep]).all():
        return _section_verdict(points, tr.jacobians[keep], p, options)
    # the run's own series and section, with the exponent of the same realization
    spec = spectrum_from_jacobians(tr.jacobians[keep], period)
    opts = _model_options(options, period)
    ser = traj.series
    x = ser.loc[ser["t"] >= t0 - 1e-9 * period, "theta_f"].to_numpy(dtype=float)
    own = traj.section
    own_points = own.loc[own["t"] >= t0 - 1e-9 * period, _SECTION_COORDS].to_numpy(float)
    v = classify_signal(
        x,
        float(s["output_dt"]),
        period,
        section=own_points,
        exponent=_exponent_of(spec),
        exponent_time=period,
        **opts,
    )
    return with_model_evidence(v, p, points, spec)


EXTEND_TO = 120.0
"""Longest recorded time [s] an undetermined verdict is extended to (classify_trajectory):
the labelled set is settled from 120 s runs, and the tangent exponent's standard error falls
as the inverse square root of the run (measured ~0.15 1/s after 60 s on the default)."""


def _extended(tr, verdict, extra, discard, options, cap) -> tuple[Verdict, dict]:
    """Run the realization 4x longer (section and tangent only) until the verdict settles
    or the recorded time reaches ``cap``: continued from the tangent run ``tr`` (and each
    round from the last, :func:`chaoscam.extend_trajectory`) when that is an RK4 run, else
    simulated on the RK4 grid once and continued from there."""
    s = tr.settings
    start = s["transient"] + discard
    recorded = s["duration"] - start
    t_wall = time.perf_counter()
    base = tr if tr.params.integrator == "rk4" else None
    while extensible(verdict) and recorded < cap:
        recorded = min(cap, 4.0 * recorded)
        if base is None:
            longer = _rk4_tangent_run(tr, start + recorded)
        else:
            longer = extend_trajectory(base, start + recorded, series=False)
        base = longer
        if longer.status is not Status.OK:  # no longer window: say so, keep the verdict
            at = float(longer.section["t"].iloc[-1]) if len(longer.section) else math.nan
            return extension_stopped(verdict, longer.status, at, recorded), extra
        verdict, extra = _tangent_verdict(longer, discard, options)
        extra["extended"] = {
            "recorded_s": recorded,
            "continued_from_s": longer.settings.get("continued_from_s"),
            "wall_time_s": time.perf_counter() - t_wall,
            "why": "the verdict on the run as given was undetermined",
        }
    return verdict, extra


def classify_trajectory(
    traj: Trajectory,
    *,
    tangent: bool = True,
    lyapunov: bool = False,
    check_step: bool = False,
    discard: float = 0.0,
    extend_to: float | None = EXTEND_TO,
    **options: Any,
) -> Verdict:
    """Classify a simulated trajectory from its stroboscopic section and its θ_f(t) series.

    The evidence is that of :func:`chaoscam.analysis.classify_signal` applied to the
    sampled θ_f(t) (``traj.series``), with the stroboscopic section (θ_f, θ̇_f) at
    t = k 2 pi / omega as section points and the cam period T = 2 pi / omega as forcing
    period (MODEL.md, "Poincaré sections"). A trajectory simulated without series
    (``series=False``) is classified from its section alone
    (:func:`chaoscam.analysis.classify_section`), with the tangent exponent (``tangent``)
    separating quasiperiodic from chaotic; both ask the same of a chaotic call.

    Parameters
    ----------
    traj : Trajectory
        The run, after its transient (``simulate(..., transient=...)``).
    tangent : bool
        Default True: the verdict comes from the section with the tangent exponent of the
        model through its impacts (:func:`chaoscam.tangent.lyapunov_spectrum`: λ₁ with its
        standard error; taken from ``traj.jacobians`` or from a re-simulation with
        ``tangent=True``, ~1.1x a simulation, on the RK4 grid at ``params.dt``: for a run of
        the adaptive path without its tangent, a RuntimeWarning says so; the orbit
        certificate and any extension are always on that grid) and, when the section
        is periodic and the model deterministic, a periodic orbit found by Newton shooting:
        converged, attracting (|μ| < 1) and with the run on it, it is recorded as the
        decisive evidence ``periodic_orbit``; a converged *unstable* orbit makes the
        verdict "undetermined". ``settings["tangent"]`` and ``settings["periodic_orbit"]``
        record the numbers. False: the series-based evidence below, which has no exponent
        through the impacts and so cannot tell n narrow chaotic bands from a period n
        (measured: l_lambda = 11 mm, sigma = 1.5 mm, seed 1, 20 s: periodic 8 with
        tangent=False; the tangent path finds lambda_1 = +0.69 +- 0.05 per iterate and
        calls the same run 8-band chaos).
    lyapunov : bool
        Instead of the tangent verdict (``tangent`` is then not used: no tangent exponent,
        no periodic-orbit certificate, no extension), the series-based evidence with the
        model's largest Lyapunov exponent from two trajectories through the impacts
        (:func:`chaoscam.lyapunov.lyapunov_model`, same params, duration, transient, seed,
        index; about twice the cost of the simulation), as evidence ``lyapunov_model``:
        λ₁ > `lyapunov_tol` (default 0.02 / T) votes chaotic, else not chaotic. Kept to
        compare the two exponents. A NaN exponent (a companion that failed) abstains with
        its reason. Weak for contact-dominated responses, where the estimate depends on the
        separation d0 (see its Limits): a period-1 orbit that chatters onto the cam every period
        (omega = 22 rad/s) gets λ₁ ≈ +0.4 1/s, and the verdict is then "undetermined".
    check_step : bool
        Re-simulate the same realization (params, duration, transient, seed, index, output
        step) with dt / 2 (adaptive integrator: tolerances / 32, see ``Params.refined``) and
        classify it the same way (Lyapunov included when asked; on the tangent path with the
        same extension to ``extend_to`` when undetermined); if
        the label or the period changes, the verdict becomes "undetermined" with that reason
        (MODEL.md: a result must not change when the step is halved). Evidence
        ``step_check`` (value 1 unchanged, 0 changed; the half-step verdict in its detail)
        does not vote. An undetermined verdict is not re-run (a half step cannot change
        it): ``step_check`` then has no value and says so.
    discard : float
        Extra time after the run's transient left out of the classification [s].
    extend_to : float or None
        With ``tangent``: when the verdict is "undetermined" (but not for a tangent that
        overflowed, evidence ``tangent_overflow``: a longer run overflows too), the same
        realization is run longer (4x the recorded time each round, section and tangent
        only, at most ``extend_to`` seconds recorded; a realization's prefix does not depend on its
        duration) and classified again, until it settles; ``settings["extended"]`` records
        the recorded time and wall time used. A round goes on from the run before it
        (:func:`chaoscam.extend_trajectory`) when that run was kept resumable (the sweeps'
        runs are; one simulated here for its tangent is), else it runs from t = 0: the
        same bits either way. None: never extend.
    **options
        Passed to the analysis classifier (``rtol``, ``atol``, ``seed``, ...; ``lyapunov_tol``
        [1/s] with ``lyapunov`` only: the tangent exponent is judged by its interval).

    Returns
    -------
    Verdict
        Period in cam periods for "periodic". A run whose status is not OK (left the cam's
        reach, diverged) is "undetermined" with a ``status`` evidence item (value: the
        integer status code) and the reason; it is not classified. ``settings`` records the
        trajectory's provenance and these options.
    """
    of_type("traj", traj, Trajectory, "from chaoscam.simulate or load_trajectory")
    tangent, lyapunov = flag("tangent", tangent), flag("lyapunov", lyapunov)
    check_step = flag("check_step", check_step)
    check_options(
        options,
        "classify_trajectory",
        series=traj.series is not None,
        tangent=tangent and not lyapunov,
    )
    discard = real("discard", discard, low=0.0, unit="s")
    if extend_to is not None:  # None: never extend
        extend_to = real("extend_to", extend_to, low=0.0, unit="s")
    recorded = traj.settings["duration"] - traj.settings["transient"]
    if discard >= recorded:
        raise ParameterError(
            f"discard = {discard!r} s must be in [0, {recorded:g}) s: the run records "
            f"{recorded:g} s after its transient"
        )
    how = dict(tangent=tangent, lyapunov=lyapunov, check_step=check_step, discard=discard)
    how["extend_to"] = extend_to if tangent and not lyapunov else None  # None: not extended
    settings = {
        "classify": {**how, **options},
        "trajectory": {
            "params": traj.params.to_dict(),
            "settings": dict(traj.settings),
            "status": traj.status.name,
        },
    }
    if traj.status is not Status.OK:
        return _status_verdict(traj, settings)

    verdict, extra = _classified(traj, lyapunov, discard, options, tangent, extend_to)
    verdict = _with_settings(verdict, **settings, **extra)
    if not check_step:
        return verdict
    fine = traj.params.refined()
    if verdict.label == "undetermined":
        return step_check.skipped(verdict, fine)
    hv, recorded = _half_step_verdict(traj, lyapunov, discard, options, tangent, extend_to)
    return step_check.compared(verdict, hv, traj.params, fine, half_recorded_s=recorded)


def _verdict_of(
    traj: Trajectory,
    lyapunov: bool,
    discard: float,
    options: dict,
    tangent: bool = False,
    tr: Trajectory | None = None,
) -> tuple[Verdict, dict]:
    if tangent and not lyapunov:
        return _tangent_verdict(traj, discard, options, tr)
    if not lyapunov:
        return _evidence_verdict(traj, discard, None, options), {}
    from .lyapunov import lyapunov_model

    s = traj.settings
    res = lyapunov_model(
        traj.params,
        duration=s["duration"],
        transient=s["transient"] + discard,
        seed=s["seed"],
        index=s["index"],
    )
    extra = {
        "lyapunov_model": dict(
            res.settings,
            exponent=res.exponent,
            stderr=res.stderr,
            n_intervals=res.n_intervals,
            message=res.message,
        )
    }
    if not res.ok:
        v = _evidence_verdict(traj, discard, None, options)
        e = Evidence("lyapunov_model", None, None, f"not computed: {res.message}")
        return dataclasses.replace(v, evidence=v.evidence + (e,)), extra
    prefix = (
        f"model equations (two-trajectory Benettin through the impacts, "
        f"{res.n_intervals} intervals): λ₁ = {res.exponent:.4g} ± {res.stderr:.2g} 1/s"
        + (f" ({res.message})" if res.message else "")
        + "; "
    )
    v = _evidence_verdict(traj, discard, res.exponent, options)
    return _rename_lyapunov(v, prefix, res.exponent), extra


def _classified(traj, lyapunov, discard, options, tangent, extend_to) -> tuple[Verdict, dict]:
    """The verdict on a run that ended normally, and its settings: the tangent verdict
    (extended up to ``extend_to`` while undetermined) or the series evidence."""
    tr = _tangent_run(traj) if tangent and not lyapunov else None
    verdict, extra = _verdict_of(traj, lyapunov, discard, options, tangent, tr)
    if tr is not None and extend_to and extensible(verdict):
        verdict, extra = _extended(tr, verdict, extra, discard, options, float(extend_to))
    return verdict, extra


def _half_step_verdict(
    traj, lyapunov, discard, options, tangent, extend_to
) -> tuple[Verdict, float]:
    """The verdict on ``traj``'s realization at half the step, reached the way the run's own
    was: the same evidence and, on the tangent path, the same extension of an undetermined
    verdict up to ``extend_to`` (else a grid verdict settled on an extended run would be
    compared with an unextended, undetermined one); with the seconds recorded behind it."""
    half = _resimulate_half_step(traj, tangent=tangent and not lyapunov)
    recorded = half.settings["duration"] - half.settings["transient"] - discard
    if half.status is not Status.OK:
        return _status_verdict(half, {}), recorded
    hv, extra = _classified(half, lyapunov, discard, options, tangent, extend_to)
    return hv, extra.get("extended", {}).get("recorded_s", recorded)


def classify_file(
    path, *, lyapunov: bool = False, check_step: bool = False, **options: Any
) -> Verdict:
    """Classify a trajectory Parquet file (``Trajectory.to_parquet``): see
    :func:`load_trajectory` and :func:`classify_trajectory`."""
    return classify_trajectory(
        load_trajectory(path), lyapunov=lyapunov, check_step=check_step, **options
    )
