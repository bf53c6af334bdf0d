"""The classifiers' decision thresholds: one frozen, visible table recorded in every verdict."""

from __future__ import annotations

import math
import numbers
from dataclasses import asdict, dataclass, fields, replace

__all__ = ["Thresholds"]


@dataclass(frozen=True)
class Thresholds:
    """Every number at which `classify_section` and `classify_signal` change a vote.

    Pass one to either classifier (``thresholds=Thresholds(period_rtol=1e-2)``); the verdict
    records it in ``settings["thresholds"]``. Exponents are per iterate of the section map
    (λ T for a stroboscopic section of a flow forced with period T); lengths are relative
    to the orbit's extent unless said.

    Attributes
    ----------
    period_rtol : float
        A period n is accepted when each of its n bands (the points k ≡ r mod n) is
        narrower than ``max(atol_j, period_rtol · extent_j)`` in every coordinate j: 3e-3
        is three times the ~0.1 % jitter integration error and a slow transient leave on a
        cam section, and refuses noise of 1 % of the extent.
    noise_floor : float
        Absolute floor of the period tolerance and of the expansion test's distances, as a
        fraction of ``max_j max_k |x_kj|``: 1e-6, far above round-off and below any dynamics
        worth resolving; it makes a fixed point (no extent) detectable.
    band_separation : float
        Two bands of a period are distinct when their centres lie more than this many
        widths of the widest band apart in some coordinate (4: a gap of at least 3 widths);
        a period-12 cam orbit repeats to 1e-9 rad while two of its points lie 9e-6 rad apart.
    stationary_low, stationary_high : float
        Spread of the second half of the points over that of the first: outside [0.5, 2]
        the points are still converging or escaping and the section abstains.
    min_points_aperiodic : int
        Fewest section points for the rotation-order and expansion votes (a period up to
        N / 2 shows on fewer; a quasiperiodic/chaotic call from fewer than 100 is weak).
    rotation_quasi : float
        Rank-shift consistency R (`rotation_order`) from which the points advance along a
        closed curve like a rotation (R ~ 1 / sqrt(N) for chaos).
    expansion_chaotic : float
        Mean one-step log growth of nearest-neighbour distances (`neighbour_expansion`)
        above which neighbours separate: 0.1 per iterate, a tenth of an e-fold.
    dimension_chaotic, dimension_min_points : float, int
        Correlation dimension from which the set is not a curve (closed curves give
        1.02-1.09, the Hénon attractor 1.17-1.19, Ueda's section 1.53-1.60), and the fewest
        points for it to vote (10^{D₂} per scaling decade).
    zero_one_chaotic, zero_one_regular : float
        0-1 test: K >= 0.8 votes chaotic, K <= 0.2 not chaotic (Gottwald & Melbourne 2009).
    zero_one_min_points : int
        Fewest samples for the 0-1 test to vote: 200, so that its first half still has the
        100 samples `zero_one_test` needs.
    zero_one_max_change : float
        Largest |K(first half) - K(whole)| for which K is taken as converged in N, else the
        test abstains (on a cam attractor K can fall from 0.94 at 229 points to 0.16 at 914).
    birkhoff_quasi_digits, birkhoff_min_points : float, int
        Converged digits of the weighted Birkhoff averages (`weighted_birkhoff`) from which
        an orbit with no period is quasiperiodic (on 200-4000 points tori give 6-15 digits,
        chaotic orbits (logistic r = 4, Hénon) below 2.5, noise of 1e-4 about 5), and the
        fewest points for it to vote (two halves of 100).
    birkhoff_rational_tol : float
        A converged rotation number within this of a rational p/q, q <= N/2, is not a torus
        vote: an unresolved period-q orbit has one too (the cam at ξ = 0.30, period 30:
        3/5 + 4e-10); 1e-8 mistakes a torus for one with probability ~1e-8 (N/2)².
    exponent_zero : float
        A largest exponent whose confidence interval lies above this is positive (chaotic),
        below it not positive: 0.01, an e-fold in 100 iterates, below what a run resolves.
    exponent_z : float
        Half-width of the exponent's confidence interval in standard errors (3: ~99.7 %).
    min_chaotic_votes : int
        Without a decisive exponent, a section is chaotic only when at least this many
        independent methods vote chaotic (one alone is fooled by noise or a long transient).
    signal_repeat : float
        `classify_signal`: a sequence whose spread is below this fraction of the signal's
        (all maxima equal, or a signal that repeats every forcing period) is K = 0.
    zero_one_line_periods : float
        `classify_signal`: a chaotic K is not used when the lags up to N / 10 cover fewer
        than this many periods of the spectrum's slowest line (a long period mimics
        diffusion).
    signal_lyapunov_tol : float
        `classify_signal`: |λ₁ T| below this counts as zero when no `lyapunov_tol` is given
        (T the forcing period or the spectrum's fundamental period).
    series_chaotic, series_regular : float
        `classify_signal`: Rosenstein's λ₁ T above 0.05 votes chaotic, |λ₁ T| below 0.01
        not chaotic, in between abstains.
    constant_signal : float
        `classify_signal`: a signal whose range is below this fraction of its magnitude is
        constant (an equilibrium).
    """

    period_rtol: float = 3e-3
    noise_floor: float = 1e-6
    stationary_low: float = 0.5
    stationary_high: float = 2.0
    min_points_aperiodic: int = 100
    rotation_quasi: float = 0.9
    expansion_chaotic: float = 0.1
    dimension_chaotic: float = 1.3
    dimension_min_points: int = 500
    zero_one_chaotic: float = 0.8
    zero_one_regular: float = 0.2
    zero_one_min_points: int = 200
    zero_one_max_change: float = 0.15
    birkhoff_quasi_digits: float = 6.0
    birkhoff_min_points: int = 200
    exponent_zero: float = 0.01
    exponent_z: float = 3.0
    min_chaotic_votes: int = 2
    signal_repeat: float = 1e-3
    zero_one_line_periods: float = 5.0
    signal_lyapunov_tol: float = 0.02
    series_chaotic: float = 0.05
    series_regular: float = 0.01
    constant_signal: float = 1e-12
    # kept last, so that positional arguments keep mapping to the fields above
    band_separation: float = 4.0
    birkhoff_rational_tol: float = 1e-8

    def __post_init__(self):
        for f in fields(self):
            v = getattr(self, f.name)
            if not (isinstance(v, numbers.Real) and math.isfinite(v) and v >= 0):
                raise ValueError(f"Thresholds.{f.name} must be a finite number >= 0, got {v!r}")
        if not self.stationary_low <= 1.0 <= self.stationary_high:
            raise ValueError("Thresholds: need stationary_low <= 1 <= stationary_high")
        if not self.zero_one_regular < self.zero_one_chaotic:
            raise ValueError("Thresholds: need zero_one_regular < zero_one_chaotic")
        if not self.band_separation > 0:
            raise ValueError(
                f"Thresholds.band_separation must be > 0, got {self.band_separation!r}"
            )

    def to_dict(self) -> dict:
        """The table as a plain dict (recorded in ``Verdict.settings["thresholds"]``)."""
        return asdict(self)


def resolve(
    thresholds: Thresholds | None, rtol: float | None, min_points_aperiodic: int | None
) -> Thresholds:
    """The table a classifier uses: `thresholds` (or the defaults) with the two entries
    that the classifiers also take as keywords (`rtol`, `min_points_aperiodic`) replaced
    when given."""
    thr = thresholds or Thresholds()
    if rtol is not None:
        try:  # the keyword's own name in the message, not the table's entry
            thr = replace(thr, period_rtol=float(rtol))
        except (TypeError, ValueError):
            raise ValueError(f"rtol must be a finite number >= 0, got {rtol!r}") from None
    if min_points_aperiodic is not None:
        thr = replace(thr, min_points_aperiodic=int(min_points_aperiodic))
    return thr
