"""One realization of a finished sweep, run again alone: a row and the sweep's ``config``
fix it, so :func:`replay` solves the run the sweep classified, bit for bit, to look at or
classify again (``classify(replay(rm, 3), check_step=True)``)."""

from __future__ import annotations

import math
import numbers
from collections.abc import Mapping
from typing import Any

from .._util import flag
from ..model import Params
from ..numerics import Numerics
from ..simulation import Solution, simulate
from ._grid import cell_params

OUTPUT_DT = 1e-3
"""Series sampling of a replayed run [s], or dt where dt is coarser."""


def _field(row: Any, name: str) -> Any:
    """``row[name]`` of a mapping or a pandas row, ``row.name`` of a namedtuple."""
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


def _sweep_row(sweep: Any, row: Any) -> tuple[dict[str, Any], Any]:
    """The sweep's ``config`` with its ``kind``, and ``row`` (a number: the table's row)."""
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
    if isinstance(row, numbers.Integral) and not isinstance(row, bool):
        table = sweep.realizations if kind == "regime_map" else sweep.verdicts
        if not 0 <= int(row) < len(table):
            raise IndexError(f"row {row}: the table has {len(table)} rows")
        row = table.iloc[int(row)]
    return {**cfg, "kind": kind}, row


def replay_params(sweep: Any, row: Any) -> tuple[Params, Numerics]:
    """The model and numerics of ``row``'s realization: the sweep's base with the row's axis
    values (a diagram's: and its initial state, NaN = in contact)."""
    cfg, row = _sweep_row(sweep, row)
    base, num = Params(**cfg["base"]), Numerics(**cfg.get("numerics", {}))
    if cfg["kind"] == "regime_map":
        names = (cfg["x"]["name"], cfg["y"]["name"])
        return cell_params(base, num, {n: float(_field(row, n)) for n in names})
    p, num = cell_params(base, num, {cfg["axis"]["name"]: float(_field(row, "value"))})
    th, om = (float(_field(row, k)) for k in ("theta_f0", "omega_f0"))
    p = p.replace(theta_f0=None if math.isnan(th) else th, omega_f0=None if math.isnan(om) else om)
    return p, num


def replay(sweep: Any, row: Any, *, tangent: bool = True, refine: int = 0) -> Solution:
    """Solve ``row``'s realization alone, as the sweep ran it.

    Parameters
    ----------
    sweep : RegimeMap or Bifurcation
        The finished sweep.
    row : int, pandas row, namedtuple or mapping
        A row (number) of ``sweep.realizations`` (a map) or ``sweep.verdicts`` (a diagram).
    tangent : bool
        Integrate the tangent too and keep the run resumable, as the sweeps do (RK4 only),
        so :func:`chaoscam.classify` needs no second solve.
    refine : int
        Halve the step this many times (:meth:`Numerics.refined`); 0: the sweep's run.

    Returns
    -------
    Solution
        Of one member, with the series every 1 ms (or dt where coarser).
    """
    cfg, row = _sweep_row(sweep, row)
    p, num = replay_params(sweep, row)
    if isinstance(refine, bool) or not isinstance(refine, int) or refine < 0:
        raise ValueError(f"refine = {refine!r}: must be an integer >= 0 (step halvings)")
    for _ in range(refine):
        num = num.refined()
    tangent = flag("tangent", tangent) and num.integrator == "rk4"
    return simulate(
        p, num, duration=float(cfg["duration"]), transient=float(cfg["transient"]),
        seed=int(_field(row, "seed")), index=int(_field(row, "sim_index")),
        output_dt=max(OUTPUT_DT, num.dt), tangent=tangent, resumable=tangent,
    )  # fmt: skip
