"""Checkpoints: finished records written as they complete, so a killed run can resume.

Layout, beside the output ``FILE.parquet``: a folder ``FILE.parquet.ckpt/`` holding
``manifest.json`` (the run's configuration and its SHA-256) and append-only part files
``part-NNNNNN.jsonl``, one JSON record per line and a last line
``#chaoscam-part n=COUNT sha256=HEX`` (the records' count and the checksum of the bytes
before it). Every file is written to a temporary name, flushed to disk and moved into place
with :func:`os.replace`, so a part is either whole or absent whatever moment the process is
killed (SIGKILL included); a resumed run reads the parts, skips the records they hold and
appends new parts. A part damaged all the same (a full disk, a copy cut short) is found by
its trailer: the last part is dropped with a one-line notice and its records recomputed; a
damaged part before it is refused with a message saying what to do. Floats are written with
Python's shortest round-trip ``repr``, so a record read back is bit-identical to the one
written. The run holds an OS lock on its output (:class:`chaoscam._outputs.OutputLock`), so
two processes never share a checkpoint.
"""

from __future__ import annotations

import hashlib
import json
import os
import re
import shutil
import sys
import time
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import pandas as pd

from ._grid import SweepError

__all__ = [
    "MemoryStore",
    "CheckpointStore",
    "config_hash",
    "checkpoint_dir",
    "discard_checkpoint",
    "remove_leftovers",
    "write_parquet",
]

_META_KEY = b"chaoscam.sweep"


def config_hash(config: dict[str, Any]) -> str:
    """SHA-256 of the configuration's canonical JSON (sorted keys, exact floats)."""
    text = json.dumps(config, sort_keys=True, separators=(",", ":"), allow_nan=False)
    return hashlib.sha256(text.encode()).hexdigest()


def differences(saved: Any, config: dict[str, Any]) -> str:
    """What sets a saved configuration apart from this run's, for the refusal message:
    " (made by other chaoscam code: ...)" when only the code differs, else the differing
    settings' names; "" when the saved one cannot be read."""
    if not isinstance(saved, dict):
        return ""
    keys = sorted(k for k in set(saved) | set(config) if saved.get(k) != config.get(k))
    if keys == ["code"]:
        old, new = saved.get("code") or {}, config["code"]
        changed = ", ".join(
            f"{k} {old.get(k, '?')}, now {new[k]}" for k in new if old.get(k) != new[k]
        )
        return (
            f" (made by other chaoscam code: {changed}; its results may differ from this "
            "code's, so it is not mixed with them)"
        )
    return f" (it differs in: {', '.join(keys)})" if keys else ""


def checkpoint_dir(out: Path) -> Path:
    """The checkpoint folder of output ``out``: ``out`` + ``.ckpt``."""
    return out.with_name(out.name + ".ckpt")


def _atomic_write(path: Path, data: bytes) -> None:
    from ..io import atomic_write_bytes

    atomic_write_bytes(path, data)


_TRAILER = b"#chaoscam-part "
_PART = re.compile(r"part-(\d{6,})\.jsonl")


class DamagedPart(ValueError):
    """A part file whose trailer is missing or does not match its records."""


def encode_part(records: list[dict[str, Any]]) -> bytes:
    """Records as JSON lines, then the trailer with their count and SHA-256."""
    body = "".join(json.dumps(r, separators=(",", ":")) + "\n" for r in records).encode()
    digest = hashlib.sha256(body).hexdigest()
    return body + _TRAILER + f"n={len(records)} sha256={digest}\n".encode()


def decode_part(data: bytes) -> list[dict[str, Any]]:
    """The records of a part; :class:`DamagedPart` when it is torn or altered.

    A part without a trailer (written before trailers existed) is accepted when every line
    is a JSON object.
    """
    body, sep, trailer = data.rpartition(_TRAILER)
    if sep:
        fields = dict(
            f.split("=", 1) for f in trailer.decode("ascii", "replace").split() if "=" in f
        )
        if hashlib.sha256(body).hexdigest() != fields.get("sha256"):
            raise DamagedPart("its checksum does not match its records")
    else:
        body = data
    try:
        records = [json.loads(line) for line in body.decode().splitlines() if line.strip()]
    except (UnicodeDecodeError, ValueError) as err:
        raise DamagedPart(f"unreadable records ({type(err).__name__})") from None
    if sep and str(len(records)) != fields.get("n"):
        raise DamagedPart(f"{len(records)} records where its trailer says {fields.get('n')}")
    if not all(isinstance(r, dict) for r in records):
        raise DamagedPart("a line that is not a record")
    return records


def remove_leftovers(path: Path) -> None:
    """Finish what killed runs left beside ``path``: the ``.tmp-PID-NAME`` and
    ``.tmp-PID-removed-NAME`` folders (a checkpoint being created, or being deleted by
    :func:`discard_checkpoint`) and files (an output being written,
    :func:`chaoscam._outputs.atomic_path`) of processes PID that no longer run.

    Call it holding the output's lock; a leftover whose process still runs is left alone.
    """
    for left in path.parent.glob(f".tmp-*-{path.name}"):
        pid = left.name.split("-", 2)[1]
        if pid.isdigit() and not _running(int(pid)):
            if left.is_dir() and not left.is_symlink():
                shutil.rmtree(left, ignore_errors=True)
            else:
                left.unlink(missing_ok=True)


def _running(pid: int) -> bool:
    if pid == os.getpid():
        return True
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except PermissionError:  # another user's process
        return True
    return True


def not_a_folder(path: Path) -> bool:
    """Whether something other than a folder (a file, a dangling link) holds ``path``."""
    return (path.is_symlink() and not path.exists()) or (path.exists() and not path.is_dir())


def discard_checkpoint(path: Path) -> None:
    """Delete a checkpoint folder: renamed away first, in one step, so a kill during the
    deletion never leaves a half-deleted checkpoint that a later --resume would trip over
    (the renamed folder it leaves is removed by the next run, :func:`remove_leftovers`).
    A file or link where the folder belongs is removed as such."""
    if not (path.exists() or path.is_symlink()):
        return
    if path.is_symlink() or not path.is_dir():
        path.unlink()
        return
    gone = path.with_name(f".tmp-{os.getpid()}-removed-{path.name}")
    os.replace(path, gone)
    shutil.rmtree(gone, ignore_errors=True)


class MemoryStore:
    """Records kept in memory only (a run without an output file)."""

    path: Path | None = None

    def __init__(self) -> None:
        self._records: list[dict[str, Any]] = []

    def open(self) -> None:
        pass

    def restored(self) -> Iterator[dict[str, Any]]:
        return iter(())

    def add(self, record: dict[str, Any]) -> None:
        self._records.append(record)

    def maybe_flush(self) -> None:
        pass

    def flush(self) -> None:
        pass

    def records(self) -> Iterator[dict[str, Any]]:
        return iter(self._records)

    def remove(self) -> None:
        self._records = []


class CheckpointStore:
    """Append-only part files under ``directory`` with a manifest of the configuration.

    Parameters
    ----------
    directory : Path
        The checkpoint folder (created if absent).
    config : dict
        The run's configuration; a folder made by another configuration is refused.
    resume : bool
        Continue the records already there. Without it an existing folder is refused, so
        nothing is overwritten by accident.
    flush_interval : float
        Seconds between part files while records arrive [s]; 0 writes one part per record.
        At most this much finished work is lost (and simply recomputed) when killed.
    replaces : list of Path
        The outputs this run was asked to replace (``--force``): the manifest records what
        they are when it starts (:func:`file_identity`), so that a resume replaces those
        files and no other made since (:func:`guard_outputs`).
    """

    def __init__(
        self,
        directory: Path,
        config: dict[str, Any],
        *,
        resume: bool,
        flush_interval: float = 1.0,
        replaces: tuple[Path, ...] = (),
    ) -> None:
        self._replaces = {p.name: file_identity(p) for p in replaces if p.exists()}
        self.path = Path(directory)
        self.hash = config_hash(config)
        self.flush_interval = float(flush_interval)
        self._pending: list[dict[str, Any]] = []
        self._last = time.monotonic()
        if not_a_folder(self.path):
            raise FileExistsError(
                f"{self.path} is a file where this run keeps its checkpoint folder: move it "
                "away, or pass --force (force=True in Python) to replace it"
            )
        if self.path.exists():
            if not resume:
                raise FileExistsError(
                    f"{self.path} holds the checkpoint of an interrupted run: run the same "
                    "command with --resume to finish it, or pass --force (force=True in Python) to "
                    "start over"
                )
        self._config = config
        if self.path.exists():
            self._check_manifest()
            for tmp in self.path.glob(".tmp-*"):
                tmp.unlink(missing_ok=True)
        self._seq = 1 + max((int(_PART.fullmatch(p.name)[1]) for p in self._parts()), default=-1)

    def open(self) -> None:
        """Create the folder and its manifest if absent (when the run starts)."""
        if not self.path.exists():
            self._create(self._config)

    def _create(self, config: dict[str, Any]) -> None:
        tmp = self.path.with_name(f".tmp-{os.getpid()}-{self.path.name}")
        shutil.rmtree(tmp, ignore_errors=True)
        tmp.mkdir(parents=True)
        manifest = {"hash": self.hash, "config": config, "replaces": self._replaces}
        _atomic_write(tmp / "manifest.json", json.dumps(manifest, indent=1).encode())
        os.replace(tmp, self.path)

    def _check_manifest(self) -> None:
        try:
            manifest = _read_manifest(self.path)
        except (OSError, ValueError) as err:
            raise SweepError(
                f"{self.path}: no readable manifest.json ({err}); not a chaoscam checkpoint, "
                "or a damaged one whose runs cannot be matched to a configuration: pass "
                "--force without --resume (force=True in Python) to start over"
            ) from None
        if manifest.get("hash") != self.hash:
            raise SweepError(
                f"{self.path} is the checkpoint of a different configuration (hash "
                f"{str(manifest.get('hash'))[:12]}, this run {self.hash[:12]})"
                f"{differences(manifest.get('config'), self._config)}; use the original "
                "command to resume it, or delete the folder to start over"
            )

    def _parts(self) -> list[Path]:
        if not self.path.is_dir():
            return []
        return sorted(p for p in self.path.glob("part-*.jsonl") if _PART.fullmatch(p.name))

    def restored(self) -> Iterator[dict[str, Any]]:
        """The records already checkpointed, part by part (streamed, not all in memory).

        A damaged last part (torn by a kill at the wrong moment, a full disk) is removed
        with a one-line notice on stderr; its records are simply computed again. A damaged
        part before the last is refused: a :class:`SweepError` says what to do.
        """
        parts = self._parts()
        for i, part in enumerate(parts):
            try:
                records = decode_part(part.read_bytes())
            except DamagedPart as err:
                if i < len(parts) - 1:
                    raise SweepError(
                        f"{part} is damaged ({err}) and is not the last part: delete that "
                        f"file to compute its records again, or delete {self.path} to start "
                        "over"
                    ) from None
                os.replace(part, part.with_name(f".tmp-{os.getpid()}-damaged-{part.name}"))
                print(
                    f"chaoscam: notice: {part.name} in {self.path} was torn ({err}); "
                    "dropped, its runs are computed again",
                    file=sys.stderr,
                    flush=True,
                )
                return
            yield from records

    def add(self, record: dict[str, Any]) -> None:
        self._pending.append(record)

    def maybe_flush(self) -> None:
        if self._pending and time.monotonic() - self._last >= self.flush_interval:
            self.flush()

    def flush(self) -> None:
        """Write the pending records as one new part file, atomically."""
        self._last = time.monotonic()
        if not self._pending:
            return
        self.open()
        _atomic_write(self.path / f"part-{self._seq:06d}.jsonl", encode_part(self._pending))
        self._seq += 1
        self._pending = []

    def records(self) -> Iterator[dict[str, Any]]:
        """Every record: the parts on disk and any not yet flushed."""
        yield from self.restored()
        yield from self._pending

    def remove(self) -> None:
        """Delete the folder (after the final table is safely written).

        It is first renamed away in one step, so a kill during the deletion never leaves a
        half-deleted checkpoint that a later --resume would trip over.
        """
        discard_checkpoint(self.path)


def write_parquet(
    frame: pd.DataFrame, path: Path, config: dict[str, Any], *, replace: bool = True
) -> None:
    """Write ``frame`` atomically, with the configuration and its hash as file metadata
    (``replace=False``: never over a file that exists; :func:`chaoscam._outputs.atomic_path`)."""
    import pyarrow as pa

    from ..io import write_table

    table = pa.Table.from_pandas(frame, preserve_index=False)
    meta = dict(table.schema.metadata or {})
    meta[_META_KEY] = json.dumps({"hash": config_hash(config), "config": config}).encode()
    from ..io import atomic_path

    with atomic_path(path, replace=replace) as tmp:
        write_table(table.replace_schema_metadata(meta), tmp)


def read_sweep_metadata(path: Path) -> dict[str, Any] | None:
    """The configuration record of a sweep output, or None if it has none (or is not a
    readable parquet file, or its record is damaged)."""
    import pyarrow as pa
    import pyarrow.parquet as pq

    try:
        meta = pq.read_schema(path).metadata or {}
        record = json.loads(meta[_META_KEY]) if _META_KEY in meta else None
    except (OSError, pa.ArrowException, ValueError):
        return None
    return record if isinstance(record, dict) else None


def guard_outputs(outputs: list[Path], config: dict[str, Any], resume: bool) -> bool:
    """Check the output files before any work; True when a finished run can be reused.

    Without ``resume`` an existing output is refused (nothing is overwritten). With it, a
    finished output of the same configuration is reused as is; one of another configuration
    is refused, unless the checkpoint beside it is this configuration's: a ``--force`` run
    over that output was interrupted, and its resume finishes it (replacing the output, as
    the ``--force`` asked). Only the file that run found there is replaced: one made since
    (another command writing the free name after the interruption) is refused.
    """
    existing = [p for p in outputs if p.exists()]
    if not existing:
        return False
    ours = _checkpoint_hash(checkpoint_dir(outputs[0])) == config_hash(config)
    if ours:
        _check_replaced(checkpoint_dir(outputs[0]), existing, config)
    if not outputs[0].exists() and not ours:
        # A companion without its main table: nothing to finish or reuse.
        raise FileExistsError(
            f"{existing[0]} exists without {outputs[0].name}, a leftover of another run: "
            "remove it, choose another --out, or pass --force (force=True in Python) to "
            "replace it (nothing was overwritten)"
        )
    if not resume:
        raise FileExistsError(
            f"{existing[0]} exists: pass --resume (resume=True in Python) to finish or reuse "
            "that run, --force to replace it, or choose another --out (nothing was "
            "overwritten)"
        )
    meta = read_sweep_metadata(outputs[0]) if outputs[0].exists() else None
    if meta is None or meta.get("hash") != config_hash(config):
        if ours:
            return False
        if meta is None:
            raise SweepError(
                f"{existing[0]} is not a readable chaoscam sweep (damaged, cut short, or "
                "another kind of file), so --resume cannot reuse it. Pass --force without "
                "--resume to compute it again, or choose another --out"
            )
        why = differences(meta.get("config"), config)
        raise SweepError(
            f"{existing[0]} was made by a different configuration{why} (or is not a chaoscam "
            "sweep); --resume continues only the same command. Choose another --out, or pass "
            "--force without --resume to replace it"
        )
    return not checkpoint_dir(outputs[0]).exists() and all(p.exists() for p in outputs)


def file_identity(path: Path) -> list[int]:
    """What tells one file at ``path`` from another made there later: [size, mtime in ns]."""
    st = path.stat()
    return [st.st_size, st.st_mtime_ns]


def _read_manifest(directory: Path) -> dict[str, Any]:
    """A checkpoint's ``manifest.json``; OSError or ValueError when it cannot be read or is
    not a JSON object."""
    manifest = json.loads((directory / "manifest.json").read_text())
    if not isinstance(manifest, dict):
        raise ValueError(f"a JSON {type(manifest).__name__}, not an object")
    return manifest


def _check_replaced(directory: Path, existing: list[Path], config: dict[str, Any]) -> None:
    """Refuse an output beside this configuration's checkpoint that is neither this
    configuration's (a finished table) nor a file the interrupted run was asked to replace
    (``--force``: recorded in its manifest as it was then): one made since would be
    overwritten silently by the resume."""
    replaces = _read_manifest(directory).get("replaces") or {}
    for path in existing:
        meta = read_sweep_metadata(path)
        if meta is not None and meta.get("hash") == config_hash(config):
            continue  # this configuration's own table (written before the checkpoint went)
        if replaces.get(path.name) != file_identity(path):
            raise FileExistsError(
                f"{path} was not there, or not as it is now, when the interrupted run of this "
                "checkpoint started: it would be overwritten. Move it away, or choose "
                "another --out (nothing was overwritten)"
            )


def _checkpoint_hash(directory: Path) -> str | None:
    """The configuration hash in a checkpoint's manifest; None without a readable one."""
    try:
        return _read_manifest(directory).get("hash")
    except (OSError, ValueError):
        return None
