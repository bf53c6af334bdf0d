"""The model-level rules on top of the analysis layer's verdict (used by chaoscam.classify).

The analysis layer (:mod:`chaoscam.analysis`) judges arrays; these rules add what only the
model knows: a periodic section of the deterministic model is certified by a periodic orbit
found by Newton shooting (:mod:`chaoscam._certify`), n narrow bands with a positive tangent
exponent and no attracting orbit inside are n-band chaos, and a periodic section is called
periodic only with a certificate or a contracting exponent (a random line length has no orbit
to certify).
"""

from __future__ import annotations

import dataclasses

import numpy as np

from ._certify import MODEL_ATOL, ORBIT_REFINE, REFINE_ITER, certify
from .analysis import Evidence, Verdict, section_period
from .analysis._classify_section import unsupported_chaos
from .model import Params, realizations_identical

__all__ = ["BAND_RTOL", "MODEL_ATOL", "ORBIT_REFINE", "REFINE_ITER", "with_model_evidence"]

BAND_RTOL = 0.05
"""Bands narrower than this fraction of the section's extent count as n narrow bands for the
n-band chaos rule, where the tangent exponent is positive beyond its interval but the section
is not periodic to its 3e-3 tolerance (bands wider, or band centres closer than it) and the
0-1 test votes regular. The 0-1 test sees a chaotic component of relative size w on top of a
periodic sequence only once its mean-square displacement (~w² N) outgrows the periodic part's
(~1): on N ≲ 1/w² samples it reads regular. Measured at (ω, ξ) = (42.5, 0.15): 4 bands of
1.4e-2 (8 of 6.7e-4) of the extent, λ₁ = 0.317 ± 0.014 per iterate over 812 periods, K =
-0.008 on the 812 points and -0.2 on one band's 101; 600 s runs at dt and dt/2 show 8-band
chaos."""


def with_model_evidence(v: Verdict, p: Params, points, spec) -> tuple[Verdict, dict]:
    """The model-level rules on top of the analysis verdict: n-band chaos, and the
    periodic-orbit certificate of a periodic section of the deterministic model."""
    extra = {
        "tangent": {
            "exponents": [float(x) for x in spec.exponents],
            "stderr": [float(x) for x in spec.stderr],
            "n_periods": spec.n_periods,
            "method": "tangent dynamics through the impacts, QR (chaoscam.tangent)",
        }
    }
    votes = {e.name: e.vote for e in v.evidence}
    if v.label == "quasiperiodic" and votes.get("exponent") != "not_chaotic":
        # A torus has lambda_1 = 0: without an exponent that confirms it (zero within its
        # interval), a quasiperiodic spectrum of a short window is not enough.
        reason = (
            "quasiperiodic evidence, but the tangent exponent does not confirm lambda_1 = 0 "
            "within its interval: run longer"
        )
        v = Verdict("undetermined", None, v.evidence, v.reasons + (reason,), v.settings)
    need = int(v.settings.get("thresholds", {}).get("min_chaotic_votes", 2))
    chaotic = unsupported_chaos(v.evidence, need) if v.label == "chaotic" else None
    if chaotic is not None:
        # The section-only path's rule (analysis._classify_section._decide) on the series
        # path too, so that one run gets one label with or without its series: a broadband
        # spectrum of 1.5 s with 11 section points called omega = 45, xi = 0.2 chaotic,
        # where the extended run is periodic 11.
        reason = (
            f"only {', '.join(chaotic)} votes chaotic; {need} independent methods or a "
            "positive tangent exponent are needed: run longer"
        )
        v = Verdict("undetermined", None, v.evidence, v.reasons + (reason,), v.settings)
    if (
        v.label == "periodic"
        and not realizations_identical(p)
        and votes.get("exponent") not in ("not_chaotic", "periodic")
    ):
        # A random line length has no periodic orbit to shoot for: its periodic response is
        # a random attractor near one, which contracts (lambda_1 < 0). Without a
        # certificate, n narrow bands are periodic only when the exponent confirms it;
        # measured: 8 bands of 1e-3 rad at sigma = 1.5 mm with lambda_1 = 0.53 +- 0.22 per
        # iterate after 46 periods, chaotic on a longer run.
        reason = (
            f"the section repeats with period {v.period} to the band tolerance, but the line "
            "length is random (no periodic orbit to certify) and the tangent exponent does "
            "not confirm lambda_1 < 0 within its interval: run longer"
        )
        v = Verdict("undetermined", None, v.evidence, v.reasons + (reason,), v.settings)
    banded = _banded_period(v, p, points)
    if v.label == "undetermined" and banded is not None:
        return _banded_verdict(v, p, points, banded, extra)
    candidate = v.period if v.label == "periodic" else _disputed_period(v)
    if candidate is None or not realizations_identical(p):
        return v, extra
    cert = certify(p, points, int(candidate), extra)
    if cert.certified:
        e = Evidence("periodic_orbit", cert.period, "periodic", "certified: " + cert.detail)
        if v.label == "periodic" and cert.period == v.period:
            return dataclasses.replace(v, evidence=v.evidence + (e,)), extra
        # The certificate decides what the section and the exponent left open: an attracting
        # orbit that the run converges to outweighs a spectral or 0-1 vote on a short series,
        # and its period (2n after a flip) the section's n bands that hid it.
        return Verdict("periodic", cert.period, v.evidence + (e,), (), v.settings), extra
    why = {"off orbit": "the run is not on it", "period differs": "its least period differs"}
    why = why.get(cert.status, cert.status)
    e = Evidence("periodic_orbit", cert.orbit.period, None, f"not certified ({why}): {cert.detail}")
    if cert.status == "step-dependent":
        return _step_dependent(v, p, cert, e), extra
    if cert.status in ("unstable", "not converged") and cert.orbit.converged:
        reason = (
            f"the section looks periodic but the orbit found is unstable ({cert.detail}): run "
            "longer, to see whether the exponent is positive (chaos near an unstable orbit)"
        )
        return Verdict(
            "undetermined", None, v.evidence + (e,), v.reasons + (reason,), v.settings
        ), extra
    if v.label == "periodic" and votes.get("exponent") != "not_chaotic":
        # Neither certified (on the run's grid or a refined one) nor contracting: narrow
        # bands after a short window may still be n-band chaos, which a longer run shows.
        reason = (
            f"the section repeats with period {v.period} but no attracting orbit is "
            f"certified ({why}) and the tangent exponent does not confirm lambda_1 < 0: "
            "run longer"
        )
        return Verdict(
            "undetermined", None, v.evidence + (e,), v.reasons + (reason,), v.settings
        ), extra
    return dataclasses.replace(v, evidence=v.evidence + (e,)), extra


def _disputed_period(v: Verdict) -> int | None:
    """n when an undetermined verdict's section is periodic (n) and the exponent does not say
    chaotic: the case a periodic-orbit certificate settles."""
    votes = {e.name: e for e in v.evidence}
    sp, ex = votes.get("section_period"), votes.get("exponent")
    if v.label != "undetermined" or sp is None or sp.vote != "periodic":
        return None
    if ex is not None and ex.vote == "chaotic":
        return None
    return int(sp.value)


def _banded_period(v: Verdict, p: Params, points) -> int | None:
    """n when the tangent exponent is positive beyond its confidence interval while the
    section keeps n narrow bands: periodic to the band tolerance, or (for an undetermined
    verdict) n bands each narrower than ``BAND_RTOL`` of the extent; else None."""
    votes = {e.name: e for e in v.evidence}
    sp, ex = votes.get("section_period"), votes.get("exponent")
    if sp is None or ex is None or ex.vote != "chaotic":
        return None
    if sp.vote == "periodic":
        return int(sp.value)
    if v.label != "undetermined":
        return None
    atol = (MODEL_ATOL, MODEL_ATOL / p.cam_period)
    bands = section_period(points, rtol=BAND_RTOL, atol=atol, allow_transient=False, distinct=False)
    return bands.period


def _banded_verdict(v: Verdict, p: Params, points, n: int, extra: dict):
    """Resolve "n narrow bands but λ₁ > 0": chaotic when no attracting period-n orbit lies in
    the bands that the run converges to (shooting: unstable, not converged, or attracting but
    not approached by the run; or a random model, which has none), periodic when the orbit is
    attracting only at refined steps (the grid's exponent is then its error in the chattering
    phases), still undetermined when the grid certifies one (a genuine conflict) or refined
    steps disagree."""
    if realizations_identical(p):
        # No flip doubling here: shooting for 2n and 4n in the default model's 8 chaotic
        # bands doubled the quick report's Fig. 4 time (10 -> 26 s). Only a section that
        # itself repeats with period 2n to the band tolerance sends the shooting to 2n.
        cert = certify(p, points, n, extra, flips_double=False)
        detail = f"from the bands: {cert.detail}"
        if cert.certified and not cert.refined:
            e = Evidence("periodic_orbit", cert.period, "periodic", "certified " + detail)
            return dataclasses.replace(
                v,
                evidence=v.evidence + (e,),
                reasons=v.reasons
                + (
                    "an attracting orbit is certified inside the bands, "
                    "yet the tangent exponent is positive",
                ),
            ), extra
        if cert.certified:
            e = Evidence("periodic_orbit", cert.period, "periodic", detail)
            where = (
                "finite kicks return to it at the run's step and at half of it"
                if cert.kicked
                else "it is attracting at every refined step"
            )
            note = (
                f"the tangent exponent on the run's grid is positive, but the run lies on the "
                f"period-{cert.period} orbit in the bands and {where}: the exponent's sign is "
                "the grid's error in the chattering phases"
            )
            return Verdict("periodic", cert.period, v.evidence + (e,), (note,), v.settings), extra
        if cert.status == "step-dependent":
            e = Evidence("periodic_orbit", n, None, detail)
            return _step_dependent(v, p, cert, e), extra
        if cert.status == "mixed":
            e = Evidence("periodic_orbit", n, None, detail)
            reason = (
                f"the period-{n} orbit in the bands changes stability with the step "
                f"({cert.detail}): run with dt = {p.dt / ORBIT_REFINE[-1]:.3g} s"
            )
            return Verdict(
                "undetermined", None, v.evidence + (e,), v.reasons + (reason,), v.settings
            ), extra
        e = Evidence(
            "periodic_orbit", cert.orbit.period, "not_periodic", f"{cert.status}: {detail}"
        )
    else:
        e = Evidence(
            "periodic_orbit", None, None, "random line length: no periodic orbit to shoot for"
        )
    band = Evidence(
        "banded_chaos",
        n,
        "chaotic",
        f"the section keeps {n} narrow bands while the tangent exponent is positive beyond "
        "its confidence interval and no attracting period-n orbit lies in them that the run "
        f"converges to: chaos confined to {n} bands (n-band chaos){_outweighed(v)}",
    )
    verdict = Verdict("chaotic", None, v.evidence + (e, band), (), v.settings)
    return verdict, extra


def _outweighed(v: Verdict) -> str:
    """The clause naming the votes n-band chaos outweighs (periodic or quasiperiodic, cast
    without the exponent), or ""."""
    names = [e.name for e in v.evidence if e.vote in ("periodic", "quasiperiodic")]
    if not names:
        return ""
    return (
        f"; it outweighs the {', '.join(names)} vote(s), which see the narrow bands (a "
        "recurrence to the band tolerance, or the lines of a spectrum) but not the "
        "stretching inside them"
    )


STEP_DEPENDENT = "step_dependent"
"""The evidence of a verdict whose periodic orbit is the grid's (:func:`_step_dependent`)."""


def _step_dependent(v: Verdict, p: Params, cert, e: Evidence) -> Verdict:
    """Undetermined, not extended: the run's grid certifies a period-n orbit that is not
    attracting at half the step, so the answer is the step's, and a longer run at this step
    gives it again."""
    why = (
        f"the period-{cert.period} orbit is certified on the run's grid (dt = {p.dt:g} s) "
        f"but not at dt/2 ({cert.detail}): the period is the step's; rerun with dt = "
        f"{p.dt / ORBIT_REFINE[-1]:.3g} s"
    )
    step = Evidence(STEP_DEPENDENT, cert.period, None, why)
    return Verdict("undetermined", None, v.evidence + (e, step), v.reasons + (why,), v.settings)


OVERFLOW = "tangent_overflow"
"""The evidence of a verdict whose Jacobians are not finite (:func:`overflow_evidence`)."""


def overflow_evidence(jacobians, p: Params) -> Evidence | None:
    """The evidence (abstaining, with the reason) that the tangent overflowed: a Jacobian
    that is not finite, RK4 past its stability limit in the contact (``l_lambda`` given in
    mm: K_n 1000 times the intended one); None when every Jacobian is finite. A verdict
    holding it is undetermined and not extended (:func:`extensible`): a longer run
    overflows too."""
    from ._run_warnings import resolution_warning

    jac = np.asarray(jacobians, dtype=float)
    if jac.ndim != 3 or not len(jac):
        return None  # a malformed shape: spectrum_from_jacobians says what it expects
    bad = ~np.isfinite(jac).all(axis=(1, 2))
    if not bad.any():
        return None
    cause = resolution_warning(p) or f"dt = {p.dt:g} s; try a smaller dt"
    why = (
        f"the tangent overflowed: {int(bad.sum())} of {len(bad)} cam periods' Jacobians are "
        f"not finite, so there is no exponent ({cause})"
    )
    return Evidence(OVERFLOW, int(bad.sum()), None, why)


def extensible(v: Verdict) -> bool:
    """Whether an undetermined verdict may settle on a longer run (not after an overflow,
    nor when its periodic orbit is the step's, nor when a longer run stopped early:
    :func:`extension_stopped`)."""
    return (
        v.label == "undetermined"
        and EXTENSION_STOPPED not in v.settings
        and not any(e.name in (OVERFLOW, STEP_DEPENDENT) for e in v.evidence)
    )


EXTENSION_STOPPED = "extension_stopped"
"""``Verdict.settings`` key of :func:`extension_stopped`."""


def extension_stopped(v: Verdict, status, stopped_at: float, wanted_s: float) -> Verdict:
    """``v``, the verdict of the recorded window, kept when the longer run that was to
    settle it ended early (the motion left the cam's reach at ``stopped_at`` [s], its last
    section time, or diverged): its advice to run longer goes, since no longer window
    exists, and a reason says so. ``settings["extension_stopped"]`` records the status, the
    time and the recorded seconds that were wanted; the extension is not tried again."""
    what = status.message.split(":")[0].split(". ")[0]  # "The follower left the cam's reach"
    why = (
        f"no longer window exists: extended to {wanted_s:g} s recorded, the run stopped "
        f"after t = {stopped_at:.4g} s ({status.name}: {what[0].lower() + what[1:]}), so "
        "the verdict is the recorded window's"
    )
    reasons = tuple(r for r in v.reasons if not r.startswith("to decide:"))
    settings = {
        **v.settings,
        EXTENSION_STOPPED: {"status": status.name, "at_s": stopped_at, "wanted_s": wanted_s},
    }
    return dataclasses.replace(v, reasons=(*reasons, why), settings=settings)
