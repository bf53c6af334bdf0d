"""Parquet files with page checksums: damage inside a file is found when it is read.

Every file chaoscam writes stores a CRC of each data page and every read verifies them: a file
changed after it was written (a bad disk, a copy cut short) raises :class:`DamagedFileError`
naming it instead of being read with wrong numbers. The key-value metadata (a trajectory's
section, a sweep's configuration) has no page checksum: its SHA-256 is stored beside it
(``chaoscam.digest``) and checked on reading. A file without checksums is read unverified.
"""

from __future__ import annotations

import hashlib
import json
from pathlib import Path

__all__ = [
    "DIGEST_KEY", "DamagedFileError", "exact_json", "read_frame", "read_table", "write_table",
]  # fmt: skip

DIGEST_KEY = b"chaoscam.digest"
"""Metadata key of the SHA-256 of the file's other metadata (:func:`write_table`)."""
_NOT_DIGESTED = (DIGEST_KEY, b"ARROW:schema")  # pyarrow adds the second itself


class DamagedFileError(OSError):
    """A Parquet file whose page checksums do not match its data."""


def _checked(path, read, metadata):
    """``read()``, refused when a page checksum or the metadata's digest does not match."""
    try:
        out = read()
    except OSError as err:
        if "checksum" in str(err).lower():
            raise DamagedFileError(
                f"{path}: damaged (a data page does not match the checksum written with it: "
                f"{err}); write it again"
            ) from None
        raise
    meta = metadata(out) or {}
    if DIGEST_KEY in meta and meta[DIGEST_KEY] != _digest(meta):
        raise DamagedFileError(
            f"{path}: damaged (its metadata does not match the digest written with it); "
            "write it again"
        )
    return out


def _digest(meta: dict) -> bytes:
    h = hashlib.sha256()
    for key in sorted(k for k in meta if k not in _NOT_DIGESTED):
        for part in (key, meta[key]):
            h.update(len(part).to_bytes(8, "little") + part)
    return h.hexdigest().encode()


def write_table(table, path: str | Path) -> None:
    """``pyarrow.parquet.write_table`` with page checksums and the metadata's :data:`DIGEST_KEY`."""
    import pyarrow.parquet as pq

    meta = {k: v for k, v in (table.schema.metadata or {}).items() if k != DIGEST_KEY}
    table = table.replace_schema_metadata({**meta, DIGEST_KEY: _digest(meta)})
    pq.write_table(table, path, write_page_checksum=True)


def read_table(path: str | Path):
    """``pyarrow.parquet.read_table``, verifying page checksums and digest where present."""
    import pyarrow.parquet as pq

    return _checked(path, lambda: pq.read_table(path, page_checksum_verification=True),
                    lambda table: table.schema.metadata)  # fmt: skip


def read_frame(path: str | Path):
    """``pandas.read_parquet``, verifying page checksums and digest where present."""
    import pandas as pd
    import pyarrow.parquet as pq

    return _checked(path, lambda: pd.read_parquet(path, page_checksum_verification=True),
                    lambda _: pq.read_schema(path).metadata)  # fmt: skip


def exact_json(frame) -> str:
    """``frame`` as pandas' "split" JSON with every float exact (Python's shortest round-trip
    repr; ``DataFrame.to_json`` keeps 15 significant digits, which moves 91 of a default 20 s
    run's 92 section points by up to 5.6e-16 rad). NaN is written as null, as by ``to_json``."""
    cells = frame.astype(object).where(frame.notna(), None)
    return json.dumps({"columns": list(frame.columns), "index": list(range(len(frame))),
                       "data": cells.values.tolist()})  # fmt: skip
