"""The periodic-orbit certificate of a run's section (used by chaoscam._model_rules).

A section that repeats with period n is certified periodic when Newton shooting
(:func:`chaoscam.tangent.periodic_orbit`) finds a period-n orbit of the stroboscopic map that
is attracting (every Floquet multiplier |μ| < 1) **and the run converges to it**, and
the same holds at half the step (:data:`CONFIRM_REFINE`: an orbit of the grid alone is
"step-dependent"). Three things can spoil the first answer, and each has a rule here:

- the default grid's tangent overstates the multipliers where chattering dominates: an orbit
  that converges unstable (or whose Newton iteration stalls within the band tolerance) and
  that the run lies on (within the band tolerance) is shot for again at ``dt / ORBIT_REFINE``,
  where it must be attracting and the motion at that step, started from the run's last
  section point, must settle on it (a direct perturbation test,
  :func:`chaoscam.tangent.iterate_map`); an attracting grid orbit that the run does not
  approach is not refined (the step is not what keeps the run off it);
- "within 3e-3 of the extent" is not "on the orbit": the run must lie within the band
  tolerance of the grid's orbit, or visibly approach it (:func:`on_orbit`);
- a period-n orbit that lost stability through a flip (a real multiplier < −1) leaves a
  period-2n orbit near it, whose 2n bands the section reads as n bands: after a flip-unstable
  n whose section shows the doubling, or after any uncertified n whose section repeats with
  period 2n to the band tolerance (:func:`_sharp_doubling`), the period 2n is shot for too
  (``MAX_DOUBLINGS``), and certified only when it is certified at the refined steps as well
  (a flip moves with the step);
- Newton's multipliers are an infinitesimal derivative, and where chattering ends in sticking
  the map is not differentiable at the scale of its event jitter: an orbit that the run lies
  on or approaches, but that shooting leaves unstable, stalled, certified at some steps only
  or on the grid alone, is certified by **kicks** (:func:`_kicked`) when finite
  perturbations return at the run's step and at half of it (:data:`KICK_STEPS`).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .model import Params
from .tangent import PeriodicOrbit, iterate_map, kick_test, periodic_orbit

__all__ = [
    "APPROACH",
    "MAX_DOUBLINGS",
    "MODEL_ATOL",
    "CONFIRM_REFINE",
    "KICK_MIN_PERIODS",
    "KICK_SIZES",
    "KICK_STEPS",
    "ORBIT_REFINE",
    "REFINE_ITER",
    "Certificate",
    "certify",
    "on_orbit",
]

MODEL_ATOL = 1e-5
"""Absolute band tolerance [rad] on the model's section, for θ_f and for θ̇_f·T: bands
narrower than this are jitter (measured: a sticking period-1 orbit at e = 0.02 m keeps
1.6e-11 rad in θ_f and 6.9e-6 rad/s in θ̇_f from its contact oscillation, whatever the run
length). The relative tolerance of the analysis layer's Thresholds applies on top. It is
also the distance within which a run lies *on* an orbit (:func:`on_orbit`), and the Newton
residual below which a stalled shooting is refined (a point that P^n maps back within the
band tolerance)."""

REFINE_ITER = 8  # Newton iterations on a refined step (from an orbit or a band point)
ORBIT_REFINE = (2, 4)
"""Step divisors at which a periodic orbit that shooting does not certify on the run's grid is shot
for again (from the same section point): where chattering dominates, the tangent on the default
grid (dt = 2e-6 s) overstates the dominant multiplier and λ₁ with the flow's tangent at events,
the default (its error is in the RK4 substep after each located event of a chatter cycle,
whose near-grazing event times are very sensitive: see integrate/_tangent.py; the grid map's
own tangent does not). Measured with the flow's: ξ = 0.45,
period 6: |μ|max = 2.97 at dt, 0.0047 at dt/2, 0.072 at dt/4, 0.026 at dt/8, from one orbit
point (from others an independent referee got 1.9–3.6 at dt, while kicks of 1e-4 to 1e-9 decay
on the grid: the grid's tangent errs, not its motion); λ₁ from the run: +0.63 at dt, −2.53 at
dt/2, −2.75 on the adaptive path: a sticking orbit; ω = 26 rad/s, ξ = 0.3, period 7: 19 (not
converged), 2.42, 1.43, 1.30 (unstable: 7-band chaos); (ω, ξ) = (20, 0.6), a sticking period 1:
Newton stalls at dt (residual 1.4e-7 rad, |μ|max 13), converges at dt/2 and dt/4 with |μ|max
0.0073 and 1.6e-4; (32.5, 0.5), period 6: |μ|max 1.23 at dt, 0.43 at dt/2, 0.33 at dt/4 where
Newton stalls at 4e-7 rad (600 s runs at dt and dt/2: 6 bands of 4e-7 rad, λ₁ = −0.32 ± 0.03 1/s
at dt/2). (These with Illinois regula falsi locating the events. With the Newton crossing
search, (32.5, 0.5) gives 1.33 at dt, 0.37 at dt/2 where Newton stalls, and a converged orbit
of 2.78 at dt/4 that the motion does not settle on: "mixed", undetermined; its 600 s runs keep
6 bands, λ₁ > 0 on the grid's tangent at dt and < 0 at dt/2.) Only an orbit that converges
unstable on the run's grid, or stalls there within ``MODEL_ATOL``, and that the run lies on
within ``MODEL_ATOL``, is shot for again, and a refined step counts a stalled Newton within
``MODEL_ATOL`` as converged (on the default model's 8 chaotic bands, 1.4e-4 rad from the run,
Newton stalls at 2e-6 rad; its refined orbits are unstable, |μ|max 33 and 23). An orbit
certified at every refined step decides "periodic"; one attracting at some refined steps only
leaves the verdict undetermined; otherwise the grid's verdict stands."""

APPROACH = 0.5
"""A run approaches an orbit when its largest distance to it over the last 4n section points
is at most this fraction of that over its first 4n points (and the run has 8n points or
more). Measured: at (ω, ξ) = (45, 0.2) shooting certifies a period-11 orbit (|μ|max 0.38)
that the run stays 2.6e-5 rad from for 600 s (ratio 1.0: the run is not attracted; at dt it
settles on period 22, at dt/2 on nothing below 2.5e-5 rad); a run converging at |μ| = 0.95
per orbit period halves its distance within 14 orbit periods."""

MAX_DOUBLINGS = 1
"""How many times a flip-unstable period-n orbit sends the shooting to period 2n, when the
run's section shows the doubling (its bands at lag 2n at most half as wide as at lag n).
Once: every doubled orbit measured was 2n (7 → 14 → 28 at ξ = 0.325 was certified at dt/2
only; 600 s runs there give 7 bands at dt and dt/4, period 28 at dt/2), and shooting for 4n
was the dearest part of the quick report's Fig. 6. Measured: (ω, ξ) = (37.5, 0.15) and
(47.5, 0.1) look like periods 8 and 9 to the section (the 2n bands lie within its
tolerance), whose orbits are flip-unstable (multipliers −3.2 and −2.9); the stable orbits are
of periods 16 (|μ|max 0.73 at dt, 0.05 at dt/2, 0.09 at dt/4) and 18 (0.81, 0.07, 0.05),
which 600 s runs settle on. A doubled orbit must be certified at the refined steps too: at
(45, 0.2) the grid's period-11 orbit is flip-unstable and a period-22 orbit is attracting at
dt (|μ|max 0.16, the run within 4.4e-7 rad of it for 600 s), but at dt/2 and dt/4 Newton
does not converge on it and 600 s runs keep 11 bands of 3e-5 rad with λ₁ = +0.37 ± 0.04 1/s
(dt/2): the period 22 is the grid's."""

CONFIRM_REFINE = ORBIT_REFINE[:1]
"""Step halving for an orbit the run's grid certifies: it is certified only when it is
certified at ``dt / 2`` too (attracting with least period n, and the motion at that step
from the run's last section point settling on it); otherwise its status is
"step-dependent" and the verdict undetermined. Measured (an independent check with 300 s
runs and twin trajectories): at ξ = 0.525 the grid's period 8 is attracting at dt, but at
dt/2 and dt/4 the runs keep 8 bands of 3.4e-6 rad whose separation grows at +0.16 to +0.18
1/s, the period-8 orbit unstable there (|μ|max 2.18 at dt/4); at ξ = 0.47 (period 3),
(ω, ξ) = (22.5, 0.55) (period 5) and (20, 0.65) (sticking period 1) the orbit is the same
at dt/2 to 1e-6 rad and attracting."""

SETTLE_PERIODS = 8
"""A refined orbit certifies only when the motion at that step, started from the run's last
section point, settles on it within this many orbit periods (:func:`on_orbit` on the
iterates: within ``MODEL_ATOL``, or approaching). Measured: at (ω, ξ) = (45, 0.4) a period-18
orbit is attracting at dt/2 and dt/4 (|μ|max 0.36, 0.33) and lies within 3e-3 of the extent
of the run, but 600 s runs at dt and dt/2 keep 9 chaotic bands of 4e-5 rad (λ₁ = +0.51 ±
0.05 1/s at dt/2): the run's motion does not go there."""


KICK_STEPS = (1, 2)
"""Step divisors at which the kick certificate (:func:`_kicked`) asks finite perturbations
to return: the run's step and half of it (as :data:`CONFIRM_REFINE` asks of Newton's orbit;
an attraction of the grid alone is the step's)."""

KICK_MIN_PERIODS = 8
"""Orbit periods the run's own section must hold before kicks are asked (``len(points) >=
KICK_MIN_PERIODS * n``, as :func:`on_orbit` needs 8n points to see a run approach): the kicks
follow 40 orbit periods, 9 runs at dt and 9 at dt/2, so on a short window they cost tens of
times the run (the quick report's Fig. 6, 4 s recorded at dt = 2e-7 s: 110 s instead of
10 s); a classifier that extends an undetermined run asks them on the longer one."""

KICK_SIZES = (1e-7, 1e-6)
"""Kick sizes [rad] of the kick certificate: the sizes that decide
:attr:`chaoscam.tangent.KickTest.returns` (1e-8 kicks sit at the ~1e-8 event jitter of
sticking orbits and decide nothing; leaving them out saves a third of the cost)."""


@dataclass(frozen=True)
class Certificate:
    """What the shooting found for one candidate period.

    Attributes
    ----------
    status : str
        "certified" (an attracting orbit the run converges to, on the grid and at dt/2, or at
        every refined step when the grid's multipliers err), "step-dependent" (certified on
        the run's grid but not at ``dt / 2``, :data:`CONFIRM_REFINE`), "mixed" (attracting at
        some refined steps only), "unstable" (converged, not attracting), "off orbit"
        (attracting, but the run neither lies on it nor approaches it), "period differs"
        (its least period is not the one shot for) or "not converged".
    period : int
        The period shot for last: n, or 2n after a flip-unstable orbit.
    orbit : PeriodicOrbit
        The orbit on the run's grid for that period (the finest refined one when certified
        on refined steps).
    detail : str
        Residual, multipliers and the run's distance, in words, for the evidence.
    refined : bool
        Certified only on the refined steps, or by kicks (the grid's multipliers were at
        fault).
    kicked : bool
        Certified by kicks (:func:`_kicked`), not by Newton's multipliers.
    """

    status: str
    period: int
    orbit: PeriodicOrbit
    detail: str
    refined: bool = False
    kicked: bool = False

    @property
    def certified(self) -> bool:
        return self.status == "certified"


def on_orbit(orbit: PeriodicOrbit, points: np.ndarray) -> tuple[bool, float, str]:
    """Whether the run lies on ``orbit``: (on it, distance of its last 4n points, in words).

    On it when every one of the run's last 4n section points lies within ``MODEL_ATOL`` of
    the orbit, or when the run approaches it: over its last 4n points at most ``APPROACH``
    times as far as over its first 4n (with 8n points or more). The distance is in the
    scaled norm |(Δθ, T Δθ̇)| [rad]. A run that keeps its distance (it circles the orbit at
    2.6e-5 rad, as at (ω, ξ) = (45, 0.2)) is not on it, whatever the orbit's multipliers:
    there the map is not smooth near the orbit, and its linear stability says nothing of the
    run.
    """
    d = orbit.distances(points)
    w = 4 * orbit.period
    tail = float(d[-w:].max())
    if tail <= MODEL_ATOL:
        return True, tail, f"the run lies within {tail:.2g} rad of the orbit"
    if len(d) < 2 * w:
        return (
            False,
            tail,
            f"the run lies {tail:.2g} rad from the orbit, too short ({len(d)} points < {2 * w})"
            " to see it approach",
        )
    head = float(d[:w].max())
    ratio = tail / head if head > 0 else np.inf
    if ratio <= APPROACH:
        return True, tail, f"the run approaches the orbit ({head:.2g} -> {tail:.2g} rad)"
    return (
        False,
        tail,
        f"the run stays {tail:.2g} rad from the orbit ({head:.2g} rad at its start: it does "
        "not approach it)",
    )


def certify(
    p: Params,
    points: np.ndarray,
    n: int,
    extra: dict,
    *,
    doublings: int = MAX_DOUBLINGS,
    flips_double: bool = True,
    confirm: bool = True,
) -> Certificate:
    """Shoot for a period-n orbit from the run's last section point and decide whether it
    certifies the run's section (see the module docstring for the rules).

    The period 2n is shot for (at most ``doublings`` times) after a flip-unstable period n
    whose section shows the doubling (only with ``flips_double``), or after any period n not
    certified whose section repeats with period 2n to the band tolerance
    (:func:`_sharp_doubling`).

    ``extra`` receives the records: ``periodic_orbit`` (the grid's orbit),
    ``periodic_orbit_refined`` (the refined steps, when shot for) and
    ``periodic_orbit_doubled`` (the certificate of the doubled period, when tried).
    """
    orbit = periodic_orbit(p, points[-1], n)
    sits, dist, where = on_orbit(orbit, points)
    long_enough = len(points) >= KICK_MIN_PERIODS * n  # for kicks (KICK_MIN_PERIODS)
    extra["periodic_orbit"] = _orbit_record(orbit, distance=dist)
    mu = float(np.max(np.abs(orbit.multipliers)))
    detail = (
        f"Newton shooting on P^{orbit.period}: residual {orbit.residual:.2g} rad, "
        f"|mu|max = {mu:.3g}, {where}"
    )
    if orbit.certified and sits and orbit.period == n:
        if not confirm:  # the caller refines it itself (a doubled period)
            return Certificate("certified", n, orbit, detail)
        # Step halving: the orbit must be the model's, not the grid's.
        again, _, _, summary = _refined(p, points, n, extra, orbit.points[0], CONFIRM_REFINE)
        detail += "; " + summary
        if again == "certified":
            return Certificate("certified", n, orbit, detail)
        if not long_enough:
            return Certificate("step-dependent", n, orbit, detail)
        kicked, summary = _kicked(p, points, n, extra)
        detail += "; " + summary
        if kicked:
            return Certificate("certified", n, orbit, detail, refined=True, kicked=True)
        return Certificate("step-dependent", n, orbit, detail)
    if orbit.converged and orbit.period != n:
        return Certificate("period differs", n, orbit, detail)
    if orbit.converged and orbit.stable:
        status = "off orbit"
    elif orbit.converged:
        status = "unstable"
    else:
        status = "not converged"
    flips = [orbit]
    # The grid's multipliers may err: the run lies on an orbit they do not call attracting
    # (around an orbit the run keeps away from, refined shooting only cost: 8 chaotic bands).
    if status != "off orbit" and orbit.residual <= MODEL_ATOL and dist <= MODEL_ATOL:
        refined, best, orbits, summary = _refined(p, points, n, extra, orbit.points[0])
        detail += "; " + summary
        if refined == "certified":
            return Certificate("certified", n, best, detail, refined=True)
        if refined in ("mixed", "off orbit") or not orbit.converged:
            status = refined
        flips += orbits
    flipped = (
        doublings > 0
        and status == "unstable"
        and flips_double
        and any(_flip(o) for o in flips)
        and _doubling_seen(points, n)
    )
    sharp = (
        doublings > 0
        and not flipped
        and status in ("unstable", "not converged", "off orbit")
        and _sharp_doubling(p, points, n)
    )
    if flipped or sharp:
        records: dict = {}
        twice = certify(
            p,
            points,
            2 * n,
            records,
            doublings=doublings - 1,
            flips_double=flips_double,
            confirm=False,
        )
        status2, detail2 = twice.status, twice.detail
        if twice.certified and not twice.refined:  # a flip moves with the step: check it
            status2, _, _, summary = _refined(
                p, points, twice.period, records, twice.orbit.points[0]
            )
            detail2 += "; " + summary
        extra["periodic_orbit_doubled"] = records
        why = "flip-unstable" if flipped else "sharper at 2n"
        detail += f"; {why}, period {2 * n} shot for: {status2} ({detail2})"
        if status2 == "certified":
            return Certificate("certified", twice.period, twice.orbit, detail, True)
    stalled = orbit.converged or orbit.residual <= MODEL_ATOL
    if confirm and status in KICKED and sits and stalled and long_enough:
        # The multipliers left it open, the run lies on the orbit or approaches it: finite
        # perturbations decide.
        kicked, summary = _kicked(p, points, n, extra)
        detail += "; " + summary
        if kicked:
            return Certificate("certified", n, orbit, detail, refined=True, kicked=True)
    return Certificate(status, n, orbit, detail)


KICKED = ("unstable", "not converged", "mixed")
"""The certificate's outcomes that kicks may overturn (with "step-dependent"): the multipliers
left the orbit unstable, stalled or certified at some refined steps only, while the run lies
on it or approaches it (:func:`on_orbit`)."""


def _kicked(p: Params, points: np.ndarray, n: int, extra: dict) -> tuple[bool, str]:
    """The kick certificate of a period-n orbit that the run lies on: at each step
    ``dt / f`` of :data:`KICK_STEPS`, :func:`chaoscam.tangent.kick_test` from the run's last
    section point (kicks of :data:`KICK_SIZES` in ±θ_f and ±θ̇_f, 40 orbit periods) must
    return (every kick ends at most a tenth of its size from the unkicked motion), and the
    unkicked motion's last 4n section points must repeat with period n to the band tolerance
    (``MODEL_ATOL`` in θ_f and θ̇_f·T). Stops at the first step that fails.

    Why: Newton's multipliers are the grid map's derivative, and where chattering ends in
    sticking that map is not smooth below the ~1e-8 rad of its event jitter (ξ = 0.525: the
    grid tangent's |μ|max is 5.9, central differences at 1e-9 give 5.1, at 1e-8 0.41, and the
    flow tangent 0.05), so an attracting orbit can read unstable. Kicks of 1e-7 and more lie
    above that scale. Measured (docs/findings.md, "Tangent dynamics checked independently"):
    ``kick_test`` agrees with all 24 deterministic settled labels of the labelled and holdout
    sets. At half the step it refuses what is the grid's alone: at ξ = 0.525 kicks return at
    dt (1e-3 of themselves) and not at dt/2 (0.58), where 300 s runs keep 8 bands whose twins
    separate at +0.17 1/s.

    Returns (certified, a summary in words); ``extra["kick_test"]`` receives a record per
    step tried. The kicks at a step stop at the first that does not return (most orbits asked
    are refused, and the first refusal decides): "the largest ends at" is then the largest
    among the kicks run.
    """
    records, words = [], []
    scale = np.array([1.0, p.cam_period])
    for f in KICK_STEPS:
        pf = p.replace(dt=p.dt / f)
        test = kick_test(pf, points[-1], n, kicks=KICK_SIZES, until_refused=True)
        tail = test.points[-4 * n :] * scale
        bands = _widest_band(tail, n) if np.all(np.isfinite(tail)) else np.inf
        worst = float(np.nanmax(test.growth[:, :, -1]))  # kicks not run: NaN
        ok = test.returns and bands <= MODEL_ATOL
        records.append(
            {"dt": pf.dt, "returns": test.returns, "largest_final": worst, "bands": bands}
        )
        words.append(
            f"at dt/{f} the largest ends at {worst:.2g} of its kick, the motion's bands "
            f"{bands:.2g} rad"
        )
        if not ok:
            break  # so ok after the loop: every step certified it
    extra["kick_test"] = records
    verdict = "return" if ok else "do not return"
    return (
        ok,
        f"kicks of {', '.join(f'{k:g}' for k in KICK_SIZES)} rad {verdict} ({'; '.join(words)})",
    )


def _doubling_seen(points: np.ndarray, n: int) -> bool:
    """The run's section shows period 2n more sharply than n: its widest θ_f band at lag 2n
    is at most ``APPROACH`` times its widest at lag n (and it holds 4n points or more).
    Measured: 8 → 16 at (37.5, 0.15), 9 → 18 at (47.5, 0.1) and 8 → 16 on the fractal
    stiffness at D = 1.4 (bands 2e-6 at lag 8, 3e-7 at lag 16); in chaotic bands around a
    flip-unstable orbit both lags give the same width, and shooting for 2n there only costs."""
    x = np.asarray(points, dtype=float)[:, 0]
    if len(x) < 4 * n:
        return False
    return _widest_band(x, 2 * n) <= APPROACH * _widest_band(x, n)


def _widest_band(x: np.ndarray, lag: int) -> float:
    """The widest band of the points at this lag: max over r of the range of x[r::lag]
    (over every coordinate of a 2-D array)."""
    return max(float(np.ptp(x[r::lag], axis=0).max()) for r in range(lag))


def _sharp_doubling(p: Params, points: np.ndarray, n: int) -> bool:
    """The run's section repeats with period 2n to the band tolerance (``MODEL_ATOL`` in θ_f
    and in θ̇_f·T) and visibly more sharply than with period n (:func:`_doubling_seen`): the n
    bands are a period-2n orbit whose halves lie close together, whatever the period-n
    orbit's multipliers. Measured at (ω, ξ) = (38, 0.34): 6 bands of 4.7e-6 rad in θ_f, 12
    of 2.7e-7 rad over 60 periods; Newton on P^6 stalls at 2e-6 rad on the grid (the run
    stays 1.2e-5 rad from that orbit) and is unstable at dt/2 and dt/4, while the period-12
    orbit is attracting there (|μ|max 0.018, 0.070; 4.9 on the grid, the chattering error)
    and the run lies within 3e-7 rad of it; 600 s runs stay on period 12 at dt. Chaotic
    bands (1e-4 rad and wider on the default model) are never that sharp, so they cost no
    shooting."""
    if not _doubling_seen(points, n):  # also: 4n points or more
        return False
    scaled = np.asarray(points, dtype=float) * np.array([1.0, p.cam_period])
    return _widest_band(scaled, 2 * n) <= MODEL_ATOL


def _flip(orbit: PeriodicOrbit) -> bool:
    """A converged orbit with a real multiplier below −1 (it lost stability by a flip)."""
    mu = np.asarray(orbit.multipliers)
    real = np.abs(mu.imag) <= 1e-9 * np.maximum(1.0, np.abs(mu))
    return bool(orbit.converged and np.any(real & (mu.real < -1.0)))


def _refined(p: Params, points, n: int, extra: dict, seed, steps=ORBIT_REFINE):
    """Shoot for the period-n orbit again at the steps ``dt / steps`` (default
    ``ORBIT_REFINE``) in turn, each from the previous orbit (the first from ``seed``, the
    grid's orbit point), with at most ``REFINE_ITER`` Newton iterations, stopping at the
    first step that does not certify it.
    A refined step certifies it when Newton's residual is within ``MODEL_ATOL`` (converged,
    or stalled at the band tolerance), the orbit is attracting with least period n, and the
    motion at that step from the run's last section point settles on it within
    ``SETTLE_PERIODS`` orbit periods.

    Returns (status, the orbit at the finest step when certified else None, the orbits shot,
    a summary of the multipliers). status: "certified" when every refined step certifies it,
    "mixed" when only the first ones do, "off orbit" when the first is attracting but the
    motion does not settle on it, "period differs" when the first converged to an orbit of
    another least period, "unstable" when it converged unstable, else "not converged".
    """
    x = seed
    orbits, records, attracting, settles = [], [], [], []
    for f in steps:
        pf = p.replace(dt=p.dt / f)
        o = periodic_orbit(pf, x, n, max_iter=REFINE_ITER)
        orbits.append(o)
        attracting.append(o.residual <= MODEL_ATOL and o.stable and o.period == n)
        on, dist = False, float("nan")
        if attracting[-1]:
            motion = iterate_map(pf, points[-1], SETTLE_PERIODS * n)
            if np.all(np.isfinite(motion)):
                on, dist, _ = on_orbit(o, motion)
        settles.append(on)
        records.append(_orbit_record(o, dt=pf.dt, settles=on, distance=dist))
        if not on:  # on implies attracting: this step does not certify it
            break
        x = o.points[0]
    extra["periodic_orbit_refined"] = records
    mus = "|mu|max " + ", ".join(
        f"{float(np.max(np.abs(o.multipliers))):.3g} at dt/{f}"
        + ("" if o.converged else f" (residual {o.residual:.2g})")
        + (", the motion not settling on it" if a and not on else "")
        + (f" (least period {o.period}, not {n})" if o.converged and o.period != n else "")
        for o, f, a, on in zip(orbits, steps, attracting, settles, strict=False)
    )
    if len(settles) == len(steps) and all(settles):  # every refined step certifies it
        return "certified", orbits[-1], orbits, f"certified at every refined step: {mus}"
    if any(settles):
        return "mixed", None, orbits, f"mixed on refined steps: {mus}"
    first = orbits[0]
    if attracting[0]:
        return "off orbit", None, orbits, f"attracting on refined steps, not settled on: {mus}"
    if first.converged and first.period != n:
        return "period differs", None, orbits, f"another least period on refined steps: {mus}"
    if first.converged:
        return "unstable", None, orbits, f"unstable on refined steps, none attracting: {mus}"
    return "not converged", None, orbits, f"not converged on refined steps: {mus}"


def _orbit_record(orbit: PeriodicOrbit, **more) -> dict:
    """What a verdict's settings keep of a periodic orbit."""
    return {
        "period": orbit.period,
        "converged": orbit.converged,
        "residual": orbit.residual,
        "multipliers_abs": [float(abs(m)) for m in orbit.multipliers],
        "wall_time_s": orbit.wall_time,
        **more,
    }
