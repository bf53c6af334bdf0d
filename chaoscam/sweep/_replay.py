"""One realization of a finished sweep, run again alone.

A regime map's or a bifurcation diagram's table row, with the sweep's ``config``, records all
that fixes its realization: the base parameters, the swept values, the window (duration,
transient), the seed and the simulate index, and for a diagram the initial state (which a
continued branch took from the previous value's run). :func:`replay` simulates that
realization with :func:`chaoscam.simulate`, the run the sweep classified bit for bit (every
engine runs the same compiled kernel per member, docs/speed.md, "Compilation"), so one cell or value
can be looked at, plotted, or classified again with other options, for instance at half the
step (``classify_trajectory(replay(rm, row), check_step=True)``).
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from typing import Any

from .._checks import flag
from .._simulate import Trajectory, simulate
from ..model import Params
from ._tasks import OUTPUT_DT

__all__ = ["replay", "replay_params"]


def _field(row: Any, name: str) -> Any:
    """``row[name]`` for a mapping or a pandas row (Series), ``row.name`` for a namedtuple
    (``DataFrame.itertuples``)."""
    if isinstance(row, Mapping) or hasattr(row, "index") and hasattr(row, "loc"):
        try:
            return row[name]
        except KeyError:
            pass
    elif hasattr(row, name):
        return getattr(row, name)
    raise KeyError(
        f"the row has no {name!r}: pass a row of a regime map's `realizations` or a "
        "bifurcation diagram's `verdicts` table"
    )


def _sweep_config(sweep: Any) -> dict[str, Any]:
    """The sweep's ``config`` with its ``kind``: recorded, or for files written before
    sweeps recorded it (which ``read_*`` still accept), told by its axes ("x" and "y": a
    regime map; "axis": a diagram)."""
    cfg = getattr(sweep, "config", None)
    kind = None
    if isinstance(cfg, dict):
        kind = cfg.get("kind") or (
            "regime_map" if {"x", "y"} <= cfg.keys() else "bifurcation" if "axis" in cfg else None
        )
    if kind not in ("regime_map", "bifurcation") or "base" not in cfg:
        raise TypeError(
            f"sweep must be a RegimeMap or a Bifurcation (from regime_map, bifurcation or "
            f"their read_* functions), got {type(sweep).__name__}"
        )
    return {**cfg, "kind": kind}


def replay_params(sweep: Any, row: Any) -> Params:
    """The parameters of ``row``'s realization: the sweep's base with the row's axis values
    (and, for a diagram, its initial state; NaN = in contact with the cam)."""
    cfg = _sweep_config(sweep)
    base = Params(**cfg["base"])
    if cfg["kind"] == "regime_map":
        names = (cfg["x"]["name"], cfg["y"]["name"])
        return base.replace(**{n: float(_field(row, n)) for n in names})
    th, om = (float(_field(row, k)) for k in ("theta_f0", "omega_f0"))
    return base.replace(
        **{cfg["axis"]["name"]: float(_field(row, "value"))},
        theta_f0=None if math.isnan(th) else th,
        omega_f0=None if math.isnan(om) else om,
    )


def replay(sweep: Any, row: Any, *, tangent: bool = True, refine: int = 0) -> Trajectory:
    """Simulate ``row``'s realization alone, as the sweep ran it.

    Parameters
    ----------
    sweep : RegimeMap or Bifurcation
        The finished sweep (``regime_map``, ``bifurcation``, ``read_regime_map``,
        ``read_bifurcation``).
    row : pandas row, namedtuple or mapping
        One row of ``sweep.realizations`` (regime map) or ``sweep.verdicts`` (diagram).
    tangent : bool
        Also integrate the tangent dynamics, and keep the run resumable, as the sweeps do for
        the default classifier (RK4 only): ``classify_trajectory`` then reads its Jacobians
        and extends it without simulating it again.
    refine : int
        Halve the step this many times (:meth:`Params.refined`: RK4's ``dt / 2**refine``;
        the adaptive path's tolerances / 32 each time), the same realization otherwise: the
        rungs of a step ladder (``analyses/step_audit.py --ladder``). 0: the sweep's run.

    Returns
    -------
    Trajectory
        Duration, transient, seed and index of the sweep; the series sampled every 1 ms (or
        every dt where dt is coarser), as in the default classifier's runs. The motion does
        not depend on it (asking for a series never changes a run), but a sweep run with a
        classifier that declared ``needs_series = False`` classified its runs without one.
    """
    cfg = _sweep_config(sweep)
    p = replay_params(sweep, row)
    if isinstance(refine, bool) or not isinstance(refine, int) or refine < 0:
        raise ValueError(f"refine = {refine!r}: must be an integer >= 0 (step halvings)")
    for _ in range(refine):
        p = p.refined()
    tangent = flag("tangent", tangent) and p.integrator == "rk4"
    return simulate(
        p,
        duration=float(cfg["duration"]),
        transient=float(cfg["transient"]),
        seed=int(_field(row, "seed")),
        index=int(_field(row, "sim_index")),
        output_dt=max(OUTPUT_DT, p.dt),
        tangent=tangent,
        resumable=tangent,
    )
