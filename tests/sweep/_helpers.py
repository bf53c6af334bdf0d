"""Small deterministic classifiers for testing the sweep machinery (not the physics).

Each takes one run as a one-member :class:`chaoscam.Solution` (what a sweep hands a
classifier of one's own) and returns an object with label, period, evidence and reasons."""

from __future__ import annotations

import os
from dataclasses import dataclass
from pathlib import Path

import numpy as np


@dataclass(frozen=True)
class _Evidence:
    name: str
    value: float
    vote: str | None = None


@dataclass(frozen=True)
class _Verdict:
    label: str
    period: int | None
    evidence: tuple
    reasons: tuple = ()


@dataclass(frozen=True)
class SpreadClassifier:
    """Labels from the spread of the section's theta_f: tiny -> periodic (period 1),
    middling -> quasiperiodic, large -> chaotic. Deterministic, fast, not physics."""

    low: float = 1e-6
    high: float = 0.05
    needs_series = False  # a class attribute, not a field: the section is enough

    def __call__(self, run):
        th = run.section["theta_f"].to_numpy()
        spread = float(np.ptp(th)) if th.size else float("nan")
        lam = float(np.mean(run.section["l_lambda"])) if th.size else float("nan")
        if not np.isfinite(spread) or spread < self.low:
            label, period = "periodic", 1
        elif spread < self.high:
            label, period = "quasiperiodic", None
        else:
            label, period = "chaotic", None
        ev = (
            _Evidence("spread", spread),
            _Evidence("lyapunov_1", lam * 100.0),  # what a cell's lyapunov_mean reads
            _Evidence("n_points", float(th.size)),
        )
        return _Verdict(label, period, ev, ("spread test",))


class SlowSpreadClassifier(SpreadClassifier):
    """SpreadClassifier taking 50 ms a run: keeps a CLI run alive long enough to be
    stopped mid-run, however fast the kernel gets."""

    def __call__(self, run):
        import time

        time.sleep(0.05)
        return super().__call__(run)


@dataclass(frozen=True)
class KillOnceClassifier:
    """SpreadClassifier that kills its own worker process (SIGKILL) the first time it sees
    realization index ``victim``: a (Dask) worker lost mid-run. ``marker`` records that it
    happened."""

    marker: str
    victim: int = 3
    needs_series = False

    def __call__(self, run):
        if run.index == self.victim and not Path(self.marker).exists():
            Path(self.marker).write_text(str(os.getpid()))
            os.kill(os.getpid(), 9)
        return SpreadClassifier()(run)


@dataclass(frozen=True)
class InterruptOnce:
    """SpreadClassifier that raises KeyboardInterrupt (a Ctrl-C) the first time it sees
    realization index ``victim`` (in-process runs, workers=1); ``marker`` records it."""

    marker: str
    victim: int
    inner: object = SpreadClassifier()
    needs_series = False

    def __call__(self, run):
        if run.index == self.victim and not Path(self.marker).exists():
            Path(self.marker).write_text("interrupted")
            raise KeyboardInterrupt
        return self.inner(run)


@dataclass(frozen=True)
class ParityClassifier:
    """Random cells (sigma > 0): label by the parity of the realization index (mixed labels
    whatever the physics); deterministic cells: always periodic."""

    needs_series = False

    def __call__(self, run):
        if run.params.l_lambda_sigma > 0 and run.index % 2:
            return _Verdict("chaotic", None, (_Evidence("parity", 1.0),))
        return _Verdict("periodic", 1, (_Evidence("parity", 0.0),))


def frames_equal(a, b) -> None:
    """Bit-identical tables: same columns, dtypes and values (NaN equal to NaN)."""
    import pandas as pd

    pd.testing.assert_frame_equal(a, b, check_exact=True)


@dataclass(frozen=True)
class FailingClassifier:
    """Raises on every run: a classifier with a bug."""

    needs_series = False

    def __call__(self, run):
        raise ValueError("this classifier has a bug")


def one_run_per_batch(monkeypatch) -> None:
    """Batches of one realization. The engine packs about two seconds of work into a CPU
    batch, which holds every run of these small sweeps, and a batch is stored when it ends:
    with batches of one, each record is stored (and, with flush_interval=0, checkpointed in
    a part of its own) as it finishes, so an interruption keeps the runs before it."""
    from chaoscam.sweep import _engine

    monkeypatch.setattr(_engine, "batch_size", lambda *a, **k: 1)
