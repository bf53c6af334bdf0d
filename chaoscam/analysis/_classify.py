"""Classify a sampled signal (with optional section points) into a `Verdict`."""

from __future__ import annotations

import dataclasses
from collections.abc import Sequence

import numpy as np

from ._evidence import exponent_votes, safe, section_evidence, zero_one_evidence
from ._lyapunov_series import lyapunov_from_series
from ._sections import local_maxima
from ._spectrum import check_spectrum_options, spectrum_analysis
from ._thresholds import Thresholds, resolve
from ._validate import MIN_SERIES, as_points, as_series, check_atol, check_settings
from ._verdict import Evidence, Verdict, combine

__all__ = ["SAMPLING_DT", "classify_signal"]

SAMPLING_DT = (1e-12, 1e6)
"""The sampling intervals [s] `classify_signal` takes: a terahertz sampler to 11.6 days a
sample (outside, 1 / dt and the spectrum's frequencies leave any physical scale)."""

_SPECTRUM_VOTES = {"periodic": "periodic", "quasiperiodic": "quasiperiodic",
                   "broadband": "chaotic", "aperiodic": "not_periodic"}  # fmt: skip


def _zero_one_signal(x, dt, forcing_period, seed, per_period, line_freq, thr):
    """0–1 test on a map-like sequence derived from the signal (see classify_signal)."""
    if forcing_period is not None:
        t = np.arange(x.size) * dt
        step = forcing_period / per_period
        tk = np.arange(0.0, t[-1] + 1e-12 * step, step)
        n_per = tk.size // per_period
        if n_per < 2:
            return Evidence("zero_one", None, None, "fewer than 2 forcing periods")
        y = np.interp(tk[: n_per * per_period], t, x).reshape(n_per, per_period)
        seq = (y - y.mean(axis=0)).ravel()
        rate = per_period / forcing_period
        what = (
            f"0-1 test on the signal sampled {per_period} times per forcing period, "
            "minus its forcing-synchronous mean"
        )
        if np.std(seq) <= thr.signal_repeat * np.std(y):
            why = ": nothing left (the signal repeats every forcing period), K = 0"
            return Evidence("zero_one", 0.0, "not_chaotic", what + why)
    else:
        _, seq = local_maxima(x, dt)
        rate = seq.size / (x.size * dt)
        what = "0-1 test on the successive local maxima"
        if seq.size >= 8 and np.ptp(seq) <= thr.signal_repeat * np.ptp(x):
            why = ": all maxima equal (a period-1 oscillation), K = 0"
            return Evidence("zero_one", 0.0, "not_chaotic", what + why)
    e = zero_one_evidence("zero_one", seq, what, seed, thr)
    if e.vote == "chaotic" and line_freq:
        period = rate / line_freq  # samples per period of the slowest line base
        n_cut = seq.size // 10
        if n_cut < thr.zero_one_line_periods * period:
            why = (
                f"; not used: the spectrum is a line spectrum whose slowest base "
                f"spans {period:.1f} samples, and lags up to {n_cut} cover fewer than 5 of "
                "its periods (a long period then mimics diffusion)"
            )
            return Evidence("zero_one", e.value, None, e.detail + why)
    return e


def _check_signal_settings(given: dict) -> int:
    """Check classify_signal's settings; returns the 0-1 test's samples per forcing period."""
    rules = dict(dt="real>0", forcing_period="real>0?", lyapunov="number?",
                 lyapunov_tol="real>=0?", max_period="int>=1?", min_points_aperiodic="int>=1?",
                 zero_one_per_period="int>=1?", seed="int>=0", exponent_time="real>0")  # fmt: skip
    check_settings("classify_signal", **{k: (given[k], rule) for k, rule in rules.items()})
    per_period, forcing_period = given["zero_one_per_period"], given["forcing_period"]
    (lo, hi), dt, n = SAMPLING_DT, given["dt"], given["x"].size
    if not lo <= dt <= hi:
        raise ValueError(f"classify_signal: dt = {dt!r} s must be in [{lo:g}, {hi:g}] s")
    if forcing_period is not None and not 2 * dt <= forcing_period <= n * dt:
        raise ValueError(f"classify_signal: forcing_period = {forcing_period!r} s must be in "
                         f"[2 dt, N dt] = [{2 * dt:g}, {n * dt:g}] s")  # fmt: skip
    most = 4 if forcing_period is None else max(1, round(forcing_period / dt))
    if per_period is not None and forcing_period is not None and per_period > most:
        raise ValueError(
            f"classify_signal: zero_one_per_period = {per_period} must be <= {most}, "
            "the samples per forcing period"
        )
    options = given["spectrum_options"]
    if options is not None and not isinstance(options, dict):
        raise TypeError(f"classify_signal: spectrum_options must be a dict, got {options!r}")
    if "forcing_frequency" in (options or {}):
        raise TypeError("classify_signal: the spectrum's forcing_frequency is 1 / forcing_period")
    check_spectrum_options("classify_signal: spectrum_options", options or {})
    return min(4, most) if per_period is None else per_period


def _spectrum_evidence(spec) -> Evidence:
    """The spectrum's vote: its line model's, the residual fraction as the value."""
    if spec.model not in _SPECTRUM_VOTES:
        return Evidence("spectrum", None, None, spec.message)
    bases = ", ".join(f"{f:.5g}" for f in spec.base_frequencies)
    txt = (
        f"{spec.model}: line model holds {spec.line_fraction:.6f} of the power "
        f"(bases {bases} Hz; spectral entropy {spec.spectral_entropy:.3f})"
    )
    return Evidence("spectrum", spec.residual_fraction, _SPECTRUM_VOTES[spec.model], txt)


def _series_evidence(x, dt, t_char, thr: Thresholds) -> Evidence:
    """Rosenstein's λ₁ T against ``series_chaotic`` and ``series_regular``, unless doubtful."""
    res, failed = safe("lyapunov_series", lyapunov_from_series, x, dt, warn=False)
    if failed:
        return failed
    if res.doubtful or t_char is None:
        why = "; ".join(res.reasons) or "no time scale"
        txt = f"Rosenstein λ₁ = {res.exponent:.4g}, doubtful: {why}"
        return Evidence("lyapunov_series", res.exponent, None, txt)
    lt = res.exponent * t_char
    txt = f"Rosenstein λ₁ = {res.exponent:.4g} (λ₁ T = {lt:.3f})"
    if lt > thr.series_chaotic:
        return Evidence("lyapunov_series", res.exponent, "chaotic", txt)
    if abs(lt) < thr.series_regular:
        return Evidence("lyapunov_series", res.exponent, "not_chaotic", txt)
    return Evidence("lyapunov_series", res.exponent, None, txt + ": inconclusive")


def classify_signal(
    x,
    dt: float,
    forcing_period: float | None = None,
    section=None,
    lyapunov: float | None = None,
    *,
    lyapunov_tol: float | None = None,
    angle_periods: Sequence[float | None] | None = None,
    rtol: float | None = None,
    atol=None,
    max_period: int | None = None,
    min_points_aperiodic: int | None = None,
    series_lyapunov: bool = False,
    zero_one_per_period: int | None = None,
    spectrum_options: dict | None = None,
    seed: int = 0,
    thresholds: Thresholds | None = None,
    exponent=None,
    exponent_time: float = 1.0,
) -> Verdict:
    """Classify a uniformly sampled flow signal (and optional section points) by votes.

    Evidence (numbers from `Thresholds`; the spectrum's from `spectrum_options`, its
    broadband tolerance recorded in ``settings["broadband_tol"]``):

    * ``spectrum`` (`spectrum_analysis`, forcing frequency 1 / `forcing_period`): a harmonic
      comb votes periodic, two incommensurate bases quasiperiodic, broadband >= 1 % chaotic,
      a smaller unexplained remainder "not_periodic".
    * ``zero_one`` (`zero_one_evidence`) on a map-like sequence: forced, the signal sampled
      `zero_one_per_period` times per forcing period less its forcing-synchronous mean;
      unforced, the successive `local_maxima`; K = 0 when nothing is left. A chaotic K is
      dropped per `Thresholds.zero_one_line_periods`.
    * `classify_section`'s evidence for `section` (prefixed ``section_``), ``exponent`` and
      ``lyapunov`` (here per unit time).
    * ``lyapunov_series`` (`series_lyapunov`): `lyapunov_from_series`, when not doubtful.

    The votes are combined by `combine`. The period comes from the section, else from the
    spectrum of a forced signal, else 1 (the signal's own fundamental, noted in `reasons`).

    Raises ValueError on NaN or infinite samples, `dt` outside `SAMPLING_DT`, or a
    `forcing_period` outside [2 dt, N dt].
    Limits: ~20 s of a cam signal (~90 forcing periods) gives the 0–1 test ~360 samples and
    the spectrum subharmonics up to order 9: a periodic call is solid, quasiperiodic versus
    chaotic rests on the spectrum and the 0–1 test agreeing.

    Parameters
    ----------
    x : array_like, shape (N,)
        Uniformly sampled signal after the transient (e.g. θ_f(t)).
    dt, forcing_period : float
        Sampling interval and (optional) forcing period [s], e.g. 2π / ω of the cam.
    section : array_like, shape (M,) or (M, d), optional
        Section points (e.g. stroboscopic (θ, θ̇) once per forcing period).
    lyapunov : float, optional
        Largest Lyapunov exponent [1/s] computed elsewhere.
    lyapunov_tol : float, optional
        ``|λ₁|`` [1/s] counted as zero; default `Thresholds.signal_lyapunov_tol` / T (T the
        forcing period, else the spectrum's fundamental period).
    angle_periods, rtol, atol, max_period, min_points_aperiodic, thresholds, seed
        As for `classify_section`.
    series_lyapunov : bool
        Also estimate λ₁ from the signal with nolds (~0.2–0.5 s more).
    zero_one_per_period : int, optional
        Samples per forcing period for the 0–1 test, at most the signal's own (default 4).
    spectrum_options : dict, optional
        Extra keyword arguments of `spectrum_analysis`.
    exponent, exponent_time
        As for `classify_section`; `exponent_time` makes λ per forcing period.

    Returns
    -------
    Verdict
        "undetermined" for a constant signal (an equilibrium, whatever its section says).
    """
    x = as_series(x, min_size=MIN_SERIES)
    zero_one_per_period = _check_signal_settings(locals())
    if section is not None:
        section = as_points(section, "section")
        check_atol("classify_signal", atol, section.shape[1])
    thr = resolve(thresholds, rtol, min_points_aperiodic)
    settings = dict(
        dt=dt,
        forcing_period=forcing_period,
        lyapunov_tol=lyapunov_tol,
        rtol=thr.period_rtol,
        atol=atol,
        max_period=max_period,
        angle_periods=None if angle_periods is None else list(angle_periods),
        min_points_aperiodic=thr.min_points_aperiodic,
        series_lyapunov=series_lyapunov,
        zero_one_per_period=zero_one_per_period,
        spectrum_options=dict(spectrum_options or {}),
        seed=seed,
        thresholds=thr.to_dict(),
    )
    if x.size < 2 or np.ptp(x) <= thr.constant_signal * max(1.0, float(np.max(np.abs(x)))):
        why = "constant signal: an equilibrium, not an oscillation"
        return Verdict("undetermined", None, (), (why,), settings)
    ev: list[Evidence] = []
    periods: dict[str, int] = {}
    reasons: list[str] = []
    f_force = None if forcing_period is None else 1.0 / forcing_period
    spec, failed = safe(
        "spectrum", spectrum_analysis, x, dt, forcing_frequency=f_force, **(spectrum_options or {})
    )
    t_char, line_freq = forcing_period, None
    if failed:
        ev.append(failed)
    else:
        settings["broadband_tol"] = spec.settings["broadband_tol"]
        ev.append(_spectrum_evidence(spec))
        if spec.model == "periodic" and spec.period is not None:
            periods["spectrum"] = spec.period
        if spec.model not in _SPECTRUM_VOTES:
            reasons.append(f"spectrum: {spec.message}")
        if t_char is None and spec.base_frequencies and spec.base_frequencies[0] > 0:
            t_char = 1.0 / spec.base_frequencies[0]
        if spec.model in ("periodic", "quasiperiodic"):
            line_freq = min(spec.base_frequencies)
    e01, failed = safe("zero_one", _zero_one_signal, x, dt, forcing_period, seed,
                       int(zero_one_per_period), line_freq, thr)  # fmt: skip
    ev.append(failed or e01)
    if section is not None:
        sev, speriods, sreasons = section_evidence(section, thr, angle_periods=angle_periods,
                                                   atol=atol, max_period=max_period,
                                                   zero_one=True, seed=seed)  # fmt: skip
        ev.extend(sev)
        periods.update(speriods)
        reasons.extend(sreasons)
    tol = lyapunov_tol
    if tol is None and t_char is not None:
        tol = thr.signal_lyapunov_tol / t_char
    ev += exponent_votes(thr, exponent, exponent_time, lyapunov, tol, "per unit time")[0]
    if series_lyapunov:
        ev.append(_series_evidence(x, dt, t_char, thr))
    settings["lyapunov_tol_used"] = tol
    verdict = combine(ev, periods, reasons, settings)
    if verdict.label == "periodic" and forcing_period is None and section is None:
        note = (
            "no forcing period and no section: the period is counted in periods of the "
            "signal's own fundamental (1)"
        )
        verdict = dataclasses.replace(verdict, period=1, reasons=(*verdict.reasons, note))
    return verdict
