"""One batch of ensemble members: set up (at t = 0 or from a kept copy), run on the CPU's
threads (or handed to the GPU's launcher), collected.

:func:`._ensemble.simulate_ensemble` and :func:`._ensemble.extend_ensemble` cut their members
into batches and come here for each; the members of a batch share ``dt`` and ``omega``.
"""

from __future__ import annotations

import threading
from dataclasses import dataclass

import numpy as np

from ..model import LineLengthStream, Params
from . import _kernel as k
from ._constants import initial_counters, initial_state, kernel_constants
from ._driver import (
    alone_kernel,
    check_stop,
    contact_fraction,
    drive_members,
    fork_safe_threads,
    members_kernel,
    on_this_thread,
)
from ._resume import Resume, snapshot_step, take
from ._status import Status

__all__ = ["fresh", "resumed", "run_batch", "run_on_cpu"]


@dataclass
class _Start:
    """Where a batch's members start: at t = 0, or from a :class:`Resume`'s copy."""

    step: int
    y: np.ndarray
    cnt: np.ndarray
    c: np.ndarray
    lam: np.ndarray
    streams: list
    rows: tuple[np.ndarray, ...]  # section rows recorded before ``step``
    impacts: np.ndarray  # impacts applied before ``step``
    status: np.ndarray  # NEED_BUFFER: to run; a member that had ended keeps its code


def fresh(plist, indices, seed, duration, transient, tangent, room) -> _Start:
    """The members of a batch at t = 0."""
    n = len(indices)
    streams = [LineLengthStream(p, seed, i) for p, i in zip(plist, indices, strict=True)]
    draws = _n_draws(plist, duration, room)  # once: it is a maximum over the batch
    lam = np.stack([s.draw(draws) for s in streams])
    y = _per_member(initial_state, plist)
    cnt = _per_member(lambda p: initial_counters(p, transient=transient), plist)
    c = _per_member(lambda p: kernel_constants(p, t_record=transient, tangent=tangent), plist)
    empty = np.empty((0, k.SECTION_COLS))
    return _Start(
        0,
        y,
        cnt,
        c,
        lam,
        streams,
        (empty,) * n,
        np.zeros(n, dtype=np.int64),
        np.full(n, k.NEED_BUFFER, dtype=np.int64),
    )


def resumed(res: Resume, plist, duration, room) -> _Start:
    """The members of ``res`` (one batch), to continue from its copy."""
    y, cnt, c, lam, streams = res.start(_n_draws(plist, duration - res.step * plist[0].dt, room))
    # A member that had ended keeps its code, and is not run.
    status = np.where(res.status == k.OK, k.NEED_BUFFER, res.status)
    return _Start(res.step, y, cnt, c, lam, streams, res.rows, res.impacts, status)


def models_of(plist) -> list[Params]:
    """The distinct parameter objects of ``plist`` (a batch of one model repeats one)."""
    return list({id(p): p for p in plist}.values())


def _margin(plist) -> int:
    """Rows and draws one grid step may use beyond the room (events, a merged flight)."""
    return 4 * (max(p.max_events_per_step + p.flight_merge for p in models_of(plist)) + 2)


def _n_draws(plist, duration, room) -> int:
    """Draws every member of the batch starts with: the most any of its models needs."""
    models = models_of(plist)
    return max(_draws(p, duration, room[0]) for p in models) + _margin(models)


def run_batch(
    plist,
    indices,
    start: _Start,
    first,
    duration,
    *,
    room,
    run=None,
    keep_impacts=False,
    resumable=False,
):
    """Run one batch of members from ``start`` to ``duration`` (CPU or GPU) and collect its
    outputs; ``room`` = (draws, impact rows) per member and launch (``_ensemble._ROOM``). With
    ``resumable`` the run stops once more on the way, at :func:`._resume.snapshot_step`,
    and returns its copy there too (else None)."""
    run = run or run_on_cpu
    n = len(plist)
    p0 = plist[0]
    n_stop = int(round(duration / p0.dt))
    t_start = start.step * p0.dt
    n_sec = int((duration - t_start) / p0.cam_period) + 4 + int(p0.dt / p0.cam_period)
    y, cnt, c, lam, streams = start.y, start.cnt, start.c, start.lam, start.streams
    section = np.empty((n, n_sec, k.SECTION_COLS))
    # impacts not kept are only counted by the kernel (a buffer of no rows): a member then
    # stops for room only when its draws run out (on a GPU each stop relaunches the batch)
    rows = room[1] + _margin(plist) if keep_impacts else 0
    impacts = np.empty((n, rows, k.IMPACT_COLS))
    status = start.status.copy()
    n_impacts = start.impacts.copy()

    kept: list[list[np.ndarray]] = [[] for _ in range(n)]

    def empty_impacts(j):
        """Count member j's impact rows (and keep them if asked); the rows are free again."""
        m = cnt[j, k.I_N_IMPACT]
        if keep_impacts and m:
            kept[j].append(impacts[j, :m].copy())
        n_impacts[j] += m
        cnt[j, k.I_N_IMPACT] = 0

    def hand_back(j, lam_j, n_new):
        """Empty member j's impact rows and drop its used draws, adding n_new."""
        empty_impacts(j)
        pos = cnt[j, k.I_LAM_POS]
        cnt[j, k.I_LAM_POS] = 0
        return np.concatenate([lam_j[pos:], streams[j].draw(n_new)])

    def rows(j):
        return np.concatenate([start.rows[j], section[j, : cnt[j, k.I_N_SECTION]]])

    resume = None
    n_snap = snapshot_step(p0, n_stop) if resumable and not keep_impacts else None
    if n_snap is not None and start.step <= n_snap < n_stop:
        run(y, cnt, c, n_snap, lam, section, impacts, status, hand_back, keep_impacts)
        so_far = n_impacts + cnt[:, k.I_N_IMPACT]
        resume = take(n_snap, y, cnt, c, lam, streams, map(rows, range(n)), so_far, status)
        status[status == k.OK] = k.NEED_BUFFER
    run(y, cnt, c, n_stop, lam, section, impacts, status, hand_back, keep_impacts)
    sections, members, impact_rows = [], [], []
    for j in range(n):
        empty_impacts(j)
        if keep_impacts and kept[j]:
            block = np.concatenate(kept[j])
            impact_rows.append(np.column_stack([np.full(len(block), first + j), block]))
        mine = rows(j)
        block = np.empty((len(mine), 1 + k.SECTION_COLS))
        block[:, 0] = first + j
        block[:, 1:] = mine
        sections.append(block)
        members.append(
            (
                first + j,
                indices[j],
                Status(int(status[j])).name,
                int(n_impacts[j]),
                contact_fraction(y[j], cnt[j], c[j]),
            )
        )
    return sections, members, impact_rows, resume


def run_on_cpu(y, cnt, c, n_stop, lam, section, impacts, status, hand_back, keep_impacts):
    """The members in parallel calls of the driver's loop: those whose ``status`` is
    ``NEED_BUFFER`` first (every member of a fresh batch), then those that asked for room,
    refilled (a resumed member is bit-identical to one that was not interrupted, so the
    pauses change nothing); the others keep their code. Inside
    :func:`._driver.members_on_this_thread` the members run one after another on the calling
    thread (:func:`_one_by_one`)."""
    if on_this_thread():
        launch = _one_by_one(y, cnt, c, n_stop, lam, section, impacts, status)
    else:
        launch = _in_parallel(y, cnt, c, n_stop, lam, section, impacts, status)

    def refill(need: np.ndarray) -> None:
        for j in need:  # the same width again: as many new draws as were used
            lam[j] = hand_back(j, lam[j], int(cnt[j, k.I_LAM_POS]))

    drive_members(y.shape[0], launch, refill, np.flatnonzero(status == k.NEED_BUFFER))


def _one_by_one(y, cnt, c, n_stop, lam, section, impacts, status):
    """A launch of the members ``need`` on this thread, each through the compiled nogil call
    on its rows in place (the same :func:`._kernel.run_chunk` as the parallel launch)."""
    run = alone_kernel(c)
    series = np.empty((1, k.SERIES_COLS))

    def launch(need: np.ndarray) -> np.ndarray:
        for j in need:
            check_stop()
            status[j] = run(y[j], cnt[j], c[j], n_stop, lam[j], series, section[j], impacts[j])
        return status[need]

    return launch


PARALLEL_LOCK = threading.Lock()
"""Held by every launch on numba's threads. The fork-safe workqueue threading layer
(:func:`._driver.fork_safe_threads`) aborts the whole process when two Python threads launch
parallel kernels at once (measured: two threads calling ``simulate_ensemble`` killed the
interpreter with "Concurrent access has been detected"); with the lock they take turns.
Both ways to run ensembles from several threads inside chaoscam avoid it anyway (the sweeps'
batch threads run members one by one, a GPU sweep's launches need no CPU threads), so it
guards a user's own threads and a stand-in device."""


def _in_parallel(y, cnt, c, n_stop, lam, section, impacts, status):
    """A launch of the members ``need`` on numba's threads (``prange``), one launch at a
    time in this process (:data:`PARALLEL_LOCK`)."""
    fork_safe_threads()
    n = y.shape[0]
    kernel = members_kernel(c)

    def run_members(*args) -> None:
        with PARALLEL_LOCK:
            kernel(*args)

    def launch(need: np.ndarray) -> np.ndarray:
        check_stop()  # a thread asked to stop (stop_on): before the next compiled call
        if need.size == n:  # every member (the first launch): in place, no copies
            run_members(
                y, cnt, c, n_stop, lam, np.empty((n, 1, k.SERIES_COLS)), section, impacts, status
            )
            return status
        sub = (y[need], cnt[need], c[need], lam[need], section[need], impacts[need])
        sub_status = np.zeros(need.size, dtype=np.int64)
        run_members(
            sub[0],
            sub[1],
            sub[2],
            n_stop,
            sub[3],
            np.empty((need.size, 1, k.SERIES_COLS)),
            sub[4],
            sub[5],
            sub_status,
        )
        y[need], cnt[need], section[need], impacts[need] = sub[0], sub[1], sub[4], sub[5]
        status[need] = sub_status
        return sub_status

    return launch


def _draws(p: Params, duration: float, room: int) -> int:
    """Line-length draws a member starts with: one per resampling interval of the run, or,
    under impact resampling (one per macro impact, or per applied jump), ``room``."""
    if p.resample == "interval":
        return int(duration / p.resample_dt) + 64
    return room


def _per_member(make, plist) -> np.ndarray:
    """``make(p)`` stacked over members, computed once per distinct parameter object."""
    done: dict[int, np.ndarray] = {}
    for p in plist:
        if id(p) not in done:
            done[id(p)] = make(p)
    return np.stack([done[id(p)] for p in plist])
