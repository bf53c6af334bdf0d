"""Memory and time of a job, estimated before it starts: refuse what cannot fit, warn about hours.

The estimates are coarse upper-side guesses, meant to catch absurd requests (a duration of
1e9 s, a series sampled every microsecond for minutes, a billion realizations), not to
predict run times:

* memory: 8 bytes per number kept — the series (``(duration - transient) / output_dt``
  rows of 4 columns, 8 in the table written), the stroboscopic section (one row of 5 per cam
  period after the transient) and twice that for the table built from them;
* time: :data:`NS_PER_STEP` per grid step ``dt`` (measured on the default model, 2-core
  machine: 8-65 ns a step from periodic to chaotic responses and without flight merging),
  divided among the workers.

A job whose memory exceeds what this machine has available is refused with a
:class:`~chaoscam.model.ParameterError` naming the setting to reduce; one estimated to take
more than :data:`WARN_SECONDS` gets a warning with the estimate.
"""

from __future__ import annotations

import math
import os
import warnings

from .model import ParameterError

__all__ = ["estimate", "check_budget", "available_memory", "JobEstimate"]

NS_PER_STEP = 40.0
"""Wall time of one grid step [ns] used for the estimate (measured 8-65 ns)."""

WARN_SECONDS = 3600.0
"""Jobs estimated to take longer than this get a warning [s]."""

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
    params,
    *,
    duration: float,
    transient: float = 0.0,
    series: bool = False,
    output_dt: float = 1e-3,
    runs: float = 1,
    in_memory: float = 1,
    workers: int = 1,
) -> JobEstimate:
    """Estimated (bytes, seconds) of ``runs`` realizations, ``in_memory`` of them held at once."""
    kept = max(0.0, float(duration) - float(transient))
    rows = kept / params.cam_period
    if series:
        rows_series = kept / max(float(output_dt), params.dt)
        per_run = rows_series * SERIES_BYTES_PER_ROW + rows * SECTION_BYTES_PER_ROW
    else:
        per_run = rows * SECTION_BYTES_PER_ROW
    steps = float(duration) / params.dt
    seconds = runs * steps * NS_PER_STEP * 1e-9 / max(1, int(workers))
    return JobEstimate((per_run * in_memory, seconds))


def _human_bytes(n: float) -> str:
    for unit in ("B", "KiB", "MiB", "GiB", "TiB", "PiB"):
        if n < 1024 or unit == "PiB":
            return f"{n:.3g} {unit}"
        n /= 1024.0
    return f"{n:.3g} PiB"  # pragma: no cover


def _human_seconds(s: float) -> str:
    if s < 3600:
        return f"{s / 60:.3g} min"
    if s < 86400 * 3:
        return f"{s / 3600:.3g} h"
    if s < 86400 * 365 * 3:
        return f"{s / 86400:.3g} days"
    return f"{s / (86400 * 365):.3g} years"


def check_budget(job: JobEstimate, *, what: str, reduce: str) -> None:
    """Refuse a job that cannot fit in memory; warn about one that will take hours.

    Parameters
    ----------
    job : JobEstimate
        From :func:`estimate`.
    what : str
        The job in words ("this run", "this regime map").
    reduce : str
        The settings to reduce, for the message ("--duration or --output-dt").
    """
    free = available_memory()
    if not math.isfinite(job.bytes) or job.bytes > free:
        raise ParameterError(
            f"{what} needs about {_human_bytes(job.bytes)} of memory and this machine has "
            f"{_human_bytes(free)} available: reduce {reduce}"
        )
    if job.seconds > WARN_SECONDS:
        warnings.warn(
            f"{what} will take about {_human_seconds(job.seconds)} (estimated at "
            f"{NS_PER_STEP:g} ns per step of dt); reduce {reduce} for a shorter run",
            RuntimeWarning,
            stacklevel=3,
        )
