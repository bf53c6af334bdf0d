"""The saved parts of a ``chaoscam ensemble`` run, and their commit into the outputs.

A part is ``FILE.parts/START.NAME.parquet`` for each table, then a ``START.done`` marker that
records each file's size and SHA-256 (a part that does not match is computed again);
``config.json`` holds the run's configuration and its digest, which ``--resume`` compares.
The commit joins the parts into the outputs, stamps the members file with the digest and the
run's record (:data:`chaoscam.report._inputs.ENSEMBLE_RECORD_KEY`), and removes the parts.
"""

from __future__ import annotations

import hashlib
import json
import os
import sys
from pathlib import Path

from .._outputs import OutputError, atomic_path
from .._parquet import read_frame
from .._parquet import write_table as parquet_table
from ..report._inputs import ENSEMBLE_KEY as _META_KEY
from ..report._inputs import ENSEMBLE_RECORD_KEY

__all__ = [
    "atomic_text",
    "commit_parts",
    "config_digest",
    "finished_run",
    "fingerprint",
    "manifest",
    "output_paths",
    "part_done",
]


def output_paths(out: Path) -> tuple[Path, Path, Path]:
    """members, sections, impacts."""
    return out, out.with_suffix(".sections.parquet"), out.with_suffix(".impacts.parquet")


def manifest(parts: Path) -> dict:
    """The ``config.json`` of an unfinished run's parts (digest and configuration), or an
    empty dict when there is none or it cannot be read."""
    try:
        saved = json.loads((parts / "config.json").read_text())
    except (OSError, ValueError):
        return {}
    return saved if isinstance(saved, dict) else {}


def atomic_text(path: Path, text: str) -> None:
    from .._outputs import atomic_write_bytes

    atomic_write_bytes(path, text.encode())


def fingerprint(path: Path) -> dict:
    data = path.read_bytes()
    return {"bytes": len(data), "sha256": hashlib.sha256(data).hexdigest()}


def part_done(parts: Path, start: int, names: tuple[str, ...]) -> bool:
    """True when part ``start`` is whole: its marker lists files that match it."""
    mark = parts / f"{start:012d}.done"
    if not mark.exists():
        return False
    try:
        files = json.loads(mark.read_text())["files"]
        whole = all(
            fingerprint(parts / f"{start:012d}.{name}.parquet") == files[name] for name in names
        )
    except (OSError, ValueError, KeyError, TypeError):
        whole = False
    if not whole:
        print(
            f"chaoscam: notice: part {start} in {parts} is damaged or incomplete; it is "
            "computed again",
            file=sys.stderr,
            flush=True,
        )
        mark.unlink(missing_ok=True)
    return whole


def config_digest(config: dict) -> str:
    return hashlib.sha256(json.dumps(config, sort_keys=True).encode()).hexdigest()[:16]


def finished_run(out: Path, digests: tuple[str, ...]) -> bool:
    """True when ``out`` is the members file of a finished run of this configuration: its
    stamp is one of ``digests`` (that of the configuration without the part size; files
    finished before that change carry the digest with it)."""
    import pyarrow.parquet as pq

    try:
        meta = pq.read_schema(out).metadata or {}
    except Exception:  # absent, or not a Parquet file: not finished
        return False
    return meta.get(_META_KEY) in {d.encode() for d in digests}


def readable_table(path: Path) -> bool:
    """True when ``path`` is a Parquet file whose data can be read (not missing, cut short
    or damaged: its pages' checksums are verified)."""
    try:
        read_frame(path)
    except Exception:  # missing, not Parquet, a failed checksum: not readable
        return False
    return True


def recorded_config(out: Path) -> dict | None:
    """The configuration a finished members file records (:func:`run_record`), for saying
    what differs; None when it has none (not a chaoscam ensemble, or unreadable)."""
    import pyarrow.parquet as pq

    try:
        meta = pq.read_schema(out).metadata or {}
        record = json.loads(meta[ENSEMBLE_RECORD_KEY])
    except Exception:  # absent, not Parquet, no record: nothing to compare
        return None
    if not isinstance(record, dict):
        return None
    return {k: v for k, v in record.items() if k not in ("kind", "version", "backends")}


def write_table(frame, path: Path, stamp: dict[bytes, bytes] | None = None) -> None:
    import pyarrow as pa

    table = pa.Table.from_pandas(frame, preserve_index=False)
    if stamp:
        table = table.replace_schema_metadata({**(table.schema.metadata or {}), **stamp})
    with atomic_path(path) as tmp:
        parquet_table(table, tmp)


def run_record(parts: Path, starts: range, config: dict) -> dict:
    """What the members file says of the run that made it (``chaoscam report`` shows it): the
    configuration, the package version, and the backends its parts ran on (a GPU's members
    are not bit-identical to the CPU's)."""
    from .._version import __version__

    used = set()
    for s in starts:
        try:
            used.add(str(json.loads((parts / f"{s:012d}.done").read_text())["settings"]["backend"]))
        except (OSError, ValueError, KeyError, TypeError):
            used.add("unknown")
    config = {k: v for k, v in config.items() if k != "chunk"}
    return {"kind": "ensemble", "version": __version__, "backends": sorted(used), **config}


STAGED = "staged.json"
"""In an ensemble's parts folder: the outputs its commit was placing, as file identities."""


def check_outputs(parts: Path, outputs: tuple[Path, ...]) -> None:
    """Before resuming the run whose parts are ``parts``: refuse an output that is neither
    one its ``--force`` start was asked to replace (``config.json``'s ``replaces``, as that
    file was then) nor one its commit placed before a kill (:data:`STAGED`); it was made
    since, and the resume would overwrite it."""
    from ..sweep._checkpoint import file_identity

    try:
        staged = json.loads((parts / STAGED).read_text())
    except (OSError, ValueError):
        staged = {}
    known = [manifest(parts).get("replaces") or {}, staged if isinstance(staged, dict) else {}]
    for path in outputs:
        if path.exists() and all(k.get(path.name) != file_identity(path) for k in known):
            raise FileExistsError(
                f"{path} was not there, or not as it is now, when the unfinished run in "
                f"{parts} started: resuming would overwrite it. Move it away, or choose "
                "another --out (nothing was overwritten)"
            )


def commit_parts(
    parts: Path,
    starts: range,
    names: tuple[str, ...],
    out: Path,
    digest: str,
    ours: set[Path],
    config: dict,
):
    """Join the parts into the outputs as one commit: every output written to a temporary
    name, then renamed, the members file last; then the parts are removed (renamed away
    first). A kill at any point leaves either the parts (``--resume`` joins them again) or
    the finished outputs. An output not in ``ours`` is put in place only if its name is
    still free (a hard link): one that another process wrote meanwhile is kept, the outputs
    placed so far are taken back, and the parts stay for a ``--resume`` once it is moved.
    An output in ``ours`` that this run does not write (the impacts of the output a
    ``--force`` run replaces, without ``--keep-impacts``) is removed."""
    import pandas as pd

    from ..sweep._checkpoint import discard_checkpoint

    targets = dict(zip(("members", "sections", "impacts"), output_paths(out), strict=True))
    staged = {}
    members = None
    stamp = {  # the members file's: what --resume compares, and the run's record
        _META_KEY: digest.encode(),
        ENSEMBLE_RECORD_KEY: json.dumps(run_record(parts, starts, config)).encode(),
    }
    for name in names:
        frame = pd.concat(
            [read_frame(parts / f"{s:012d}.{name}.parquet") for s in starts],
            ignore_index=True,
        )
        if name == "members":
            members = frame
        staged[name] = parts / f".staged.{name}.parquet"
        write_table(frame, staged[name], stamp if name == "members" else None)
    for name, target in targets.items():
        if name not in names and target in ours:
            # The replaced (--force) output's companion that this run does not write (its
            # impacts, without --keep-impacts): left, it would pass for this run's.
            target.unlink(missing_ok=True)
    from ..sweep._checkpoint import file_identity

    # What the outputs will be once placed (renames keep size and mtime): a resume after a
    # kill in the middle of placing them recognises them as this run's (check_outputs).
    atomic_text(
        parts / STAGED, json.dumps({targets[n].name: file_identity(staged[n]) for n in names})
    )
    placed = []
    for name in sorted(names, key=lambda n: n == "members"):  # members last
        target = targets[name]
        if target in ours:
            os.replace(staged[name], target)
            continue
        try:
            os.link(staged[name], target)
        except FileExistsError:
            for p in placed:
                p.unlink(missing_ok=True)
            raise OutputError(
                f"{target} appeared while this run was working (another process wrote it); "
                f"it was not overwritten. The finished members are kept in {parts}: move "
                f"{target} away and run the same command with --resume to write them"
            ) from None
        placed.append(target)
    discard_checkpoint(parts)
    return members
