"""One batch of members through the compiled kernel: set up at t = 0 or from a kept copy, run on
the CPU's threads or a GPU, collected as arrays. Members share ``dt`` and ``omega``; each is a
pure function of its model, numerics and ``(seed, index)``, whatever the batch.

RK4 resumes bit-identically at any hand-back, but its end step cuts short a block of proven
flight that a longer run takes whole; no block crosses a section, so a resumable run keeps its
copy at its last section before the end. Not adaptive: it shortens its last step onto the end.
"""

from __future__ import annotations

import copy
import math
import threading
from dataclasses import dataclass

import numpy as np

from ..kernel import (
    alone_kernel,
    check_stop,
    drive_members,
    fork_safe_threads,
    initial_counters,
    initial_state,
    kernel_constants,
    members_kernel,
    on_this_thread,
    run_on_gpu,
)
from ..kernel import layout as k
from ..model import LineLengthStream, Params
from ..numerics import Numerics

OUTPUTS = ("section", "impacts", "series")
"""The kernel's outputs, in the order a :class:`Batch` keeps them."""

ROOM = {"cpu": (2048, 2048), "gpu": (512, 256)}
"""Room per member and launch on each backend: (line-length draws, impact rows, used only when
impacts are kept). Every stop is a relaunch, waiting for the slowest member again; 2048 of
each cost 144 KiB a member, and a GPU batch holds tens of thousands."""

SERIES_ROWS = 4096
"""Rows of a member's series buffer between two hand-backs (when a series is kept)."""

_COLS = {"section": k.SECTION_COLS, "impacts": k.IMPACT_COLS, "series": k.SERIES_COLS}


def snapshot_step(num: Numerics, p: Params, n_stop: int) -> int | None:
    """The grid step N = floor(k T / dt) of the last section time k T (k >= 0) before step
    ``n_stop``, where a resumable run keeps its copy; None for the adaptive integrator."""
    if num.integrator != "rk4":
        return None
    t_end = n_stop * num.dt
    kk = max(math.ceil(t_end / p.cam_period) - 1, 0)
    while kk > 0 and kk * p.cam_period >= t_end:
        kk -= 1
    return min(int(kk * p.cam_period / num.dt), n_stop)


@dataclass(frozen=True)
class Resume:
    """Each member's state at grid step ``step``, from which :func:`chaoscam.extend` goes on.

    Attributes
    ----------
    step : int
        The grid step of the copy.
    y, cnt, c : ndarray
        State, counters (the buffers' row counts and the draw position zeroed) and constants.
    draws, streams : tuple
        Each member's unused line-length draws and its LineLengthStream (copied before use).
    kept : dict
        For each output of :data:`OUTPUTS`, each member's rows recorded before ``step``.
    n_impacts, status : ndarray of int
        Each member's impacts after the transient before ``step``, and its status code there
        (``OK`` to go on, else the code it ended with).
    """

    step: int
    y: np.ndarray
    cnt: np.ndarray
    c: np.ndarray
    draws: tuple[np.ndarray, ...]
    streams: tuple[LineLengthStream, ...]
    kept: dict[str, tuple[np.ndarray, ...]]
    n_impacts: np.ndarray
    status: np.ndarray

    def __len__(self) -> int:
        return len(self.draws)

    def select(self, picks) -> Resume:
        """The entries of members ``picks`` (positions), in that order."""
        picks = [int(j) for j in picks]
        return Resume(
            self.step, self.y[picks], self.cnt[picks], self.c[picks],
            tuple(self.draws[j] for j in picks), tuple(self.streams[j] for j in picks),
            {name: tuple(rows[j] for j in picks) for name, rows in self.kept.items()},
            self.n_impacts[picks], self.status[picks],
        )  # fmt: skip

    @staticmethod
    def join(parts: list[Resume]) -> Resume:
        """The entries of ``parts`` (batches of one run, at one step) one after another."""
        if len({r.step for r in parts}) != 1:
            raise ValueError("only copies taken at one step can be joined")
        return Resume(
            parts[0].step, np.concatenate([r.y for r in parts]),
            np.concatenate([r.cnt for r in parts]), np.concatenate([r.c for r in parts]),
            sum((r.draws for r in parts), ()), sum((r.streams for r in parts), ()),
            {name: sum((r.kept[name] for r in parts), ()) for name in OUTPUTS},
            np.concatenate([r.n_impacts for r in parts]), np.concatenate([r.status for r in parts]),
        )  # fmt: skip


@dataclass
class Start:
    """Where a batch's members start: at t = 0, or from a :class:`Resume`'s copy."""

    step: int
    y: np.ndarray
    cnt: np.ndarray
    c: np.ndarray
    lam: np.ndarray
    streams: list
    kept: dict[str, list[list[np.ndarray]]]  # rows recorded before ``step``
    n_impacts: np.ndarray
    status: np.ndarray  # NEED_BUFFER: to run; a member that had ended keeps its code


@dataclass
class Batch:
    """A finished batch: each member's rows (``kept[name][j]``, the kernel's columns), final
    arrays, status, impact count and copy (None unless resumable)."""

    first: int
    indices: list[int]
    kept: dict[str, list[np.ndarray] | None]
    y: np.ndarray
    cnt: np.ndarray
    c: np.ndarray
    status: np.ndarray
    n_impacts: np.ndarray
    resume: Resume | None


def models_of(plist) -> list[Params]:
    """The distinct parameter objects of ``plist`` (a batch of one model repeats one)."""
    return list({id(p): p for p in plist}.values())


def _per_member(make, plist) -> np.ndarray:
    """``make(p)`` stacked over members, computed once per distinct parameter object."""
    done: dict[int, np.ndarray] = {}
    for p in plist:
        if id(p) not in done:
            done[id(p)] = make(p)
    return np.stack([done[id(p)] for p in plist])


def _margin(num: Numerics) -> int:
    """Rows and draws one grid step may use beyond the room (events, a merged flight)."""
    return 4 * (num.max_events_per_step + num.flight_merge + 2)


def _n_draws(plist, num: Numerics, duration: float, room: int) -> int:
    """Draws each member starts with: the most any model needs (one per interval, or ``room``)."""

    def draws(p: Params) -> int:
        return int(duration / p.resample_dt) + 64 if p.resample == "interval" else room

    return max(draws(p) for p in models_of(plist)) + _margin(num)


def fresh(plist, num, indices, seed, duration, transient, *, tangent, stride, room) -> Start:
    """The members of a batch at t = 0 (a series row at t = 0 when one is kept from it)."""
    n = len(indices)
    streams = [LineLengthStream(p, seed, i) for p, i in zip(plist, indices, strict=True)]
    width = _n_draws(plist, num, duration, room[0])
    lam = np.stack([s.draw(width) for s in streams])
    y = _per_member(initial_state, plist)
    cnt = np.stack([initial_counters() for _ in range(n)])
    c = _per_member(
        lambda p: kernel_constants(p, num, t_record=transient, stride=stride, tangent=tangent),
        plist,
    )
    kept: dict[str, list[list[np.ndarray]]] = {name: [[] for _ in range(n)] for name in OUTPUTS}
    if stride > 0 and transient == 0.0:
        for j in range(n):
            kept["series"][j].append(np.array([[0.0, y[j, k.Y_THETA], y[j, k.Y_OMEGA], lam[j, 0]]]))
    status = np.full(n, k.NEED_BUFFER, dtype=np.int64)
    return Start(0, y, cnt, c, lam, streams, kept, np.zeros(n, dtype=np.int64), status)


def resumed(res: Resume, plist, num, duration: float, room, *, series: bool) -> Start:
    """The members of ``res`` (one batch), to continue from its copy to ``duration``
    (``series`` False: a series kept before is dropped and no more is sampled)."""
    width = _n_draws(plist, num, duration - res.step * num.dt, room[0])
    streams = [copy.deepcopy(s) for s in res.streams]
    width = max([width, *(len(d) for d in res.draws)])
    pairs = zip(res.draws, streams, strict=True)
    lam = np.stack([np.concatenate([d, s.draw(width - len(d))]) for d, s in pairs])
    c = res.c.copy()
    if not series:
        c[:, k.C_STRIDE] = 0.0
    kept = {name: [[r] if len(r) else [] for r in res.kept[name]] for name in OUTPUTS}
    if not series:
        kept["series"] = [[] for _ in range(len(res))]
    status = np.where(res.status == k.OK, k.NEED_BUFFER, res.status)
    return Start(
        res.step, res.y.copy(), res.cnt.copy(), c, lam, streams, kept, res.n_impacts.copy(),
        status,
    )  # fmt: skip


def run_batch(
    plist, num: Numerics, indices, start: Start, first: int, duration: float, *, room,
    gpu: bool = False, keep_impacts: bool = False, resumable: bool = False,
) -> Batch:  # fmt: skip
    """Run one batch of members from ``start`` to ``duration`` and collect its outputs; ``room``
    = (draws, impact rows) per member and launch (:data:`ROOM`). With ``resumable`` (RK4) the
    run stops once more, at :func:`snapshot_step`, and keeps its copy there (:class:`Resume`)."""
    n, p0 = len(plist), plist[0]
    n_stop = int(round(duration / num.dt))
    n_sec = int((duration - start.step * num.dt) / p0.cam_period) + 4 + int(num.dt / p0.cam_period)
    y, cnt, c, lam, streams = start.y, start.cnt, start.c, start.lam, start.streams
    stride = int(c[0, k.C_STRIDE])
    section = np.empty((n, n_sec, k.SECTION_COLS))
    impacts = np.empty((n, room[1] + _margin(num) if keep_impacts else 0, k.IMPACT_COLS))
    series = np.empty((n, _series_rows(num, stride), k.SERIES_COLS))
    buffers = {"section": section, "impacts": impacts, "series": series}
    counts = {"section": k.I_N_SECTION, "impacts": k.I_N_IMPACT, "series": k.I_N_SERIES}
    kept = start.kept
    n_impacts = start.n_impacts.copy()
    status = start.status.copy()

    def flush(j: int, names=OUTPUTS) -> None:
        """Move member j's filled rows of ``names`` out of the buffers (impacts counted)."""
        for name in names:
            m = int(cnt[j, counts[name]])
            if name == "impacts":
                n_impacts[j] += m
            if m and buffers[name].shape[1]:
                kept[name][j].append(buffers[name][j, :m].copy())
            cnt[j, counts[name]] = 0

    def hand_back(j: int, lam_j: np.ndarray, n_new: int) -> np.ndarray:
        """Empty member j's impact and series rows; its draws, used ones dropped and ``n_new``
        appended. The section buffer holds the whole run (on a GPU, the device's)."""
        flush(j, ("impacts", "series"))
        pos = cnt[j, k.I_LAM_POS]
        cnt[j, k.I_LAM_POS] = 0
        return np.concatenate([lam_j[pos:], streams[j].draw(n_new)])

    def run(to: int) -> None:
        if gpu:
            run_on_gpu(y, cnt, c, to, lam, section, impacts, status, hand_back, keep_impacts)
        else:
            run_on_cpu(y, cnt, c, to, lam, series, section, impacts, status, hand_back)

    resume = None
    n_snap = snapshot_step(num, p0, n_stop) if resumable else None
    if n_snap is not None and start.step <= n_snap < n_stop:
        run(n_snap)
        for j in range(n):
            flush(j)
        resume = _copy(n_snap, y, cnt, c, lam, streams, kept, n_impacts, status)
        status[status == k.OK] = k.NEED_BUFFER
    run(n_stop)
    for j in range(n):
        flush(j)
    out = {name: [_stack(kept[name][j], _COLS[name]) for j in range(n)] for name in OUTPUTS}
    out["impacts"] = out["impacts"] if keep_impacts else None
    out["series"] = out["series"] if stride > 0 else None
    return Batch(first, list(indices), out, y, cnt, c, status, n_impacts, resume)


def _series_rows(num: Numerics, stride: int) -> int:
    """Rows of the series buffer: one step's samples, an adaptive step's too (1 if none)."""
    if stride <= 0:
        return 1
    rows = SERIES_ROWS
    if num.integrator == "adaptive":
        rows = max(rows, 4 * (int(num.h_max / (stride * num.dt)) + 2))
    return rows


def _stack(blocks: list[np.ndarray], ncol: int) -> np.ndarray:
    return np.concatenate(blocks) if blocks else np.empty((0, ncol))


def _copy(step, y, cnt, c, lam, streams, kept, n_impacts, status) -> Resume:
    """The copy of a batch's members at grid step ``step`` (their buffers just emptied)."""
    cnt = cnt.copy()
    draws = tuple(lam[j, cnt[j, k.I_LAM_POS] :].copy() for j in range(len(cnt)))
    cnt[:, k.I_LAM_POS] = 0
    rows = {
        name: tuple(_stack(kept[name][j], _COLS[name]) for j in range(len(cnt))) for name in OUTPUTS
    }
    return Resume(
        int(step), y.copy(), cnt, c.copy(), draws, tuple(copy.deepcopy(s) for s in streams),
        rows, n_impacts.copy(), status.copy(),
    )  # fmt: skip


def run_on_cpu(y, cnt, c, n_stop, lam, series, section, impacts, status, hand_back) -> None:
    """The members whose ``status`` is ``NEED_BUFFER`` through ``kernel.drive_members``:
    on this thread for one member or in ``members_on_this_thread``, else on numba's threads."""
    if on_this_thread() or y.shape[0] == 1:
        launch = _one_by_one(y, cnt, c, n_stop, lam, series, section, impacts, status)
    else:
        launch = _in_parallel(y, cnt, c, n_stop, lam, series, section, impacts, status)

    def refill(need: np.ndarray) -> None:
        for j in need:  # the same width again: as many new draws as were used
            lam[j] = hand_back(j, lam[j], int(cnt[j, k.I_LAM_POS]))

    drive_members(y.shape[0], launch, refill, np.flatnonzero(status == k.NEED_BUFFER))


def _one_by_one(y, cnt, c, n_stop, lam, series, section, impacts, status):
    """A launch of the members ``need`` on this thread, each through the nogil call."""
    run = alone_kernel(c)

    def launch(need: np.ndarray) -> np.ndarray:
        for j in need:
            check_stop()
            status[j] = run(y[j], cnt[j], c[j], n_stop, lam[j], series[j], section[j], impacts[j])
        return status[need]

    return launch


def _in_parallel(y, cnt, c, n_stop, lam, series, section, impacts, status):
    """A launch of the members ``need`` on numba's threads (one at a time: PARALLEL_LOCK)."""
    fork_safe_threads()
    n = y.shape[0]
    kernel = members_kernel(c)

    def launch(need: np.ndarray) -> np.ndarray:
        check_stop()  # a thread asked to stop (stop_on): before the next compiled call
        if need.size == n:  # every member (the first launch): in place, no copies
            with PARALLEL_LOCK:
                kernel(y, cnt, c, n_stop, lam, series, section, impacts, status)
            return status
        sub = [a[need] for a in (y, cnt, c, lam, series, section, impacts)]
        sub_status = np.zeros(need.size, dtype=np.int64)
        with PARALLEL_LOCK:
            kernel(sub[0], sub[1], sub[2], n_stop, *sub[3:], sub_status)
        y[need], cnt[need], series[need], section[need], impacts[need] = (
            sub[0], sub[1], sub[4], sub[5], sub[6],
        )  # fmt: skip
        status[need] = sub_status
        return sub_status

    return launch


PARALLEL_LOCK = threading.Lock()
"""Held by every launch on numba's threads: the workqueue layer aborts the process when two
Python threads launch parallel kernels at once."""
