"""Read the files a report is built from, and say clearly which file is wrong and why.

Four kinds of input, told apart by the metadata chaoscam writes into its Parquet files:
a trajectory (``chaoscam simulate --out``, key ``chaoscam.trajectory``), a bifurcation
diagram and a regime map (``chaoscam bifurcation`` / ``regime-map``, whose sweep record
says ``kind``), and an ensemble (``chaoscam ensemble --out``, key ``chaoscam.ensemble``).
A sweep may be named by its main file or by its companion (``.verdicts.parquet``,
``.cells.parquet``), an ensemble by its members file or its ``.sections.parquet``.
"""

from __future__ import annotations

import json
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from .._parquet import read_frame

__all__ = [
    "EnsembleOutput",
    "InputError",
    "Inputs",
    "load_ensemble",
    "load_inputs",
    "load_trajectory",
]

_TRAJ_KEY = b"chaoscam.trajectory"
_COMPANIONS = {".verdicts": "bifurcation", ".cells": "regime_map"}

ENSEMBLE_KEY = b"chaoscam.ensemble"
"""Members-file metadata: the digest of the run's configuration (what ``--resume`` compares)."""

ENSEMBLE_RECORD_KEY = b"chaoscam.ensemble.record"
"""Members-file metadata, JSON: kind, package version, backends used, and the configuration
(params, seed, duration, transient, first, members, classify, keep_impacts). Files written
before it was kept have the digest only."""


class InputError(ValueError):
    """An input file is missing, unreadable or not a chaoscam output."""


@dataclass
class Inputs:
    """What was read: trajectories, bifurcation diagrams, regime maps (each with its path)."""

    trajectories: list[tuple[str, Any]] = field(default_factory=list)
    bifurcations: list[tuple[str, Any]] = field(default_factory=list)
    regime_maps: list[tuple[str, Any]] = field(default_factory=list)
    ensembles: list[tuple[str, Any]] = field(default_factory=list)


@dataclass(frozen=True)
class EnsembleOutput:
    """The files of one ``chaoscam ensemble`` run.

    Attributes
    ----------
    members : pandas.DataFrame
        One row per member: member, index, status, n_impacts, contact_fraction, and with
        ``--classify`` label, period, reasons.
    sections : pandas.DataFrame or None
        member, k, t, theta_f, omega_f, l_lambda; None when ``FILE.sections.parquet`` is
        not beside the members file.
    record : dict
        :data:`ENSEMBLE_RECORD_KEY`'s JSON; empty for a file written before it was kept.
    """

    members: Any
    sections: Any
    record: dict


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


def load_ensemble(path: str | Path) -> EnsembleOutput:
    """An :class:`EnsembleOutput` from a ``chaoscam ensemble`` members file (or its
    ``.sections.parquet``), with the sections file beside it when there is one."""

    path = Path(path)
    if Path(path.stem).suffix == ".sections":
        path = path.with_name(Path(path.stem).stem + ".parquet")
    meta = _schema_metadata(path)
    if ENSEMBLE_KEY not in meta:
        raise InputError(f"{path}: not the members file of a chaoscam ensemble")
    try:
        record = json.loads(meta.get(ENSEMBLE_RECORD_KEY, b"{}"))
    except ValueError:
        raise InputError(f"{path}: its ensemble record is not readable JSON") from None
    sections = path.with_suffix(".sections.parquet")
    try:
        members = read_frame(path)
        sec = read_frame(sections) if sections.is_file() else None
    except Exception as err:  # pyarrow raises several types for damaged files
        raise InputError(f"{path}: could not read the ensemble ({err})") from None
    missing = {"member", "status"} - set(members.columns)
    if missing or (sec is not None and not {"member", "theta_f", "omega_f"} <= set(sec.columns)):
        raise InputError(f"{path}: the ensemble's tables lack the columns chaoscam writes")
    return EnsembleOutput(members, sec, record if isinstance(record, dict) else {})


def _sweep_kind(path: Path, meta: dict[bytes, bytes]) -> str | None:
    for key, value in meta.items():
        if key.startswith(b"chaoscam") and key not in (
            _TRAJ_KEY,
            ENSEMBLE_KEY,
            ENSEMBLE_RECORD_KEY,
        ):
            try:
                return json.loads(value).get("config", {}).get("kind")
            except (ValueError, AttributeError):
                return None
    return None


def require_inputs(inputs) -> Inputs:
    """``inputs`` itself when it is an :class:`Inputs`; otherwise a TypeError saying how to
    make one (``build_report(["run.parquet"])`` failed deep inside with an AttributeError)."""
    if not isinstance(inputs, Inputs):
        raise TypeError(
            f"build_report takes what load_inputs returns, not a {type(inputs).__name__}: "
            "build_report(load_inputs(paths))"
        )
    return inputs


def load_inputs(paths: list[str | Path] | str | Path) -> Inputs:
    """Read every input (one path, or a list of them); an :class:`InputError` names the
    first bad file."""
    from ..sweep import read_bifurcation, read_regime_map

    if isinstance(paths, str | Path):  # one file, not the characters of its name
        paths = [paths]
    out = Inputs()
    for raw in paths:
        path = Path(raw)
        if path.suffix != ".parquet":
            raise InputError(f"{path}: expected a .parquet output of chaoscam")
        meta = _schema_metadata(path)
        if _TRAJ_KEY in meta:
            out.trajectories.append((str(path), load_trajectory(path)))
            continue
        stem = Path(path.stem)
        main = path
        if stem.suffix in (*_COMPANIONS, ".sections"):  # a companion: read its main file
            main = path.with_name(stem.stem + ".parquet")
        if ENSEMBLE_KEY in meta or (
            stem.suffix == ".sections" and main.is_file() and ENSEMBLE_KEY in _schema_metadata(main)
        ):
            out.ensembles.append((str(main), load_ensemble(main)))
            continue
        kind = _sweep_kind(path, meta)
        try:
            if kind == "bifurcation":
                out.bifurcations.append((str(main), read_bifurcation(main)))
            elif kind == "regime_map":
                out.regime_maps.append((str(main), read_regime_map(main)))
            else:
                raise InputError(
                    f"{path}: a Parquet file but not a chaoscam trajectory, bifurcation, "
                    "regime map or ensemble"
                )
        except (OSError, ValueError, KeyError, TypeError) as err:
            if isinstance(err, InputError):
                raise
            raise InputError(f"{path}: could not read the {kind} ({err})") from None
    for kind, items in (
        ("bifurcations", out.bifurcations),
        ("regime_maps", out.regime_maps),
        ("ensembles", out.ensembles),
    ):
        seen: dict[str, Any] = {}
        for p, r in items:
            seen.setdefault(p, r)
        setattr(out, kind, list(seen.items()))
    return out
