"""numba's on-disk cache, emptied when any source file of a package changes: numba keys a cached
function on its own file's time and size only, so a caller would keep a changed callee's old
copy. :func:`guard`, called on import, removes the cache when the sources' fingerprint differs.
"""

from __future__ import annotations

import hashlib
import os
from pathlib import Path

STAMP = "chaoscam-sources.sha256"
"""The fingerprint's file, in :func:`cache_folder`."""


def fingerprint(folder: Path) -> str:
    """SHA-256 over the names and contents of ``folder``'s ``.py`` files, in name order."""
    h = hashlib.sha256()
    for path in sorted(folder.glob("*.py")):
        h.update(path.name.encode())
        h.update(b"\0")
        h.update(path.read_bytes())
    return h.hexdigest()


def cache_folder(folder: str | os.PathLike) -> Path:
    """Where numba caches functions of ``folder``'s modules (``NUMBA_CACHE_DIR``, a writable
    ``__pycache__``, or numba's per-user folder): the first of numba's cache locators to accept
    a file of ``folder``, or ``folder/__pycache__`` where they cannot be asked."""
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
    """Remove numba's cache files (``*.nbi``, ``*.nbc``) of ``folder``'s modules
    (:func:`cache_folder`) when its sources differ from those they were compiled from, and
    record the new fingerprint; returns whether any was removed. Concurrent importers may both
    remove them (neither has compiled yet); a read-only cache folder is left as it is."""
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
