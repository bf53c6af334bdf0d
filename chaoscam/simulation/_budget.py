"""Memory and time of a job, estimated before it starts: refuse what cannot fit, warn about hours.

Coarse upper-side guesses that catch absurd requests (a duration of 1e9 s, a series every
microsecond for minutes, picosecond adaptive steps from a tiny inertia), not predictions: 8 bytes
per number kept, time per step and series row over the workers, adaptive :func:`adaptive_seconds`.
"""

from __future__ import annotations

import math
import os

from .._util import ParameterError, warn

NS_PER_STEP = 40.0  # wall time of one grid step [ns] (8-65 ns, periodic to chaotic)
NS_PER_SERIES_ROW = 2000.0  # wall time of one series row [ns], its table row and Parquet write
WARN_SECONDS = 3600.0  # jobs estimated to take longer get a warning [s]
RUN_WARN_SECONDS = 60.0  # one run estimated to take longer gets a warning [s]
RUN_REFUSE_SECONDS = 2 * 3600.0  # one run estimated to take longer is refused [s]
# The adaptive path's cost (:func:`adaptive_seconds`): wall seconds per model second times T_c^2
# in persistent contact [s^2] (0.9e-10 to 2.1e-9 at rtol = 1e-12), the exponent of 1 / rtol
# (rtol 1e-13 to 1e-8), and a response with flights relative to persistent contact (0.006-0.35).
ADAPTIVE_COST = 1e-9
ADAPTIVE_RTOL_EXPONENT = 0.6
ADAPTIVE_FLIGHT_SHARE = 0.1

SERIES_BYTES_PER_ROW = 8 * 8  # the kernel's 4 columns and the 8 of the written table
SECTION_BYTES_PER_ROW = 3 * 5 * 8  # the kernel's buffer, the table and its copy


class JobEstimate(tuple):
    """(bytes, seconds) of a job."""

    @property
    def bytes(self) -> float:
        return self[0]

    @property
    def seconds(self) -> float:
        return self[1]


def available_memory() -> float:
    """Bytes this machine can give a job now (``MemAvailable``; physical memory elsewhere)."""
    try:
        with open("/proc/meminfo") as fh:
            for line in fh:
                if line.startswith("MemAvailable:"):
                    return float(line.split()[1]) * 1024.0
    except OSError:  # pragma: no cover - not Linux
        pass
    try:
        return float(os.sysconf("SC_PAGE_SIZE") * os.sysconf("SC_PHYS_PAGES"))
    except (ValueError, OSError, AttributeError):  # pragma: no cover
        return math.inf


def estimate(
    params, num, *, duration: float, transient: float = 0.0, series: bool = False,
    output_dt: float = 1e-3, runs: float = 1, in_memory: float = 1, workers: int = 1,
) -> JobEstimate:  # fmt: skip
    """Estimated (bytes, seconds) of ``runs`` realizations, ``in_memory`` of them held at once."""
    kept = max(0.0, float(duration) - float(transient))
    rows = kept / params.cam_period
    rows_series = kept / max(float(output_dt), num.dt) if series else 0.0
    per_run = rows_series * SERIES_BYTES_PER_ROW + rows * SECTION_BYTES_PER_ROW
    seconds = runs * run_seconds(params, num, duration, rows_series) / max(1, int(workers))
    return JobEstimate((per_run * in_memory, seconds))


def persistent_contact(params) -> bool:
    """Whether gravity holds the follower on the cam: m g l / (2 J) >= e omega^2 / l_1 (gravity's
    angular acceleration against the cam's largest, at the initial contact's lever arm)."""
    from ..model import contact_angle, lever_arm

    l1 = float(lever_arm(params, 0.0, contact_angle(params, 0.0)))
    gravity = params.m * params.g * params.l / (2.0 * params.inertia)
    return gravity * l1 >= params.e * params.omega**2


def adaptive_seconds(params, num, duration: float) -> float:
    """Wall time [s] the adaptive path needs to follow the contact for ``duration`` [s].

    ``t_wall = duration * s * ADAPTIVE_COST * (1e-12 / rtol)^ADAPTIVE_RTOL_EXPONENT / T_c^2``

    with ``T_c = 2 pi sqrt(J / (K_n l_1^2))`` the contact's natural period
    (:func:`chaoscam.model.contact_period`) and ``s = 1`` in persistent contact
    (:func:`persistent_contact`), else :data:`ADAPTIVE_FLIGHT_SHARE`: the error control must
    resolve the contact oscillation (measured on 2 cores, J = 1e-9 to 1e-2 kg m^2, Hertz and
    fractal stiffness). Limits: an order of magnitude either way; chattering can cost more.
    """
    from ..model import contact_period

    try:
        tc = contact_period(params)
        share = 1.0 if persistent_contact(params) else ADAPTIVE_FLIGHT_SHARE
    except (ArithmeticError, ValueError):  # no contact geometry to judge by
        return 0.0
    if not (math.isfinite(tc) and tc > 0.0):
        return 0.0
    tolerance = (1e-12 / num.rtol) ** ADAPTIVE_RTOL_EXPONENT
    return float(duration) * share * ADAPTIVE_COST * tolerance / (tc * tc)


def run_seconds(params, num, duration: float, series_rows: float = 0.0) -> float:
    """Estimated wall time [s] of one run of ``duration`` [s] keeping ``series_rows``."""
    return max(_costs(params, num, duration, series_rows)[:2])


def _costs(params, num, duration: float, series_rows: float = 0.0):
    """One run's times [s] (grid steps and series rows; adaptive steps in contact) and (the least
    number of steps it takes, why, what shortens it)."""
    duration = float(duration)
    found = [(duration / num.dt, f"steps of dt = {num.dt:g} s", "raise dt")]
    adaptive = num.integrator == "adaptive"
    if adaptive:
        found.append((duration / num.h_max, f"steps of at most h_max = {num.h_max:g} s",
                      "raise h_max"))  # fmt: skip
    if params.resample == "interval":
        found.append((duration / params.resample_dt,
                      f"line-length draws every resample_dt = {params.resample_dt:g} s",
                      "raise resample_dt"))  # fmt: skip
    steps = max(found)
    grid = (steps[0] * NS_PER_STEP + series_rows * NS_PER_SERIES_ROW) * 1e-9
    return grid, adaptive_seconds(params, num, duration) if adaptive else 0.0, steps


def check_run(params, num, duration: float, *, what: str = "one run",
              series_rows: float = 0.0) -> bool:  # fmt: skip
    """Refuse one run estimated beyond :data:`RUN_REFUSE_SECONDS` (a ParameterError), warn
    beyond :data:`RUN_WARN_SECONDS`, naming the fields that set the cost; whether it warned."""
    grid, contact, (steps, why, raise_) = _costs(params, num, duration, series_rows)
    seconds = max(grid, contact)
    if seconds <= RUN_WARN_SECONDS:
        return False
    text = f"{what} (duration = {float(duration):g} s) will take about {human_seconds(seconds)}"
    if contact > grid:
        from ..model import contact_period

        text += (
            f" with integrator = 'adaptive': the contact's period 2 pi sqrt(J / (K_n l_1^2))"
            f" = {contact_period(params):.2g} s (J = {params.inertia:.3g} kg m^2, K_n = "
            f"{params.stiffness_at(params.l_lambda):.3g} N/m) forces steps that short at "
            f"rtol = {num.rtol:g}"
        )
        remedy = "raise J, lower the stiffness (l_lambda, stiffness), loosen rtol or shorten "
        remedy += "duration"
    else:
        text += f": {steps:.3g} {why}"
        remedy = f"shorten duration or {raise_}"
        if series_rows:
            text += f" and {series_rows:.3g} series rows"
            remedy += " or output_dt"
    if seconds > RUN_REFUSE_SECONDS:
        raise ParameterError(f"{text}: refused; {remedy}")
    warn(f"{text}; {remedy} for a shorter run")
    return True


def human_bytes(n: float) -> str:
    for unit in ("B", "KiB", "MiB", "GiB", "TiB", "PiB"):
        if n < 1024 or unit == "PiB":
            return f"{n:.3g} {unit}"
        n /= 1024.0


def human_seconds(s: float) -> str:
    if s < 120:
        return f"{s:.3g} s"
    if s < 3600:
        return f"{s / 60:.3g} min"
    if s < 86400 * 3:
        return f"{s / 3600:.3g} h"
    if s < 86400 * 365 * 3:
        return f"{s / 86400:.3g} days"
    return f"{s / (86400 * 365):.3g} years"


def check_budget(job: JobEstimate, *, what: str, reduce: str, run: tuple | None = None) -> None:
    """Refuse (ParameterError) a job that cannot fit in memory, judge one run of it
    (:func:`check_run`), warn about one past :data:`WARN_SECONDS` (unless its run was warned).

    Parameters
    ----------
    job : JobEstimate
        From :func:`estimate`.
    what, reduce : str
        The job in words ("this run"); the settings to reduce ("--duration or --output-dt").
    run : dict, optional
        One run of the job: the keyword arguments of :func:`check_run`.
    """
    free = available_memory()
    if not math.isfinite(job.bytes) or job.bytes > free:
        raise ParameterError(
            f"{what} needs about {human_bytes(job.bytes)} of memory and this machine has "
            f"{human_bytes(free)} available: reduce {reduce}"
        )
    if run is not None and check_run(**run):
        return
    if job.seconds > WARN_SECONDS:
        warn(
            f"{what} will take about {human_seconds(job.seconds)} (a coarse estimate: "
            f"{NS_PER_STEP:g} ns per step of dt, more on the adaptive path in contact); "
            f"reduce {reduce} for a shorter run"
        )
