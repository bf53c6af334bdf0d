"""Read the files a report is built from, and say clearly which file is wrong and why.

Four kinds, told apart by the metadata chaoscam writes into its Parquet files: a run
(``Solution.to_parquet``; key ``chaoscam.trajectory``), and the sweeps whose record names
their ``kind``: a bifurcation diagram, a regime map, an ensemble. A sweep may be named by its
main file or by its companion (``.verdicts``, ``.cells`` or ``.sections.parquet``).
"""

from __future__ import annotations

import json
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

__all__ = ["InputError", "Inputs", "as_inputs", "load_inputs"]

_TRAJ_KEY = b"chaoscam.trajectory"
_SWEEP_KEY = b"chaoscam.sweep"
_COMPANIONS = (".verdicts", ".cells", ".sections")
_KINDS = {"bifurcation": "bifurcations", "regime_map": "regime_maps", "ensemble": "ensembles"}


class InputError(ValueError):
    """An input file is missing, unreadable or not a chaoscam output."""


@dataclass
class Inputs:
    """What was read: runs (one-member Solutions), bifurcation diagrams, regime maps and
    ensembles, each as (path, result)."""

    trajectories: list[tuple[str, Any]] = field(default_factory=list)
    bifurcations: list[tuple[str, Any]] = field(default_factory=list)
    regime_maps: list[tuple[str, Any]] = field(default_factory=list)
    ensembles: list[tuple[str, Any]] = field(default_factory=list)


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


def _sweep_kind(meta: dict[bytes, bytes]) -> str | None:
    try:
        return json.loads(meta[_SWEEP_KEY]).get("config", {}).get("kind")
    except (KeyError, ValueError, AttributeError):
        return None


def _read_run(path: Path):
    from ..simulation import TrajectoryFileError, read_trajectory

    try:
        return read_trajectory(path)
    except TrajectoryFileError as err:
        raise InputError(str(err)) from None


def _read_sweep(path: Path, kind: str):
    from .. import sweep

    try:
        return getattr(sweep, f"read_{kind}")(path)
    except (OSError, ValueError, KeyError, TypeError) as err:
        raise InputError(f"{path}: could not read the {kind} ({err})") from None


def load_inputs(paths: list[str | Path] | str | Path) -> Inputs:
    """Read every input (one path, or a list of them); an :class:`InputError` names the
    first bad file. A sweep named twice (by its main file and its companion) is read once."""
    if isinstance(paths, str | Path):  # one file, not the characters of its name
        paths = [paths]
    out = Inputs()
    seen: set[str] = set()
    for raw in paths:
        path = Path(raw)
        if path.suffix != ".parquet":
            raise InputError(f"{path}: expected a .parquet output of chaoscam")
        meta = _schema_metadata(path)
        if _TRAJ_KEY in meta:
            out.trajectories.append((str(path), _read_run(path)))
            continue
        kind = _sweep_kind(meta)
        if kind not in _KINDS:
            raise InputError(
                f"{path}: a Parquet file but not a chaoscam run, bifurcation, regime map or "
                "ensemble"
            )
        stem = Path(path.stem)
        main = path.with_name(stem.stem + ".parquet") if stem.suffix in _COMPANIONS else path
        if str(main) not in seen:
            seen.add(str(main))
            getattr(out, _KINDS[kind]).append((str(main), _read_sweep(main, kind)))
    return out


def as_inputs(items) -> Inputs:
    """:class:`Inputs` from what :func:`load_inputs` returns, or from one or a list of paths
    and results in memory (one-member :class:`chaoscam.Solution`, :class:`~chaoscam.sweep.
    Bifurcation`, :class:`~chaoscam.sweep.RegimeMap`, :class:`~chaoscam.sweep.Ensemble`), a
    result in memory named by its kind and place ("regime map 2"); a TypeError otherwise."""
    from ..simulation import Solution
    from ..sweep import Bifurcation, Ensemble, RegimeMap

    if isinstance(items, Inputs):
        return items
    kinds = {
        Solution: ("trajectories", "run"),
        Bifurcation: ("bifurcations", "bifurcation"),
        RegimeMap: ("regime_maps", "regime map"),
        Ensemble: ("ensembles", "ensemble"),
    }
    items = list(items) if isinstance(items, list | tuple) else [items]
    out = load_inputs([item for item in items if isinstance(item, str | Path)])
    for i, item in enumerate(items):
        if isinstance(item, str | Path):
            continue
        if type(item) not in kinds:
            raise TypeError(
                f"build_report takes paths, results (Solution, Bifurcation, RegimeMap, "
                f"Ensemble) or what load_inputs returns, not a {type(item).__name__}"
            )
        where, what = kinds[type(item)]
        getattr(out, where).append((f"{what} {i + 1}", item))
    return out
