"""extend_trajectory(traj, duration) -> Trajectory: a run made longer without repeating it.

A run that is too short to settle a question (an undetermined verdict, an exponent whose
standard error is too large) is made longer. Simulating again from t = 0 repeats everything
already done; a run kept resumable (``simulate(..., resumable=True)``) goes on from a copy
of its state near its end instead (:mod:`chaoscam.integrate._resume`), to the same bits.
"""

from __future__ import annotations

import time

from ._checks import flag, of_type, real
from ._simulate import KernelRun, RawRun, Trajectory, _check_run, output_block, simulate
from .integrate import _kernel as k
from .model import ParameterError

__all__ = ["extend_trajectory"]


def extend_trajectory(
    traj: Trajectory, duration: float, *, series: bool | None = None
) -> Trajectory:
    """The realization of ``traj`` made ``duration`` seconds long.

    With the copy a resumable run keeps (``simulate(..., resumable=True)``, RK4) the run
    goes on from near its end (the grid step before its last section time) instead of
    starting again: the result has the bits of :func:`chaoscam.simulate` that long from
    t = 0 with the same settings (sections, Jacobians, impacts, series, statistics,
    status) and keeps a copy in turn, so it can be extended again. Without a copy (the
    adaptive integrator, a run not kept resumable, one read from a file) the realization is
    simulated again from t = 0, resumable: the same result at the full cost.

    Parameters
    ----------
    traj : Trajectory
        The run to make longer.
    duration : float
        The new end time [s], at least the run's.
    series : bool, optional
        Keep the time series; default: as the run did. False drops it (for a classifier
        that reads sections and Jacobians only); a run that kept none cannot gain one.

    Returns
    -------
    Trajectory
        ``settings["continued_from_s"]`` gives the time the run went on from (None when
        the run had ended before its copy, absent when it was simulated again);
        ``settings["wall_time_s"]`` the time this call took.

    Examples
    --------
    >>> import chaoscam
    >>> short = chaoscam.simulate(duration=2.0, transient=1.0, series=False, resumable=True)
    >>> longer = chaoscam.extend_trajectory(short, 4.0)
    >>> len(longer.section) > len(short.section)
    True
    """
    s = of_type("traj", traj, Trajectory, "from chaoscam.simulate or load_trajectory").settings
    duration = real("duration", duration, low=0.0, strict=True, unit="s")
    if duration < s["duration"]:
        raise ParameterError(
            f"duration = {duration!r} s must be >= the run's duration, {s['duration']!r} s"
        )
    had_series = traj.series is not None
    keep_series = had_series if series is None else flag("series", series)
    if keep_series and not had_series:
        raise ParameterError(
            "series = True: the run kept no time series, so its extension cannot have one "
            "(simulate it with series=True)"
        )
    if traj.resume is None:
        return simulate(
            traj.params,
            duration=duration,
            transient=s["transient"],
            seed=s["seed"],
            index=s["index"],
            series=keep_series,
            output_dt=s["output_dt"] if keep_series else 1e-3,
            tangent=bool(s.get("tangent", False)),
            resumable=True,
        )
    return continue_run(traj, duration, series=keep_series).trajectory()


def continue_run(run: Trajectory | RawRun, duration: float, *, series: bool) -> RawRun:
    """``run`` made ``duration`` seconds long, continued from its copy (``run.resume``, a
    :class:`~chaoscam.integrate._resume.RunCopy`) without repeating what came before it:
    the same bits as :func:`._simulate.raw_run` that long from t = 0 (``series`` False drops the
    series; the state never depends on it)."""
    p, s, cp = run.params, run.settings, run.resume
    if cp is None:
        raise ValueError("internal: continue_run needs a run kept resumable")
    output_dt = s["output_dt"] if series else None
    _check_run(p, duration, s["transient"], output_dt, s["seed"], s["index"])
    t0 = time.perf_counter()
    n_stop = int(round(duration / p.dt))
    y, cnt, c, lam, stream = cp.start(output_block(p))
    if not series:
        c[k.C_STRIDE] = 0.0
    parts = {
        "series": [cp.series] if series else [],
        "section": [cp.section],
        "impacts": [cp.impacts],
    }
    go = KernelRun(p, y, cnt, c, lam, stream, parts)
    went_on = cp.status == k.OK  # else the run ended before its copy: so does a longer one
    code = go.go(n_stop, True) if went_on else cp.status
    settings = {
        **s,
        "duration": float(duration),
        "output_dt": output_dt,
        "wall_time_s": time.perf_counter() - t0,
        "continued_from_s": cp.step * p.dt if went_on else None,
    }
    return go.result(code, settings)
