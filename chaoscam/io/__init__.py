"""Files: one rule for every output (checked first, never overwritten silently, written
whole, locked against a second process), Parquet with checksums, and the provenance of the
code that made a result."""

from ._outputs import (
    OutputError,
    OutputLock,
    atomic_path,
    atomic_write_bytes,
    check_output,
    conflict_name,
    lock_all,
    tmp_name,
    write_new_parquet,
)
from ._parquet import DamagedFileError, exact_json, read_frame, read_table, write_table
from ._provenance import DRIVERS, code_identity, code_rows

__all__ = [
    "DRIVERS", "DamagedFileError", "OutputError", "OutputLock", "atomic_path",
    "atomic_write_bytes", "check_output", "code_identity", "code_rows", "conflict_name",
    "exact_json", "lock_all", "read_frame", "read_table", "tmp_name", "write_new_parquet",
    "write_table",
]  # fmt: skip
