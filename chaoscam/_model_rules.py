"""The model-level rules on top of the analysis layer's verdict (used by chaoscam.classify).

The analysis layer (:mod:`chaoscam.analysis`) judges arrays; these rules add what only the
model knows: a periodic section of the deterministic model is certified by a periodic orbit
found by Newton shooting (:func:`chaoscam.tangent.periodic_orbit`), n narrow bands with a
positive tangent exponent and no attracting orbit inside are n-band chaos, and a periodic
section is called periodic only with a certificate or a contracting exponent (a random line
length has no orbit to certify).
"""

from __future__ import annotations

import dataclasses

import numpy as np

from .analysis import Evidence, Verdict
from .model import Params, realizations_identical
from .tangent import periodic_orbit

__all__ = ["MODEL_ATOL", "ORBIT_REFINE", "REFINE_ITER", "with_model_evidence"]

MODEL_ATOL = 1e-5
"""Absolute band tolerance [rad] on the model's section, for θ_f and for θ̇_f·T: bands
narrower than this are jitter (measured: a sticking period-1 orbit at e = 0.02 m keeps
1.6e-11 rad in θ_f and 6.9e-6 rad/s in θ̇_f from its contact oscillation, whatever the run
length). The relative tolerance of the analysis layer's Thresholds applies on top."""

REFINE_ITER = 8  # Newton iterations on a refined step (from an orbit or a band point)
ORBIT_REFINE = (2, 4)
"""Step divisors at which a periodic orbit that shooting does not certify on the run's grid
is shot for again (from the same section point): where chattering dominates, the tangent on
the default grid (dt = 2e-6 s) overstates the dominant multiplier and λ₁ (its error is in
the Hertz contact phase that ends each chattering sequence, whose closings are near-grazing).
Measured: ξ = 0.45, period 6: |μ|max = 2.97 at dt, 0.0047 at dt/2, 0.072 at dt/4, 0.026 at
dt/8 (λ₁ from the run: +0.63 at dt, −2.53 at dt/2, −2.75 on the adaptive path: a sticking
orbit); ω = 26 rad/s, ξ = 0.3, period 7: 19 (not converged), 2.42, 1.43, 1.30 (unstable: 7-band
chaos). Only an orbit that converges on the run's grid but is not certified there is shot
for again (Newton fails in chaotic bands at every step; measured on the default model, 8
bands: not converged at dt and dt/2). An orbit certified at every refined step decides
"periodic"; one attracting at some refined steps only leaves the verdict undetermined;
otherwise the grid's verdict stands."""


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
    banded = _banded_period(v)
    if v.label == "undetermined" and banded is not None:
        return _banded_verdict(v, p, points, banded, extra)
    candidate = v.period if v.label == "periodic" else _disputed_period(v)
    if candidate is None or not realizations_identical(p):
        return v, extra
    orbit = periodic_orbit(p, points[-1], int(candidate))
    dist = orbit.distance(points[-min(len(points), 4 * orbit.period) :])
    extent = float(np.ptp(points[:, 0])) or 1.0
    sits = dist <= max(MODEL_ATOL, 3e-3 * extent)
    extra["periodic_orbit"] = _orbit_record(orbit, distance=dist)
    mu = float(np.max(np.abs(orbit.multipliers)))
    detail = (
        f"Newton shooting on P^{orbit.period}: residual {orbit.residual:.2g} rad, "
        f"|mu|max = {mu:.3g}, the run lies within {dist:.2g} rad of the orbit"
    )
    certified = orbit.certified and sits and orbit.period == candidate
    unstable = orbit.converged and not orbit.stable
    if not certified and orbit.converged:  # the grid's multipliers may be at fault
        status, better, refined = _refined(p, points, candidate, extent, extra, orbit.points[0])
        detail += "; " + refined
        unstable = status in ("unstable", "not converged")
        if status == "certified":
            orbit, certified = better, True
    if certified:
        e = Evidence("periodic_orbit", orbit.period, "periodic", "certified: " + detail)
        if v.label == "periodic":
            return dataclasses.replace(v, evidence=v.evidence + (e,)), extra
        # The certificate decides what the section and the exponent left open: an attracting
        # orbit that the run sits on outweighs a spectral or 0-1 vote on a short series.
        return Verdict("periodic", orbit.period, v.evidence + (e,), (), v.settings), extra
    if not orbit.converged:
        why = "not converged"
    elif not orbit.stable:
        why = "unstable"
    else:
        why = "the run is not on it" if not sits else "its least period differs"
    e = Evidence("periodic_orbit", orbit.period, None, f"not certified ({why}): " + detail)
    if unstable:
        reason = (
            f"the section looks periodic but the orbit found is unstable ({detail}): run "
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


def _refined(p: Params, points, n: int, extent: float, extra: dict, seed):
    """Shoot for the period-n orbit again at the steps ``dt / ORBIT_REFINE`` in turn, each
    from the previous orbit (the first from ``seed``, the grid's orbit point), with at most
    ``REFINE_ITER`` Newton iterations, stopping at the first step that does not certify it.

    Returns (status, the orbit at the finest step when certified else None, a summary of the
    multipliers). status: "certified" when every refined orbit is attracting and the run lies
    on it, "mixed" when only the first ones are, "unstable" when the first converged unstable,
    else "not converged".
    """
    tail = points[-min(len(points), 4 * n) :]
    x = seed
    orbits, records, good = [], [], []
    for f in ORBIT_REFINE:
        o = periodic_orbit(p.replace(dt=p.dt / f), x, n, max_iter=REFINE_ITER)
        dist = o.distance(tail)
        orbits.append(o)
        records.append(_orbit_record(o, dt=p.dt / f, distance=dist))
        good.append(o.certified and o.period == n and dist <= max(MODEL_ATOL, 3e-3 * extent))
        if not good[-1]:
            break
        x = o.points[0]
    extra["periodic_orbit_refined"] = records
    mus = "|mu|max " + ", ".join(
        f"{float(np.max(np.abs(o.multipliers))):.3g} at dt/{f}"
        + ("" if o.converged else " (not converged)")
        for o, f in zip(orbits, ORBIT_REFINE, strict=False)
    )
    if len(good) == len(ORBIT_REFINE):  # none failed: every refined step certifies it
        return "certified", orbits[-1], f"certified at every refined step: {mus}"
    if any(good):
        return "mixed", None, f"mixed on refined steps: {mus}"
    if orbits[0].converged:
        return "unstable", None, f"unstable on refined steps, none attracting: {mus}"
    return "not converged", None, f"not converged on refined steps: {mus}"


def _orbit_record(orbit, **more) -> dict:
    """What a verdict's settings keep of a periodic orbit."""
    return {
        "period": orbit.period,
        "converged": orbit.converged,
        "residual": orbit.residual,
        "multipliers_abs": [float(abs(m)) for m in orbit.multipliers],
        "wall_time_s": orbit.wall_time,
        **more,
    }


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


def _banded_period(v: Verdict) -> int | None:
    """n when the section is periodic to the band tolerance (n narrow bands) while the
    tangent exponent is positive beyond its confidence interval; else None."""
    votes = {e.name: e for e in v.evidence}
    sp, ex = votes.get("section_period"), votes.get("exponent")
    if sp is None or ex is None or sp.vote != "periodic" or ex.vote != "chaotic":
        return None
    return int(sp.value)


def _banded_verdict(v: Verdict, p: Params, points, n: int, extra: dict):
    """Resolve "n narrow bands but λ₁ > 0": chaotic when no attracting period-n orbit lies in
    the bands (shooting: unstable or not converged; or a random model, which has none),
    still undetermined when shooting certifies one (a genuine conflict)."""
    if realizations_identical(p):
        orbit = periodic_orbit(p, points[-1], n)
        mu = float(np.max(np.abs(orbit.multipliers)))
        extra["periodic_orbit"] = _orbit_record(orbit)
        detail = (
            f"Newton shooting on P^{n} from the bands: residual {orbit.residual:.2g} rad, "
            f"converged {orbit.converged}, |mu|max = {mu:.3g}"
        )
        if orbit.certified:
            e = Evidence("periodic_orbit", orbit.period, "periodic", "certified: " + detail)
            return dataclasses.replace(
                v,
                evidence=v.evidence + (e,),
                reasons=v.reasons
                + (
                    "an attracting orbit is certified inside the bands, "
                    "yet the tangent exponent is positive",
                ),
            ), extra
        extent = float(np.ptp(points[:, 0])) or 1.0
        status, refined = None, ""
        if orbit.converged:  # an unstable orbit: the grid's multipliers may be at fault
            status, _, refined = _refined(p, points, n, extent, extra, orbit.points[0])
        if status == "certified":
            e = Evidence("periodic_orbit", n, "periodic", f"{detail}; {refined}")
            note = (
                f"the tangent exponent on the run's grid is positive, but the period-{n} orbit "
                "in the bands is attracting at every refined step: the exponent's sign is the "
                "grid's error in the chattering phases"
            )
            return Verdict("periodic", n, v.evidence + (e,), (note,), v.settings), extra
        if status == "mixed":
            e = Evidence("periodic_orbit", n, None, f"{detail}; {refined}")
            reason = (
                f"the period-{n} orbit in the bands changes stability with the step ({refined}):"
                f" run with dt = {p.dt / ORBIT_REFINE[-1]:.3g} s"
            )
            return Verdict(
                "undetermined", None, v.evidence + (e,), v.reasons + (reason,), v.settings
            ), extra
        why = "unstable" if orbit.converged else "not converged"
        detail += f"; {refined}" if refined else ""
        e = Evidence("periodic_orbit", orbit.period, "not_periodic", f"{why}: {detail}")
    else:
        e = Evidence(
            "periodic_orbit", None, None, "random line length: no periodic orbit to shoot for"
        )
    band = Evidence(
        "banded_chaos",
        n,
        "chaotic",
        f"the section keeps {n} narrow bands while the tangent exponent is positive beyond "
        "its confidence interval and no attracting period-n orbit lies in them: chaos "
        f"confined to {n} bands (n-band chaos)",
    )
    verdict = Verdict("chaotic", None, v.evidence + (e, band), (), v.settings)
    return verdict, extra
