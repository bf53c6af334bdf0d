"""The kernel's first compilation shared with a second process (integrate._precompile)."""

import os
import subprocess
import sys

import pytest

from chaoscam.integrate import _precompile

# A run's last section point, printed exactly, and how each of the second process's callees
# came to this process: numba's cache hits and misses for it.
PROBE = """
import chaoscam
from chaoscam.integrate._precompile import _callees
traj = chaoscam.simulate(duration=2.0, seed=3)
print(repr(tuple(traj.section[["theta_f", "omega_f"]].iloc[-1])))
for d, sig in _callees():
    print(d.py_func.__name__, sum(d.stats.cache_hits.values()), sum(d.stats.cache_misses.values()))
"""


def _run(code: str, cache, *args: str) -> str:
    env = {**os.environ, "NUMBA_CACHE_DIR": str(cache)}
    out = subprocess.run(
        [sys.executable, *args, code] if code else [sys.executable, *args],
        env=env,
        check=True,
        capture_output=True,
        text=True,
    )
    return out.stdout


@pytest.mark.slow
def test_the_kernel_loads_the_second_processs_callees_and_gives_the_same_bits(tmp_path):
    """In an empty cache, after `python -m chaoscam.integrate._precompile` the kernel's
    compilation finds every one of its callees in numba's cache (their signatures are those
    the kernel asks for: a hit each, no miss), and the run equals one compiled without it.
    About 45 s: two compilations from empty caches."""
    helped = _run(None, tmp_path / "helped", "-m", "chaoscam.integrate._precompile")
    assert helped == ""
    lines = _run(PROBE, tmp_path / "helped", "-c").splitlines()
    alone = _run(PROBE, tmp_path / "alone", "-c").splitlines()
    assert lines[0] == alone[0]  # the same last section point, bit for bit
    for line in lines[1:]:
        name, hits, misses = line.split()
        assert (int(hits), int(misses)) == (1, 0), line
    assert len(lines) == 1 + len(_precompile._callees())


def test_the_second_process_starts_only_where_a_callee_is_not_cached(monkeypatch):
    """Every callee cached (every run after the first): nothing starts. One missing: the
    second process runs and ends cleanly (here it loads them from the cache)."""
    import chaoscam

    chaoscam.simulate(duration=0.01)  # the kernel compiled or loaded: its callees cached
    monkeypatch.setattr(_precompile, "_cached", lambda d: True)
    assert _precompile.start_beside() is None
    monkeypatch.setattr(_precompile, "_cached", lambda d: False)
    proc = _precompile.start_beside()
    assert proc is not None and proc.wait(timeout=120) == 0
