"""The periodic-orbit certificate of a run's section (the rules' last word on a period).

A section that repeats with period n is certified periodic when Newton shooting
(:func:`~._orbits.periodic_orbit`) finds a period-n orbit of the stroboscopic map that is
attracting (every Floquet multiplier |mu| < 1) **and the run converges to it**, and the same
holds at half the step (:data:`CONFIRM_REFINE`: an orbit of the grid alone is
"step-dependent"). Four things can spoil the first answer, and each has a rule here:

- the default grid's tangent overstates the multipliers where chattering dominates: an orbit
  that converges unstable (or whose Newton iteration stalls within the band tolerance) and
  that the run lies on is shot for again at ``dt / ORBIT_REFINE``, where it must be
  attracting and the motion at that step, started from the run's last section point, must
  settle on it (a direct perturbation test); an attracting grid orbit that the run does not
  approach is not refined (the step is not what keeps the run off it);
- "within the section's tolerance" is not "on the orbit": the run must lie within the band
  tolerance of the orbit, or visibly approach it (:func:`on_orbit`);
- a period-n orbit that lost stability through a flip (a real multiplier < -1) leaves a
  period-2n orbit near it, whose 2n bands the section reads as n bands: the period 2n is shot
  for too (:data:`MAX_DOUBLINGS`) after a flip-unstable n whose section shows the doubling,
  or after any uncertified n whose section repeats with period 2n to the band tolerance
  (:func:`_sharp_doubling`), and certified only when it holds at the refined steps as well;
- Newton's multipliers are an infinitesimal derivative, and where chattering ends in sticking
  the map is not differentiable at the scale of its event jitter (~1e-8 rad): an orbit the
  run lies on or approaches but that shooting leaves unstable, stalled, certified at some
  steps only or on the grid alone is certified by **kicks** (:func:`_kicked`) when finite
  perturbations return at the run's step and at half of it (:data:`KICK_STEPS`).

Each threshold below was set on measured configurations; docs/verdicts.md gives them.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..model import Params
from ..numerics import Numerics
from ._orbits import PeriodicOrbit, iterate_map, kick_test, periodic_orbit

__all__ = [
    "APPROACH",
    "CONFIRM_REFINE",
    "KICK_MIN_PERIODS",
    "KICK_SIZES",
    "KICK_STEPS",
    "MAX_DOUBLINGS",
    "MODEL_ATOL",
    "ORBIT_REFINE",
    "REFINE_ITER",
    "Certificate",
    "certify",
    "on_orbit",
]

MODEL_ATOL = 1e-5
"""Absolute band tolerance [rad] on the model's section, for theta_f and for theta_f' T: bands
narrower than this are jitter (a sticking period-1 orbit at e = 0.02 m keeps 1.6e-11 rad in
theta_f and 6.9e-6 rad/s in theta_f' from its contact oscillation, whatever the run length).
It is also the distance within which a run lies *on* an orbit (:func:`on_orbit`), and the
Newton residual below which a stalled shooting is refined."""

REFINE_ITER = 8
"""Newton iterations on a refined step (from the grid's orbit or a band point)."""

ORBIT_REFINE = (2, 4)
"""Step divisors at which an orbit that shooting does not certify on the run's grid is shot
for again. Where chattering dominates, the tangent on the default grid overstates the
dominant multiplier (at xi = 0.45, period 6: |mu|max 2.97 at dt, 0.0047 at dt/2, 0.072 at
dt/4, while kicks of 1e-4 to 1e-9 rad decay on the grid: the grid's tangent errs, not its
motion). Only an orbit that converges unstable on the grid, or stalls there within
``MODEL_ATOL``, and that the run lies on within ``MODEL_ATOL``, is shot for again; a refined
step counts a stalled Newton within ``MODEL_ATOL`` as converged."""

APPROACH = 0.5
"""A run approaches an orbit when its largest distance to it over the last 4n section points
is at most this fraction of that over its first 4n points (and the run has 8n points or
more): a run converging at |mu| = 0.95 per orbit period halves its distance within 14 orbit
periods, while at (omega, xi) = (45, 0.2) the run stays 2.6e-5 rad from a certified period-11
orbit for 600 s (ratio 1.0: not attracted)."""

MAX_DOUBLINGS = 1
"""How many times a flip-unstable or uncertified period-n orbit sends the shooting to 2n:
every doubled orbit measured was 2n (at (37.5, 0.15) and (47.5, 0.1) the section reads
periods 8 and 9 whose orbits are flip-unstable; the stable orbits of periods 16 and 18 are
what 600 s runs settle on), and shooting for 4n was the dearest part of the quick report."""

CONFIRM_REFINE = ORBIT_REFINE[:1]
"""Step halving for an orbit the run's grid certifies: it must be certified at ``dt / 2`` too
(attracting with least period n, the motion at that step settling on it), else its status is
"step-dependent". At xi = 0.525 the grid's period 8 is attracting at dt, but at dt/2 and dt/4
runs keep 8 bands of 3.4e-6 rad whose separation grows at +0.17 1/s."""

SETTLE_PERIODS = 8
"""A refined orbit certifies only when the motion at that step, started from the run's last
section point, settles on it within this many orbit periods (at (45, 0.4) a period-18 orbit
is attracting at dt/2 and dt/4, but 600 s runs keep 9 chaotic bands: the motion does not go
there)."""

KICK_STEPS = (1, 2)
"""Step divisors at which the kick certificate asks finite perturbations to return: the run's
step and half of it (an attraction of the grid alone is the step's)."""

KICK_MIN_PERIODS = 8
"""Orbit periods the run's section must hold before kicks are asked: the kicks follow 40
orbit periods at two steps, so on a short window they cost tens of times the run; a
classifier that extends an undetermined run asks them on the longer one."""

KICK_SIZES = (1e-7, 1e-6)
"""Kick sizes [rad] of the kick certificate: those that decide ``KickTest.returns`` (1e-8
kicks sit at the ~1e-8 event jitter of sticking orbits and decide nothing)."""

KICKED = ("unstable", "not converged", "mixed")
"""The outcomes that kicks may overturn (with "step-dependent"): the multipliers left the
orbit unstable, stalled or certified at some refined steps only, while the run lies on it."""


@dataclass(frozen=True)
class Certificate:
    """What the shooting found for one candidate period.

    Attributes
    ----------
    status : str
        "certified" (an attracting orbit the run converges to, on the grid and at dt/2, or at
        every refined step when the grid's multipliers err, or by kicks), "step-dependent"
        (certified on the run's grid but not at dt / 2), "mixed" (attracting at some refined
        steps only), "unstable" (converged, not attracting), "off orbit" (attracting, but the
        run neither lies on it nor approaches it), "period differs" (its least period is not
        the one shot for) or "not converged".
    period : int
        The period shot for last: n, or 2n after a flip.
    orbit : PeriodicOrbit
        The orbit on the run's grid for that period (the finest refined one when certified
        on refined steps).
    detail : str
        Residual, multipliers and the run's distance, in words, for the evidence.
    refined : bool
        Certified only on the refined steps, or by kicks (the grid's multipliers were at
        fault).
    kicked : bool
        Certified by kicks, not by Newton's multipliers.
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


@dataclass(frozen=True)
class _Run:
    """The run a certificate judges: its model, numerics, section points and the record
    (``extra``) the shootings are written to."""

    p: Params
    num: Numerics
    points: np.ndarray
    extra: dict

    def at(self, divisor: int) -> Numerics:
        """The run's numerics with the step divided by ``divisor``."""
        return self.num.replace(dt=self.num.dt / divisor)


def on_orbit(orbit: PeriodicOrbit, points: np.ndarray) -> tuple[bool, float, str]:
    """Whether the run lies on ``orbit``: (on it, distance of its last 4n points, in words).

    On it when every one of the run's last 4n section points lies within ``MODEL_ATOL`` of
    the orbit, or when the run approaches it: over its last 4n points at most ``APPROACH``
    times as far as over its first 4n (with 8n points or more). The distance is in the
    scaled norm |(d theta, T d theta')| [rad]. A run that keeps its distance is not on the
    orbit, whatever its multipliers: the map is not smooth near it there.
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
    num: Numerics,
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

    ``extra`` receives the records: ``periodic_orbit`` (the grid's orbit),
    ``periodic_orbit_refined`` (the refined steps, when shot for),
    ``periodic_orbit_doubled`` (the doubled period, when tried) and ``kick_test``.
    """
    run = _Run(p, num, points, extra)
    orbit = periodic_orbit(p, points[-1], n, numerics=num)
    sits, dist, where = on_orbit(orbit, points)
    extra["periodic_orbit"] = _orbit_record(orbit, distance=dist)
    mu = float(np.max(np.abs(orbit.multipliers)))
    detail = (
        f"Newton shooting on P^{orbit.period}: residual {orbit.residual:.2g} rad, "
        f"|mu|max = {mu:.3g}, {where}"
    )
    if orbit.certified and sits and orbit.period == n:
        if not confirm:  # the caller refines it itself (a doubled period)
            return Certificate("certified", n, orbit, detail)
        return _confirmed(run, n, orbit, detail)
    if orbit.converged and orbit.period != n:
        return Certificate("period differs", n, orbit, detail)
    status = "off orbit" if orbit.converged and orbit.stable else (
        "unstable" if orbit.converged else "not converged"
    )  # fmt: skip
    flips = [orbit]
    # The grid's multipliers may err: the run lies on an orbit they do not call attracting.
    if status != "off orbit" and orbit.residual <= MODEL_ATOL and dist <= MODEL_ATOL:
        refined, best, orbits, summary = _refined(run, n, orbit.points[0])
        detail += "; " + summary
        if refined == "certified":
            return Certificate("certified", n, best, detail, refined=True)
        if refined in ("mixed", "off orbit") or not orbit.converged:
            status = refined
        flips += orbits
    doubled = _doubled(run, n, status, flips, doublings, flips_double)
    if doubled is not None:
        twice, words = doubled
        detail += words
        if twice is not None:
            return Certificate("certified", twice.period, twice.orbit, detail, True)
    stalled = orbit.converged or orbit.residual <= MODEL_ATOL
    if confirm and status in KICKED and sits and stalled and _long_enough(points, n):
        # The multipliers left it open, the run lies on the orbit or approaches it: finite
        # perturbations decide.
        kicked, summary = _kicked(run, n)
        detail += "; " + summary
        if kicked:
            return Certificate("certified", n, orbit, detail, refined=True, kicked=True)
    return Certificate(status, n, orbit, detail)


def _long_enough(points: np.ndarray, n: int) -> bool:
    return len(points) >= KICK_MIN_PERIODS * n


def _confirmed(run: _Run, n: int, orbit: PeriodicOrbit, detail: str) -> Certificate:
    """An orbit certified on the run's grid, checked at half the step (and by kicks when the
    half step does not confirm it and the run is long enough)."""
    again, _, _, summary = _refined(run, n, orbit.points[0], CONFIRM_REFINE)
    detail += "; " + summary
    if again == "certified":
        return Certificate("certified", n, orbit, detail)
    if not _long_enough(run.points, n):
        return Certificate("step-dependent", n, orbit, detail)
    kicked, summary = _kicked(run, n)
    detail += "; " + summary
    if kicked:
        return Certificate("certified", n, orbit, detail, refined=True, kicked=True)
    return Certificate("step-dependent", n, orbit, detail)


def _doubled(run: _Run, n, status, flips, doublings, flips_double):
    """The period 2n shot for after a flip-unstable n whose section shows the doubling, or an
    uncertified n whose section is sharper at 2n: (the certificate of 2n when it holds at the
    refined steps, else None; the words for the detail); None when 2n is not tried."""
    flipped = (
        doublings > 0
        and status == "unstable"
        and flips_double
        and any(_flip(o) for o in flips)
        and _doubling_seen(run.points, n)
    )
    sharp = (
        doublings > 0
        and not flipped
        and status in ("unstable", "not converged", "off orbit")
        and _sharp_doubling(run.p, run.points, n)
    )
    if not (flipped or sharp):
        return None
    records: dict = {}
    twice = certify(run.p, run.num, run.points, 2 * n, records, doublings=doublings - 1,
                    flips_double=flips_double, confirm=False)  # fmt: skip
    status2, detail2 = twice.status, twice.detail
    if twice.certified and not twice.refined:  # a flip moves with the step: check it
        status2, _, _, summary = _refined(_Run(run.p, run.num, run.points, records),
                                          twice.period, twice.orbit.points[0])  # fmt: skip
        detail2 += "; " + summary
    run.extra["periodic_orbit_doubled"] = records
    why = "flip-unstable" if flipped else "sharper at 2n"
    words = f"; {why}, period {2 * n} shot for: {status2} ({detail2})"
    return (twice if status2 == "certified" else None), words


def _kicked(run: _Run, n: int) -> tuple[bool, str]:
    """The kick certificate of a period-n orbit that the run lies on: at each step
    ``dt / f`` of :data:`KICK_STEPS`, :func:`~._orbits.kick_test` from the run's last
    section point (kicks of :data:`KICK_SIZES` in +-theta_f and +-theta_f', 40 orbit periods)
    must return (every kick ends at most a tenth of its size from the unkicked motion), and
    the unkicked motion's last 4n section points must repeat with period n to the band
    tolerance. Stops at the first step that fails.

    Returns (certified, a summary in words); ``extra["kick_test"]`` receives a record per
    step tried.
    """
    records, words = [], []
    scale = np.array([1.0, run.p.cam_period])
    ok = False
    for f in KICK_STEPS:
        num = run.at(f)
        test = kick_test(run.p, run.points[-1], n, numerics=num, kicks=KICK_SIZES,
                         until_refused=True)  # fmt: skip
        tail = test.points[-4 * n :] * scale
        bands = _widest_band(tail, n) if np.all(np.isfinite(tail)) else np.inf
        worst = float(np.nanmax(test.growth[:, :, -1]))  # kicks not run: NaN
        ok = test.returns and bands <= MODEL_ATOL
        records.append({"dt": num.dt, "returns": test.returns, "largest_final": worst,
                        "bands": bands})  # fmt: skip
        words.append(
            f"at dt/{f} the largest ends at {worst:.2g} of its kick, the motion's bands "
            f"{bands:.2g} rad"
        )
        if not ok:
            break  # so ok after the loop: every step certified it
    run.extra["kick_test"] = records
    verdict = "return" if ok else "do not return"
    return (
        ok,
        f"kicks of {', '.join(f'{k:g}' for k in KICK_SIZES)} rad {verdict} ({'; '.join(words)})",
    )


def _doubling_seen(points: np.ndarray, n: int) -> bool:
    """The run's section shows period 2n more sharply than n: its widest theta_f band at lag
    2n is at most ``APPROACH`` times its widest at lag n (with 4n points or more). In chaotic
    bands around a flip-unstable orbit both lags give the same width."""
    x = np.asarray(points, dtype=float)[:, 0]
    if len(x) < 4 * n:
        return False
    return _widest_band(x, 2 * n) <= APPROACH * _widest_band(x, n)


def _widest_band(x: np.ndarray, lag: int) -> float:
    """The widest band of the points at this lag: max over r of the range of x[r::lag]
    (over every coordinate of a 2-D array)."""
    return max(float(np.ptp(x[r::lag], axis=0).max()) for r in range(lag))


def _sharp_doubling(p: Params, points: np.ndarray, n: int) -> bool:
    """The run's section repeats with period 2n to the band tolerance (``MODEL_ATOL`` in
    theta_f and in theta_f' T) and visibly more sharply than with period n: the n bands are a
    period-2n orbit whose halves lie close together (at (38, 0.34): 6 bands of 4.7e-6 rad,
    12 of 2.7e-7 rad). Chaotic bands (1e-4 rad and wider on the default model) are never that
    sharp, so they cost no shooting."""
    if not _doubling_seen(points, n):  # also: 4n points or more
        return False
    scaled = np.asarray(points, dtype=float) * np.array([1.0, p.cam_period])
    return _widest_band(scaled, 2 * n) <= MODEL_ATOL


def _flip(orbit: PeriodicOrbit) -> bool:
    """A converged orbit with a real multiplier below -1 (it lost stability by a flip)."""
    mu = np.asarray(orbit.multipliers)
    real = np.abs(mu.imag) <= 1e-9 * np.maximum(1.0, np.abs(mu))
    return bool(orbit.converged and np.any(real & (mu.real < -1.0)))


def _refined(run: _Run, n: int, seed, steps=ORBIT_REFINE):
    """Shoot for the period-n orbit again at the steps ``dt / steps`` in turn, each from the
    previous orbit (the first from ``seed``), with at most ``REFINE_ITER`` Newton iterations,
    stopping at the first step that does not certify it. A refined step certifies it when
    Newton's residual is within ``MODEL_ATOL``, the orbit is attracting with least period n,
    and the motion at that step from the run's last section point settles on it within
    ``SETTLE_PERIODS`` orbit periods.

    Returns (status, the orbit at the finest step when certified else None, the orbits shot,
    a summary of the multipliers); status "certified" (every refined step), "mixed" (the
    first ones only), "off orbit" (the first is attracting but the motion does not settle on
    it), "period differs", "unstable" or "not converged".
    """
    x = seed
    orbits, records, attracting, settles = [], [], [], []
    for f in steps:
        num = run.at(f)
        o = periodic_orbit(run.p, x, n, numerics=num, max_iter=REFINE_ITER)
        orbits.append(o)
        attracting.append(o.residual <= MODEL_ATOL and o.stable and o.period == n)
        on, dist = False, float("nan")
        if attracting[-1]:
            motion = iterate_map(run.p, run.points[-1], SETTLE_PERIODS * n, num)
            if np.all(np.isfinite(motion)):
                on, dist, _ = on_orbit(o, motion)
        settles.append(on)
        records.append(_orbit_record(o, dt=num.dt, settles=on, distance=dist))
        if not on:  # on implies attracting: this step does not certify it
            break
        x = o.points[0]
    run.extra["periodic_orbit_refined"] = records
    return _refined_outcome(orbits, steps, attracting, settles, n)


def _refined_outcome(orbits, steps, attracting, settles, n):
    """:func:`_refined`'s (status, orbit, orbits, summary) from what each step found."""
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
