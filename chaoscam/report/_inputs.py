"""Read the files a report is built from, and say clearly which file is wrong and why.

Three kinds of input, told apart by the metadata chaoscam writes into its Parquet files:
a trajectory (``chaoscam simulate --out``, key ``chaoscam.trajectory``), a bifurcation
diagram and a regime map (``chaoscam bifurcation`` / ``regime-map``, whose sweep record
says ``kind``). A sweep may be named by its main file or by its companion
(``.verdicts.parquet``, ``.cells.parquet``).
"""

from __future__ import annotations

import json
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

__all__ = ["InputError", "Inputs", "load_inputs", "load_trajectory"]

_TRAJ_KEY = b"chaoscam.trajectory"
_COMPANIONS = {".verdicts": "bifurcation", ".cells": "regime_map"}


class InputError(ValueError):
    """An input file is missing, unreadable or not a chaoscam output."""


@dataclass
class Inputs:
    """What was read: trajectories, bifurcation diagrams, regime maps (each with its path)."""

    trajectories: list[tuple[str, Any]] = field(default_factory=list)
    bifurcations: list[tuple[str, Any]] = field(default_factory=list)
    regime_maps: list[tuple[str, Any]] = field(default_factory=list)


def _schema_metadata(path: Path) -> dict[bytes, bytes]:
    import pyarrow.parquet as pq

    if not path.exists():
        raise InputError(f"{path}: no such file")
    if not path.is_file():
        raise InputError(f"{path}: not a file")
    try:
        return dict(pq.read_schema(path).metadata or {})
    except Exception as err:  # pyarrow raises several types for non-Parquet input
        raise InputError(f"{path}: not a readable Parquet file ({err})") from None


def load_trajectory(path: str | Path):
    """A :class:`chaoscam.Trajectory` from a ``Trajectory.to_parquet`` file, read by the one
    reader ``classify`` uses too (:func:`chaoscam._trajectory_io.read_trajectory`)."""
    from .._trajectory_io import TrajectoryFileError, read_trajectory

    try:
        return read_trajectory(path)
    except TrajectoryFileError as err:
        raise InputError(str(err)) from None


def _sweep_kind(path: Path, meta: dict[bytes, bytes]) -> str | None:
    for key, value in meta.items():
        if key.startswith(b"chaoscam") and key != _TRAJ_KEY:
            try:
                return json.loads(value).get("config", {}).get("kind")
            except (ValueError, AttributeError):
                return None
    return None


def load_inputs(paths: list[str | Path]) -> Inputs:
    """Read every input; an :class:`InputError` names the first bad file."""
    from ..sweep import read_bifurcation, read_regime_map

    out = Inputs()
    for raw in paths:
        path = Path(raw)
        if path.suffix != ".parquet":
            raise InputError(f"{path}: expected a .parquet output of chaoscam")
        meta = _schema_metadata(path)
        if _TRAJ_KEY in meta:
            out.trajectories.append((str(path), load_trajectory(path)))
            continue
        kind = _sweep_kind(path, meta)
        stem = Path(path.stem)
        main = path
        if stem.suffix in _COMPANIONS:  # a companion file: read its main file
            main = path.with_name(stem.stem + ".parquet")
        try:
            if kind == "bifurcation":
                out.bifurcations.append((str(main), read_bifurcation(main)))
            elif kind == "regime_map":
                out.regime_maps.append((str(main), read_regime_map(main)))
            else:
                raise InputError(
                    f"{path}: a Parquet file but not a chaoscam trajectory, bifurcation or "
                    "regime map"
                )
        except (OSError, ValueError, KeyError, TypeError) as err:
            if isinstance(err, InputError):
                raise
            raise InputError(f"{path}: could not read the {kind} ({err})") from None
    for kind, items in (("bifurcations", out.bifurcations), ("regime_maps", out.regime_maps)):
        seen: dict[str, Any] = {}
        for p, r in items:
            seen.setdefault(p, r)
        setattr(out, kind, list(seen.items()))
    return out
