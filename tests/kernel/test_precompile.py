"""The kernel's first compilation shared with a second process (kernel._precompile)."""

import os
import subprocess
import sys
import time
from pathlib import Path

import pytest

from chaoscam.kernel import _precompile


def _alive(pids, timeout=10.0) -> list[int]:
    """The processes of ``pids`` still running (not zombies) after up to ``timeout`` s."""
    t0 = time.monotonic()
    while True:
        left = [
            p
            for p in pids
            if Path(f"/proc/{p}").exists()
            and "Z" not in (Path(f"/proc/{p}/stat").read_text().rsplit(")", 1)[1][:3])
        ]
        if not left or time.monotonic() - t0 > timeout:
            return left
        time.sleep(0.05)


# A run's last section point, printed exactly; PROBE adds how each of the second process's
# callees came to this process: numba's cache hits and misses for it.
LAST_POINT = """
import chaoscam
traj = chaoscam.simulate(duration=2.0, seed=3)
print(repr(tuple(traj.section[["theta_f", "omega_f"]].iloc[-1])))
"""
PROBE = (
    LAST_POINT
    + """
from chaoscam.kernel._precompile import _callees
for d, sig in _callees():
    print(d.py_func.__name__, sum(d.stats.cache_hits.values()), sum(d.stats.cache_misses.values()))
"""
)


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
    """In an empty cache, after `python -m chaoscam.kernel._precompile` the kernel's
    compilation finds every one of its callees in numba's cache (their signatures are those
    the kernel asks for: a hit each, no miss), and the run equals one compiled without it.
    About 45 s: two compilations from empty caches."""
    helped = _run(None, tmp_path / "helped", "-m", "chaoscam.kernel._precompile")
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


def test_start_once_starts_one_second_process_a_process_and_none_in_a_worker(monkeypatch):
    """The first ask starts it, the next asks do not (however many threads ask); a sweep's
    worker process (one with a parent) starts none."""
    import multiprocessing

    started = []
    monkeypatch.setattr(_precompile, "start_beside", lambda: started.append(1))
    monkeypatch.setattr(_precompile, "_started", False)
    for _ in range(3):
        _precompile.start_once()
    assert started == [1]
    monkeypatch.setattr(_precompile, "_started", False)
    monkeypatch.setattr(multiprocessing, "parent_process", lambda: object())
    _precompile.start_once()
    assert started == [1]


@pytest.mark.slow
def test_a_fresh_installs_first_simulate_starts_the_second_process(tmp_path):
    """In an empty cache a plain ``simulate`` (no ``chaoscam paper``) starts the second
    process once, before the kernel compiles, and its run is the same bits as one without
    it. About 35 s: two compilations from empty caches."""
    code = (
        "import chaoscam.kernel._precompile as p\n"
        "calls = []\n"
        "real = p.start_beside\n"
        "p.start_beside = lambda: calls.append(real()) or calls[-1]\n"
        + LAST_POINT
        + "chaoscam.simulate(duration=0.5)\n"
        "print(len(calls), calls[0] is not None)\n"
    )
    helped = _run(code, tmp_path / "a", "-c").splitlines()
    alone = _run(
        "import chaoscam.kernel._precompile as p\np.start_once = lambda: None\n" + LAST_POINT,
        tmp_path / "b",
        "-c",
    ).splitlines()
    assert helped[-1] == "1 True" and helped[0] == alone[0]


@pytest.mark.skipif(not os.path.exists("/proc/self/stat"), reason="needs Linux /proc")
def test_the_second_process_ends_when_its_parent_is_killed(tmp_path):
    """A run SIGKILLed on a fresh install leaves no compiler behind: the second process,
    compiling into an empty cache (about 10 s of work), ends within 3 s of its parent."""
    import signal

    code = (
        "import subprocess, sys, time\n"
        "p = subprocess.Popen([sys.executable, '-m', 'chaoscam.kernel._precompile'])\n"
        "print(p.pid, flush=True)\n"
        "time.sleep(60)\n"
    )
    env = {**os.environ, "NUMBA_CACHE_DIR": str(tmp_path)}
    parent = subprocess.Popen([sys.executable, "-c", code], env=env, stdout=subprocess.PIPE)
    helper = int(parent.stdout.readline())
    try:
        time.sleep(1.5)  # importing numba, or compiling
        assert _alive([helper], timeout=0) == [helper]
        parent.kill()
        parent.wait(timeout=10)
        assert _alive([helper], timeout=3.0) == []
    finally:
        for pid in _alive([helper], timeout=0):
            os.kill(pid, signal.SIGKILL)
