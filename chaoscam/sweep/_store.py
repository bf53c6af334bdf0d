"""Checkpoints: finished records written as they complete, so a killed run can resume.

``FILE.parquet.ckpt/`` holds ``manifest.json`` (the configuration and its SHA-256) and parts
``part-NNNNNN.jsonl`` (JSON records, then ``#chaoscam-part n=COUNT sha256=HEX``), each moved
into place whole (:func:`os.replace`); a damaged last part is recomputed, an earlier one
refused. Floats round-trip exactly; the output's OS lock keeps a checkpoint to one process.
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

from .._util import real
from ..io import atomic_path, atomic_write_bytes, check_output, tmp_name, write_table
from ._grid import SweepError

_META_KEY = b"chaoscam.sweep"


def config_hash(config: dict[str, Any]) -> str:
    """SHA-256 of the configuration's canonical JSON (sorted keys, exact floats)."""
    text = json.dumps(config, sort_keys=True, separators=(",", ":"), allow_nan=False)
    return hashlib.sha256(text.encode()).hexdigest()


def differences(saved: Any, config: dict[str, Any]) -> str:
    """What sets a saved configuration apart from this run's (the code, or the settings)."""
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
    """The records of a part; :class:`DamagedPart` when torn or altered (no trailer: older)."""
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
    """Remove the ``.tmp-PID-...`` files and folders beside ``path`` of processes now gone."""
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
        pass
    return True


def discard_checkpoint(path: Path) -> None:
    """Delete a checkpoint folder, renamed away first (a kill never leaves half of one)."""
    if not (path.exists() or path.is_symlink()):
        return
    if path.is_symlink() or not path.is_dir():
        path.unlink()
        return
    gone = tmp_name(path, "removed")
    os.replace(path, gone)
    shutil.rmtree(gone, ignore_errors=True)


class CheckpointStore:
    """A run's records: part files every ``flush_interval`` s (0: one per record) under
    ``directory`` with a manifest of ``config``, or in memory (None); an existing folder is
    refused without ``resume``, of another configuration always. ``replaces``: the outputs
    ``--force`` replaces, recorded (:func:`file_identity`) so a resume replaces no later file."""

    def __init__(self, directory: Path | None, config: dict[str, Any], *, resume: bool,
                 flush_interval: float = 1.0, replaces: tuple[Path, ...] = ()) -> None:  # fmt: skip
        self._replaces = {p.name: file_identity(p) for p in replaces if p.exists()}
        self.path = None if directory is None else Path(directory)
        self.hash = config_hash(config)
        self.flush_interval = float(flush_interval)
        self._pending: list[dict[str, Any]] = []
        self._last = time.monotonic()
        self._config, self._seq = config, 0
        if self.path is None:
            return
        if (self.path.is_symlink() and not self.path.exists()) or (
            self.path.exists() and not self.path.is_dir()
        ):
            raise FileExistsError(
                f"{self.path} is a file where this run keeps its checkpoint folder: move it "
                "away, or pass --force (force=True in Python) to replace it"
            )
        if self.path.exists() and not resume:
            raise FileExistsError(
                f"{self.path} holds the checkpoint of an interrupted run: run the same "
                "command with --resume to finish it, or pass --force (force=True in Python) to "
                "start over"
            )
        if self.path.exists():
            self._check_manifest()
            for tmp in self.path.glob(".tmp-*"):
                tmp.unlink(missing_ok=True)
        self._seq = 1 + max((int(_PART.fullmatch(p.name)[1]) for p in self._parts()), default=-1)

    def open(self) -> None:
        """Create the folder and its manifest if absent (when the run starts)."""
        if self.path is None or self.path.exists():
            return
        tmp = tmp_name(self.path)
        shutil.rmtree(tmp, ignore_errors=True)
        tmp.mkdir(parents=True)
        manifest = {"hash": self.hash, "config": self._config, "replaces": self._replaces}
        try:
            atomic_write_bytes(tmp / "manifest.json", json.dumps(manifest, indent=1).encode())
            os.replace(tmp, self.path)
        except OSError:  # a full disk: no half-made folder left behind
            shutil.rmtree(tmp, ignore_errors=True)
            raise

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
        if self.path is None or not self.path.is_dir():
            return []
        return sorted(p for p in self.path.glob("part-*.jsonl") if _PART.fullmatch(p.name))

    def restored(self) -> Iterator[dict[str, Any]]:
        """The records checkpointed; a damaged last part is dropped, an earlier one refused."""
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
                os.replace(part, tmp_name(part, "damaged"))
                print(f"chaoscam: notice: {part.name} in {self.path} was torn ({err}); dropped, "
                      "its runs are computed again", file=sys.stderr, flush=True)  # fmt: skip
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
        if not self._pending or self.path is None:
            return
        self.open()
        atomic_write_bytes(self.path / f"part-{self._seq:06d}.jsonl", encode_part(self._pending))
        self._seq += 1
        self._pending = []

    def records(self) -> Iterator[dict[str, Any]]:
        """Every record: the parts on disk and any not yet flushed."""
        yield from self.restored()
        yield from self._pending

    def remove(self) -> None:
        """Delete the folder (after the final table is safely written)."""
        if self.path is not None:
            discard_checkpoint(self.path)


def write_parquet(
    frame: pd.DataFrame, path: Path, config: dict[str, Any], *, replace: bool = True
) -> None:
    """Write ``frame`` atomically with the configuration and its hash as file metadata."""
    import pyarrow as pa

    table = pa.Table.from_pandas(frame, preserve_index=False)
    meta = dict(table.schema.metadata or {})
    meta[_META_KEY] = json.dumps({"hash": config_hash(config), "config": config}).encode()
    with atomic_path(path, replace=replace) as tmp:
        write_table(table.replace_schema_metadata(meta), tmp)


def read_sweep_metadata(path: Path) -> dict[str, Any] | None:
    """The configuration record of a sweep output; None without a readable one."""
    import pyarrow as pa
    import pyarrow.parquet as pq

    try:
        meta = pq.read_schema(path).metadata or {}
        record = json.loads(meta[_META_KEY]) if _META_KEY in meta else None
    except (OSError, pa.ArrowException, ValueError):
        return None
    return record if isinstance(record, dict) else None


def guard_outputs(outputs: list[Path], config: dict[str, Any], resume: bool) -> bool:
    """Check the outputs before any work; True when a finished run can be reused. Without
    ``resume`` an existing output is refused; with it, this configuration's is reused, another's
    refused unless the checkpoint beside is this configuration's (an interrupted ``--force``)."""
    existing = [p for p in outputs if p.exists()]
    if not existing:
        return False
    try:
        manifest = _read_manifest(checkpoint_dir(outputs[0]))
    except (OSError, ValueError):
        manifest = {}
    ours = manifest.get("hash") == config_hash(config)
    if ours:
        _check_replaced(manifest, existing, config)
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
    """A checkpoint's ``manifest.json``; OSError or ValueError when it is not a JSON object."""
    manifest = json.loads((directory / "manifest.json").read_text())
    if not isinstance(manifest, dict):
        raise ValueError(f"a JSON {type(manifest).__name__}, not an object")
    return manifest


def _check_replaced(manifest: dict, existing: list[Path], config: dict[str, Any]) -> None:
    """Refuse an output neither this configuration's nor recorded by the interrupted --force."""
    replaces = manifest.get("replaces") or {}
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


def open_store(outputs: list[Path] | None, config, resume: bool, flush_interval, force: bool):
    """(the run's record store, whether a finished output is reused), under the outputs'
    lock; ``force`` discards a checkpoint and replaces the outputs."""
    flush_interval = real("flush_interval", flush_interval, low=0.0, unit="s")
    if outputs is None:
        return CheckpointStore(None, config, resume=False), False
    if outputs[0].suffix != ".parquet":
        raise SweepError(f"--out {outputs[0]}: the output must be a .parquet file")
    for path in outputs:
        check_output(path, force=True)  # the folder and the path; existence is below
    ckpt = checkpoint_dir(outputs[0])
    for path in (ckpt, *outputs):  # of a run killed while it made or removed them
        remove_leftovers(path)
    if force and not resume:
        discard_checkpoint(ckpt)
    elif guard_outputs(outputs, config, resume):
        return None, True
    store = CheckpointStore(ckpt, config, resume=resume, flush_interval=flush_interval,
                            replaces=tuple(outputs) if force else ())  # fmt: skip
    return store, False
