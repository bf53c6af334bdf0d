"""Many trajectories in one compiled call, parallel over cores (numba ``prange``).

Each member runs the same kernel as :func:`chaoscam.simulate` (:func:`_kernel.run_chunk`) on
its own line-length draws, so member ``i`` equals ``simulate(params_i, seed=seed,
index=indices[i], series=False)`` bit for bit. Only sections, impact counts and statuses are
kept; a member that outgrows its impact buffer or its draws is finished on the serial path.

``backend="gpu"`` runs the same kernel on an NVIDIA GPU, one thread per member
(:mod:`._gpu`, numba-cuda), equal to this path within ``GPU_TOLERANCE`` on short or periodic
runs.
"""

from __future__ import annotations

import time
import warnings
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

import numpy as np

from ..model import LineLengthStream, Params
from . import _gpu
from . import _kernel as k
from ._constants import initial_counters, initial_state, kernel_constants
from ._driver import (
    check_window,
    contact_fraction,
    drive_members,
    fork_safe_threads,
    members_kernel,
)
from ._status import Status
from ._tangent import section_jacobians

if TYPE_CHECKING:
    import pandas as pd

__all__ = ["BACKENDS", "Ensemble", "simulate_ensemble"]

_ROOM = {"cpu": (2048, 2048), "gpu": (512, 256)}
"""Room per member and launch, on each backend: (line-length draws, impact rows; the rows
are only counted, unless impacts are kept). A member stops for a refill when either runs
out (a 20 s run of Table 1 applies ~15,000 impacts, most of them the micro-impacts of
chattering, each with a draw under impact resampling), and every stop is a relaunch, where
the CPU's threads wait for the slowest member: 2048 of each cut a regime map's kernel time
by 6 % against 512 and 256 (measured on 2 cores), for 144 KiB a member (150 MB for a batch
of 1024). The GPU keeps the small room: its batches hold tens of thousands of members."""
_CPU_BATCH = 1024
BACKENDS = ("cpu", "gpu", "auto")


@dataclass(frozen=True)
class Ensemble:
    """Sections and per-member summaries of an ensemble run.

    Attributes
    ----------
    sections : pandas.DataFrame
        member, k, t, theta_f, omega_f, l_lambda: the stroboscopic points after the transient.
    members : pandas.DataFrame
        member, index, status (name), n_impacts, contact_fraction;
        :func:`chaoscam.classify.classify_ensemble` adds each member's verdict (label,
        period, reasons).
    settings : dict
        duration, transient, seed, threads, backend ("cpu" or "gpu", the one used), device,
        batch, integrators, wall time.
    impacts : pandas.DataFrame or None
        With ``keep_impacts=True``: member plus the columns of ``Trajectory.impacts`` (the
        applied jumps after the transient); else None (only counted).
    jacobians : ndarray or None
        With ``tangent=True``: the Jacobian of the stroboscopic map over the period ending at
        each row of ``sections``, shape (len(sections), 2, 2), as ``Trajectory.jacobians``.
    """

    sections: pd.DataFrame
    members: pd.DataFrame
    settings: dict[str, Any] = field(default_factory=dict)
    impacts: pd.DataFrame | None = None
    jacobians: np.ndarray | None = None


def simulate_ensemble(
    params: Params | list[Params],
    indices,
    *,
    seed: int = 0,
    duration: float = 20.0,
    transient: float = 0.0,
    batch: int | None = None,
    backend: str = "cpu",
    keep_impacts: bool = False,
    tangent: bool = False,
    progress=None,
) -> Ensemble:
    """Simulate realizations ``indices`` of one model (or one model per member) in parallel.

    Parameters
    ----------
    params : Params or list of Params
        One model for all members, or one per member (same ``dt`` and ``omega`` required:
        members share the grid and the section times).
    indices : sequence of int
        Realization indices under ``seed`` (see :func:`chaoscam.simulate`).
    duration, transient : float
        End time and discarded start [s].
    batch : int, optional
        Members per compiled call; bounds memory, about 40 kB per member for 20 s runs (of
        which 40 B per cam period of sections), on the host and, for the GPU, on the device.
        Default 1024 on the CPU, 65,536 on the GPU (about 2.7 GB).
    backend : {"cpu", "gpu", "auto"}
        ``"cpu"``: numba threads over cores (bit-identical to :func:`chaoscam.simulate`).
        ``"gpu"``: one CUDA thread per member (numba-cuda, ``pip install 'chaoscam[gpu]'``);
        where it cannot run (see :func:`_gpu.gpu_status`) the CPU path is used after a
        one-line :class:`GPUFallbackWarning` giving the reason. ``"auto"``: the GPU when
        available, else the CPU without a notice. ``settings["backend"]`` records the one
        used.
    keep_impacts : bool
        Also return every member's impacts (``Ensemble.impacts``); by default they are only
        counted, so that memory stays flat for long runs.
    tangent : bool
        Integrate the tangent dynamics too and keep each section row's stroboscopic Jacobian
        (``Ensemble.jacobians``), from which :func:`chaoscam.classify.classify_ensemble`
        labels the members (the tangent exponent, n-band chaos, the periodic-orbit
        certificate). The members' motion is the same with and without it.
    progress : callable, optional
        Called with the number of members just finished after each batch (a progress bar's
        ``update``); a smaller ``batch`` gives more frequent calls (and a Ctrl-C that is
        honoured sooner: it waits for the compiled call to return).

    Notes
    -----
    Threads: numba's thread count (``NUMBA_NUM_THREADS`` or ``numba.set_num_threads``).

    The GPU path equals the CPU path only up to rounding (fused multiply-adds, libdevice
    trigonometry), which the model amplifies: sections of the first cam period and of
    periodic configurations after a transient agree within 1e-6 rad and rad/s
    (``_gpu.GPU_TOLERANCE``); chaotic runs part after a few periods, as any two roundings of
    them do, and only their statistics compare.
    """
    duration, transient = check_window(duration, transient)
    use_gpu, device = _pick_backend(backend)
    if batch is None:
        batch = _gpu.GPU_BATCH if use_gpu else _CPU_BATCH
    if int(batch) < 1:
        raise ValueError(f"batch must be >= 1, got {batch!r}")
    batch = int(batch)
    indices = [int(i) for i in indices]
    plist = list(params) if isinstance(params, list | tuple) else [params] * len(indices)
    if len(plist) != len(indices):
        raise ValueError(f"{len(plist)} parameter sets for {len(indices)} indices")
    if len({(p.dt, p.omega) for p in plist}) > 1:
        raise ValueError("members must share dt and omega")
    t0 = time.perf_counter()
    sections, rows, impact_rows = [], [], []
    for start in range(0, len(indices), batch):
        chunk = slice(start, start + batch)
        s, r, im = _run_batch(
            plist[chunk],
            indices[chunk],
            start,
            seed,
            duration,
            transient,
            run=_gpu.run_on_gpu if use_gpu else _run_on_cpu,
            room=_ROOM["gpu" if use_gpu else "cpu"],
            keep_impacts=keep_impacts,
            tangent=tangent,
        )
        sections.extend(s)
        rows.extend(r)
        impact_rows.extend(im)
        if progress is not None:
            progress(len(r))
    import pandas as pd

    cols = ["member", *k.SECTION_NAMES]
    every = np.concatenate(sections) if sections else np.empty((0, 1 + k.SECTION_COLS))
    sec = pd.DataFrame(every[:, : len(cols)], columns=cols)
    sec[["member", "k"]] = sec[["member", "k"]].astype(np.int64)
    members = pd.DataFrame(
        rows, columns=["member", "index", "status", "n_impacts", "contact_fraction"]
    )
    jac = section_jacobians(every[:, 1:]) if tangent else None  # without the member column
    impacts = None
    if keep_impacts:
        icols = ["member", *k.IMPACT_NAMES]
        impacts = pd.DataFrame(
            np.concatenate(impact_rows) if impact_rows else np.empty((0, len(icols))),
            columns=icols,
        )
        impacts["member"] = impacts["member"].astype(np.int64)
        impacts["kind"] = pd.Categorical.from_codes(
            impacts["kind"].to_numpy(dtype=np.int64), categories=list(k.IMPACT_KINDS)
        )
    import numba

    return Ensemble(
        sections=sec,
        members=members,
        impacts=impacts,
        jacobians=jac,
        settings={
            "duration": duration,
            "transient": transient,
            "seed": seed,
            "threads": numba.get_num_threads(),
            "backend": "gpu" if use_gpu else "cpu",
            "device": device,
            "batch": batch,
            "integrators": sorted({p.integrator for p in plist}),
            "tangent": bool(tangent),
            "wall_time_s": time.perf_counter() - t0,
        },
    )


def _pick_backend(backend: str) -> tuple[bool, str]:
    """(use the GPU?, the device in words) for ``backend``; warns if "gpu" cannot run."""
    if backend not in BACKENDS:
        raise ValueError(
            f"backend must be one of {', '.join(map(repr, BACKENDS))}, got {backend!r}"
        )
    if backend == "cpu":
        return False, "cpu"
    ok, reason = _gpu.gpu_status()
    if ok:
        return True, reason
    if backend == "gpu":
        warnings.warn(
            f"GPU backend unavailable: {reason}; falling back to the CPU",
            _gpu.GPUFallbackWarning,
            stacklevel=3,
        )
    return False, "cpu"


def _run_batch(
    plist,
    indices,
    first,
    seed,
    duration,
    transient,
    run=None,
    keep_impacts=False,
    tangent=False,
    room=_ROOM["cpu"],
):
    """Set up one batch of members, ``run`` it (CPU or GPU) and collect its outputs;
    ``room`` = (draws, impact rows) per member and launch (:data:`_ROOM`)."""
    n = len(indices)
    p0 = plist[0]
    n_stop = int(round(duration / p0.dt))
    n_sec = int(duration / p0.cam_period) + 4 + int(p0.dt / p0.cam_period)
    extra = max(p.max_events_per_step + p.flight_merge for p in plist) + 2
    streams = [LineLengthStream(p, seed, i) for p, i in zip(plist, indices, strict=True)]
    n_draws = max(_draws(p, duration, room[0]) for p in plist) + 4 * extra
    lam = np.stack([s.draw(n_draws) for s in streams])
    y = _per_member(initial_state, plist)
    cnt = _per_member(lambda p: initial_counters(p, transient=transient), plist)
    c = _per_member(lambda p: kernel_constants(p, t_record=transient, tangent=tangent), plist)
    section = np.empty((n, n_sec, k.SECTION_COLS))
    impacts = np.empty((n, room[1] + 4 * extra, k.IMPACT_COLS))
    status = np.zeros(n, dtype=np.int64)
    n_impacts = np.zeros(n, dtype=np.int64)

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

    (run or _run_on_cpu)(y, cnt, c, n_stop, lam, section, impacts, status, hand_back, keep_impacts)
    sections, rows, impact_rows = [], [], []
    for j in range(n):
        empty_impacts(j)
        if keep_impacts and kept[j]:
            block = np.concatenate(kept[j])
            impact_rows.append(np.column_stack([np.full(len(block), first + j), block]))
        m = cnt[j, k.I_N_SECTION]
        block = np.empty((m, 1 + k.SECTION_COLS))
        block[:, 0] = first + j
        block[:, 1:] = section[j, :m]
        sections.append(block)
        rows.append(
            (
                first + j,
                indices[j],
                Status(int(status[j])).name,
                int(n_impacts[j]),
                contact_fraction(y[j], cnt[j], c[j]),
            )
        )
    return sections, rows, impact_rows


def _run_on_cpu(y, cnt, c, n_stop, lam, section, impacts, status, hand_back, keep_impacts):
    """The members in parallel calls of the driver's loop: all of them first, then those
    that asked for room, refilled (a resumed member is bit-identical to one that was not
    interrupted, so the pauses change nothing)."""
    fork_safe_threads()
    n = y.shape[0]
    run_members = members_kernel(c)

    def launch(need: np.ndarray) -> np.ndarray:
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

    def refill(need: np.ndarray) -> None:
        for j in need:  # the same width again: as many new draws as were used
            lam[j] = hand_back(j, lam[j], int(cnt[j, k.I_LAM_POS]))

    drive_members(n, launch, refill)


def _draws(p: Params, duration: float, room: int) -> int:
    """Line-length draws a member starts with: one per resampling interval of the run, or,
    under impact resampling (one per applied impact), ``room``."""
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
