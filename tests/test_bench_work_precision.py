"""The work-precision benchmark's rule for "the cheapest setting that meets the target"."""

import importlib.util
import os
from pathlib import Path

import numba
import pytest

BENCH = Path(__file__).resolve().parents[1] / "benchmarks" / "bench_work_precision.py"


@pytest.fixture
def bench(monkeypatch):
    """The benchmark module, imported without changing this process's environment (it sets
    ``NUMBA_NUM_THREADS`` when unset)."""
    threads = os.environ.get("NUMBA_NUM_THREADS", str(numba.config.NUMBA_NUM_THREADS))
    monkeypatch.setenv("NUMBA_NUM_THREADS", threads)
    spec = importlib.util.spec_from_file_location("bench_work_precision", BENCH)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def _rows(kind, errors, seconds):
    return [(kind, f"r{i}", s, e) for i, (e, s) in enumerate(zip(errors, seconds, strict=True))]


def test_a_rung_that_meets_above_a_failing_one_does_not_count(bench):
    """Coarse to fine: r1 meets by chance, r2 fails, r3 and r4 meet: the cheapest of r3, r4."""
    tol = bench.TOL
    rows = _rows("adaptive", [2 * tol, tol / 2, 3 * tol, tol / 2, tol / 3], [1, 2, 3, 5, 4])
    assert bench.settled(rows, "adaptive") == ("r4", 4, False)


def test_the_ladders_first_rung_is_flagged(bench):
    """Every rung meets: the cheapest is chosen and flagged as the ladder's coarsest."""
    tol = bench.TOL
    rows = _rows("rk4 fixed", [tol / 2, tol / 4, tol / 8], [1, 2, 4])
    assert bench.settled(rows, "rk4 fixed") == ("r0", 1, True)


def test_no_setting_when_the_finest_rung_misses(bench):
    """However many coarser rungs meet, a ladder whose finest rung misses settles nothing."""
    tol = bench.TOL
    rows = _rows("adaptive", [tol / 2, tol / 2, 2 * tol], [1, 2, 3])
    assert bench.settled(rows, "adaptive") is None
    assert bench.settled(rows, "rk4 merged") is None
