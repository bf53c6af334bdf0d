"""solve(params, numerics, ...) -> Solution: realizations of the model, a run a batch of one;
:func:`extend` continues a solution bit for bit, :func:`simulate` is the one-run convenience."""

from __future__ import annotations

import dataclasses
import hashlib
import math
import numbers
import time
from collections.abc import Sequence
from typing import Any

from .._util import ParameterError, flag, real, warn, whole
from .._version import __version__
from ..kernel import (
    GPU_BATCH,
    GPUFallbackWarning,
    by_size,
    gpu_status,
    kernel_constants,
    thread_count,
)
from ..kernel import layout as k
from ..model import Params, field_names, params_arg
from ..numerics import Numerics
from ._batch import ROOM, fresh, models_of, resumed, run_batch
from ._budget import JobEstimate, check_budget, estimate
from ._solution import Solution, assemble
from ._warnings import run_warnings

BACKENDS = ("cpu", "gpu", "auto")
CPU_BATCH = 1024
"""Members per compiled call on the CPU: bounds memory (~40 kB a member for 20 s runs)."""


def check_window(duration, transient, *, dt: float | None = None) -> tuple[float, float]:
    """The run's time window [s] as floats, checked for every entry point: ``duration`` > 0 (at
    least one step ``dt``), ``transient`` in [0, duration)."""
    if isinstance(duration, bool) or not (
        isinstance(duration, numbers.Real) and math.isfinite(duration) and duration > 0
    ):
        raise ParameterError(f"duration = {duration!r} s must be a finite number > 0")
    if isinstance(transient, bool) or not (
        isinstance(transient, numbers.Real) and 0 <= transient < duration
    ):
        raise ParameterError(f"transient = {transient!r} s must be in [0, duration = {duration})")
    if dt is not None and round(duration / dt) < 1:
        raise ParameterError(
            f"duration = {duration!r} s is shorter than one step dt = {dt!r} s: nothing "
            "would be simulated"
        )
    return float(duration), float(transient)


def numerics_arg(numerics: Any) -> Numerics:
    """An API function's ``numerics`` argument: a :class:`Numerics`, or None for defaults."""
    if numerics is None:
        return Numerics()
    if isinstance(numerics, Numerics):
        return numerics
    raise TypeError(
        f"numerics must be a chaoscam.Numerics or None, got {type(numerics).__name__} {numerics!r}"
    )


def split_overrides(p: Params, num: Numerics, overrides: dict, caller) -> tuple[Params, Numerics]:
    """``overrides`` (keywords) applied to the model or the numerics by field name; another is
    refused with what it was probably meant to be (``duraton`` -> ``duration``)."""
    import inspect

    from .._util import close_names

    fields = (*field_names(), *Numerics.field_names())
    unknown = [name for name in overrides if name not in fields]
    if unknown:
        own = [n for n, a in inspect.signature(caller).parameters.items()
               if a.kind is inspect.Parameter.KEYWORD_ONLY]  # fmt: skip
        close = close_names(unknown[0], own + list(fields))
        hint = f" Did you mean {', '.join(close)}?" if close else ""
        raise ParameterError(
            f"{caller.__name__}() got an unknown keyword {unknown[0]!r}: neither one of its "
            f"settings nor a model parameter or numerics setting.{hint} Its settings: "
            f"{', '.join(own)}; the fields: {', '.join(fields)}"
        )
    model = {n: v for n, v in overrides.items() if n in field_names()}
    steps = {n: v for n, v in overrides.items() if n not in model}
    return (p.replace(**model) if model else p), (num.replace(**steps) if steps else num)


def models_digest(plist: Sequence[Params], num: Numerics) -> str:
    """A fingerprint (16 hex digits) of the members' models in order and their numerics,
    numbers as floats (``omega=10`` and ``10.0`` are one model, as ``==`` says)."""

    def canonical(v):
        return float(v) if isinstance(v, numbers.Real) and not isinstance(v, bool) else v

    whole_run, seen = hashlib.sha256(repr(sorted(num.to_dict().items())).encode()), {}
    for p in plist:
        one = seen.get(id(p))
        if one is None:  # members that share a model are hashed once
            fields = [(n, canonical(v)) for n, v in p.to_dict().items()]
            one = seen[id(p)] = hashlib.sha256(repr(fields).encode()).digest()
        whole_run.update(one)
    return whole_run.hexdigest()[:16]


def _pick_backend(backend: str, members: int) -> tuple[bool, str]:
    """(use the GPU?, the device in words) for ``backend`` and ``members``; warns if "gpu" can't."""
    if backend not in BACKENDS:
        raise ValueError(
            f"backend must be one of {', '.join(map(repr, BACKENDS))}, got {backend!r}"
        )
    backend = by_size(backend, members)
    if backend == "cpu":
        return False, "cpu"
    ok, reason = gpu_status()
    if ok:
        return True, reason
    if backend == "gpu":
        warn(f"GPU backend unavailable: {reason}; falling back to the CPU", GPUFallbackWarning)
    return False, "cpu"


def _check_request(p, num, duration, transient, series, output_dt, members) -> None:
    """Refuse a request that cannot fit in memory; judge one run by its time (:func:`check_run`)."""
    one = estimate(p, num, duration=duration, transient=transient, series=series,
                   output_dt=output_dt)  # fmt: skip
    if members > 1:
        job = JobEstimate((one.bytes * members, 0.0))
        what = f"an ensemble of {members} members"
        check_budget(job, what=what, reduce="the members or duration")
        return
    rows = (duration - transient) / output_dt if series else 0.0
    check_budget(one, what="this run", reduce="duration (or raise output_dt)",
                 run=dict(params=p, num=num, duration=duration, what="this run",
                          series_rows=rows))  # fmt: skip


def solve(
    params: Params | Sequence[Params] | None = None, numerics: Numerics | None = None, *,
    indices=(0,), seed: int = 0, duration: float = 20.0, transient: float = 0.0,
    tangent: bool = False, series: bool = False, output_dt: float = 1e-3, impacts: bool = False,
    resumable: bool = False, backend: str = "cpu", batch: int | None = None, progress=None,
) -> Solution:  # fmt: skip
    """Simulate realizations of the model with located impacts, all in one call.

    Parameters
    ----------
    params : Params or sequence of Params, optional
        One model for every member, or one per member sharing ``omega`` (the section times);
        Table 1 defaults when omitted.
    numerics : Numerics, optional
        The integrator and its settings (default: the paper's fixed-step RK4).
    indices : sequence of int
        Member i is realization ``indices[i]`` under ``seed``, a pure function of ``(seed,
        indices[i])`` whatever the batch, backend or thread count.
    seed : int
        Master seed of the random line length.
    duration, transient : float
        End time [s]; outputs before ``transient`` are discarded.
    tangent : bool
        Also keep the stroboscopic map's Jacobian over each recorded period (the tangent
        dynamics; ``Solution.jacobians``); the motion is the same without it.
    series, output_dt : bool, float
        Keep the time series, sampled every ``output_dt`` [s] (rounded to whole steps).
    impacts : bool
        Keep every applied impact (``Solution.impacts``); otherwise only counted.
    resumable : bool
        Keep each member's state near its end (RK4) for :func:`extend` to continue bit for bit.
    backend : {"cpu", "gpu", "auto"}
        ``"cpu"``: numba threads. ``"gpu"``: one CUDA thread per member (``pip install
        'chaoscam[gpu]'``), within ``GPU_TOLERANCE`` of the CPU on short or periodic runs;
        where it cannot run (or with a series), the CPU after a :class:`GPUFallbackWarning`.
        ``"auto"``: the GPU from ``AUTO_GPU_MIN`` members.
    batch : int, optional
        Members per compiled call (memory); default :data:`CPU_BATCH`, or ``GPU_BATCH``.
    progress : callable, optional
        Called with the number of members just finished after each batch.

    Returns
    -------
    Solution
        Its ``members`` table says how each run ended (leaving the cam's reach or diverging is
        not an error).
    """
    p0, plist, num = _models(params, numerics, indices)
    duration, transient = check_window(duration, transient, dt=num.dt)
    tangent, series = flag("tangent", tangent), flag("series", series)
    impacts, resumable = flag("impacts", impacts), flag("resumable", resumable)
    seed = whole("seed", seed)
    output_dt = real("output_dt", output_dt, low=0.0, strict=True, unit="s")
    if series and output_dt < num.dt:
        raise ParameterError(
            f"output_dt = {output_dt!r} s (the series' sampling step, --output-dt) must be "
            f">= dt = {num.dt} s: raise output_dt or lower dt"
        )
    if progress is not None and not callable(progress):
        raise TypeError(f"progress must be callable (or None), got {type(progress).__name__}")
    _check_request(p0, num, duration, transient, series, output_dt, len(indices))
    indices = [whole("index", i) for i in indices]
    plist = plist if len(plist) == len(indices) else plist * len(indices)
    gpu, device = _pick_backend(backend, len(indices))
    if gpu and series:
        warn("a series is kept on the CPU only: this run goes there", GPUFallbackWarning)
        gpu, device = False, "cpu"
    batch = whole("batch", (GPU_BATCH if gpu else CPU_BATCH) if batch is None else batch, low=1)
    for text in dict.fromkeys(w for q in models_of(plist) for w in run_warnings(q, num)):
        warn(text)
    stride = max(1, int(round(output_dt / num.dt))) if series else 0

    def start(chunk, room):
        return fresh(plist[chunk], num, indices[chunk], seed, duration, transient,
                     tangent=tangent, stride=stride, room=room)  # fmt: skip

    settings = {
        "duration": duration, "transient": transient, "seed": seed, "tangent": tangent,
        "output_dt": stride * num.dt if series else None, "impacts": impacts,
        "backend": "gpu" if gpu else "cpu", "device": device, "batch": batch,
        "models": models_digest(plist, num), "version": __version__,
    }  # fmt: skip
    return _run(plist, num, indices, start, settings, progress, resumable)


def _models(params, numerics, indices) -> tuple[Params, list[Params], Numerics]:
    """(the first model, the models as given, the numerics), checked."""
    if isinstance(indices, str | bytes) or not hasattr(indices, "__len__"):
        raise TypeError(
            f"indices must be a sequence of realization indices (e.g. range(5)), got "
            f"{type(indices).__name__} {indices!r}"
        )
    per_member = isinstance(params, list | tuple)
    plist = [params_arg(q) for q in params] if per_member else [params_arg(params)]
    if per_member and len(plist) != len(indices):
        raise ValueError(f"{len(plist)} parameter sets for {len(indices)} indices")
    if not plist:
        raise ValueError("no members: give at least one index")
    if len({p.omega for p in plist}) > 1:
        raise ValueError("members must share omega (the section times)")
    return plist[0], plist, numerics_arg(numerics)


def _run(plist, num, indices, start, settings: dict, progress, resumable) -> Solution:
    """The members in batches of ``settings["batch"]``, each from ``start(chunk, room)`` through
    :func:`run_batch`, as one Solution; ``threads`` 1 for one member (asking numba would fix its
    threading layer)."""
    t0, parts = time.perf_counter(), []
    gpu, batch, duration = settings["backend"] == "gpu", settings["batch"], settings["duration"]
    room = ROOM["gpu" if gpu else "cpu"]
    for first in range(0, len(plist), batch):
        chunk = slice(first, first + batch)
        parts.append(run_batch(plist[chunk], num, indices[chunk], start(chunk, room), first,
                               duration, room=room, gpu=gpu, keep_impacts=settings["impacts"],
                               resumable=resumable))  # fmt: skip
        if progress is not None:
            progress(len(parts[-1].indices))
    threads = thread_count() if len(plist) > 1 else 1
    settings = {**settings, "threads": threads, "wall_time_s": time.perf_counter() - t0}
    return assemble(parts, plist, num, settings)


def extend(
    solution: Solution, duration: float, *, members=None, series: bool | None = None,
    resumable: bool = False, backend: str | None = None, progress=None,
) -> Solution:  # fmt: skip
    """Members of ``solution`` made ``duration`` seconds long, bit-identical to runs that long
    from t = 0: continued from ``solution.resume``'s copy (``resumable=True``, RK4), else (the
    adaptive integrator, a run not resumable or read from a file) run again from t = 0.

    Parameters
    ----------
    solution : Solution
        The run to make longer.
    duration : float
        The new end time [s], at least that of ``solution``.
    members : sequence of int, optional
        Which members (default all), renumbered 0, 1, ... in this order (``index`` kept).
    series : bool, optional
        Keep the time series (default: as the solution did; one that kept none cannot gain one).
    resumable : bool
        Keep a copy again, so that the result can be extended further.
    backend : {"cpu", "gpu", "auto"} or None
        Where the continuation runs (None: where the solution ran), from the same state.
    progress : callable, optional
        As for :func:`solve`.
    """
    if not isinstance(solution, Solution):
        raise TypeError(
            f"solution must be a chaoscam Solution (from chaoscam.solve), got "
            f"{type(solution).__name__}"
        )
    s = solution.settings
    duration, transient = check_window(duration, s["transient"])
    if duration < s["duration"]:
        raise ParameterError(
            f"duration = {duration!r} s must be >= the run's duration, {s['duration']!r} s"
        )
    had = s["output_dt"] is not None
    keep_series = had if series is None else flag("series", series)
    if keep_series and not had:
        raise ParameterError(
            "series = True: the run kept no time series, so its extension cannot have one "
            "(simulate it with series=True)"
        )
    last = len(solution) - 1
    picks = list(range(len(solution))) if members is None else [
        whole("members", m, low=0, high=last) for m in members  # not -1, 1.9, True
    ]  # fmt: skip
    sub = solution.select(picks) if picks != list(range(len(solution))) else solution
    if sub.resume is None:
        return _again(sub, duration, keep_series, resumable, backend, progress)
    return _continued(sub, duration, keep_series, resumable, backend, progress)


def _again(sub: Solution, duration, series, resumable, backend, progress) -> Solution:
    """The members of ``sub`` run again from t = 0 to ``duration``."""
    s = sub.settings
    out = solve(
        list(sub.models), sub.numerics, indices=[int(i) for i in sub.members["index"]],
        seed=s["seed"], duration=duration, transient=s["transient"], tangent=s["tangent"],
        series=series, output_dt=s["output_dt"] or 1e-3, impacts=s["impacts"],
        resumable=resumable, backend=backend or s["backend"], progress=progress,
    )  # fmt: skip
    more = {"continued_from": None, "backends": [*s.get("backends", [s["backend"]]),
                                                out.settings["backend"]]}  # fmt: skip
    return dataclasses.replace(out, settings={**out.settings, **more})


def _continued(sub: Solution, duration, series, resumable, backend, progress) -> Solution:
    """The members of ``sub`` continued from its copy to ``duration``."""
    s, res, num = sub.settings, sub.resume, sub.numerics
    plist = list(sub.models)
    for j, p in enumerate(plist):
        made = kernel_constants(p, num, t_record=s["transient"], tangent=s["tangent"])
        made[k.C_STRIDE] = res.c[j, k.C_STRIDE]  # (a continuation may drop the series)
        if not (made == res.c[j]).all():
            raise ValueError(f"member {j}'s model is not the one its copy was made with")
    if backend is None:
        gpu, device, batch = s["backend"] == "gpu", s.get("device", s["backend"]), s["batch"]
    else:
        gpu, device = _pick_backend(backend, len(plist))
        same = ("gpu" if gpu else "cpu") == s["backend"]
        batch = s["batch"] if same else (GPU_BATCH if gpu else CPU_BATCH)
    if gpu and series:
        gpu, device = False, "cpu"

    def start(chunk, room):
        return resumed(res.select(range(len(plist))[chunk]), plist[chunk], num, duration, room,
                       series=series)  # fmt: skip

    used = "gpu" if gpu else "cpu"
    settings = {
        **s, "duration": duration, "output_dt": s["output_dt"] if series else None,
        "continued_from": res.step, "backend": used, "device": device, "batch": batch,
        "backends": [*s.get("backends", [s["backend"]]), used],
    }  # fmt: skip
    indices = [int(i) for i in sub.members["index"]]
    return _run(plist, num, indices, start, settings, progress, resumable)


def simulate(
    params: Params | None = None, numerics: Numerics | None = None, *, duration: float = 20.0,
    transient: float = 0.0, seed: int = 0, index: int = 0, series: bool = True,
    output_dt: float = 1e-3, tangent: bool = False, resumable: bool = False, **overrides: Any,
) -> Solution:  # fmt: skip
    """One realization: :func:`solve` of one member, keeping its series and impacts.

    Keyword ``overrides`` apply on top of ``params`` and ``numerics`` by field name, e.g.
    ``simulate(omega=30.0, dt=1e-6)``. The follower starts in contact with the cam (``theta_f0``,
    ``omega_f0`` None); ``simulate(theta_f0=theta_f, omega_f0=omega_f)`` from an earlier run's
    section point is a new run, not that run's continuation to the bit (:func:`extend` is).

    Returns
    -------
    Solution
        Of one member: ``section``, ``impacts``, ``series``, ``status``, ``stats`` read it.
    """
    p, num = params_arg(params), numerics_arg(numerics)
    if overrides:
        p, num = split_overrides(p, num, overrides, simulate)
    return solve(
        p, num, indices=[index], seed=seed, duration=duration, transient=transient,
        tangent=tangent, series=series, output_dt=output_dt, impacts=True, resumable=resumable,
    )  # fmt: skip
