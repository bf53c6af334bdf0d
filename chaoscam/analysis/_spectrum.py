"""Power spectrum of a sampled signal and a line-spectrum model of it."""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from ._sections import peak_indices, vertex_offset
from ._validate import as_series, check_settings

__all__ = ["SpectrumResult", "power_spectrum", "spectrum_analysis"]


def power_spectrum(x, dt: float) -> tuple[np.ndarray, np.ndarray]:
    """One-sided periodogram with a linear detrend and a Hann window.

    ``P_k = |Σ_j w_j (x_j - a - b j) e^{-2πi jk/N}|²`` at ``f_k = k / (N dt)``; the scale
    is arbitrary (only power fractions are used).

    Parameters
    ----------
    x : array_like, shape (N,)
        Uniformly sampled signal.
    dt : float
        Sampling interval (s).

    Returns
    -------
    freqs, power : ndarray
        Frequencies (Hz), 0 .. Nyquist, and the periodogram.
    """
    x = as_series(x)
    check_settings("power_spectrum", dt=(dt, "real>0"))
    n = x.size
    j = np.arange(n) - 0.5 * (n - 1)
    slope = float(j @ x) / float(j @ j) if n > 1 else 0.0
    w = np.hanning(n + 2)[1:-1]  # symmetric Hann without the zero end points
    y = (x - x.mean() - slope * j) * w
    power = np.abs(np.fft.rfft(y)) ** 2
    return np.fft.rfftfreq(n, dt), power


@dataclass(frozen=True)
class SpectrumResult:
    """Result of `spectrum_analysis`; frequencies in Hz.

    ``model`` is "periodic", "quasiperiodic", "broadband", "aperiodic" (no line model, small
    broadband part) or "undetermined" (see ``message``). ``period``, for a forced periodic
    model, is the smallest n whose comb f_forcing / n holds the power; it can divide the
    period a section sees (subharmonics below `line_tol` are missed).
    """

    model: str
    period: int | None
    base_frequencies: tuple[float, ...]  # the comb's fundamental, or the two bases
    line_fraction: float  # power within ± half_width bins of the best line model's lines
    periodic_fraction: float  # the same for each model (NaN when not tried)
    quasiperiodic_fraction: float
    spectral_entropy: float  # normalised Shannon entropy of the power, in [0, 1]
    spectral_flatness: float  # geometric over arithmetic mean of the power, in [0, 1]
    peaks: tuple[tuple[float, float], ...]  # (frequency, power fraction in ± half_width bins)
    resolution: float  # 1 / (N dt)
    message: str = ""  # why the analysis is undetermined or weak
    settings: dict = field(default_factory=dict)

    @property
    def residual_fraction(self) -> float:
        """Fraction of the power outside the best line model (the broadband measure)."""
        return 1.0 - self.line_fraction


def _windows(centres: np.ndarray, n_bins: int, h: int) -> np.ndarray:
    """Mask of the bins within ± h of the given bins, and of the DC line."""
    mask = np.zeros(n_bins, dtype=bool)
    mask[: h + 1] = True  # the m = 0 line of every model (what the detrend leaves)
    if centres.size:
        idx = (centres[:, None] + np.arange(-h, h + 1)[None, :]).ravel()
        mask[idx[(idx >= 0) & (idx < n_bins)]] = True
    return mask


def _local_maxima(power: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Peak bins and their parabola-refined positions on the log power (bias < 0.02 bin)."""
    p = power
    k = peak_indices(p)
    k = k[p[k] > 1e-14 * p.max()]
    a, b, c = np.log(p[k - 1] + 1e-300), np.log(p[k]), np.log(p[k + 1] + 1e-300)
    return k, k + vertex_offset(a, b, c)


def _refine_fundamental(f0: float, fk: np.ndarray, pk: np.ndarray, tol: float) -> float:
    """Weighted least-squares fundamental (in bins) from the peaks on its harmonics."""
    m = np.rint(fk / f0)
    on = (m >= 1) & (np.abs(fk - m * f0) <= tol)
    if not np.any(on):
        return f0
    w = pk[on]
    return float(np.sum(w * m[on] * fk[on]) / np.sum(w * m[on] ** 2))


def _entropy_flatness(power: np.ndarray, total: float) -> tuple[float, float]:
    """Normalised Shannon entropy and flatness (Wiener entropy) of a periodogram, DC left out."""
    pk = power[1:] / power[1:].sum()
    pk = pk[pk > 0]
    entropy = float(-np.sum(pk * np.log(pk)) / math.log(power.size - 1))
    flatness = float(np.exp(np.mean(np.log(power[1:] + 1e-300 * total))) / np.mean(power[1:]))
    return entropy, flatness


def _on_torus_lines(fk, f1, f2, max_order, ftol) -> np.ndarray:
    """Which peaks lie within `ftol` of a line ``|a f1 + b f2|``, |a|, |b| <= `max_order`."""
    a = np.arange(-max_order, max_order + 1)
    lines = np.unique(np.abs(a[:, None] * f1 + a[None, :] * f2).ravel())
    pos = np.clip(np.searchsorted(lines, fk), 1, lines.size - 1)
    return np.minimum(np.abs(fk - lines[pos - 1]), np.abs(fk - lines[pos])) <= ftol


def _comb_candidates(fk, pk, forcing_frequency, df, max_period, min_cycles, ftol):
    """(max_period, [(n, f0 in bins)]): the comb fundamentals with `min_cycles` in the record."""
    if max_period is None:
        if forcing_frequency is not None:
            max_period = int(min(64, max(1, forcing_frequency / df // min_cycles)))
        else:
            max_period = 8
    min_f0 = float(min_cycles)  # in bins: f0 / df = cycles in the record
    if forcing_frequency is not None:
        found = [(k, forcing_frequency / k / df) for k in range(1, max_period + 1)]
    else:
        found = [(k, _refine_fundamental(fk[0] / k, fk, pk, max(ftol, 0.5)))
                 for k in range(1, max_period + 1) if fk[0] / k >= min_f0]  # fmt: skip
    return max_period, [(k, f0) for k, f0 in found if f0 >= min_f0]


SPECTRUM_RULES = {
    "forcing_frequency": "real>0?",
    "max_period": "int>=1?",
    "half_width": "int>=0",
    "line_tol": "real>0",
    "broadband_tol": "real>0",
    "max_order": "int>=1",
    "n_peaks": "int>=0",
    "min_cycles": "real>0",
    "peak_tol": "real>0",
}
"""The settings of `spectrum_analysis` and their ranges (see ``check_settings``)."""


def check_spectrum_options(fn: str, options: dict) -> None:
    """TypeError for a setting `spectrum_analysis` does not take, ValueError for a bad one."""
    unknown = sorted(set(options) - set(SPECTRUM_RULES))
    if unknown:
        raise TypeError(
            f"{fn}: unknown spectrum option {unknown[0]!r}; spectrum_analysis takes "
            f"{', '.join(SPECTRUM_RULES)}"
        )
    check_settings(fn, **{k: (v, SPECTRUM_RULES[k]) for k, v in options.items()})


def spectrum_analysis(
    x,
    dt: float,
    *,
    forcing_frequency: float | None = None,
    max_period: int | None = None,
    half_width: int = 4,
    line_tol: float = 1e-3,
    broadband_tol: float = 0.01,
    max_order: int = 8,
    n_peaks: int = 12,
    min_cycles: float = 10.0,
    peak_tol: float = 0.2,
) -> SpectrumResult:
    """Line-spectrum analysis of a sampled signal: harmonic comb, two-frequency torus or broadband.

    Each local maximum of the periodogram (`power_spectrum`) is located to a fraction of a
    bin and belongs to a line model when within `peak_tol` bins of one of its lines; a model
    explains the power within ± `half_width` bins of its peaks (and of DC). The models:

    * periodic: lines at ``m f0``; forced, ``f0 = f_F / n``, n = 1 .. `max_period`, the
      smallest n explaining ``>= 1 - line_tol`` of the power being the period in forcing
      periods; unforced, f0 is the strongest peak over k = 1 .. `max_period`, refined by
      least squares on its harmonics;
    * quasiperiodic: lines at ``|a f1 + b f2|``, ``|a|, |b|`` <= `max_order`, f1 the forcing (or
      strongest) frequency, f2 the strongest peak off the f1 comb.

    The residual ``1 - line_fraction`` is the broadband measure (chaos has a continuous
    spectrum). Spectral entropy ``-Σ p_k ln p_k / ln K`` and flatness are reported, not used:
    they depend on how far the sampling rate exceeds the bandwidth.

    References: Harris (1978), Proc. IEEE 66, 51 (windows); Bergé, Pomeau & Vidal (1984),
    "Order within Chaos", ch. 2–3; Powell & Percival (1979), J. Phys. A 12, 2053 (entropy).

    Limits: a transient, noise or drift add broadband power. Lines closer than ~`peak_tol`
    bins are one (a torus whose second base is that close to a low subharmonic reads as
    periodic). A forced period above `max_period` reads as quasiperiodic.

    Parameters
    ----------
    x : array_like, shape (N,)
        Signal after the transient.
    dt : float
        Sampling interval (s).
    forcing_frequency : float, optional
        Forcing frequency (Hz) of a forced system.
    max_period : int, optional
        Largest subharmonic order n (forced) or harmonic rank k (unforced); default, forced,
        every n with ``n <= f_F N dt / min_cycles`` up to 64 (9 for 20 s of the cam), else 8.
    half_width, peak_tol : int, float
        Half width of a line, and the distance of a refined peak on a model line [bins].
    line_tol, broadband_tol : float
        Power fraction a line model may leave unexplained; residual from which it is broadband.
    max_order, n_peaks : int
        Largest ``|a|``, ``|b|`` of the two-frequency combinations; number of peaks reported.
    min_cycles : float
        Fewest periods of a candidate fundamental in the record (else it is skipped).

    Returns
    -------
    SpectrumResult
    """
    x = as_series(x)
    n = x.size
    settings = dict(dt=dt, forcing_frequency=forcing_frequency, max_period=max_period,
                    half_width=half_width, line_tol=line_tol, broadband_tol=broadband_tol,
                    max_order=max_order, min_cycles=min_cycles, peak_tol=peak_tol)  # fmt: skip
    check_settings("spectrum_analysis", dt=(dt, "real>0"))
    options = {k: v for k, v in settings.items() if k != "dt"}
    check_spectrum_options("spectrum_analysis", {**options, "n_peaks": n_peaks})
    if half_width > n:
        raise ValueError(
            f"spectrum_analysis: half_width = {half_width} bins must be <= the {n} samples of x"
        )
    nan = math.nan
    df = 1.0 / (n * dt) if n > 0 else nan

    def undetermined(msg, entropy=nan, flatness=nan, peaks=()):
        return SpectrumResult("undetermined", None, (), nan, nan, nan, entropy, flatness,
                              tuple(peaks), df, msg, settings)  # fmt: skip

    if n < 64:
        return undetermined(f"only {n} samples; the spectrum needs >= 64")
    _, power = power_spectrum(x, dt)
    total = float(power.sum())
    if np.ptp(x) <= 1e-12 * max(1.0, float(np.max(np.abs(x)))) or total <= 0.0:
        return undetermined("constant signal: no spectrum to analyse")
    h, nb = int(half_width), power.size
    entropy, flatness = _entropy_flatness(power, total)
    kb, fk = _local_maxima(power)  # peak bins and refined positions, in bins
    if kb.size == 0:
        return undetermined("no spectral peak", entropy, flatness)
    pk = power[kb]
    order = np.argsort(pk)[::-1]
    kb, fk, pk = kb[order], fk[order], pk[order]
    peak_out = tuple((float(f * df), float(power[max(k - h, 0) : k + h + 1].sum()) / total)
                     for k, f in zip(kb[:n_peaks], fk[:n_peaks], strict=True))  # fmt: skip
    ftol = float(peak_tol)

    def result(model, period, bases, line_fraction, periodic, quasiperiodic):
        return SpectrumResult(model, period, bases, line_fraction, periodic, quasiperiodic,
                              entropy, flatness, peak_out, df, "", settings)  # fmt: skip

    def explained(on_model: np.ndarray) -> float:
        return float(power[_windows(kb[on_model], nb, h)].sum()) / total

    def on_comb(f0: float) -> np.ndarray:
        m = np.rint(fk / f0)
        return np.abs(fk - m * f0) <= ftol

    # --- periodic model (frequencies in bins)
    max_period, candidates = _comb_candidates(fk, pk, forcing_frequency, df, max_period,
                                              min_cycles, ftol)  # fmt: skip
    settings["max_period"] = max_period
    if not candidates:
        why = f"the record holds fewer than {min_cycles:g} cycles of the fundamental"
        return undetermined(why + "; use a longer signal", entropy, flatness, peak_out)
    per_best, per_f0 = -1.0, nan
    for k, f0 in candidates:
        e = explained(on_comb(f0))
        if e > per_best:
            per_best, per_f0 = e, f0
        if e >= 1.0 - line_tol:
            period = k if forcing_frequency is not None else None
            return result("periodic", period, (f0 * df,), e, e, nan)

    # --- two-frequency model: f1 the forcing (or strongest line), f2 the strongest off it
    if forcing_frequency is not None:
        f1 = forcing_frequency / df
    else:
        f1 = _refine_fundamental(fk[0], fk, pk, max(ftol, 0.5))
    off = ~on_comb(f1) & (fk >= float(min_cycles))  # in bins: cycles in the record
    qp, f2 = nan, nan
    if np.any(off):
        f2 = float(fk[np.argmax(off)])
        qp = explained(_on_torus_lines(fk, f1, f2, max_order, ftol))
        if qp >= 1.0 - line_tol:
            return result("quasiperiodic", None, (f1 * df, f2 * df), qp, per_best, qp)
    best = max(per_best, -1.0 if math.isnan(qp) else qp)
    model = "broadband" if 1.0 - best >= broadband_tol else "aperiodic"
    bases = (per_f0 * df,) if best == per_best else (f1 * df, f2 * df)
    return result(model, None, bases, best, per_best, qp)
