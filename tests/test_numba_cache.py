"""numba's cache follows a callee's edit in another file only with the package's guard."""

import os
import subprocess
import sys
import textwrap
from pathlib import Path

import pytest

import chaoscam
from chaoscam.kernel import _numba_cache

CALLER = """
from numba import njit

from .callee import g


@njit(cache=True)
def f():
    return g()
"""

INIT = """
import os
from pathlib import Path

from chaoscam.kernel._numba_cache import guard

if os.environ.get("GUARD") == "1":
    guard(Path(__file__).parent)
"""


def _callee(value: int) -> str:
    return f"from numba import njit\n\n\n@njit(cache=True)\ndef g():\n    return {value}\n"


def _f(root: Path, guarded: bool, cache_dir: Path | None = None) -> str:
    env = dict(os.environ, GUARD="1" if guarded else "0")
    env.pop("NUMBA_CACHE_DIR", None)
    if cache_dir is not None:
        env["NUMBA_CACHE_DIR"] = str(cache_dir)
    env["PYTHONPATH"] = os.pathsep.join([str(root), str(Path(chaoscam.__file__).parents[1])])
    code = "import pkg.caller as c; print(c.f())"
    done = subprocess.run(
        [sys.executable, "-c", code], env=env, capture_output=True, text=True, timeout=120
    )
    assert done.returncode == 0, done.stderr
    return done.stdout.strip()


@pytest.mark.parametrize("where", ["beside the sources", "NUMBA_CACHE_DIR"])
def test_a_callees_edit_reaches_a_cached_caller_through_the_guard(tmp_path, where):
    """A cached function calling one of another file: after that file's edit numba still
    runs the old callee (its cache is keyed on the caller's own file), unless the package's
    guard empties the cache because the sources' fingerprint changed; also where numba
    caches in ``NUMBA_CACHE_DIR`` instead of ``__pycache__`` (before 2026-11-28's ninth
    session the guard emptied ``__pycache__`` only, and this case ran the stale callee)."""
    src = tmp_path / "src"
    pkg = src / "pkg"
    pkg.mkdir(parents=True)
    (pkg / "__init__.py").write_text(textwrap.dedent(INIT))
    (pkg / "caller.py").write_text(CALLER)
    (pkg / "callee.py").write_text(_callee(1))
    cache_dir = tmp_path / "numba-cache" if where == "NUMBA_CACHE_DIR" else None
    assert _f(src, guarded=True, cache_dir=cache_dir) == "1"  # compiled, cached, stamped
    # pkg's fingerprint (importing the guard from chaoscam.kernel stamps the kernel's too)
    ours = _numba_cache.fingerprint(pkg)
    stamps = [s for s in tmp_path.rglob(_numba_cache.STAMP) if s.read_text() == ours]
    cached = list(tmp_path.rglob("*.nbi"))
    assert len(stamps) == 1 and cached and all(c.parent == stamps[0].parent for c in cached)
    assert (stamps[0].parent == pkg / "__pycache__") == (cache_dir is None)
    (pkg / "callee.py").write_text(_callee(22))
    assert _f(src, guarded=False, cache_dir=cache_dir) == "1"  # numba alone: the stale callee
    assert _f(src, guarded=True, cache_dir=cache_dir) == "22"  # the guard: from the sources
    assert _f(src, guarded=True, cache_dir=cache_dir) == "22"  # cached again, nothing removed


def test_the_kernels_cache_is_guarded():
    """Importing chaoscam.kernel records its sources' fingerprint beside numba's cache
    (where that folder is writable, as in a checkout)."""
    import chaoscam.kernel as kernel

    folder = Path(kernel.__file__).parent
    stamp = _numba_cache.cache_folder(folder) / _numba_cache.STAMP
    if os.access(stamp.parent, os.W_OK):
        assert stamp.read_text() == _numba_cache.fingerprint(folder)
    if not os.environ.get("NUMBA_CACHE_DIR") and os.access(folder, os.W_OK):
        assert stamp.parent == folder / "__pycache__"
