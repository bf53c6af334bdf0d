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
    (λ T for a stroboscopic section, T the forcing period); lengths are relative to the
    orbit's extent unless said.

    Attributes
    ----------
    period_rtol : float
        Period n accepted when each band (k ≡ r mod n) is narrower than ``max(atol_j,
        period_rtol · extent_j)``: 3x the ~0.1 % jitter of a cam section, refuses 1 % noise.
    noise_floor : float
        Absolute floor of the period and expansion tests, times ``max_j max_k |x_kj|``: above
        round-off, below any dynamics; it makes a fixed point (no extent) detectable.
    band_separation : float
        Bands are distinct when their centres lie > this many widest-band widths apart: a
        period-12 cam orbit repeats to 1e-9 rad with two points 9e-6 rad apart.
    stationary_low, stationary_high : float
        Second-half over first-half spread outside [0.5, 2]: still converging or escaping.
    min_points_aperiodic : int
        Fewest points for the rotation and expansion votes (fewer make a weak call).
    rotation_quasi : float
        `rotation_order` R from which the points rotate on a closed curve (chaos: 1/sqrt N).
    expansion_chaotic : float
        `neighbour_expansion` above which neighbours separate: 0.1, a tenth of an e-fold.
    dimension_chaotic, dimension_min_points : float, int
        Correlation dimension above closed curves' 1.02-1.09 (Hénon 1.17-1.19, Ueda 1.53-1.60),
        and the fewest points for it to vote (10^{D₂} per scaling decade).
    zero_one_chaotic, zero_one_regular : float
        0-1 test: K >= 0.8 votes chaotic, K <= 0.2 not chaotic (Gottwald & Melbourne 2009).
    zero_one_min_points : int
        Fewest samples for the 0-1 test: 200, so its first half has the 100 it needs.
    zero_one_max_change : float
        Largest ``|K(first half) - K(whole)|`` taken as converged (a cam attractor's K fell from
        0.94 at 229 points to 0.16 at 914).
    birkhoff_quasi_digits, birkhoff_min_points : float, int
        Converged Birkhoff digits for a torus vote (tori 6-15, chaos < 2.5, 1e-4 noise ~5 on
        200-4000 points), and the fewest points (two halves of 100).
    birkhoff_rational_tol : float
        A rotation number this close to p/q, q <= N/2, is no torus vote (cam at ξ = 0.30,
        period 30: 3/5 + 4e-10); a torus is refused with probability ~1e-8 (N/2)².
    exponent_zero : float
        Exponent interval above this: positive; below: not (0.01, an e-fold in 100 iterates).
    exponent_z : float
        Half-width of the exponent's confidence interval in standard errors (3: ~99.7 %).
    min_chaotic_votes : int
        Chaotic votes needed without a decisive exponent (one is fooled by noise, transients).
    signal_repeat : float
        `classify_signal`: K = 0 when the 0-1 sequence's spread is below this of the signal's.
    zero_one_line_periods : float
        `classify_signal`: a chaotic K is dropped when lags up to N / 10 cover fewer periods of
        the slowest spectral line (a long period mimics diffusion).
    signal_lyapunov_tol : float
        `classify_signal`: default `lyapunov_tol` is this / T (T the forcing or fundamental period).
    series_chaotic, series_regular : float
        `classify_signal`: Rosenstein's λ₁ T > 0.05 votes chaotic, < 0.01 not, else abstains.
    constant_signal : float
        `classify_signal`: range below this fraction of the magnitude is constant (equilibrium).
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
    """`thresholds` (or the defaults) with the keywords `rtol`, `min_points_aperiodic` applied."""
    thr = thresholds or Thresholds()
    if rtol is not None:
        try:  # the keyword's own name in the message, not the table's entry
            thr = replace(thr, period_rtol=float(rtol))
        except (TypeError, ValueError):
            raise ValueError(f"rtol must be a finite number >= 0, got {rtol!r}") from None
    if min_points_aperiodic is not None:
        thr = replace(thr, min_points_aperiodic=int(min_points_aperiodic))
    return thr
