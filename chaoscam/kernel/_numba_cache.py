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

The cache handled is the one numba uses for the package's folder: ``NUMBA_CACHE_DIR`` when it
is set (numba then writes there even for a checkout), else ``__pycache__`` beside the sources
when that folder is writable (an editable install, a checkout), else numba's per-user cache
folder (a read-only install); numba's own cache locators say which (:func:`cache_folder`).
Until 2026-11-28's ninth session only ``__pycache__`` was handled, and a checkout run with
``NUMBA_CACHE_DIR`` set kept a stale callee (tested).
"""

from __future__ import annotations

import hashlib
import os
from pathlib import Path

__all__ = ["STAMP", "cache_folder", "fingerprint", "guard"]

STAMP = "chaoscam-sources.sha256"
"""The fingerprint's file, in the folder numba caches the package in (:func:`cache_folder`)."""


def fingerprint(folder: Path) -> str:
    """SHA-256 over the names and contents of ``folder``'s ``.py`` files, in name order."""
    h = hashlib.sha256()
    for path in sorted(folder.glob("*.py")):
        h.update(path.name.encode())
        h.update(b"\0")
        h.update(path.read_bytes())
    return h.hexdigest()


def cache_folder(folder: str | os.PathLike) -> Path:
    """The folder where numba keeps the cache of functions defined in ``folder``'s modules:
    the path of the first of numba's cache locators that accepts a file of ``folder`` (the
    order numba itself tries them in), or ``folder/__pycache__`` when numba's locators cannot
    be asked (they are not public API)."""
    folder = Path(folder)
    try:
        from numba.core.caching import CacheImpl

        probe = str((folder / "__init__.py").resolve())
        for locator in CacheImpl._locator_classes:
            found = locator.from_function(cache_folder, probe)
            if found is not None:
                return Path(found.get_cache_path())
    except (ImportError, AttributeError, TypeError, OSError):
        pass
    return folder / "__pycache__"


def guard(folder: str | os.PathLike) -> bool:
    """Remove numba's cache files (``*.nbi``, ``*.nbc``) for ``folder``'s modules from the
    folder numba keeps them in (:func:`cache_folder`) when ``folder``'s sources differ from
    those they were compiled from, and record the new fingerprint there. Returns whether any
    file was removed. Processes that import the package at the same moment may both remove
    the files; neither has compiled anything yet, so nothing is lost. A cache folder that
    cannot be written is left as it is."""
    folder = Path(folder)
    cache = cache_folder(folder)
    stamp = cache / STAMP
    now = fingerprint(folder)
    try:
        if stamp.read_text() == now:
            return False
    except OSError:
        pass  # no fingerprint yet: whatever is cached may be from any sources
    removed = False
    try:
        cache.mkdir(parents=True, exist_ok=True)
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
