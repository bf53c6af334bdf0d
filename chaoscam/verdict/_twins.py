"""Common-noise twins: the direct test of the sign of the random system's top Lyapunov exponent.

With a random line length the follower is a random dynamical system (L. Arnold, *Random
Dynamical Systems*, Springer 1998): the cam's forcing and one realization of the draws drive it.
Its top exponent lambda_1 is that of the linearised cocycle along almost every realization.
lambda_1 < 0: trajectories driven by the same draws converge (the response is synchronised by the
noise; its random attractor is a single random point at each phase, a random periodic solution);
lambda_1 > 0: they separate to the attractor's size (random chaos). Twin runs measure this
directly, at finite amplitude, without the tangent: two runs from the same section point, one
moved by ``TWIN_DELTA``, sharing the draws (the same seed and index)."""

from __future__ import annotations

from dataclasses import asdict, dataclass

import numpy as np

from ..model import Params
from ..numerics import Numerics
from ..simulation import solve

__all__ = ["TWIN_DELTA", "TWIN_DURATION", "TwinTest", "twin_test"]

TWIN_DELTA = 1e-6
"""Twins' initial distance [rad] in theta_f (first pair) or theta_f' T (second pair): three
decades above the floor where the event-location jitter dominates the section map where
chattering ends in sticking (twins 1e-8 apart hover at 1-3e-9 rad over 160 s at xi = 0.525,
sigma = 2 mm, while 1e-6 apart they contract to 2e-10 in 40 s), below the bands of Table 1's
attractor (~1e-4 rad)."""

TWIN_DURATION = 30.0
"""How long [s] the twins run (~140 cam periods at Table 1's omega): a response contracting at
-0.08 1/s or faster shrinks the distance tenfold."""

SYNC_RATIO, SEPARATE_RATIO = 0.1, 10.0
"""The criterion on the distance d over the twins' last quarter (its geometric mean over the
sections, in units of TWIN_DELTA): synchronised when every pair ends below SYNC_RATIO (a tenfold
contraction), separated when a pair ends above SEPARATE_RATIO (a tenfold growth, sustained) with
the draws still shared when it first passed SEPARATE_RATIO; else inconclusive."""

_TAIL = 0.25


@dataclass(frozen=True)
class TwinTest:
    """The outcome of common-noise twin runs of one realization.

    ``outcome``: "synchronised", "separated" or "inconclusive". Per pair (start, direction):
    ``ratios`` (distance over the last quarter / TWIN_DELTA; 0 when the twins coincide, as after
    a plastic closure), ``growth`` (largest distance / TWIN_DELTA), ``split_at`` (time [s] after
    the start when the pair's draws first differ, None while shared: under ``resample =
    'contact'`` a contact one twin makes and the other does not). ``exponent``: the finite-time
    rate ln(ratio) / duration [1/s], the median over the pairs (bounded below by the distance's
    floor and above by saturation: evidence of the sign, not an estimate of lambda_1)."""

    outcome: str
    ratios: tuple[float, ...]
    growth: tuple[float, ...]
    split_at: tuple[float | None, ...]
    exponent: float
    duration: float
    detail: str

    def to_dict(self) -> dict:
        """JSON-safe form."""
        d = asdict(self)
        d["exponent"] = float(self.exponent) if np.isfinite(self.exponent) else None
        return d


def twin_test(p: Params, num: Numerics, starts, *, seed: int, index: int,
              duration: float = TWIN_DURATION, delta: float = TWIN_DELTA) -> TwinTest:  # fmt: skip
    """Twin runs of realization (``seed``, ``index``) of ``p`` from each section point of
    ``starts`` (rows theta_f [rad], theta_f' [rad/s], at cam phase ``p.theta_c0``): the point and
    the point moved by ``delta`` (in theta_f from the first start, in theta_f' T from the second,
    alternately), all solved in one call for ``duration`` [s] at ``num``; the distance between
    a pair's sections is |(d theta_f, d theta_f' T)|.

    Limits: finite time and amplitude; a restart draws the first contact's line anew, so the twins
    share one realization of the draws, not the original run's continuation; a response whose
    contraction is slower than ~0.08 1/s (ln 10 over the default duration) is inconclusive."""
    starts = np.atleast_2d(np.asarray(starts, dtype=float))
    period = p.cam_period
    models = []
    for i, (th, om) in enumerate(starts):
        moved = (th + delta, om) if i % 2 == 0 else (th, om + delta / period)
        models.append(p.replace(theta_f0=th, omega_f0=om))
        models.append(p.replace(theta_f0=moved[0], omega_f0=moved[1]))
    sol = solve(models, num, indices=[index] * len(models), seed=seed, duration=duration)
    pairs = [_pair(sol, 2 * i, 2 * i + 1, period, delta) for i in range(len(starts))]
    return _outcome(pairs, duration, delta)


def _pair(sol, a: int, b: int, period: float, delta: float):
    """(tail ratio, growth, split time, whether the draws were shared when the distance first
    passed SEPARATE_RATIO) of members ``a`` and ``b``; NaN ratio when a run failed."""
    if not (sol.members["status"].iat[a] == sol.members["status"].iat[b] == "OK"):
        return np.nan, np.nan, None, False
    sec, cols = sol.sections, ["t", "theta_f", "omega_f", "l_lambda"]
    member = sec["member"].to_numpy()
    xa, xb = (sec.loc[member == m, cols].to_numpy() for m in (a, b))
    n = min(len(xa), len(xb))
    xa, xb = xa[:n], xb[:n]
    d = np.hypot(xa[:, 1] - xb[:, 1], (xa[:, 2] - xb[:, 2]) * period) / delta
    tail = d[int((1.0 - _TAIL) * n) :]
    ratio = 0.0 if (tail == 0).any() else float(np.exp(np.log(tail).mean()))
    differ = np.flatnonzero(xa[:, 3] != xb[:, 3])
    split = float(xa[differ[0], 0]) if len(differ) else None
    grown = np.flatnonzero(d > SEPARATE_RATIO)
    shared = split is None or (len(grown) > 0 and differ[0] > grown[0])
    return ratio, float(d.max()), split, bool(shared)


def _outcome(pairs, duration: float, delta: float) -> TwinTest:
    ratios, growth, split, shared = (tuple(x) for x in zip(*pairs, strict=True))
    rates = [np.log(max(r, 1e-300)) / duration for r in ratios if np.isfinite(r)]
    exponent = float(np.median(rates)) if rates else np.nan
    grown = [r > SEPARATE_RATIO and s for r, s in zip(ratios, shared, strict=True)]
    if not all(np.isfinite(ratios)):
        outcome, why = "inconclusive", "a twin run did not end normally"
    elif any(grown):
        outcome, why = "separated", f"a pair grew over {SEPARATE_RATIO:g}x, the draws shared"
    elif all(r <= SYNC_RATIO for r in ratios):
        outcome, why = "synchronised", f"every pair contracted below {SYNC_RATIO:g}x"
    else:
        outcome, why = "inconclusive", "no pair grew with shared draws and not every one shrank"
    shown = ", ".join(f"{r:.2g}" for r in ratios)
    splits = sum(s is not None for s in split)
    detail = (f"{len(pairs)} twin pairs {delta:g} rad apart sharing the draws, {duration:.3g} "
              f"s: distance over the last quarter {shown} x the start ({why}); finite-time rate "
              f"{exponent:+.3g} 1/s")  # fmt: skip
    if splits:
        detail += (f"; {splits} pair(s) stopped sharing the draws (a contact one twin made and "
                   "the other did not)")  # fmt: skip
    return TwinTest(outcome, ratios, growth, split, exponent, duration, detail)
