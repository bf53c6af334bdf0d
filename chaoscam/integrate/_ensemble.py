"""Many trajectories in one compiled call, parallel over cores (numba ``prange``).

Each member runs the same kernel as :func:`chaoscam.simulate` (:func:`_kernel.run_chunk`) on
its own line-length draws, so member ``i`` equals ``simulate(params_i, seed=seed,
index=indices[i], series=False)`` bit for bit. Only sections, impact counts and statuses are
kept; a member that fills its impact rows or uses up its draws is refilled and launched
again (:mod:`._members`, one batch). :func:`extend_ensemble` continues members of a run
kept ``resumable`` to a longer duration, bit for bit (:mod:`._resume`).

``backend="gpu"`` runs the same kernel on an NVIDIA GPU, one thread per member
(:mod:`._gpu`, numba-cuda), equal to this path within ``GPU_TOLERANCE`` on short or periodic
runs.
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

import numpy as np

from .._checks import flag, params_arg, whole
from .._frozen import freeze_fields
from .._run_warnings import run_warnings
from .._warn import warn
from ..model import Params
from . import _gpu
from . import _kernel as k
from ._constants import kernel_constants
from ._driver import check_window, thread_count
from ._members import fresh, models_of, resumed, run_batch, run_on_cpu
from ._resume import Resume
from ._tangent import section_jacobians

if TYPE_CHECKING:
    import pandas as pd

__all__ = ["BACKENDS", "Ensemble", "extend_ensemble", "simulate_ensemble"]

_ROOM = {"cpu": (2048, 2048), "gpu": (512, 256)}
"""Room per member and launch, on each backend: (line-length draws, impact rows). Impact
rows are used only when impacts are kept (``keep_impacts``); otherwise the kernel counts the
impacts in a buffer of no rows and a member stops only when its draws run out. A member
stops for a refill when either runs out (a 20 s run of Table 1 applies ~15,000 impacts,
most of them the micro-impacts of chattering, each with a draw under resample="impact"),
and every stop is a relaunch, where the CPU's threads wait for the slowest member: 2048 of
each cut a regime map's kernel time by 6 % against 512 and 256 (measured on 2 cores, when
rows were filled whether kept or not), for 144 KiB a member (150 MB for a batch of 1024).
The GPU keeps the small room: its batches hold tens of thousands of members."""
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
        batch, integrators, tangent, wall time; from :func:`extend_ensemble` also
        ``continued_from``, the grid step its members went on from.
    impacts : pandas.DataFrame or None
        With ``keep_impacts=True``: member plus the columns of ``Trajectory.impacts`` (the
        applied jumps after the transient); else None (only counted).
    jacobians : ndarray or None
        With ``tangent=True``: the Jacobian of the stroboscopic map over the period ending at
        each row of ``sections``, shape (len(sections), 2, 2), as ``Trajectory.jacobians``.
    resume : Resume or None
        With ``resumable=True``: each member's state where :func:`extend_ensemble` can
        continue it (see :mod:`._resume`).
    """

    sections: pd.DataFrame
    members: pd.DataFrame
    settings: dict[str, Any] = field(default_factory=dict)
    impacts: pd.DataFrame | None = None
    jacobians: np.ndarray | None = None
    resume: Resume | None = field(default=None, repr=False, compare=False)

    def __post_init__(self) -> None:
        freeze_fields(self, "settings", "jacobians")


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
    resumable: bool = False,
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
        available and the ensemble has :data:`_gpu.AUTO_GPU_MIN` members or more (fewer
        run as fast or faster on the CPU), else the CPU without a notice.
        ``settings["backend"]`` records the one used.
    keep_impacts : bool
        Also return every member's impacts (``Ensemble.impacts``); by default they are only
        counted, so that memory stays flat for long runs.
    tangent : bool
        Integrate the tangent dynamics too and keep each section row's stroboscopic Jacobian
        (``Ensemble.jacobians``), from which :func:`chaoscam.classify.classify_ensemble`
        labels the members (the tangent exponent, n-band chaos, the periodic-orbit
        certificate). The members' motion is the same with and without it.
    resumable : bool
        Keep each member's state at its last section time before the end
        (``Ensemble.resume``), so that :func:`extend_ensemble` can continue it to a longer
        duration instead of running it again; the run's results are the same bits. RK4
        members only, without ``keep_impacts`` (otherwise ``resume`` is None); it costs one
        more stop of the compiled call and about 20 kB a member.
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
    keep_impacts, tangent = flag("keep_impacts", keep_impacts), flag("tangent", tangent)
    resumable = flag("resumable", resumable)
    seed = whole("seed", seed)
    if isinstance(indices, str | bytes) or not hasattr(indices, "__iter__"):
        raise TypeError(
            f"indices must be a sequence of realization indices (e.g. range(5)), got "
            f"{type(indices).__name__} {indices!r}"
        )
    if progress is not None and not callable(progress):
        raise TypeError(f"progress must be callable (or None), got {type(progress).__name__}")
    per_member = isinstance(params, list | tuple)
    plist = [params_arg(q) for q in params] if per_member else [params_arg(params)]
    if plist and hasattr(indices, "__len__"):  # before the list: range(10**10) would hang there
        _check_memory(plist[0], duration, transient, len(indices))
    indices = [whole("index", i) for i in indices]
    use_gpu, device = _pick_backend(backend, len(indices))
    batch = whole(
        "batch", (_gpu.GPU_BATCH if use_gpu else _CPU_BATCH) if batch is None else batch, low=1
    )
    if not per_member:
        plist = plist * len(indices)
    if len(plist) != len(indices):
        raise ValueError(f"{len(plist)} parameter sets for {len(indices)} indices")
    if len({(p.dt, p.omega) for p in plist}) > 1:
        raise ValueError("members must share dt and omega")
    models = models_of(plist)  # one model for all members: checked once
    for text in dict.fromkeys(w for q in models for w in run_warnings(q)):
        warn(text)  # as simulate() warns
    t0 = time.perf_counter()
    room = _ROOM["gpu" if use_gpu else "cpu"]
    parts = []
    for first in range(0, len(indices), batch):
        chunk = slice(first, first + batch)
        start = fresh(plist[chunk], indices[chunk], seed, duration, transient, tangent, room)
        parts.append(
            run_batch(
                plist[chunk],
                indices[chunk],
                start,
                first,
                duration,
                run=_gpu.run_on_gpu if use_gpu else run_on_cpu,
                room=room,
                keep_impacts=keep_impacts,
                resumable=resumable,
            )
        )
        if progress is not None:
            progress(len(parts[-1][1]))
    settings = {
        "duration": duration,
        "transient": transient,
        "seed": seed,
        "backend": "gpu" if use_gpu else "cpu",
        "device": device,
        "batch": batch,
        "integrators": sorted({p.integrator for p in plist}),
        "tangent": bool(tangent),
        "models": models_digest(plist),
    }
    return _assemble(parts, settings, keep_impacts, t0)


def models_digest(plist: list[Params]) -> str:
    """A fingerprint of the members' models, in order (``settings["models"]``): the sha256
    of each one's fields, numbers as floats (``repr``, exact; ``omega=10`` and ``10.0`` are
    one model, as ``==`` says), 16 hex digits. What
    :func:`chaoscam.classify.classify_ensemble` compares its ``params`` with."""
    import dataclasses
    import hashlib
    import numbers

    def canonical(v):
        return float(v) if isinstance(v, numbers.Real) and not isinstance(v, bool) else v

    whole_run, seen = hashlib.sha256(), {}
    for p in plist:
        one = seen.get(id(p))
        if one is None:  # members that share a model are hashed once
            fields = [(f.name, canonical(getattr(p, f.name))) for f in dataclasses.fields(p)]
            one = seen[id(p)] = hashlib.sha256(repr(fields).encode()).digest()
        whole_run.update(one)
    return whole_run.hexdigest()[:16]


def _check_memory(p: Params, duration: float, transient: float, members: int) -> None:
    """Refuse an ensemble whose sections cannot fit in this machine's memory (the CLI's
    ``chaoscam ensemble`` refuses it too, with its parts on disk)."""
    from .._budget import JobEstimate, check_budget, estimate

    one = estimate(p, duration=duration, transient=transient)
    job = JobEstimate((one.bytes * members, 0.0))
    check_budget(job, what=f"an ensemble of {members} members", reduce="the members or duration")


def extend_ensemble(
    ens: Ensemble,
    params: Params | list[Params],
    duration: float,
    *,
    members=None,
    resumable: bool = False,
    progress=None,
    backend: str | None = None,
) -> Ensemble:
    """Members of ``ens`` continued to ``duration``, bit-identical to runs made that long.

    Each member goes on from the copy ``ens.resume`` keeps (a run made with
    ``resumable=True``), at its last section time before the end, instead of being run
    again from t = 0 (see :mod:`._resume`); its sections, Jacobians, impact count, contact
    fraction and status are those of ``simulate_ensemble`` over the longer window.

    Parameters
    ----------
    ens : Ensemble
        A run made with ``resumable=True`` (and without ``keep_impacts``).
    params : Params or list of Params
        The model of every member of ``ens``, as given to ``simulate_ensemble``.
    duration : float
        The new end time [s], at least that of ``ens``.
    members : sequence of int, optional
        Which members (their ``member`` numbers in ``ens``); default all. They are numbered
        0, 1, ... in the result, in this order (``index`` keeps their realization).
    resumable : bool
        Keep a copy again, so that the result can be extended further.
    progress : callable, optional
        As for :func:`simulate_ensemble`.
    backend : {"cpu", "gpu", "auto"} or None
        Where the continuation runs; None (default): where ``ens`` ran. ``"auto"`` settles by
        the members continued, as :func:`simulate_ensemble` does (the GPU from
        ``_gpu.AUTO_GPU_MIN`` of them). A continuation on the other backend goes on from the
        same state, so it is bit-identical to a run that changed backend there, and equal
        to one made on either backend throughout only within ``_gpu.GPU_TOLERANCE`` (see
        :func:`simulate_ensemble`). ``settings["backends"]`` lists where each leg ran;
        ``settings["backend"]`` is the last.

    Raises
    ------
    ValueError
        When ``ens`` holds no copy, ``duration`` is shorter than its run, or ``params``
        is not the model of its members.
    """
    res = ens.resume
    if res is None:
        raise ValueError(
            "this ensemble cannot be continued: run simulate_ensemble with resumable=True "
            "(the RK4 integrator, without keep_impacts)"
        )
    s = ens.settings
    duration, transient = check_window(duration, s["transient"])
    if duration < s["duration"]:
        raise ValueError(f"duration = {duration!r} s is shorter than the run's {s['duration']} s")
    last = len(res) - 1
    picks = (
        list(range(len(res)))
        if members is None
        else [whole("members", m, low=0, high=last) for m in members]  # not -1, 1.9, True
    )
    plist = list(params) if isinstance(params, list | tuple) else [params] * len(res)
    if len(plist) != len(res):
        raise ValueError(f"{len(plist)} parameter sets for {len(res)} members")
    plist = [plist[j] for j in picks]
    res = res.select(picks)
    for j, p in enumerate(plist):
        made = kernel_constants(p, t_record=transient, tangent=s["tangent"])
        if not np.array_equal(made, res.c[j]):
            raise ValueError(f"params[{picks[j]}] is not the model member {picks[j]} ran with")
    indices = [int(ens.members["index"].iat[j]) for j in picks]
    if backend is None:
        use_gpu, device, batch = s["backend"] == "gpu", s.get("device", s["backend"]), s["batch"]
    else:
        use_gpu, device = _pick_backend(backend, len(picks))
        same = ("gpu" if use_gpu else "cpu") == s["backend"]
        batch = s["batch"] if same else (_gpu.GPU_BATCH if use_gpu else _CPU_BATCH)
    room = _ROOM["gpu" if use_gpu else "cpu"]
    t0 = time.perf_counter()
    parts = []
    for first in range(0, len(picks), batch):
        chunk = slice(first, first + batch)
        sub = res.select(range(len(picks))[chunk])
        parts.append(
            run_batch(
                plist[chunk],
                indices[chunk],
                resumed(sub, plist[chunk], duration, room),
                first,
                duration,
                run=_gpu.run_on_gpu if use_gpu else run_on_cpu,
                room=room,
                resumable=resumable,
            )
        )
        if progress is not None:
            progress(len(parts[-1][1]))
    used = "gpu" if use_gpu else "cpu"
    more = {
        "duration": duration,
        "continued_from": res.step,
        "models": models_digest(plist),
        "backend": used,
        "device": device,
        "batch": batch,
        "backends": [*s.get("backends", [s["backend"]]), used],
    }
    return _assemble(parts, {**s, **more}, False, t0)


def _assemble(parts, settings: dict, keep_impacts: bool, t0: float) -> Ensemble:
    """The Ensemble of batches' outputs (``_run_batch``'s), in order."""
    import pandas as pd

    sections = [b for part in parts for b in part[0]]
    rows = [r for part in parts for r in part[1]]
    impact_rows = [r for part in parts for r in part[2]]
    resumes = [part[3] for part in parts]
    cols = ["member", *k.SECTION_NAMES]
    every = np.concatenate(sections) if sections else np.empty((0, 1 + k.SECTION_COLS))
    sec = pd.DataFrame(every[:, : len(cols)], columns=cols)
    sec[["member", "k"]] = sec[["member", "k"]].astype(np.int64)
    members = pd.DataFrame(
        rows, columns=["member", "index", "status", "n_impacts", "contact_fraction"]
    )
    # the Jacobians from the rows without the member column
    jac = section_jacobians(every[:, 1:]) if settings["tangent"] else None
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
    resume = None
    if resumes and all(r is not None for r in resumes):
        resume = Resume.join(resumes)
    settings = {
        **settings,
        "threads": thread_count(),
        "wall_time_s": time.perf_counter() - t0,
    }
    return Ensemble(sec, members, settings, impacts, jac, resume)


def _pick_backend(backend: str, members: int) -> tuple[bool, str]:
    """(use the GPU?, the device in words) for ``backend`` and a run of ``members``
    (``"auto"`` settled by size, :func:`._gpu.by_size`); warns if "gpu" cannot run."""
    if backend not in BACKENDS:
        raise ValueError(
            f"backend must be one of {', '.join(map(repr, BACKENDS))}, got {backend!r}"
        )
    backend = _gpu.by_size(backend, members)
    if backend == "cpu":
        return False, "cpu"
    ok, reason = _gpu.gpu_status()
    if ok:
        return True, reason
    if backend == "gpu":
        warn(f"GPU backend unavailable: {reason}; falling back to the CPU", _gpu.GPUFallbackWarning)
    return False, "cpu"
