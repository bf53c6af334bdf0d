"""One realization of a finished sweep, run again alone.

A regime map's or a bifurcation diagram's table row, with the sweep's ``config``, records all
that fixes its realization: the base model and numerics, the swept values, the window
(duration, transient), the seed and the solve index, and for a diagram the initial state
(which a continued branch took from the previous value's run). :func:`replay` solves that
realization alone, the run the sweep classified bit for bit, so one cell or value can be
looked at, plotted, or classified again with other options, for instance at half the step
(``classify(replay(rm, 3), check_step=True)``).
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from typing import Any

from .._util import flag
from ..model import Params
from ..numerics import Numerics
from ..simulation import Solution, simulate
from ._grid import cell_params

OUTPUT_DT = 1e-3
"""Series sampling of a replayed run [s], or dt where dt is coarser."""

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


def replay_params(sweep: Any, row: Any) -> tuple[Params, Numerics]:
    """The model and numerics of ``row``'s realization: the sweep's base with the row's axis
    values (and, for a diagram, its initial state; NaN = in contact with the cam)."""
    cfg = _sweep_config(sweep)
    row = _row(sweep, cfg, row)
    base, num = Params(**cfg["base"]), Numerics(**cfg.get("numerics", {}))
    if cfg["kind"] == "regime_map":
        names = (cfg["x"]["name"], cfg["y"]["name"])
        return cell_params(base, num, {n: float(_field(row, n)) for n in names})
    p, num = cell_params(base, num, {cfg["axis"]["name"]: float(_field(row, "value"))})
    th, om = (float(_field(row, k)) for k in ("theta_f0", "omega_f0"))
    p = p.replace(theta_f0=None if math.isnan(th) else th, omega_f0=None if math.isnan(om) else om)
    return p, num


def _row(sweep: Any, cfg: dict, row: Any) -> Any:
    """``row`` itself, or for a whole number the table's row at that position."""
    import numbers

    if isinstance(row, numbers.Integral) and not isinstance(row, bool):
        table = sweep.realizations if cfg["kind"] == "regime_map" else sweep.verdicts
        if not 0 <= int(row) < len(table):
            raise IndexError(f"row {row}: the table has {len(table)} rows")
        return table.iloc[int(row)]
    return row


def replay(sweep: Any, row: Any, *, tangent: bool = True, refine: int = 0) -> Solution:
    """Solve ``row``'s realization alone, as the sweep ran it.

    Parameters
    ----------
    sweep : RegimeMap or Bifurcation
        The finished sweep (``regime_map``, ``bifurcation``, ``read_regime_map``,
        ``read_bifurcation``).
    row : int, pandas row, namedtuple or mapping
        A row number or one row of ``sweep.realizations`` (regime map) or ``sweep.verdicts``
        (diagram).
    tangent : bool
        Also integrate the tangent dynamics, and keep the run resumable, as the sweeps do
        (RK4 only): :func:`chaoscam.classify` then reads its Jacobians and extends it without
        solving it again.
    refine : int
        Halve the step this many times (:meth:`Numerics.refined`), the same realization
        otherwise: the rungs of a step ladder. 0: the sweep's run.

    Returns
    -------
    Solution
        Of one member: duration, transient, seed and index of the sweep, the series sampled
        every 1 ms (or every dt where dt is coarser). The motion does not depend on it.
    """
    cfg = _sweep_config(sweep)
    row = _row(sweep, cfg, row)
    p, num = replay_params(sweep, row)
    if isinstance(refine, bool) or not isinstance(refine, int) or refine < 0:
        raise ValueError(f"refine = {refine!r}: must be an integer >= 0 (step halvings)")
    for _ in range(refine):
        num = num.refined()
    tangent = flag("tangent", tangent) and num.integrator == "rk4"
    return simulate(
        p,
        num,
        duration=float(cfg["duration"]),
        transient=float(cfg["transient"]),
        seed=int(_field(row, "seed")),
        index=int(_field(row, "sim_index")),
        output_dt=max(OUTPUT_DT, num.dt),
        tangent=tangent,
        resumable=tangent,
    )
