"""The 0–1 test for chaos (Gottwald & Melbourne), correlation method."""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from .._util import freeze_fields
from ._validate import as_series, check_settings

__all__ = ["ZeroOneResult", "zero_one_test"]


@dataclass(frozen=True)
class ZeroOneResult:
    """Result of `zero_one_test`. ``oversampled``: Matthews' z1test heuristic (little motion per
    sample, or K_c far apart for small and large c): subsample and run again."""

    k: float  # median of K_c: near 1 chaotic, near 0 regular; NaN when not run (`message`)
    k_c: np.ndarray  # K_c for each c
    c: np.ndarray  # the c values used
    n: int  # series length used
    n_cut: int  # largest lag of the displacement D_c(n)
    oversampled: bool
    message: str = ""  # why the test did not run, else empty
    settings: dict = field(default_factory=dict)  # n_c, c_range, seed, n_cut, min_length

    def __post_init__(self) -> None:
        freeze_fields(self, "k_c", "c", "settings")


def zero_one_test(
    x,
    *,
    n_c: int = 100,
    c_range: tuple[float, float] = (math.pi / 5.0, 4.0 * math.pi / 5.0),
    n_cut: int | None = None,
    seed: int = 0,
    min_length: int = 100,
) -> ZeroOneResult:
    """0–1 test for chaos, modified mean-square displacement and correlation method.

    For each c drawn uniformly from `c_range` (a ``numpy.random.Generator`` seeded from
    ``SeedSequence(seed)``) the observable φ_j = x_j drives the translation variables
    ``p_c(n) = Σ_{j<=n} φ_j cos(j c)``, ``q_c(n) = Σ_{j<=n} φ_j sin(j c)``, whose
    mean-square displacement is (Gottwald & Melbourne 2009, eq. 2.2)

        M_c(n) = 1/(N - n_cut) Σ_{j=1}^{N - n_cut} [p_c(j+n) - p_c(j)]² + [q_c(j+n) - q_c(j)]²,

    and, with the oscillatory term removed (their eq. 2.4),

        D_c(n) = M_c(n) - (E φ)² (1 - cos n c) / (1 - cos c),   n = 1 .. n_cut.

    K_c is the correlation coefficient of (n, D_c(n)) (their eq. 2.6) and K the median of
    K_c over c, which discards the resonant c where a regular signal also grows.

    Parameters
    ----------
    x : array_like, shape (N,)
        Observable, one sample per map iterate or per (coarse) sampling time of a flow.
    n_c : int
        Number of c values (100 in the reference).
    c_range : (float, float)
        Interval of c; (π/5, 4π/5) avoids the resonances at c = 0 and c = π.
    n_cut : int, optional
        Largest lag; default N // 10 as recommended.
    seed : int
        Seed of the c draws (results are reproducible).
    min_length : int
        Fewest samples (at least 4) for the test to run (else K is NaN, `message` says why).

    Returns
    -------
    ZeroOneResult

    Notes
    -----
    Reference: G. A. Gottwald and I. Melbourne, "On the implementation of the 0–1 test for
    chaos", SIAM J. Appl. Dyn. Syst. 8 (2009) 129–145.

    Limits: N ~ 1000 separates 0 from 1 cleanly (a few hundred scatter K by ±0.1–0.2);
    quasiperiodic signals give K -> 0 only slowly with N. An oversampled flow can look
    regular: subsample to a few samples per mean (or forcing) period and check
    `oversampled`. FFT correlations give all M_c(n) at once: cost O(n_c N log N).
    """
    phi = as_series(x)
    check_settings(
        "zero_one_test",
        n_c=(n_c, "int>=1"),
        n_cut=(n_cut, "int>=2?"),
        seed=(seed, "int>=0"),
        min_length=(min_length, "int>=4"),
    )
    low, high = np.asarray(c_range, dtype=float) if np.size(c_range) == 2 else (0.0, 0.0)
    if not 0.0 < low < high < math.pi:
        raise ValueError(
            f"zero_one_test: c_range = {c_range!r} must be two numbers 0 < low < high < π "
            "(c = 0 and c = π are resonant)"
        )
    n_total = phi.size
    settings = dict(n_c=n_c, c_range=tuple(c_range), seed=seed, n_cut=n_cut, min_length=min_length)
    why = ""
    if n_total < min_length:
        why = f"only {n_total} samples; the 0-1 test needs >= {min_length}"
    elif np.ptp(phi) <= 1e-12 * max(1.0, float(np.max(np.abs(phi)))):
        why = "constant series: the 0-1 test is undefined"
    if why:
        empty = np.array([])
        return ZeroOneResult(math.nan, empty, empty, n_total, 0, False, why, settings)
    nc = int(n_cut) if n_cut is not None else n_total // 10
    nc = max(2, min(nc, n_total - 2))
    rng = np.random.default_rng(np.random.SeedSequence(seed))
    c = rng.uniform(c_range[0], c_range[1], size=int(n_c))

    j = np.arange(1, n_total + 1)
    # z_c(n) = p_c(n) + i q_c(n), shape (n_c, N)
    z = np.cumsum(phi[None, :] * np.exp(1j * np.outer(c, j)), axis=1)
    length = n_total - nc  # number of j in each average
    lags = np.arange(1, nc + 1)
    abs2 = np.abs(z) ** 2
    csum = np.concatenate([np.zeros((c.size, 1)), np.cumsum(abs2, axis=1)], axis=1)
    # sum_{j<length} |z(j+n)|^2 and sum_{j<length} |z(j)|^2
    s_shift = csum[:, lags + length] - csum[:, lags]
    s_base = csum[:, length][:, None]
    # cross term sum_{j<length} z(j+n) conj(z(j)) by FFT correlation
    nfft = 1 << int(math.ceil(math.log2(n_total + length)))
    fz = np.fft.fft(z, nfft, axis=1)
    fb = np.fft.fft(z[:, :length], nfft, axis=1)
    corr = np.fft.ifft(fz * np.conj(fb), axis=1)[:, lags]
    m = (s_shift + s_base - 2.0 * corr.real) / length
    mean_phi = float(np.mean(phi))
    osc = mean_phi**2 * (1.0 - np.cos(np.outer(c, lags))) / (1.0 - np.cos(c))[:, None]
    d = m - osc
    xi = lags - lags.mean()
    dd = d - d.mean(axis=1, keepdims=True)
    denom = np.sqrt(np.sum(xi**2) * np.sum(dd**2, axis=1))
    with np.errstate(invalid="ignore", divide="ignore"):
        k_c = np.where(denom > 0, dd @ xi / denom, 0.0)
    k = float(np.median(k_c))
    small = c < np.mean(c_range)
    oversampled = bool(
        np.ptp(phi) / max(np.mean(np.abs(np.diff(phi))), 1e-300) > 10.0
        or (
            np.any(small)
            and np.any(~small)
            and np.median(k_c[small]) - np.median(k_c[~small]) > 0.5
        )
    )
    settings["n_cut"] = nc
    return ZeroOneResult(k, k_c, c, n_total, nc, oversampled, "", settings)
