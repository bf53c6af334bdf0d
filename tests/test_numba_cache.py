"""numba's cache follows a callee's edit in another file only with the package's guard."""

import os
import subprocess
import sys
import textwrap
from pathlib import Path

import chaoscam
from chaoscam import _numba_cache

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

from chaoscam._numba_cache import guard

if os.environ.get("GUARD") == "1":
    guard(Path(__file__).parent)
"""


def _callee(value: int) -> str:
    return f"from numba import njit\n\n\n@njit(cache=True)\ndef g():\n    return {value}\n"


def _f(root: Path, guarded: bool) -> str:
    env = dict(os.environ, GUARD="1" if guarded else "0")
    env["PYTHONPATH"] = os.pathsep.join([str(root), str(Path(chaoscam.__file__).parents[1])])
    code = "import pkg.caller as c; print(c.f())"
    done = subprocess.run(
        [sys.executable, "-c", code], env=env, capture_output=True, text=True, timeout=120
    )
    assert done.returncode == 0, done.stderr
    return done.stdout.strip()


def test_a_callees_edit_reaches_a_cached_caller_through_the_guard(tmp_path):
    """A cached function calling one of another file: after that file's edit numba still
    runs the old callee (its cache is keyed on the caller's own file), unless the package's
    guard empties the cache because the sources' fingerprint changed."""
    pkg = tmp_path / "pkg"
    pkg.mkdir()
    (pkg / "__init__.py").write_text(textwrap.dedent(INIT))
    (pkg / "caller.py").write_text(CALLER)
    (pkg / "callee.py").write_text(_callee(1))
    assert _f(tmp_path, guarded=True) == "1"  # compiled and cached, fingerprint written
    assert (pkg / "__pycache__" / _numba_cache.STAMP).exists()
    (pkg / "callee.py").write_text(_callee(22))
    assert _f(tmp_path, guarded=False) == "1"  # numba alone: the stale callee
    assert _f(tmp_path, guarded=True) == "22"  # the guard: compiled from the sources
    assert _f(tmp_path, guarded=True) == "22"  # and cached again (nothing removed)
    assert not _numba_cache.guard(pkg)


def test_the_integrators_cache_is_guarded():
    """Importing chaoscam.integrate records its sources' fingerprint beside numba's cache
    (where that folder is writable, as in a checkout)."""
    import chaoscam.integrate as integrate

    folder = Path(integrate.__file__).parent
    stamp = folder / "__pycache__" / _numba_cache.STAMP
    if os.access(folder, os.W_OK):
        assert stamp.read_text() == _numba_cache.fingerprint(folder)
