"""numba's on-disk cache, emptied when any source file of a package changes.

numba keys a cached function on its own file's modification time and size only. A compiled
function that calls a function of another file keeps its compiled copy of that callee after
the callee's file changes: after a pull that changed only ``integrate/_events.py`` (the
crossing search, 2026-11-28), runs with a warm cache kept the old search, and so other
trajectories than the code's, until the cache was emptied (measured: the same run left the
cam's reach at 16.1 s instead of 28.9 s). A package whose compiled functions call each other
across files calls :func:`guard` when it is imported, before any of them is compiled or
loaded: a fingerprint of all its ``.py`` files is kept beside numba's cache files, and when
it differs the package's cache files are removed, so that every function compiles from the
current sources (on a fresh install that is what happens anyway).

Only the cache beside the sources is handled (``__pycache__``, where numba writes when that
folder is writable: an editable install, a checkout); where numba has to use its per-user
cache folder instead, nothing is removed.
"""

from __future__ import annotations

import hashlib
import os
from pathlib import Path

__all__ = ["STAMP", "fingerprint", "guard"]

STAMP = "chaoscam-sources.sha256"
"""The fingerprint's file, in the package's ``__pycache__``."""


def fingerprint(folder: Path) -> str:
    """SHA-256 over the names and contents of ``folder``'s ``.py`` files, in name order."""
    h = hashlib.sha256()
    for path in sorted(folder.glob("*.py")):
        h.update(path.name.encode())
        h.update(b"\0")
        h.update(path.read_bytes())
    return h.hexdigest()


def guard(folder: str | os.PathLike) -> bool:
    """Remove numba's cache files (``*.nbi``, ``*.nbc``) from ``folder/__pycache__`` when
    ``folder``'s sources differ from those they were compiled from, and record the new
    fingerprint. Returns whether any file was removed. Processes that import the package at
    the same moment may both remove the files; neither has compiled anything yet, so
    nothing is lost. A folder that cannot be written is left as it is."""
    folder = Path(folder)
    cache = folder / "__pycache__"
    stamp = cache / STAMP
    now = fingerprint(folder)
    try:
        if stamp.read_text() == now:
            return False
    except OSError:
        pass  # no fingerprint yet: whatever is cached may be from any sources
    removed = False
    try:
        cache.mkdir(exist_ok=True)
        for path in [*cache.glob("*.nbi"), *cache.glob("*.nbc")]:
            try:
                path.unlink()
                removed = True
            except FileNotFoundError:
                pass  # another process removed it
        part = cache / f"{STAMP}.{os.getpid()}"
        part.write_text(now)
        os.replace(part, stamp)
    except OSError:
        pass  # a read-only install: numba caches elsewhere, or not at all
    return removed
