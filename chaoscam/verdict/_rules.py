"""The model-level rules on top of the analysis layer's verdict, in the order of :data:`RULES`:
each leaves the verdict to the next, changes it and passes it on, or decides (the last word).
``tests/verdict/test_rules.py`` shows each one's verdict and the one it overturns."""

from __future__ import annotations

import dataclasses
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from ..analysis import Evidence, Verdict, section_period
from ..model import Params, realizations_identical
from ..numerics import Numerics
from ._certificate import MODEL_ATOL, ORBIT_REFINE, certify, on_orbit
from ._twins import TWIN_DURATION, TwinTest, twin_test

__all__ = ["RULES", "STEP_MARGINAL", "Context", "Rule", "apply_rules", "extensible",
           "extension_stopped", "overflow_evidence"]  # fmt: skip

BAND_RTOL = 0.05
"""Bands narrower than this fraction of the section's extent count as n narrow bands for the
n-band chaos rule: the 0-1 test sees a chaotic component of relative size w on a periodic
sequence only on N >~ 1/w^2 samples (at (omega, xi) = (42.5, 0.15) 4 bands of 1.4e-2 of the
extent have lambda_1 = 0.317 +- 0.014 per iterate and are 8-band chaos on 600 s runs)."""

MIN_TWIN_POINTS = 20
"""Fewest recorded section points for the common-noise twins to be run: their starts are the
record's middle and last points, which a shorter record leaves in the transient, and its clusters
need a few visits each."""

CLUSTER_RTOL, MAX_CLUSTERS = 0.2, 16
"""A synchronised random response is periodic n when its section visits n clusters in turn,
each narrower than CLUSTER_RTOL of the section's extent (n <= MAX_CLUSTERS)."""

STEP_DEPENDENT, OVERFLOW = "step_dependent", "tangent_overflow"
"""The evidence names of a verdict whose periodic orbit is the grid's alone, and of one whose
Jacobians are not finite (:func:`overflow_evidence`): neither is extended."""

STEP_MARGINAL = "step_marginal"
"""The evidence name of an n-band chaos verdict whose run lies on an unstable period-n orbit in
its bands: ``classify`` checks it at half the step by itself (at (omega, xi) = (25, 0.5) 7 bands
of 1-6e-5 rad are chaotic at dt, periodic 7 at dt/2 by kicks and certified at dt/4)."""


@dataclass(frozen=True)
class Context:
    """What the rules know of a member, and the record (``extra``) of the certificate."""

    p: Params
    num: Numerics
    points: np.ndarray
    extra: dict
    seed: int = 0
    index: int = 0

    @property
    def deterministic(self) -> bool:
        return realizations_identical(self.p)

    def twins(self) -> TwinTest:
        """The common-noise twin test from the middle and the last section point, run for the
        recorded time within [TWIN_DURATION / 3, TWIN_DURATION] (recorded in ``extra["twins"]``)."""
        starts = self.points[[len(self.points) // 2, -1]]
        recorded = len(self.points) * self.p.cam_period
        duration = min(TWIN_DURATION, max(recorded, TWIN_DURATION / 3))
        tw = twin_test(self.p, self.num, starts, seed=self.seed, index=self.index,
                       duration=duration)  # fmt: skip
        self.extra["twins"] = tw.to_dict()
        return tw


@dataclass(frozen=True)
class Rule:
    """A named model-level rule: ``apply(verdict, context)`` returns None (not for this
    verdict) or ``(verdict, final)``, the verdict passed on or, when ``final``, the last word."""

    name: str
    checks: str
    apply: Callable[[Verdict, Context], tuple[Verdict, bool] | None]


def _votes(v: Verdict) -> dict[str, str | None]:
    return {e.name: e.vote for e in v.evidence}


def _undetermined(v: Verdict, reason: str, *more: Evidence) -> Verdict:
    return Verdict("undetermined", None, v.evidence + more, v.reasons + (reason,), v.settings)


def _torus_needs_zero_exponent(v: Verdict, ctx: Context):
    if v.label != "quasiperiodic" or _votes(v).get("exponent") == "not_chaotic":
        return None
    reason = ("quasiperiodic evidence, but the tangent exponent does not confirm lambda_1 = 0 "
              "within its interval: run longer")  # fmt: skip
    return _undetermined(v, reason), False


def _common_noise_twins(v: Verdict, ctx: Context):
    votes = _votes(v)
    broad_chaos = v.label == "chaotic" and votes.get("section_period") != "periodic"
    if ctx.deterministic or broad_chaos or len(ctx.points) < MIN_TWIN_POINTS:
        return None
    tw = ctx.twins()
    vote = {"synchronised": "not_chaotic", "separated": "chaotic"}.get(tw.outcome)
    e = Evidence("twins", tw.exponent, vote, f"{tw.outcome}: {tw.detail}")
    if tw.outcome == "synchronised":
        return _noisy_periodic(v, ctx, e), True
    if tw.outcome == "separated" and votes.get("exponent") == "not_chaotic":
        why = ("common-noise twins separate while the tangent exponent says lambda_1 < 0: run "
               "longer")  # fmt: skip
        return _undetermined(v, why, e), True
    v = dataclasses.replace(v, evidence=v.evidence + (e,))
    if tw.outcome != "separated" or v.label == "chaotic":
        return v, False
    n = _bands(v, ctx)
    if n is None:
        return Verdict("chaotic", None, v.evidence, (), v.settings), True
    return _banded_verdict(v, ctx, n), True


def _noisy_periodic(v: Verdict, ctx: Context, twins: Evidence) -> Verdict:
    """The verdict of a response the noise synchronises: periodic n, n the least number of
    clusters the last half of the section visits in turn, each narrower than ``CLUSTER_RTOL`` of
    its extent (1 when none: one noise-blurred cluster), with the widest cluster's width
    (``noise_width``)."""
    z = ctx.points[len(ctx.points) // 2 :] * np.array([1.0, ctx.p.cam_period])  # past a transient
    extent = float(np.ptp(z, axis=0).max())
    n, width = 1, extent
    for m in range(1, min(MAX_CLUSTERS, len(z) // 4) + 1):
        w = max(float(np.ptp(z[r::m], axis=0).max()) for r in range(m))
        if w <= max(MODEL_ATOL, CLUSTER_RTOL * extent):
            n, width = m, w
            break
    what = (f"{n} cluster(s) visited in turn, the widest {width:.2g} rad (theta_f, theta_f' T) "
            f"of an extent of {extent:.2g} rad")  # fmt: skip
    noise = Evidence("noise_width", width, None, what)
    tangent = _votes(v).get("exponent")
    note = () if tangent != "chaotic" else (
        "the tangent exponent is positive, but twins sharing the draws converge at finite "
        "amplitude: the infinitesimal tangent reads the event jitter where chattering ends in "
        "sticking",)  # fmt: skip
    settings = {**v.settings, "noisy": {"period": n, "band_width": width, "extent": extent}}
    return Verdict("periodic", n, v.evidence + (twins, noise), note, settings)


def _random_period_needs_contraction(v: Verdict, ctx: Context):
    exponent = _votes(v).get("exponent")
    if v.label != "periodic" or ctx.deterministic or exponent in ("not_chaotic", "periodic"):
        return None
    reason = (f"the section repeats with period {v.period} to the band tolerance, but the line "
              "length is random (no periodic orbit to certify) and the tangent exponent does "
              "not confirm lambda_1 < 0 within its interval: run longer")  # fmt: skip
    return _undetermined(v, reason), False


def _banded_chaos(v: Verdict, ctx: Context):
    n = _banded_period(v, ctx) if v.label == "undetermined" else None
    return None if n is None else (_banded_verdict(v, ctx, n), True)


def _periodic_orbit(v: Verdict, ctx: Context):
    candidate = v.period if v.label == "periodic" else _disputed_period(v)
    if candidate is None or not ctx.deterministic:
        return None
    return _certified_verdict(v, ctx, int(candidate)), True


RULES: tuple[Rule, ...] = (
    Rule("common_noise_twins",
         "with a random line length, twin runs sharing the draws decide the sign of the top "
         "exponent unless the section is broad chaos: synchronised, periodic n (noise-blurred "
         "clusters, noise_width); separated, chaotic (at xi = 0.525, sigma = 2 mm the tangent "
         "reads +1.17 1/s at dt and +0.19 at dt/2 over 8 bands, while twins 1e-6 rad apart end "
         "at 8e-5 to 0.29 of their start at dt and 4e-5 to 4e-4 at dt/2: analyses/random_set.py)",
         _common_noise_twins),
    Rule("torus_needs_zero_exponent",
         "a quasiperiodic verdict needs lambda_1 = 0 within the tangent exponent's interval "
         "(a torus has a zero top exponent); else undetermined", _torus_needs_zero_exponent),
    Rule("random_period_needs_contraction",
         "with a random line length there is no orbit to certify: n bands are periodic only "
         "when the tangent exponent confirms lambda_1 < 0 (8 bands of 1e-3 rad at sigma = "
         "1.5 mm, lambda_1 = 0.53 +- 0.22 after 46 periods, were chaotic on a longer run)",
         _random_period_needs_contraction),
    Rule("banded_chaos",
         "n narrow bands with lambda_1 > 0 beyond its interval: n-band chaos unless an "
         "attracting period-n orbit the run converges to lies in them (BAND_RTOL)", _banded_chaos),
    Rule("periodic_orbit",
         "a periodic (or disputed periodic) section of the deterministic model is certified "
         "by Newton shooting, refined steps and kicks (the certificate), or not", _periodic_orbit),
)  # fmt: skip
"""The model-level rules, in the order they apply."""


def apply_rules(v: Verdict, ctx: Context) -> Verdict:
    """The verdict after :data:`RULES`, in order, until one decides."""
    for rule in RULES:
        out = rule.apply(v, ctx)
        if out is not None:
            v, final = out
            if final:
                break
    return v


def _disputed_period(v: Verdict) -> int | None:
    """n when an undetermined verdict's section is periodic (n) and the exponent does not say
    chaotic (the case a certificate settles)."""
    votes = {e.name: e for e in v.evidence}
    sp, ex = votes.get("section_period"), votes.get("exponent")
    if v.label != "undetermined" or sp is None or sp.vote != "periodic":
        return None
    return None if ex is not None and ex.vote == "chaotic" else int(sp.value)


def _banded_period(v: Verdict, ctx: Context) -> int | None:
    """n when the tangent exponent is positive beyond its interval while the section keeps n
    bands, periodic to the band tolerance or each narrower than ``BAND_RTOL``; else None."""
    ex = next((e for e in v.evidence if e.name == "exponent"), None)
    return None if ex is None or ex.vote != "chaotic" else _bands(v, ctx)


def _bands(v: Verdict, ctx: Context) -> int | None:
    """n when the section keeps n bands, periodic to the band tolerance or each narrower than
    ``BAND_RTOL``; else None."""
    sp = next((e for e in v.evidence if e.name == "section_period"), None)
    if sp is None:
        return None
    if sp.vote == "periodic":
        return int(sp.value)
    atol = (MODEL_ATOL, MODEL_ATOL / ctx.p.cam_period)
    return section_period(
        ctx.points, rtol=BAND_RTOL, atol=atol, allow_transient=False, distinct=False
    ).period


def _certified_verdict(v: Verdict, ctx: Context, n: int) -> Verdict:
    """The verdict a period-n certificate gives a periodic or disputed section."""
    cert = certify(ctx.p, ctx.num, ctx.points, n, ctx.extra)
    if cert.certified:
        e = Evidence("periodic_orbit", cert.period, "periodic", "certified: " + cert.detail)
        if v.label == "periodic" and cert.period == v.period:
            return dataclasses.replace(v, evidence=v.evidence + (e,))
        # an attracting orbit the run converges to outweighs a spectral or 0-1 vote
        return Verdict("periodic", cert.period, v.evidence + (e,), (), v.settings)
    why = {"off orbit": "the run is not on it", "period differs": "its least period differs"}
    why = why.get(cert.status, cert.status)
    e = Evidence("periodic_orbit", cert.orbit.period, None, f"not certified ({why}): {cert.detail}")
    if cert.status == "step-dependent":
        return _step_dependent(v, ctx, cert, e)
    if cert.status in ("unstable", "not converged") and cert.orbit.converged:
        reason = (f"the section looks periodic but the orbit found is unstable ({cert.detail}): "
                  "run longer, to see whether the exponent is positive (chaos near an unstable "
                  "orbit)")  # fmt: skip
        return _undetermined(v, reason, e)
    if v.label == "periodic" and _votes(v).get("exponent") != "not_chaotic":
        reason = (f"the section repeats with period {v.period} but no attracting orbit is "
                  f"certified ({why}) and the tangent exponent does not confirm lambda_1 < 0: "
                  "run longer")  # fmt: skip
        return _undetermined(v, reason, e)
    return dataclasses.replace(v, evidence=v.evidence + (e,))


def _banded_verdict(v: Verdict, ctx: Context, n: int) -> Verdict:
    """Resolve "n narrow bands but lambda_1 > 0": chaotic when no attracting period-n orbit the run
    converges to lies in them (none in a random model), periodic when one attracts only at
    refined steps or by kicks (the grid's exponent is its error in the chattering phases),
    undetermined when the grid certifies one (a conflict) or refined steps disagree."""
    if not ctx.deterministic:
        why = "random line length: no periodic orbit to shoot for"
        return _band_chaos(v, n, Evidence("periodic_orbit", None, None, why))
    # no flip doubling: only a section that repeats with period 2n sends the shooting to 2n
    # (2n and 4n in the default's 8 chaotic bands would double Fig. 4's cost)
    cert = certify(ctx.p, ctx.num, ctx.points, n, ctx.extra, flips_double=False)
    detail = f"from the bands: {cert.detail}"
    if cert.certified and not cert.refined:
        e = Evidence("periodic_orbit", cert.period, "periodic", "certified " + detail)
        conflict = ("an attracting orbit is certified inside the bands, yet the tangent "
                    "exponent is positive")  # fmt: skip
        return dataclasses.replace(v, evidence=v.evidence + (e,), reasons=v.reasons + (conflict,))
    if cert.certified:
        e = Evidence("periodic_orbit", cert.period, "periodic", detail)
        where = "it is attracting at every refined step"
        if cert.kicked:
            where = "finite kicks return to it at the run's step and at half of it"
        note = (f"the tangent exponent on the run's grid is positive, but the run lies on the "
                f"period-{cert.period} orbit in the bands and {where}: the exponent's sign is "
                "the grid's error in the chattering phases")  # fmt: skip
        return Verdict("periodic", cert.period, v.evidence + (e,), (note,), v.settings)
    if cert.status == "step-dependent":
        return _step_dependent(v, ctx, cert, Evidence("periodic_orbit", n, None, detail))
    if cert.status == "mixed":
        dt = ctx.num.dt / ORBIT_REFINE[-1]
        reason = (f"the period-{n} orbit in the bands changes stability with the step "
                  f"({cert.detail}): run with dt = {dt:.3g} s")  # fmt: skip
        return _undetermined(v, reason, Evidence("periodic_orbit", n, None, detail))
    e = Evidence("periodic_orbit", cert.orbit.period, "not_periodic", f"{cert.status}: {detail}")
    chaos = _band_chaos(v, n, e)
    if cert.status == "unstable" and on_orbit(cert.orbit, ctx.points)[0]:
        why = (f"the run lies on the period-{n} orbit in the bands, unstable only by the "
               "multipliers of a step that may be too coarse for it")  # fmt: skip
        marginal = Evidence(STEP_MARGINAL, n, None, why)
        chaos = dataclasses.replace(chaos, evidence=chaos.evidence + (marginal,))
    return chaos


def _band_chaos(v: Verdict, n: int, e: Evidence) -> Verdict:
    names = [e.name for e in v.evidence if e.vote in ("periodic", "quasiperiodic")]
    outweighed = (f"; it outweighs the {', '.join(names)} vote(s), which see the narrow bands (a "
                  "recurrence to the band tolerance, or the lines of a spectrum) but not the "
                  "stretching inside them") if names else ""  # fmt: skip
    votes = _votes(v)
    stretch = (
        "the tangent exponent is positive beyond its confidence interval"
        if votes.get("exponent") == "chaotic"
        else "twins sharing the draws separate"
    )
    why = (f"the section keeps {n} narrow bands while {stretch} and no attracting period-n orbit "
           f"lies in them that the run converges to: chaos confined to {n} bands (n-band "
           f"chaos){outweighed}")  # fmt: skip
    band = Evidence("banded_chaos", n, "chaotic", why)
    return Verdict("chaotic", None, v.evidence + (e, band), (), v.settings)


def _step_dependent(v: Verdict, ctx: Context, cert, e: Evidence) -> Verdict:
    """Undetermined and not extended: the grid's period-n orbit is not certified at dt/2."""
    dt = ctx.num.dt
    why = (f"the period-{cert.period} orbit is certified on the run's grid (dt = {dt:g} s) "
           f"but not at dt/2 ({cert.detail}): the period is the step's; rerun with dt = "
           f"{dt / ORBIT_REFINE[-1]:.3g} s")  # fmt: skip
    step = Evidence(STEP_DEPENDENT, cert.period, None, why)
    return _undetermined(v, why, e, step)


def overflow_evidence(jacobians, p: Params, num: Numerics) -> Evidence | None:
    """The abstaining evidence that the tangent overflowed (a Jacobian not finite: RK4 past
    its stability limit in the contact), else None; its verdict is undetermined and not
    extended (a longer run overflows too)."""
    from ..simulation import resolution_warning

    jac = np.asarray(jacobians, dtype=float)
    if jac.ndim != 3 or not len(jac):
        return None  # a malformed shape: spectrum_from_jacobians says what it expects
    bad = ~np.isfinite(jac).all(axis=(1, 2))
    if not bad.any():
        return None
    cause = resolution_warning(p, num) or f"dt = {num.dt:g} s; try a smaller dt"
    why = (f"the tangent overflowed: {int(bad.sum())} of {len(bad)} cam periods' Jacobians are "
           f"not finite, so there is no exponent ({cause})")  # fmt: skip
    return Evidence(OVERFLOW, int(bad.sum()), None, why)


def extensible(v: Verdict) -> bool:
    """Whether an undetermined verdict may settle on a longer run: not after an overflow, a
    step-dependent orbit, or a longer run that stopped early."""
    flagged = any(e.name in (OVERFLOW, STEP_DEPENDENT) for e in v.evidence)
    return v.label == "undetermined" and "extension_stopped" not in v.settings and not flagged


def extension_stopped(v: Verdict, status, stopped_at: float, wanted_s: float) -> Verdict:
    """``v``, the recorded window's verdict, kept when the longer run meant to settle it ended
    early (left the cam's reach at ``stopped_at`` [s], its last section time, or diverged):
    its advice to run longer goes and a reason says why; ``settings["extension_stopped"]``
    records the status, the time and the seconds wanted (the extension is not tried again)."""
    what = status.message.split(":")[0].split(". ")[0]  # "The follower left the cam's reach"
    why = (f"no longer window exists: extended to {wanted_s:g} s recorded, the run stopped "
           f"after t = {stopped_at:.4g} s ({status.name}: {what[0].lower() + what[1:]}), so "
           "the verdict is the recorded window's")  # fmt: skip
    reasons = tuple(r for r in v.reasons if not r.startswith("to decide:"))
    stopped = {"status": status.name, "at_s": stopped_at, "wanted_s": wanted_s}
    settings = {**v.settings, "extension_stopped": stopped}
    return dataclasses.replace(v, reasons=(*reasons, why), settings=settings)
