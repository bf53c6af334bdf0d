"""What code produced a result, recorded with every sweep and ensemble and matched by a resumed
checkpoint: a fingerprint of the sources that decide a result's numbers (the version is not
bumped with every kernel change) and the versions of numpy and numba, which run the kernels."""

from __future__ import annotations

import functools
import hashlib
from pathlib import Path

from .._version import __version__

__all__ = ["DRIVERS", "code_identity", "code_rows"]

DRIVERS = ("cli", "report", "paper")
"""Subpackages left out of the fingerprint: they run and draw, they compute no result."""


@functools.cache
def code_identity() -> dict[str, str]:
    """``{"version", "sources", "numpy", "numba"}``: the package version, the SHA-256
    (16 hex digits) of the result-deciding sources (path and bytes of each ``.py`` file
    outside :data:`DRIVERS`, in sorted order), and the two libraries' versions."""
    import numba
    import numpy

    root = Path(__file__).resolve().parents[1]
    digest = hashlib.sha256()
    for path in sorted(root.rglob("*.py")):
        rel = path.relative_to(root)
        if rel.parts[0] in DRIVERS:
            continue
        digest.update(rel.as_posix().encode() + b"\0" + path.read_bytes() + b"\0")
    return {"version": __version__, "sources": digest.hexdigest()[:16],
            "numpy": numpy.__version__, "numba": numba.__version__}  # fmt: skip


def code_rows(code: object) -> dict[str, object]:
    """A code record (:func:`code_identity`) as rows of a report's provenance table (none for a
    result without one)."""
    if not isinstance(code, dict):
        return {}
    return {"source fingerprint": code.get("sources"),
            "numpy / numba": f"{code.get('numpy')} / {code.get('numba')}"}  # fmt: skip
