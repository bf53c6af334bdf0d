"""Continuing ensemble members to a longer duration from where they stopped, bit for bit.

A classifier that finds a member undetermined runs it longer
(:func:`chaoscam.classify.classify_ensemble`: 4x the recorded time, up to 120 s). Re-running
from t = 0 repeats the transient and the time already recorded: for a sweep's default 10 s
transient and 10 s recorded, 20 of the 50 s a first extension simulates. Continuing from
the end of the first run does not repeat them.

A continued member must carry the bits of a run made that long from the start (a sweep's
record is a pure function of its task, whichever path made it). The fixed-step kernel
resumes bit-identically at any grid step where it stopped to hand back a buffer, but not
quite at its end step ``n_stop``: a block of proven flight (up to ``flight_merge`` grid
steps in one RK4 step) is cut short there, where a longer run takes it whole. No block
crosses a stroboscopic section, though: the kernel ends each one at most at the grid step
before the section time k T. So a resumable run stops once more, at the grid step
N = floor(k T / dt) of its last section before its end (:func:`snapshot_step`), keeps a
copy of its state there (:class:`Resume`) and goes on to its end; a continuation starts
from the copy and records again from that section on. ``tests/integrate/test_resume.py``
compares continued members with runs made long from the start.

A single run (``simulate(..., resumable=True)``) keeps the same copy, :class:`RunCopy`,
with the rows it recorded before it; :func:`chaoscam.extend_trajectory` continues it.

Only the fixed-step RK4 kernel: the adaptive one shortens its last step to land on the end
time, so that its runs are re-run instead.
"""

from __future__ import annotations

import copy
import math
from dataclasses import dataclass

import numpy as np

from ..model import LineLengthStream, Params
from . import _kernel as k

__all__ = ["Resume", "RunCopy", "snapshot_step"]


def snapshot_step(p: Params, n_stop: int) -> int | None:
    """The grid step N = floor(k T / dt) of the last section time k T before step
    ``n_stop`` (k >= 0), where a resumable run keeps its copy; None for the adaptive
    integrator (see the module's docstring)."""
    if p.integrator != "rk4":
        return None
    t_end = n_stop * p.dt
    kk = max(math.ceil(t_end / p.cam_period) - 1, 0)
    while kk > 0 and kk * p.cam_period >= t_end:
        kk -= 1
    return min(int(kk * p.cam_period / p.dt), n_stop)


@dataclass(frozen=True)
class Resume:
    """Each member's state at grid step ``step`` (t = step dt), from which
    :func:`chaoscam.integrate.extend_ensemble` continues it; one entry per member, in the
    order of the ensemble's members.

    Attributes
    ----------
    step : int
        The grid step of the copy (one for all members: they share dt and omega).
    y, cnt, c : ndarray
        State (members, Y_SIZE), counters (members, N_COUNTERS; the buffers' row counts and
        the draw position zeroed) and constants (members, N_CONSTANTS) there.
    draws : tuple of ndarray
        Each member's line-length draws not yet used, in order.
    streams : tuple of LineLengthStream
        Each member's stream after those draws (never drawn from: copied before use).
    rows : tuple of ndarray
        Each member's section rows (``SECTION_COLS`` columns, with the tangent's) recorded
        before ``step``.
    impacts : ndarray of int
        Impacts each member applied after the transient and before ``step``.
    status : ndarray of int
        Each member's status code there: ``OK`` to go on, else the code it ended with
        before ``step`` (it left the cam's reach, diverged, ...): it is not continued.
    """

    step: int
    y: np.ndarray
    cnt: np.ndarray
    c: np.ndarray
    draws: tuple[np.ndarray, ...]
    streams: tuple[LineLengthStream, ...]
    rows: tuple[np.ndarray, ...]
    impacts: np.ndarray
    status: np.ndarray

    def __len__(self) -> int:
        return len(self.draws)

    def select(self, picks) -> Resume:
        """The entries of members ``picks`` (positions), in that order."""
        picks = [int(j) for j in picks]
        return Resume(
            self.step,
            self.y[picks],
            self.cnt[picks],
            self.c[picks],
            tuple(self.draws[j] for j in picks),
            tuple(self.streams[j] for j in picks),
            tuple(self.rows[j] for j in picks),
            self.impacts[picks],
            self.status[picks],
        )

    @staticmethod
    def join(parts: list[Resume]) -> Resume:
        """The entries of ``parts`` (batches of one run, at one step) one after another."""
        if len({r.step for r in parts}) != 1:
            raise ValueError("only copies taken at one step can be joined")
        return Resume(
            parts[0].step,
            np.concatenate([r.y for r in parts]),
            np.concatenate([r.cnt for r in parts]),
            np.concatenate([r.c for r in parts]),
            sum((r.draws for r in parts), ()),
            sum((r.streams for r in parts), ()),
            sum((r.rows for r in parts), ()),
            np.concatenate([r.impacts for r in parts]),
            np.concatenate([r.status for r in parts]),
        )

    def start(self, n_draws: int) -> tuple[np.ndarray, ...]:
        """Fresh arrays to continue every entry from: (y, cnt, c, lam, streams), ``lam``
        holding at least ``n_draws`` draws a member (the unused ones first), ``streams``
        copies positioned after them."""
        streams = [copy.deepcopy(s) for s in self.streams]
        width = max([n_draws, *(len(d) for d in self.draws)])
        pairs = zip(self.draws, streams, strict=True)
        lam = np.stack([np.concatenate([d, s.draw(width - len(d))]) for d, s in pairs])
        return self.y.copy(), self.cnt.copy(), self.c.copy(), lam, streams


def take(step, y, cnt, c, lam, streams, rows, impacts, status) -> Resume:
    """The copy of a batch's members at grid step ``step``, taken between the two launches
    of a resumable run; ``rows`` each member's section rows so far (those of its start and
    those in its buffer), ``impacts`` its impacts so far (counted and in its buffer)."""
    cnt = cnt.copy()
    draws = tuple(lam[j, cnt[j, k.I_LAM_POS] :].copy() for j in range(len(cnt)))
    cnt[:, k.I_LAM_POS] = 0
    cnt[:, k.I_N_SECTION] = 0
    cnt[:, k.I_N_IMPACT] = 0
    cnt[:, k.I_N_SERIES] = 0
    return Resume(
        int(step),
        y.copy(),
        cnt,
        c.copy(),
        draws,
        tuple(copy.deepcopy(s) for s in streams),
        tuple(rows),
        np.asarray(impacts, dtype=np.int64).copy(),
        status.copy(),
    )


@dataclass(frozen=True)
class RunCopy:
    """One trajectory's state at grid step ``step`` (t = step dt), the copy a resumable
    ``simulate`` keeps, and the rows it had recorded before that step: what
    :func:`chaoscam.extend_trajectory` continues it from (see the module's docstring).

    Attributes
    ----------
    step : int
        The grid step of the copy (:func:`snapshot_step`).
    y, cnt, c : ndarray
        State, counters (the buffers' row counts and the draw position zeroed) and
        constants there.
    draws : ndarray
        The line-length draws not yet used, in order.
    stream : LineLengthStream
        The realization's stream after those draws (never drawn from: copied before use).
    series, section, impacts : ndarray
        The rows recorded before ``step``, in the kernel's columns (``SERIES_COLS``,
        ``SECTION_COLS`` with the tangent's, ``IMPACT_COLS``); ``series`` None when the run
        kept none.
    status : int
        ``OK`` to go on, else the code the run ended with before ``step`` (it left the
        cam's reach, diverged, ...): a longer run ends the same way.
    """

    step: int
    y: np.ndarray
    cnt: np.ndarray
    c: np.ndarray
    draws: np.ndarray
    stream: LineLengthStream
    series: np.ndarray | None
    section: np.ndarray
    impacts: np.ndarray
    status: int

    def start(self, n_draws: int) -> tuple:
        """Fresh arrays to continue from: (y, cnt, c, lam, stream), ``lam`` holding the
        unused draws and ``n_draws`` more, ``stream`` a copy positioned after them."""
        stream = copy.deepcopy(self.stream)
        lam = np.concatenate([self.draws, stream.draw(n_draws)])
        return self.y.copy(), self.cnt.copy(), self.c.copy(), lam, stream
