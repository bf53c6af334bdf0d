"""Many trajectories in one compiled call, parallel over cores (numba ``prange``).

Each member runs the same kernel as :func:`chaoscam.simulate` (:func:`_kernel.run_chunk`) on
its own line-length draws, so member ``i`` equals ``simulate(params_i, seed=seed,
index=indices[i], series=False)`` bit for bit. Only sections, impact counts and statuses are
kept; a member that outgrows its impact buffer or its draws is finished on the serial path.
"""

from __future__ import annotations

import os
import time
from dataclasses import dataclass, field
from typing import Any

import numpy as np
import pandas as pd
from numba import njit, prange

from ..model import LineLengthStream, Params
from . import _kernel as k
from ._advance import advance
from ._constants import initial_counters, initial_state, kernel_constants
from ._status import Status

__all__ = ["Ensemble", "contact_fraction", "run_members", "run_one", "simulate_ensemble"]

# numba's GNU OpenMP layer aborts a process that forks after using it, and the sweeps fork
# their workers from a driver that has simulated; the workqueue layer is fork-safe (though not
# safe for parallel calls from several Python threads at once). A user's choice wins.
if "NUMBA_THREADING_LAYER" not in os.environ:
    import numba

    numba.config.THREADING_LAYER = "workqueue"

_DRAWS = 2048  # line-length draws per member before a refill
_IMPACT_ROWS = 256  # impact rows per member per call (only counted, not kept)


@njit(parallel=True, cache=True)
def run_members(y, cnt, c, n_stop, lam, series, section, impacts, status):
    """:func:`_advance.advance` for each member ``i`` of stacked arrays, in parallel.

    The one compiled entry point of every simulation (``chaoscam.simulate`` calls it with a
    single member), so that a realization is bit-identical on every path and thread count.
    """
    for i in prange(y.shape[0]):
        status[i] = advance(
            y[i], cnt[i], c[i], n_stop, lam[i], series[i], section[i], impacts[i]
        )


def contact_fraction(y, cnt, c) -> float:
    """Fraction of the recorded time spent in contact (gap <= 0); NaN if nothing recorded.

    The fixed-step kernel counts grid steps ending in contact; the adaptive one integrates
    time (slots ``Y_RECORDED`` and ``Y_CONTACT``).
    """
    if c[k.C_METHOD] == k.METHOD_ADAPTIVE:
        rec = y[k.Y_RECORDED]
        return float(y[k.Y_CONTACT] / rec) if rec > 0 else float("nan")
    counted = cnt[k.I_COUNTED_STEPS]
    return float(cnt[k.I_CONTACT_STEPS] / counted) if counted else float("nan")


def run_one(y, cnt, c, n_stop, lam, series, section, impacts) -> int:
    """:func:`run_members` for one trajectory (arrays of a single member, updated in place)."""
    status = np.zeros(1, dtype=np.int64)
    run_members(
        y[None], cnt[None], c[None], n_stop, lam[None], series[None], section[None],
        impacts[None], status,
    )
    return int(status[0])


@dataclass(frozen=True)
class Ensemble:
    """Sections and per-member summaries of an ensemble run.

    Attributes
    ----------
    sections : pandas.DataFrame
        member, k, t, theta_f, omega_f, l_lambda: the stroboscopic points after the transient.
    members : pandas.DataFrame
        member, index, status (name), n_impacts, contact_fraction.
    settings : dict
        duration, transient, seed, threads, wall time.
    """

    sections: pd.DataFrame
    members: pd.DataFrame
    settings: dict[str, Any] = field(default_factory=dict)


def simulate_ensemble(
    params: Params | list[Params],
    indices,
    *,
    seed: int = 0,
    duration: float = 20.0,
    transient: float = 0.0,
    batch: int = 1024,
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
    batch : int
        Members per compiled call; bounds memory (about 40 kB per member).

    Notes
    -----
    Threads: numba's thread count (``NUMBA_NUM_THREADS`` or ``numba.set_num_threads``).
    """
    indices = [int(i) for i in indices]
    plist = list(params) if isinstance(params, list | tuple) else [params] * len(indices)
    if len(plist) != len(indices):
        raise ValueError(f"{len(plist)} parameter sets for {len(indices)} indices")
    if len({(p.dt, p.omega) for p in plist}) > 1:
        raise ValueError("members must share dt and omega")
    t0 = time.perf_counter()
    sections, rows = [], []
    for start in range(0, len(indices), batch):
        chunk = slice(start, start + batch)
        s, r = _run_batch(plist[chunk], indices[chunk], start, seed, duration, transient)
        sections.extend(s)
        rows.extend(r)
    cols = ["member", "k", "t", "theta_f", "omega_f", "l_lambda"]
    sec = pd.DataFrame(np.concatenate(sections) if sections else np.empty((0, 6)), columns=cols)
    sec[["member", "k"]] = sec[["member", "k"]].astype(np.int64)
    import numba

    return Ensemble(
        sections=sec,
        members=pd.DataFrame(
            rows, columns=["member", "index", "status", "n_impacts", "contact_fraction"]
        ),
        settings={
            "duration": duration,
            "transient": transient,
            "seed": seed,
            "threads": numba.get_num_threads(),
            "wall_time_s": time.perf_counter() - t0,
        },
    )


def _run_batch(plist, indices, first, seed, duration, transient):
    n = len(indices)
    p0 = plist[0]
    n_stop = int(round(duration / p0.dt))
    n_sec = int(duration / p0.cam_period) + 4 + int(p0.dt / p0.cam_period)
    extra = max(p.max_events_per_step + p.flight_merge for p in plist) + 2
    streams = [LineLengthStream(p, seed, i) for p, i in zip(plist, indices, strict=True)]
    lam = np.stack([s.draw(_DRAWS + 4 * extra) for s in streams])
    y = np.stack([initial_state(p) for p in plist])
    cnt = np.stack([initial_counters(p, transient=transient) for p in plist])
    c = np.stack([kernel_constants(p, t_record=transient) for p in plist])
    section = np.empty((n, n_sec, k.SECTION_COLS))
    impacts = np.empty((n, _IMPACT_ROWS + 4 * extra, k.IMPACT_COLS))
    status = np.zeros(n, dtype=np.int64)
    n_impacts = np.zeros(n, dtype=np.int64)
    run_members(y, cnt, c, n_stop, lam, np.empty((n, 1, k.SERIES_COLS)), section, impacts, status)
    # Members that asked for room finish one by one on the same kernel.
    no_series = np.empty((1, k.SERIES_COLS))
    for j in np.flatnonzero(status == k.NEED_BUFFER):
        lam_j = lam[j]
        while status[j] == k.NEED_BUFFER:
            n_impacts[j] += cnt[j, k.I_N_IMPACT]
            cnt[j, k.I_N_IMPACT] = 0
            pos = cnt[j, k.I_LAM_POS]
            lam_j = np.concatenate([lam_j[pos:], streams[j].draw(_DRAWS)])
            cnt[j, k.I_LAM_POS] = 0
            status[j] = run_one(
                y[j], cnt[j], c[j], n_stop, lam_j, no_series, section[j], impacts[j]
            )
    sections, rows = [], []
    for j in range(n):
        m = cnt[j, k.I_N_SECTION]
        block = np.empty((m, 6))
        block[:, 0] = first + j
        block[:, 1:] = section[j, :m]
        sections.append(block)
        rows.append(
            (
                first + j,
                indices[j],
                Status(int(status[j])).name,
                int(n_impacts[j] + cnt[j, k.I_N_IMPACT]),
                contact_fraction(y[j], cnt[j], c[j]),
            )
        )
    return sections, rows
