"""Largest Lyapunov exponent from the equations: Benettin's two-trajectory method and the
tangent-map (QR) method for maps with a Jacobian."""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field

import numpy as np

from .._util import freeze_fields
from ._validate import check_settings

__all__ = [
    "LyapunovResult",
    "LyapunovSpectrum",
    "lyapunov_benettin",
    "lyapunov_benettin_map",
    "lyapunov_spectrum_map",
]

_LINEAR_LIMIT = 1e-3  # separation, relative to 1 + |x|, beyond which linearity is doubtful


@dataclass(frozen=True)
class LyapunovResult:
    """Largest Lyapunov exponent estimated by `lyapunov_benettin`.

    Attributes
    ----------
    exponent : float
        Largest exponent, per unit time (per iterate for maps unless `time_per_iterate`
        was given). NaN when the estimate failed (see `message`).
    stderr : float
        Standard error from 20 batch means of the log growth (a statistical error only:
        it says nothing about the bias from a too-short run or a too-large d0).
    running : ndarray
        Running estimate after each renormalisation (after the alignment phase).
    total_time : float
        Time (or iterates × time_per_iterate) averaged over.
    max_log_growth : float
        Largest log growth ln(d/d0) over one renormalisation interval (compare with λ₁ τ).
    message : str
        Empty when nothing looked wrong; otherwise what did.
    settings : dict
        Everything the estimate used.
    """

    exponent: float
    stderr: float
    running: np.ndarray
    total_time: float
    max_log_growth: float
    message: str = ""
    settings: dict = field(default_factory=dict)

    def __post_init__(self) -> None:
        freeze_fields(self, "running", "settings")


@dataclass(frozen=True)
class LyapunovSpectrum:
    """Lyapunov exponents from `lyapunov_spectrum_map`, largest first.

    Attributes
    ----------
    exponents : ndarray
        The exponents, per iterate divided by `time_per_iterate`.
    stderr : ndarray
        Batch-means standard error of each exponent.
    settings : dict
        The settings used.
    """

    exponents: np.ndarray
    stderr: np.ndarray
    settings: dict = field(default_factory=dict)

    def __post_init__(self) -> None:
        freeze_fields(self, "exponents", "stderr", "settings")

    @property
    def largest(self) -> float:
        """The largest exponent."""
        return float(self.exponents[0])


def _batch_stderr(values: np.ndarray, n_batches: int = 20) -> float:
    n = values.size // n_batches
    if n < 1:
        return math.nan
    means = values[: n * n_batches].reshape(n_batches, n).mean(axis=1)
    return float(means.std(ddof=1) / math.sqrt(n_batches))


def lyapunov_benettin(
    advance: Callable[[np.ndarray, float], np.ndarray],
    x0,
    *,
    renorm_time: float,
    n_renorm: int,
    d0: float = 1e-8,
    transient_time: float = 0.0,
    components: Sequence[int] | None = None,
    n_align: int = 10,
    seed: int = 0,
) -> LyapunovResult:
    """Largest Lyapunov exponent of a flow by Benettin's two-trajectory method.

    A reference trajectory x and a companion y = x + d0 u (u a random unit vector in the
    perturbed components S) are advanced together for τ = `renorm_time`; the separation
    ``d_i = ||(y - x)_S||`` is recorded and y is pulled back to distance d0 along it. After
    `n_align` renormalisations (the separation turns to the most unstable direction),

        λ₁ = 1 / (n τ) Σ_{i=1}^{n} ln(d_i / d0)

    (Benettin, Galgani, Giorgilli & Strelcyn 1980, Meccanica 15, 9; Parker & Chua 1989,
    "Practical Numerical Algorithms for Chaotic Systems", §4.2).

    Parameters
    ----------
    advance : callable
        ``advance(state, duration) -> state``: the system's own integrator. It may handle
        impacts or other discontinuities itself (non-smooth systems): the method only
        compares states, it never differentiates the vector field.
    x0 : array_like
        Initial state.
    renorm_time : float
        τ, the time between renormalisations. Keep ``λ₁ τ`` below ~ 5 so that the
        separation stays small (d0 e^{λτ} << the attractor's size).
    n_renorm : int
        Number of renormalisations averaged (after alignment).
    d0 : float
        Separation, in state units. It must be far above the integrator's error and far
        below the attractor's size; 1e-8 suits O(1) states integrated to ~1e-12.
    transient_time : float
        Advanced first and discarded, to reach the attractor.
    components : sequence of int, optional
        State components perturbed and measured (default all). For a forced system carried
        as (x, v, ..., t), exclude the time: with ``components=(0, 1)`` the exponent is that
        of the (x, v) dynamics.
    n_align : int
        Renormalisations discarded at the start.
    seed : int
        Seed of the initial direction (``numpy.random.default_rng(SeedSequence(seed))``).

    Returns
    -------
    LyapunovResult

    Notes
    -----
    Zero exponents: an autonomous flow has one exponent exactly zero, along the flow, so
    its periodic orbits have λ₁ = 0 and only λ₁ > 0 signals chaos. For a forced system
    carried with time (or the forcing phase) as a state variable, the trivial zero
    exponent belongs to that direction; the exponents of the (x, v) dynamics (those of the
    stroboscopic map divided by the forcing period) do not contain it: a periodic response
    has λ₁ < 0, a quasiperiodic one λ₁ = 0, a chaotic one λ₁ > 0.

    Limits: a finite-time average; `stderr` shrinks like 1/sqrt(total time) and is large
    for weakly chaotic or intermittent systems. For a non-smooth system, two trajectories
    on either side of an impact (or stick/slip switch) at a renormalisation instant are a
    jump apart, not d0 e^{λτ}, and that interval dominates the sum: `message` flags any
    interval ending with a separation above 1e-3 (1 + |x|) (an impact or switch between
    the two, or a `renorm_time` too long for d0; compare `max_log_growth` with λ₁ τ).
    Grazing impacts make the flow's derivative unbounded and the exponent ill-defined.
    """
    check_settings(
        "lyapunov_benettin",
        renorm_time=(renorm_time, "real>0"),
        n_renorm=(n_renorm, "int>=1"),
        d0=(d0, "real>0"),
        transient_time=(transient_time, "real>=0"),
        n_align=(n_align, "int>=0"),
        seed=(seed, "int>=0"),
    )
    x = np.array(x0, dtype=float)
    comps = np.arange(x.size) if components is None else np.asarray(components, dtype=int)
    settings = dict(
        renorm_time=renorm_time,
        n_renorm=n_renorm,
        d0=d0,
        transient_time=transient_time,
        components=tuple(int(c) for c in comps),
        n_align=n_align,
        seed=seed,
    )
    if transient_time > 0:
        x = np.asarray(advance(x, transient_time), dtype=float)
    rng = np.random.default_rng(np.random.SeedSequence(seed))
    u = rng.standard_normal(comps.size)
    u /= np.linalg.norm(u)
    y = x.copy()
    y[comps] += d0 * u
    logs = np.empty(int(n_renorm))
    total = int(n_align) + int(n_renorm)
    message = ""
    worst = 0.0  # largest separation relative to the linear limit
    for i in range(total):
        x = np.asarray(advance(x, renorm_time), dtype=float)
        y = np.asarray(advance(y, renorm_time), dtype=float)
        delta = y[comps] - x[comps]
        d = float(np.linalg.norm(delta))
        if not math.isfinite(d):
            return LyapunovResult(
                math.nan,
                math.nan,
                np.array([]),
                0.0,
                math.nan,
                "non-finite state: the integration diverged",
                settings,
            )
        if d == 0.0:
            return LyapunovResult(
                -math.inf,
                math.nan,
                np.array([]),
                0.0,
                math.nan,
                "the two trajectories merged (d = 0): contraction faster than d0 can "
                "resolve; the exponent is strongly negative",
                settings,
            )
        if i >= n_align:
            logs[i - n_align] = math.log(d / d0)
            worst = max(worst, d / (_LINEAR_LIMIT * (1.0 + float(np.linalg.norm(x[comps])))))
        y = x.copy()
        y[comps] += d0 * delta / d
    exponent = float(logs.mean() / renorm_time)
    running = np.cumsum(logs) / (renorm_time * np.arange(1, logs.size + 1))
    max_growth = float(logs.max())
    if worst > 1.0:
        message = (
            f"the separation left the linear regime (largest growth e^{max_growth:.1f} in one "
            "interval): an impact or switch may have separated the two trajectories at a "
            "renormalisation instant, or renorm_time is too long for d0"
        )
    stderr = _batch_stderr(logs) / renorm_time
    return LyapunovResult(
        exponent, stderr, running, n_renorm * renorm_time, max_growth, message, settings
    )


def lyapunov_benettin_map(
    step: Callable[[np.ndarray], np.ndarray],
    x0,
    n: int,
    *,
    d0: float = 1e-8,
    transient: int = 0,
    components: Sequence[int] | None = None,
    n_align: int = 10,
    seed: int = 0,
    time_per_iterate: float = 1.0,
) -> LyapunovResult:
    """Largest Lyapunov exponent of a map ``x_{k+1} = step(x_k)`` by Benettin's method.

    Same estimator as `lyapunov_benettin` with one renormalisation per iterate:
    ``λ₁ = 1 / (n T) Σ ln(d_k / d0)`` with T = `time_per_iterate` (1: per iterate; the
    forcing period: per unit time for a stroboscopic map). `step` may be a Poincaré or
    stroboscopic map of a non-smooth system computed by the simulator.

    See `lyapunov_benettin` for the parameters, the zero-exponent conventions and the limits.
    """

    check_settings(
        "lyapunov_benettin_map",
        n=(n, "int>=1"),
        d0=(d0, "real>0"),
        transient=(transient, "int>=0"),
        n_align=(n_align, "int>=0"),
        seed=(seed, "int>=0"),
        time_per_iterate=(time_per_iterate, "real>0"),
    )

    def advance(state, k):
        for _ in range(int(round(k))):
            state = step(state)
        return state

    res = lyapunov_benettin(
        advance,
        x0,
        renorm_time=1.0,
        n_renorm=n,
        d0=d0,
        transient_time=float(transient),
        components=components,
        n_align=n_align,
        seed=seed,
    )
    settings = dict(res.settings, time_per_iterate=time_per_iterate)
    t = float(time_per_iterate)
    return LyapunovResult(
        res.exponent / t,
        res.stderr / t,
        res.running / t,
        res.total_time * t,
        res.max_log_growth,
        res.message,
        settings,
    )


def lyapunov_spectrum_map(
    step: Callable[[np.ndarray], np.ndarray],
    jacobian: Callable[[np.ndarray], np.ndarray],
    x0,
    n: int,
    *,
    transient: int = 0,
    n_exponents: int | None = None,
    time_per_iterate: float = 1.0,
) -> LyapunovSpectrum:
    """Lyapunov exponents of a map from its Jacobian, by repeated QR (tangent map).

    With ``Q_0 = I`` and ``J(x_k) Q_k = Q_{k+1} R_{k+1}`` (QR with positive diagonal), the
    exponents are (Benettin et al. 1980; Eckmann & Ruelle 1985, Rev. Mod. Phys. 57, 617,
    §IV.C)

        λ_i = 1 / (n T) Σ_{k=1}^{n} ln |R_k[i, i]|.

    For a 1-D map this is the mean of ln |f'(x_k)|.

    Parameters
    ----------
    step, jacobian : callable
        ``step(x) -> x'`` and ``jacobian(x) -> (d, d) array``.
    x0 : array_like
        Initial state.
    n, transient : int
        Iterates averaged, and iterates discarded first.
    n_exponents : int, optional
        How many exponents (default all).
    time_per_iterate : float
        Divide by this to get exponents per unit time.

    Returns
    -------
    LyapunovSpectrum

    Notes
    -----
    Checks: the exponents sum to the mean of ln |det J| (for the Hénon map, ln b). The
    method needs a Jacobian everywhere along the orbit; for non-smooth maps use
    `lyapunov_benettin_map` (or supply the saltation-corrected Jacobian). An orbit that
    lands exactly on a critical point (f'(x) = 0) gives -inf.
    """
    x = np.array(x0, dtype=float).reshape(-1)
    d = x.size
    check_settings(
        "lyapunov_spectrum_map",
        n=(n, "int>=1"),
        transient=(transient, "int>=0"),
        n_exponents=(n_exponents, "int>=1?"),
        time_per_iterate=(time_per_iterate, "real>0"),
    )
    m = d if n_exponents is None else int(n_exponents)
    if m > d:
        raise ValueError(
            f"lyapunov_spectrum_map: n_exponents = {m} must be <= {d}, the state's dimension"
        )
    for _ in range(int(transient)):
        x = np.asarray(step(x), dtype=float).reshape(-1)
    q = np.eye(d)[:, :m]
    logs = np.empty((int(n), m))
    for k in range(int(n)):
        j = np.asarray(jacobian(x), dtype=float).reshape(d, d)
        q, r = np.linalg.qr(j @ q)
        diag = np.diag(r)
        with np.errstate(divide="ignore"):
            logs[k] = np.log(np.abs(diag))
        q = q * np.where(diag < 0, -1.0, 1.0)[None, :]
        x = np.asarray(step(x), dtype=float).reshape(-1)
    t = float(time_per_iterate)
    exps = logs.mean(axis=0) / t
    errs = np.array([_batch_stderr(logs[:, i]) for i in range(m)]) / t
    settings = dict(n=n, transient=transient, n_exponents=m, time_per_iterate=t)
    return LyapunovSpectrum(exps, errs, settings)
