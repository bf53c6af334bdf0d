"""The periodic-orbit certificate of a run's section (the rules' last word on a period).

A section that repeats with period n is certified periodic when Newton shooting
(:func:`~._orbits.periodic_orbit`) finds a period-n orbit of the stroboscopic map that is
attracting (every Floquet multiplier |mu| < 1), the run converges to it (:func:`on_orbit`),
and both hold at half the step (else "step-dependent"). Where chattering makes the grid's
multipliers err the orbit is shot for at refined steps, after a flip the period 2n is tried,
and where chattering ends in sticking finite kicks decide. docs/verdicts.md gives the
configurations each threshold was set on.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..model import Params
from ..numerics import Numerics
from ._orbits import PeriodicOrbit, iterate_map, kick_test, periodic_orbit

__all__ = ["MODEL_ATOL", "Certificate", "certify", "on_orbit"]

MODEL_ATOL = 1e-5
"""Absolute band tolerance [rad] of the model's section (theta_f and theta_f' T), below which
bands are jitter (a sticking period-1 orbit at e = 0.02 m keeps 6.9e-6 rad/s in theta_f');
also the distance within which a run lies on an orbit, and the Newton residual below which a
stalled shooting is refined."""

REFINE_ITER = 8
"""Newton iterations on a refined step (from the grid's orbit or a band point)."""

ORBIT_REFINE = (2, 4)
"""Step divisors at which an orbit the grid does not certify (unstable, or stalled within
``MODEL_ATOL``, the run lying on it) is shot for again; there a stalled Newton within
``MODEL_ATOL`` counts as converged. Where chattering dominates the grid's tangent overstates
the multipliers (xi = 0.45, period 6: |mu|max 2.97 at dt, 0.0047 at dt/2)."""

APPROACH = 0.5
"""A run approaches an orbit when its largest distance over its last 4n section points is at
most this fraction of that over its first 4n (8n points or more): |mu| = 0.95 halves the
distance within 14 orbit periods, while at (omega, xi) = (45, 0.2) a run stays 2.6e-5 rad from
a certified period-11 orbit for 600 s (ratio 1.0)."""

MAX_DOUBLINGS = 1
"""How many times a flip-unstable or uncertified period-n orbit sends the shooting to 2n
(every doubled orbit found in the model is 2n: at (37.5, 0.15) and (47.5, 0.1) periods 8 and
9 settle on 16 and 18; shooting for 4n would be a report's dearest part)."""

CONFIRM_REFINE = ORBIT_REFINE[:1]
"""The step division at which an orbit the grid certifies must be certified too, else it is
"step-dependent" (at xi = 0.525 the grid's attracting period 8 is, at dt/2, 8 bands of 3.4e-6
rad whose separation grows at +0.17 1/s)."""

SETTLE_PERIODS = 8
"""Orbit periods within which the motion at a refined step, from the run's last section
point, must settle on the refined orbit (at (45, 0.4) a period-18 orbit attracts at dt/2 and
dt/4, but 600 s runs keep 9 chaotic bands)."""

KICK_STEPS = (1, 2)
"""Step divisors at which kicks must return (an attraction of the grid alone is the step's)."""

KICK_MIN_PERIODS = 8
"""Orbit periods the section must hold before kicks are asked (40 orbit periods at two steps
cost tens of times a short run; an extended run asks them on its window)."""

KICK_SIZES = (1e-7, 1e-6)
"""Kick sizes [rad] of the certificate: those that decide ``KickTest.returns`` (1e-8 kicks sit
at the event jitter of sticking orbits)."""

KICKED = ("unstable", "not converged", "mixed")
"""The outcomes kicks may overturn (with "step-dependent")."""


@dataclass(frozen=True)
class Certificate:
    """What the shooting found for one candidate period.

    Attributes
    ----------
    status : str
        "certified" (an attracting orbit the run converges to, on the grid and at dt/2, at
        every refined step, or by kicks), "step-dependent" (on the grid, not at dt / 2),
        "mixed" (attracting at some refined steps only), "unstable" (converged, not
        attracting), "off orbit" (the run neither lies on it nor approaches it), "period
        differs" (its least period is not the one shot for) or "not converged".
    period : int
        The period shot for last: n, or 2n after a flip.
    orbit : PeriodicOrbit
        The orbit on the run's grid (the finest refined one when certified on refined steps).
    detail : str
        Residual, multipliers and the run's distance, in words, for the evidence.
    refined, kicked : bool
        Certified only on refined steps or by kicks (the grid's multipliers were at fault);
        by kicks, not by Newton's multipliers.
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
    """The run a certificate judges, and the record (``extra``) its shootings go to."""

    p: Params
    num: Numerics
    points: np.ndarray
    extra: dict

    def at(self, divisor: int) -> Numerics:
        """The run's numerics with the step divided by ``divisor``."""
        return self.num.replace(dt=self.num.dt / divisor)


def on_orbit(orbit: PeriodicOrbit, points: np.ndarray) -> tuple[bool, float, str]:
    """(on it, the distance [rad] of its last 4n section points, in words): the run lies on
    ``orbit`` when those points are within ``MODEL_ATOL`` of it (scaled norm |(d theta, T d
    theta')|), or approach it (at most ``APPROACH`` times as far as its first 4n, on 8n points
    or more); a run that keeps its distance is not on the orbit, whatever its multipliers."""
    d = orbit.distances(points)
    w = 4 * orbit.period
    tail = float(d[-w:].max())
    if tail <= MODEL_ATOL:
        return True, tail, f"the run lies within {tail:.2g} rad of the orbit"
    if len(d) < 2 * w:
        short = f"too short ({len(d)} points < {2 * w}) to see it approach"
        return False, tail, f"the run lies {tail:.2g} rad from the orbit, {short}"
    head = float(d[:w].max())
    ratio = tail / head if head > 0 else np.inf
    if ratio <= APPROACH:
        return True, tail, f"the run approaches the orbit ({head:.2g} -> {tail:.2g} rad)"
    stays = f"({head:.2g} rad at its start: it does not approach it)"
    return False, tail, f"the run stays {tail:.2g} rad from the orbit {stays}"


def certify(p: Params, num: Numerics, points: np.ndarray, n: int, extra: dict, *,
            doublings: int = MAX_DOUBLINGS, flips_double: bool = True,
            confirm: bool = True) -> Certificate:  # fmt: skip
    """Shoot for a period-n orbit from the run's last section point and decide whether it
    certifies the run's section (the module's rules). ``extra`` receives the records
    ``periodic_orbit``, ``periodic_orbit_refined``, ``periodic_orbit_doubled`` and
    ``kick_test`` of the shootings and kicks tried."""
    run = _Run(p, num, points, extra)
    orbit = periodic_orbit(p, points[-1], n, numerics=num)
    sits, dist, where = on_orbit(orbit, points)
    extra["periodic_orbit"] = _orbit_record(orbit, distance=dist)
    mu = float(np.max(np.abs(orbit.multipliers)))
    detail = (f"Newton shooting on P^{orbit.period}: residual {orbit.residual:.2g} rad, "
              f"|mu|max = {mu:.3g}, {where}")  # fmt: skip
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
    if confirm and status in KICKED and sits and stalled:
        # the multipliers left it open and the run lies on the orbit: finite kicks decide
        return _by_kicks(run, n, orbit, detail, status)
    return Certificate(status, n, orbit, detail)


def _confirmed(run: _Run, n: int, orbit: PeriodicOrbit, detail: str) -> Certificate:
    """A grid-certified orbit checked at half the step (then by kicks, on a long run)."""
    again, _, _, summary = _refined(run, n, orbit.points[0], CONFIRM_REFINE)
    detail += "; " + summary
    if again == "certified":
        return Certificate("certified", n, orbit, detail)
    return _by_kicks(run, n, orbit, detail, "step-dependent")


def _by_kicks(run: _Run, n: int, orbit: PeriodicOrbit, detail: str, status: str) -> Certificate:
    """Certified when the run holds ``KICK_MIN_PERIODS`` orbit periods and kicks return
    (:func:`_kicked`), else ``status``."""
    if len(run.points) < KICK_MIN_PERIODS * n:
        return Certificate(status, n, orbit, detail)
    kicked, summary = _kicked(run, n)
    detail += "; " + summary
    if kicked:
        return Certificate("certified", n, orbit, detail, refined=True, kicked=True)
    return Certificate(status, n, orbit, detail)


def _doubled(run: _Run, n, status, flips, doublings, flips_double):
    """A flip-unstable period-n orbit (a real multiplier < -1) leaves a period-2n orbit whose
    2n bands read as n: 2n is shot for when the section shows the doubling, or when an
    uncertified n's section repeats with period 2n within ``MODEL_ATOL``. Returns None (2n not
    tried) or (the certificate of 2n when it holds at the refined steps too, else None; words)."""
    flipped = (doublings > 0 and status == "unstable" and flips_double
               and any(_flip(o) for o in flips) and _doubling_seen(run.points, n))  # fmt: skip
    sharp = (doublings > 0 and not flipped and status in ("unstable", "not converged", "off orbit")
             and _sharp_doubling(run.p, run.points, n))  # fmt: skip
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
    """The kick certificate (where chattering ends in sticking the map is not differentiable
    at the scale of its ~1e-8 rad event jitter): (certified, in words) when at each step
    ``dt / f`` of :data:`KICK_STEPS` :func:`~._orbits.kick_test` from the last section point
    returns and the unkicked motion's last 4n points repeat with period n within MODEL_ATOL."""
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
        words.append(f"at dt/{f} the largest ends at {worst:.2g} of its kick, the motion's "
                     f"bands {bands:.2g} rad")  # fmt: skip
        if not ok:
            break  # so ok after the loop: every step certified it
    run.extra["kick_test"] = records
    sizes = ", ".join(f"{k:g}" for k in KICK_SIZES)
    verdict = "return" if ok else "do not return"
    return ok, f"kicks of {sizes} rad {verdict} ({'; '.join(words)})"


def _doubling_seen(points: np.ndarray, n: int) -> bool:
    """The section's widest theta_f band at lag 2n is at most ``APPROACH`` times that at lag
    n (4n points or more); chaotic bands around a flip-unstable orbit give both the same."""
    x = np.asarray(points, dtype=float)[:, 0]
    if len(x) < 4 * n:
        return False
    return _widest_band(x, 2 * n) <= APPROACH * _widest_band(x, n)


def _widest_band(x: np.ndarray, lag: int) -> float:
    """Max over r (and coordinates) of the range of ``x[r::lag]``."""
    return max(float(np.ptp(x[r::lag], axis=0).max()) for r in range(lag))


def _sharp_doubling(p: Params, points: np.ndarray, n: int) -> bool:
    """The section repeats with period 2n within ``MODEL_ATOL`` (theta_f and theta_f' T) and
    visibly more sharply than with n: a period-2n orbit whose halves lie close (at (38,
    0.34): 6 bands of 4.7e-6 rad, 12 of 2.7e-7 rad); chaotic bands are never that sharp."""
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
    """The period-n orbit shot for again at ``dt / f`` for f in ``steps``, each from the last,
    until a step does not certify it (residual within ``MODEL_ATOL`` after ``REFINE_ITER``
    iterations, attracting with least period n, the motion from the run's last section point
    settling on it within ``SETTLE_PERIODS`` orbit periods). Returns (status, the finest orbit
    when certified, the orbits shot, in words); status "certified" (every step), "mixed" (the
    first ones only), "off orbit" (attracting, not settled on), "period differs", "unstable"
    or "not converged"."""
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
    """:func:`_refined`'s result from what each step found."""
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
    return {"period": orbit.period, "converged": orbit.converged, "residual": orbit.residual,
            "multipliers_abs": [float(abs(m)) for m in orbit.multipliers],
            "wall_time_s": orbit.wall_time, **more}  # fmt: skip
