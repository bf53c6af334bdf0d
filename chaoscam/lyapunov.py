"""lyapunov_model(params, ...) -> ModelLyapunov: the largest Lyapunov exponent of the model.

Benettin's two-trajectory method driven by the compiled RK4 + impact kernel
(:func:`chaoscam.integrate._kernel.run_chunk`) directly: a reference trajectory and a companion
a distance d0 away are advanced interval by interval (one cam period by default), the
separation is measured and the companion is pulled back to d0 along it. Both trajectories
read the same array of line-length draws, so with a random line length (sigma > 0) they see
the same noise realization, the one ``simulate(params, seed=seed, index=index)`` sees.

This module sits above the kernels and :mod:`chaoscam._simulate`; the analysis layer
(:func:`chaoscam.analysis.lyapunov_benettin`) holds the generic method, which is used here
as an independent cross-check in the tests.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from ._checks import params_arg, whole, with_overrides
from ._frozen import freeze_fields
from ._version import __version__
from .integrate import Status, kernel_constants
from .integrate import _kernel as k
from .integrate._constants import initial_counters, initial_state
from .integrate._driver import Buffers, advance_pair, check_window, drive
from .model import LineLengthStream, ParameterError, Params

__all__ = ["ModelLyapunov", "lyapunov_model"]

_BLOCK = 4096  # line-length draws per refill


@dataclass(frozen=True)
class ModelLyapunov:
    """The largest Lyapunov exponent of one realization, from the model's equations.

    Attributes
    ----------
    exponent : float
        λ₁ [1/s]; NaN when it could not be computed (see `message`), -inf when the two
        trajectories merged to the last bit.
    per_period : float
        λ₁ T, the exponent per iterate of the stroboscopic map (T = 2 pi / omega).
    stderr : float
        Standard error [1/s] from 20 batch means of the interval log growths (statistical
        only; NaN with fewer than 20 intervals).
    running : ndarray
        Running estimate [1/s] after each averaged interval.
    total_time : float
        Time averaged over [s].
    n_intervals : int
        Renormalisation intervals averaged.
    max_log_growth : float
        Largest ln(d / d0) over one interval (compare with λ₁ τ).
    postponed : int
        Renormalisations postponed because the two trajectories were on either side of an
        impact (one had jumped, the other not yet).
    unsynced : int
        Renormalisations done while the impact counts still differed after `max_wait`
        steps (a chattering sequence ended one micro-impact apart, or a grazing impact).
    status : Status
        How the reference run ended (``Status.OK`` unless it failed).
    message : str
        Empty when nothing looked wrong; otherwise what did, and what to do.
    settings : dict
        Everything the estimate used.
    """

    exponent: float
    per_period: float
    stderr: float
    running: np.ndarray
    total_time: float
    n_intervals: int
    max_log_growth: float
    postponed: int
    unsynced: int
    status: Status
    message: str = ""
    settings: dict[str, Any] = field(default_factory=dict)

    def __post_init__(self) -> None:
        freeze_fields(self, "running", "settings")

    @property
    def ok(self) -> bool:
        """True when the exponent is a number (finite or -inf)."""
        return not math.isnan(self.exponent)


def _growths(logs, lengths, window, synced) -> str:
    """' (mean growth ... against ... for the others)' over the averaged window, in 1/s."""
    u, o = window & ~synced, window & synced
    if not (u.any() and o.any()):
        return ""
    r = [float(logs[m].sum() / lengths[m].sum()) for m in (u, o)]
    return f" (their growth {r[0]:+.3g} 1/s against {r[1]:+.3g} 1/s for the others)"


class _Draws:
    """The line-length draws shared by both trajectories (one stream, one array)."""

    def __init__(self, stream: LineLengthStream, block: int) -> None:
        self.stream = stream
        self.block = block
        self.lam = stream.draw(block)
        self.counters: list[np.ndarray] = []

    def refill(self) -> None:
        lo = min(int(c[k.I_LAM_POS]) for c in self.counters)
        self.lam = np.concatenate([self.lam[lo:], self.stream.draw(self.block)])
        for c in self.counters:
            c[k.I_LAM_POS] -= lo


class _Runner:
    """Advances one trajectory through the kernel's driver; counts the impacts it applies."""

    def __init__(self, y, cnt, c, draws: _Draws, per_step: int) -> None:
        self.y, self.cnt, self.c, self.draws = y, cnt, c, draws
        self.per_step = per_step
        self.buffers = Buffers.empty(1, 8 * per_step, 8 * per_step)
        self.n_impacts = 0
        draws.counters.append(cnt)

    def _on_rows(self, name: str, rows: np.ndarray) -> None:
        if name == "impacts":
            self.n_impacts += len(rows)

    def _more_draws(self, lam: np.ndarray) -> np.ndarray:
        if self.cnt[k.I_LAM_POS] + 2 * self.per_step >= self.draws.lam.shape[0]:
            self.draws.refill()
        return self.draws.lam

    def run_to(self, n_to: int) -> int:
        return drive(
            self.y,
            self.cnt,
            self.c,
            n_to,
            self.draws.lam,
            self.buffers,
            on_rows=self._on_rows,
            more_draws=self._more_draws,
            run=k.run_chunk,  # both trajectories are on the RK4 grid (see lyapunov_model)
        )


def _postpone(ref: _Runner, cmp: _Runner, wait: int, n_stop: int) -> tuple[int, int, str]:
    """Step both trajectories a grid step at a time until they have applied as many impacts
    (at most ``wait`` steps, not past ``n_stop``): compiled (:func:`advance_pair`), with the
    buffers and draws seen to here when it stops for them. Returns (steps waited, status
    code, which trajectory a code other than OK belongs to)."""
    waited = 0
    bufs = [(r.buffers.series, r.buffers.section, r.buffers.impacts) for r in (ref, cmp)]
    while True:
        steps, code, who = advance_pair(
            ref.y, ref.cnt, cmp.y, cmp.cnt, ref.c, ref.draws.lam, *bufs,
            ref.n_impacts - cmp.n_impacts, wait - waited, n_stop,
        )  # fmt: skip
        waited += steps
        if who == 0:
            break
        if code != k.NEED_BUFFER:
            return waited, code, ("reference", "companion")[who - 1]
        n1 = int(ref.cnt[k.I_STEP]) + (1 if who == 1 else 0)  # the step under way
        for name, tr in (("reference", ref), ("companion", cmp))[who - 1 :]:
            code = tr.run_to(n1)
            if code != k.OK:
                return waited, code, name
        waited += 1
    for r in (ref, cmp):  # count the impact rows advance_pair left in the buffers
        r.n_impacts += int(r.cnt[k.I_N_IMPACT])
        r.cnt[[k.I_N_SERIES, k.I_N_SECTION, k.I_N_IMPACT]] = 0
    return waited, k.OK, ""


def _batch_stderr(values: np.ndarray, n_batches: int = 20) -> float:
    n = values.size // n_batches
    if n < 1:
        return math.nan
    means = values[: n * n_batches].reshape(n_batches, n).mean(axis=1)
    return float(means.std(ddof=1) / math.sqrt(n_batches))


def _no_exponent(msg, status, postponed, unsynced, settings) -> ModelLyapunov:
    nan = math.nan
    return ModelLyapunov(
        nan, nan, nan, np.array([]), 0.0, 0, nan, postponed, unsynced, status, msg, settings
    )


def lyapunov_model(
    params: Params | None = None,
    *,
    duration: float = 20.0,
    transient: float = 0.0,
    seed: int = 0,
    index: int = 0,
    renorm_periods: int = 1,
    d0: float = 1e-8,
    theta_scale: float = 1.0,
    omega_scale: float | None = None,
    n_align: int = 5,
    max_wait: int | None = None,
    direction_seed: int = 0,
    exclude_unsynced: bool = False,
    **overrides: Any,
) -> ModelLyapunov:
    """Largest Lyapunov exponent of the cam-follower model by Benettin's two-trajectory method.

    The reference trajectory starts where :func:`chaoscam.simulate` starts (in contact, or at
    ``theta_f0``/``omega_f0``) and is the same RK4 + located-impact run; the companion starts
    at a distance `d0` in a random direction (`direction_seed`). Every `renorm_periods` cam
    periods (at the grid step nearest to i τ, τ = renorm_periods 2 pi / omega) the
    separation d_i is measured in the scaled space

        ``d = sqrt((Δθ_f / theta_scale)² + (Δθ̇_f / omega_scale)²)``,

    (defaults theta_scale = 1 rad and omega_scale = omega, the cam speed: both terms are then
    angles, Δθ̇_f / omega being the change of dθ_f/dθ_c), and the companion is put back at
    ``reference + d0 (Δ / d)`` with the reference's discrete state (line length in use,
    resampling and section counters). The exponent is (Benettin, Galgani, Giorgilli &
    Strelcyn 1980, Meccanica 15, 9)

        ``λ₁ = Σ ln(d_i / d0) / Σ τ_i``,

    over the intervals that end after `transient` and after the first `n_align` (which let
    the separation turn to the most unstable direction). The scaling changes finite-time
    values only, not the limit.

    Impacts: the restitution jump (4) makes the flow discontinuous (its derivative, with the
    saltation matrix, is finite away from grazing); twins d0 apart hit the cam a lag ~ d0
    apart, during which their separation is the jump's size, so a renormalisation in such a
    lag is postponed step by step (up to `max_wait` steps) until both applied the same
    number of jumps. A mismatch that persists (`unsynced`, named in `message`) is here a
    chattering sequence that ended one micro-impact apart (approach speeds ~5e-7 m/s: a
    tiny jump) or a grazing contact. Those intervals are averaged by default: on the
    default model they are sticking phases, 21 % of the intervals and strongly contracting,
    and leaving them out (``exclude_unsynced=True``) raised λ₁ from +1.67 ± 0.09 to +3.83 ±
    0.14 1/s (320 s after 20 s; the tangent exponent: +1.82 at dt/2, +1.51 at dt/4; an
    independent referee's twins, renormalised every period whatever the impacts: +1.48).
    At ξ = 0.43, x_O = -0.45, ω = 45 and v_min = 1e-3 it changed nothing beyond the errors.

    Parameters
    ----------
    params : Params, optional
        The model (Table 1 defaults when omitted); keyword `overrides` are applied on top.
    duration : float
        End time [s] (the paper: 20 s).
    transient : float
        Intervals ending before this time are not averaged [s].
    seed, index : int
        The realization of the random line length (the same as ``simulate``'s).
    renorm_periods : int
        Cam periods between renormalisations. Keep λ₁ τ below ~5.
    d0 : float
        Separation in the scaled space [rad]: far above the event-location error (1e-12 s
        times the speeds, ~1e-12 rad) and far below the attractor's size (~0.1 rad).
    theta_scale : float
        Scale of θ_f in the separation [rad].
    omega_scale : float, optional
        Scale of θ̇_f in the separation [rad/s]; default omega (the cam speed).
    n_align : int
        Intervals discarded at the start (at least; more when `transient` asks for it).
    max_wait : int, optional
        Most grid steps a renormalisation is postponed; default 1 % of a cam period.
    direction_seed : int
        Seed of the initial direction (``numpy.random.default_rng(SeedSequence(...))``).
    exclude_unsynced : bool
        Leave out the intervals that end with different impact counts (biased: see Impacts).

    Returns
    -------
    ModelLyapunov
        With NaN and a message when either trajectory ends with a status other than OK
        (left the cam's reach, diverged) or when fewer than one interval is averaged.

    Notes
    -----
    Which exponent is the trivial zero: the forced system is an autonomous flow in
    (θ_f, θ̇_f, θ_c) with θ_c = omega t + θ_c0; its exponent along θ_c (the time, or phase,
    direction) is exactly zero. This method perturbs and measures only (θ_f, θ̇_f) at equal
    times, i.e. it follows the stroboscopic map (θ_f, θ̇_f) -> (θ_f, θ̇_f) after one cam
    period, whose two exponents (divided by T) carry no trivial zero. So a periodic response
    has λ₁ < 0, a quasiperiodic one λ₁ = 0 and a chaotic one λ₁ > 0.

    Cost: about twice ``simulate(series=False)`` (``benchmarks/bench_lyapunov_model.py``),
    plus one Python call per interval (postponed steps run compiled: :func:`advance_pair`).

    Limits: a finite-time average (see `stderr`); near a grazing impact the flow's
    derivative is unbounded (watch `unsynced`). Contact is the weak case: the static
    penetration is ~3e-9 m, so d0 = 1e-8 rad (5e-9 m at the contact) already lifts the
    follower off the cam, and twins that both stick to the cam can leave it bit for bit
    equal. Measured (v_min = 0, 2026-11-27): the default, 320 s after 20 s, +1.67 ± 0.09 1/s at
    d0 = 1e-8, +1.11 at 1e-6, -2.28 at 1e-4 (its 8 bands' scale), -inf at 1e-10 (merged while
    sticking); the contact orbit e = 0.02 m (20 s after 10 s): -inf at d0 = 1e-14 and 1e-11,
    -26.2 at 1e-8, -28.5 at 1e-5 (tangent at dt/4: -24.4). A finite-size exponent at scale
    d0, then: trust its sign only with the section and spectrum evidence, and -inf only where
    a larger d0 agrees. The tangent exponent (:func:`chaoscam.lyapunov_spectrum`) has no d0
    but overstates λ₁ on the default grid where chattering dominates (+2.60 at dt, +1.51 at
    dt/4 on the default; here +1.67 at dt).

    Integrator: both trajectories always run on the RK4 grid (``settings["integrator"]`` says
    so when another was asked for): adaptive steps differ between the two, and that noise
    enters the separation; in contact it biases the estimate (omega = 45 rad/s, period 7:
    +0.29 1/s adaptive, -0.75 1/s on the grid).
    """
    p = params_arg(params)
    if overrides:
        p = with_overrides(p, overrides, lyapunov_model)
    asked = p.integrator
    # Decision: both trajectories on the RK4 grid (docstring, 'Integrator').
    p = p.replace(integrator="rk4")
    duration, transient = check_window(duration, transient, dt=p.dt)
    renorm_periods = whole("renorm_periods", renorm_periods, low=1)
    seed, index = whole("seed", seed), whole("index", index)
    if not (math.isfinite(d0) and d0 > 0):
        raise ParameterError(f"d0 = {d0!r} must be > 0")
    om_scale = p.omega if omega_scale is None else float(omega_scale)
    if not (theta_scale > 0 and om_scale > 0):
        raise ParameterError("theta_scale and omega_scale must be > 0")
    t_wall = time.perf_counter()
    dt = p.dt
    period = p.cam_period
    tau = int(renorm_periods) * period
    n_stop = int(round(duration / dt))
    n_align = whole("n_align", n_align, low=0)
    wait = (
        max(1, int(0.01 * period / dt)) if max_wait is None else whole("max_wait", max_wait, low=1)
    )
    scale = np.array([theta_scale, om_scale])
    settings = dict(
        method="benettin two-trajectory, kernel-driven",
        duration=float(duration),
        transient=float(transient),
        seed=int(seed),
        index=int(index),
        renorm_periods=int(renorm_periods),
        renorm_time=tau,
        d0=float(d0),
        theta_scale=float(theta_scale),
        omega_scale=om_scale,
        n_align=int(n_align),
        max_wait=wait,
        direction_seed=int(direction_seed),
        exclude_unsynced=bool(exclude_unsynced),
        dt=dt,
        integrator="rk4" if asked == "rk4" else f"rk4 (asked: {asked}; see Notes)",
        version=__version__,
    )

    per_step = p.max_events_per_step + 2
    if p.resample == "interval":
        per_step += int(dt / p.resample_dt) + 2
    per_step = max(per_step, int(dt / period) + 2)
    draws = _Draws(LineLengthStream(p, seed, index), max(_BLOCK, 4 * per_step))
    c = kernel_constants(p, t_record=0.0, stride=0)
    cnt_ref = initial_counters(p)
    ref = _Runner(initial_state(p), cnt_ref, c, draws, per_step)
    rng = np.random.default_rng(np.random.SeedSequence(direction_seed))
    u = rng.standard_normal(2)
    u /= np.linalg.norm(u)
    cmp = _Runner(ref.y.copy(), cnt_ref.copy(), c, draws, per_step)
    cmp.y[:2] += d0 * u * scale
    cmp.cnt[k.I_SAFE_STEP] = 0  # the reference's flight horizon does not hold for a moved state
    cmp.cnt[k.I_SURFACE] = 0  # nor its surface flags

    logs: list[float] = []
    lengths: list[float] = []
    ends: list[float] = []
    synced: list[bool] = []
    postponed = unsynced = 0
    n_last = 0
    i = 0

    def failed(which: str, code: int) -> ModelLyapunov:
        st = Status(code)
        t_fail = (cmp if which == "companion" else ref).y[k.Y_TIME]
        msg = (
            f"the {which} trajectory ended with status {st.name} at t = {t_fail:.6g} s "
            f"({st.label}): {st.message} No exponent (NaN)."
        )
        settings["wall_time_s"] = time.perf_counter() - t_wall
        return _no_exponent(
            msg, st if which == "reference" else Status.OK, postponed, unsynced, settings
        )

    while ref.cnt[k.I_STEP] < n_stop:
        i += 1
        n_to = min(n_stop, int(round(i * tau / dt)))
        if n_to <= ref.cnt[k.I_STEP]:
            continue
        for which, tr in (("reference", ref), ("companion", cmp)):
            code = tr.run_to(n_to)
            if code != k.OK:
                return failed(which, code)
        waited, code, which = _postpone(ref, cmp, wait, n_stop)
        if code != k.OK:
            return failed(which, code)
        postponed += waited > 0
        unsynced += ref.n_impacts != cmp.n_impacts
        delta = (cmp.y[:2] - ref.y[:2]) / scale
        d = float(np.hypot(delta[0], delta[1]))
        n_now = int(ref.cnt[k.I_STEP])
        if not math.isfinite(d):
            return failed("companion", k.NON_FINITE)
        logs.append(math.log(d / d0) if d > 0 else -math.inf)
        lengths.append((n_now - n_last) * dt)
        ends.append(n_now * dt)
        synced.append(ref.n_impacts == cmp.n_impacts)
        n_last = n_now
        if d == 0.0:
            break
        cmp.y[:] = ref.y
        cmp.y[:2] += d0 * (delta / d) * scale
        cmp.cnt[:] = ref.cnt
        cmp.cnt[k.I_SAFE_STEP] = 0  # the reference's flight horizon does not hold for cmp
        cmp.cnt[k.I_SURFACE] = 0  # nor its surface flags
        cmp.n_impacts = ref.n_impacts

    lg = np.asarray(logs)
    ln = np.asarray(lengths)
    window = (np.asarray(ends) > transient + 1e-12 * period) & (np.arange(lg.size) >= n_align)
    sync = np.asarray(synced, dtype=bool)
    keep = window & sync if exclude_unsynced else window
    settings["wall_time_s"] = time.perf_counter() - t_wall
    notes = []
    if lg.size and lg[-1] == -math.inf:
        notes.append(
            f"the two trajectories merged (d = 0 at t = {ends[-1]:.6g} s): the separation fell "
            "below what floating point resolves (both stuck to the cam, or a periodic orbit's "
            f"contraction); -inf at d0 = {d0:g} is a periodic orbit's signature only if a "
            "larger d0 agrees"
        )
        return ModelLyapunov(
            -math.inf,
            -math.inf,
            math.nan,
            np.array([]),
            float(ln.sum()),
            int(lg.size),
            math.nan,
            postponed,
            unsynced,
            Status.OK,
            "; ".join(notes),
            settings,
        )
    if not keep.any():
        msg = (
            f"no interval to average: {lg.size} intervals of {tau:.4g} s, of which the first "
            f"{n_align} and those ending before the transient {transient:g} s are discarded"
            + (f", and {unsynced} with different impact counts" if exclude_unsynced else "")
            + "; lengthen the run"
            + (" or lower d0" if unsynced else "")
        )
        return _no_exponent(msg, Status.OK, postponed, unsynced, settings)
    lk, tk = lg[keep], ln[keep]
    exponent = float(lk.sum() / tk.sum())
    running = np.cumsum(lk) / np.cumsum(tk)
    stderr = _batch_stderr(lk / tk)
    max_growth = float(lk.max())
    if unsynced:
        notes.append(
            f"{unsynced} of {lg.size} renormalisations ended with the impact counts still "
            f"different after {wait} steps (a chattering sequence that ended one micro-impact "
            "apart, or grazing, seen by one trajectory only): "
            + (
                "left out of the average (exclude_unsynced=True), which raises the estimate "
                "where they are contracting sticking phases"
                if exclude_unsynced
                else "kept in the average" + _growths(lg, ln, window, sync)
            )
        )
    if d0 * math.exp(max_growth) > 1e-3:
        notes.append(
            f"the separation left the linear regime (largest growth e^{max_growth:.1f} in one "
            "interval): lower renorm_periods or d0"
        )
    return ModelLyapunov(
        exponent,
        exponent * period,
        stderr,
        running,
        float(tk.sum()),
        int(lk.size),
        max_growth,
        postponed,
        unsynced,
        Status.OK,
        "; ".join(notes),
        settings,
    )
