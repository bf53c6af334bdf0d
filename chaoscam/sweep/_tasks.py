"""The work a sweep sends to its workers: simulate one realization, classify it, keep a record.

A task is a small frozen dataclass (parameters, settings, the classifier); its record is a
JSON-safe dict holding the section points or the verdict, never a time series, so the
driver's and the workers' memory stays flat however large the grid. A record is a pure
function of its task: the same on any worker, in any order, on any backend.
"""

from __future__ import annotations

import functools
import hashlib
import importlib
import inspect
import math
import numbers
from collections.abc import Callable
from dataclasses import dataclass, is_dataclass
from typing import Any

import pandas as pd

from .._simulate import simulate
from .._warn import quiet, recorded
from ..analysis import LABELS
from ..integrate import Status
from ..model import Params

__all__ = [
    "FATE_LABELS",
    "DefaultClassifier",
    "RealizationTask",
    "BranchTask",
    "RunSummary",
    "fate_columns",
    "fate_fields",
    "run_task",
]

FATE_LABELS = frozenset({"chaotic", "quasiperiodic", "undetermined"})
"""Labels whose runs a sweep's ``fate`` horizon continues: their motion is not a certified
attracting orbit, so it may still leave the cam's reach or settle later (transient chaos: at
(omega, xi) = (42.5 rad/s, 0.40) the motion is chaotic for 229 s and then leaves; at
xi = 0.30 it is chaotic for ~53 s and then settles on a period 30)."""


@dataclass(frozen=True)
class DefaultClassifier:
    """The package classifier, ``chaoscam.classify.classify_trajectory``, imported lazily.

    Parameters
    ----------
    tangent : bool
        Default True: the verdict uses the tangent exponent through the impacts and, for a
        periodic section of the deterministic model, a certified periodic orbit (see
        ``classify_trajectory``); the runs are then simulated with ``tangent=True``.
    lyapunov : bool
        Instead, the model's two-trajectory exponent (evidence ``lyapunov_model``, about
        twice the cost of the run), kept for comparison; what a regime map's
        ``lyapunov_mean`` / ``lyapunov_std`` summarise.
    check_step : bool
        Re-simulate with dt / 2 and call the verdict undetermined if it changes (twice the
        cost).
    extend_to : float or None
        Longest recorded time [s] an undetermined verdict is extended to
        (``classify_trajectory``'s ``extend_to``; default its ``EXTEND_TO``, 120 s); None
        never extends. Cap it for models whose runs are expensive (a small dt).
    """

    lyapunov: bool = False
    check_step: bool = False
    tangent: bool = True
    extend_to: float | None = 120.0  # chaoscam.classify.EXTEND_TO (tested equal)
    needs_series = True  # the classifier may use the sampled signal, not only the section

    @property
    def needs_tangent(self) -> bool:
        """Simulate with the tangent dynamics (so the classifier need not run again)."""
        return self.tangent and not self.lyapunov

    def __call__(self, traj):
        from ..classify import classify_trajectory

        return classify_trajectory(
            traj,
            tangent=self.tangent,
            lyapunov=self.lyapunov,
            check_step=self.check_step,
            extend_to=self.extend_to,
        )


def classifier_identity(classify: Callable) -> str:
    """A stable text naming a classifier and its settings, part of a run's configuration.

    ``module.qualname`` for a function (plus a digest of its code, defaults and closure for
    a lambda or a local function, whose names are not unique; the digest leaves out line
    numbers and file names, so moving the code does not change it); for a bound method, its
    instance's identity too; for ``functools.partial``, its function's identity with the
    bound arguments; for an instance, its class's name plus ``repr`` (a dataclass's repr
    lists its fields, so two settings never share an identity), or its attributes where
    the repr would name a memory address.
    """
    if isinstance(classify, type) or not callable(classify):
        raise TypeError(f"classify must be a function or an instance, got {classify!r}")
    if isinstance(classify, functools.partial):  # its own name is functools.partial's
        args = [_stable_repr(v) for v in classify.args]
        keywords = sorted((k_, _stable_repr(v)) for k_, v in classify.keywords.items())
        inner = classifier_identity(classify.func)
        return f"functools.partial({inner}, args={args!r}, keywords={keywords!r})"
    if hasattr(classify, "__qualname__") and hasattr(classify, "__module__"):
        name = f"{classify.__module__}.{classify.__qualname__}"
        if inspect.ismethod(classify):  # Clf(0.1).classify and Clf(0.5).classify differ
            return f"{name}@{_stable_repr(classify.__self__)}"
        code = getattr(classify, "__code__", None)
        if "<" in classify.__qualname__ and code is not None:  # <lambda>, <locals>: not unique
            name += ":" + _code_digest(classify, code)
        return name
    cls = type(classify)
    return f"{cls.__module__}.{cls.__qualname__}:{_stable_repr(classify)}"


def _stable_repr(value: Any) -> str:
    """``repr(value)``, or its attributes where the repr would name a memory address."""
    if inspect.isfunction(value) or inspect.ismethod(value) or isinstance(value, functools.partial):
        return classifier_identity(value)
    text = repr(value)
    if " at 0x" in text and not is_dataclass(value) and hasattr(value, "__dict__"):
        text = repr(sorted((k_, _stable_repr(v)) for k_, v in vars(value).items()))
    return text


def _code_key(code) -> tuple:
    """A code object's content without its position (file, line numbers)."""
    consts = tuple(_code_key(c) if inspect.iscode(c) else repr(c) for c in code.co_consts)
    return (code.co_code, consts, code.co_names, code.co_varnames)


def _code_digest(func: Callable, code) -> str:
    """A digest of a lambda's or a local function's code, defaults and closure: two of them
    with one name get two identities (a closure value whose repr names an address and has no
    attributes gives a new identity each run: a resume is refused rather than mixing)."""
    cells = tuple(_stable_repr(c.cell_contents) for c in (func.__closure__ or ()))
    extra = (func.__defaults__, func.__kwdefaults__, cells)
    return hashlib.sha256(repr((_code_key(code), extra)).encode()).hexdigest()[:16]


def needs_series(classify: Callable) -> bool:
    """Whether to simulate with the time series for this classifier.

    A classifier may declare ``needs_series = False`` when the section (and impacts) are
    enough; otherwise it receives the series (sampled every 1 ms). Either way the series
    stays in the worker: records hold sections and verdicts only.
    """
    return bool(getattr(classify, "needs_series", True))


def load_classifier(spec: str) -> Callable:
    """``MODULE:NAME`` to a classifier: a function, or a class instantiated without arguments."""
    module, sep, name = spec.partition(":")
    if not sep or not module or not name:
        raise ValueError(f"classifier {spec!r}: expected MODULE:NAME")
    obj = getattr(importlib.import_module(module), name)
    made = isinstance(obj, type)
    if made:
        try:
            obj = obj()
        except TypeError as err:
            raise ValueError(f"the class {name} cannot be made without arguments ({err})") from None
    if not callable(obj):
        what = f"{name}() makes" if made else f"{name} is"
        raise ValueError(
            f"{what} {obj!r} (type {type(obj).__name__}), which cannot be called; a classifier "
            "is a function, or a class whose instances are called, taking a trajectory and "
            "returning a verdict"
        )
    return obj


def _number(v: Any) -> float:
    if isinstance(v, bool):
        return float(v)
    try:
        f = float(v)
    except (TypeError, ValueError):
        return math.nan
    return f


def verdict_fields(verdict: Any) -> dict[str, Any]:
    """The parts of a verdict a table keeps: label, period, reasons, evidence values, and
    ``recorded_s``, the recorded time of the extended run the verdict was made on
    (``settings["extended"]``; None when made on the run as given).

    Works with any object with ``label`` (one of :data:`LABELS`), ``period`` (a whole
    number >= 1, or None), ``evidence`` (items with ``name``, ``value``) and ``reasons``;
    another label or period is a ValueError (the run's task fails naming it). Values that
    are not numbers become NaN; a repeated evidence name keeps its first value.
    """
    evidence: dict[str, float] = {}
    for e in getattr(verdict, "evidence", ()) or ():
        evidence.setdefault(str(e.name), _number(e.value))
    label, period = verdict.label, getattr(verdict, "period", None)
    if label not in LABELS:  # a custom classifier's: it would become a cell's dominant label
        raise ValueError(f"the classifier's label {label!r} is not one of {', '.join(LABELS)}")
    number = isinstance(period, numbers.Real) and not isinstance(period, bool)
    if period is not None and not (number and float(period).is_integer() and period >= 1):
        raise ValueError(f"the classifier's period {period!r} is not a whole number >= 1 or None")
    return {
        "label": str(label),
        "period": None if period is None else int(period),
        "reasons": "; ".join(str(r) for r in (getattr(verdict, "reasons", ()) or ())),
        "evidence": evidence,
        "recorded_s": _extended_to(getattr(verdict, "settings", None)),
    }


def _extended_to(settings: Any) -> float | None:
    ext = settings.get("extended") if isinstance(settings, dict) else None
    return _number(ext["recorded_s"]) if isinstance(ext, dict) and "recorded_s" in ext else None


def recorded_seconds(fields: dict[str, Any], duration: float, transient: float) -> float:
    """The ``recorded_s`` column: seconds of section recording behind the label, the
    extension's when the verdict was extended, else the run's own (duration - transient)."""
    extended = fields.get("recorded_s")
    return float(extended) if extended is not None else float(duration - transient)


OUTPUT_DT = 1e-3
"""Series sampling of a sweep's runs [s] (simulate's default), or dt where dt is coarser."""


@dataclass(frozen=True)
class RunSummary:
    """What a record keeps of one simulated realization, whichever driver ran it.

    ``section`` has the columns of ``Trajectory.section``; ``status`` is a ``Status`` name.
    """

    status: str
    section: pd.DataFrame
    n_impacts: int
    contact_fraction: float
    truncated_mass: float


FATE_LATE = 0.5
"""The part of a fate run (its last half) on which its verdict at the horizon is taken: a
run that settles does so well before (xi = 0.30 settles on a period 30 at 53 s at dt)."""


def fate_fields(status: str, section: pd.DataFrame, jacobians, params: Params) -> dict[str, Any]:
    """The record's fate at the horizon, from the fate run's status, section (k, t, theta_f,
    omega_f) and stroboscopic Jacobians (one per section row): ``fate`` (the status name:
    ``"OK"`` the motion stayed in the cam's reach, ``"LEFT_REACH"``, ``"DIVERGED"``, ...),
    ``left_at`` [s] (the last section time before a run that stopped, within a cam period
    of it; NaN for one that stayed) and, for one that stayed, ``fate_label`` and
    ``fate_period``: the model's verdict on the run's last half (:data:`FATE_LATE`;
    :func:`chaoscam.classify.classify_section_run`, certificate included), which says
    whether chaos over the recorded window settles later (None for one that stopped, for a
    last half without a whole cam period, and without ``jacobians``: a run of the adaptive
    integrator, whose tangent is not kept, so its sweeps say nothing of settling)."""
    from ..classify import classify_section_run

    t = section["t"].to_numpy(dtype=float)
    stopped = status != Status.OK.name
    unjudged = {
        "fate": status,
        "left_at": float(t[-1]) if stopped and len(t) else math.nan,
        "fate_label": None,
        "fate_period": None,
    }
    if stopped or jacobians is None or not len(t):
        return unjudged
    late = (t >= (1.0 - FATE_LATE) * t[-1]) & (section["k"].to_numpy() > 0)
    if not late.any():  # a horizon within a cam period or so: nothing to judge
        return unjudged
    with quiet():  # a short late window warns like the first run did (on batch threads too)
        v = classify_section_run(
            section.loc[late, ["theta_f", "omega_f"]].to_numpy(dtype=float),
            jacobians[late],
            params,
        )
    return {"fate": status, "left_at": math.nan, "fate_label": v.label, "fate_period": v.period}


FATE_FIELDS = ("fate", "left_at", "fate_label", "fate_period")
"""A record's fate fields (:func:`fate_fields`); None in a run not continued."""


def fate_columns(records: list[dict]) -> dict[str, Any]:
    """The fate columns of a sweep's table (None / NaN where a run was not continued)."""
    return {
        "fate": [r.get("fate") for r in records],
        "left_at": [math.nan if r.get("left_at") is None else r["left_at"] for r in records],
        "fate_label": [r.get("fate_label") for r in records],
        "fate_period": pd.array([r.get("fate_period") for r in records], dtype="Int64"),
    }


def fate_continues(resumable: bool, transient: float, fate: float, period: float) -> bool:
    """Whether a run kept resumable can go on to the horizon ``fate`` with the fate fields
    of a run made from t = 0: the last half of a run that stays to the horizon (from
    ``(1 - FATE_LATE) t_last``, its last section ``t_last > fate - period``) starts a cam
    ``period`` after the ``transient``, from which a continued run records."""
    return resumable and (1.0 - FATE_LATE) * (fate - period) > transient + period


def _fate(params: Params, task: Any, traj=None) -> dict[str, Any]:
    """The task's realization run on to ``task.fate`` seconds with the tangent (the same
    motion, bit for bit): does it stay in the cam's reach, and what is it at the end?
    Continued from its first run ``traj``'s copy (:func:`chaoscam._extend.extend_trajectory`)
    where :func:`fate_continues`, else (or without ``traj``: the fate audit) run again."""
    from .._extend import extend_trajectory

    with quiet():  # the model's warnings came with the first run
        if traj is not None and fate_continues(
            traj.resume is not None, task.transient, task.fate, params.cam_period
        ):
            long = extend_trajectory(traj, task.fate, series=False)
        else:
            long = simulate(
                params,
                duration=task.fate,
                transient=0.0,
                seed=task.seed,
                index=task.sim_index,
                series=False,
                tangent=params.integrator == "rk4",
            )
    return fate_fields(long.status.name, long.section, long.jacobians, params)


def status_fields(status: Status) -> dict[str, Any]:
    """The verdict fields of a run that did not end normally: labelled by its status."""
    return {"label": status.label, "period": None, "reasons": status.message, "evidence": {}}


def _run(params: Params, task: Any) -> tuple[RunSummary, dict[str, Any]]:
    """Simulate and classify; a run that did not end normally is labelled by its status."""
    tangent = bool(getattr(task.classify, "needs_tangent", False)) and params.integrator == "rk4"
    with recorded() as caught:  # (thread-safe: chaoscam._warn)
        traj = simulate(
            params,
            duration=task.duration,
            transient=task.transient,
            seed=task.seed,
            index=task.sim_index,
            series=task.series,
            output_dt=max(OUTPUT_DT, params.dt),  # a swept dt may exceed it
            tangent=tangent,
            resumable=tangent,  # an undetermined verdict's extension goes on from it
        )
        fields = verdict_fields(task.classify(traj)) if traj.ok else status_fields(traj.status)
    if traj.ok and task.fate is not None and fields["label"] in FATE_LABELS:
        fields.update(_fate(params, task, traj))
    seen = dict.fromkeys(str(w.message) for w in caught)
    fields["status"] = traj.status.name
    fields["warnings"] = " | ".join(seen)
    summary = RunSummary(
        traj.status.name,
        traj.section,
        int(traj.stats["n_impacts"]),
        _number(traj.stats["contact_fraction"]),
        _number(traj.stats["truncated_mass"]),
    )
    return summary, fields


def simulate_call(task: Any) -> str:
    """The ``chaoscam.simulate`` call that reproduces ``task``'s run alone: its parameters
    (those that differ from the defaults), window, seed and index."""
    base = Params().to_dict()
    changed = {k: v for k, v in task.params.to_dict().items() if v != base[k]}
    args = ", ".join(f"{k}={v!r}" for k, v in changed.items())
    extra = ""
    if not task.series:
        extra = ", series=False"
    elif task.params.dt > OUTPUT_DT:  # as the task ran it (:func:`_run`)
        extra = f", output_dt={task.params.dt!r}"
    return (
        f"chaoscam.simulate(chaoscam.Params({args}), duration={task.duration!r}, "
        f"transient={task.transient!r}, seed={task.seed}, index={task.sim_index}{extra})"
    )


@dataclass(frozen=True)
class RealizationTask:
    """Realization ``index`` of regime-map cell ``cell`` (simulate index ``sim_index``)."""

    cell: int
    index: int
    seed: int
    sim_index: int
    params: Params
    duration: float
    transient: float
    classify: Callable
    series: bool = True
    fate: float | None = None

    def key(self) -> tuple[int, int]:
        return (self.cell, self.index)

    def hint(self) -> str:
        """How to reproduce the run alone."""
        return simulate_call(self)

    def run(self) -> dict[str, Any]:
        return self.record(*_run(self.params, self))

    def record(self, run: RunSummary, fields: dict[str, Any]) -> dict[str, Any]:
        """The record of this realization from its run and its verdict fields."""
        return {
            "cell": self.cell,
            "index": self.index,
            "seed": self.seed,
            "sim_index": self.sim_index,
            "status": fields["status"],
            "label": fields["label"],
            "period": fields["period"],
            "n_section": int(len(run.section)),
            "recorded_s": recorded_seconds(fields, self.duration, self.transient),
            "n_impacts": run.n_impacts,
            "contact_fraction": run.contact_fraction,
            "truncated_mass": run.truncated_mass,
            "reasons": fields["reasons"],
            "warnings": fields["warnings"],
            "evidence": fields["evidence"],
            **{name: fields.get(name) for name in FATE_FIELDS},
        }


@dataclass(frozen=True)
class BranchTask:
    """One point of a bifurcation diagram: value ``value_index``, initial condition ``ic``.

    ``params`` already holds the swept value and the initial state (theta_f0, omega_f0;
    None = in contact); ``continued`` says the state came from the previous value's run.
    """

    value_index: int
    ic: int
    value: float
    seed: int
    sim_index: int
    params: Params
    duration: float
    transient: float
    classify: Callable
    continued: bool = False
    series: bool = True
    fate: float | None = None

    def key(self) -> tuple[int, int]:
        return (self.value_index, self.ic)

    def hint(self) -> str:
        """How to reproduce the run alone."""
        return simulate_call(self)

    def run(self) -> dict[str, Any]:
        return self.record(*_run(self.params, self))

    def record(self, run: RunSummary, fields: dict[str, Any]) -> dict[str, Any]:
        """The record of this point from its run and its verdict fields."""
        sec = run.section
        nxt = None
        if run.status == "OK" and len(sec):
            # The last stroboscopic point lies at cam phase theta_c0 (t = k 2 pi / omega):
            # a state the next value can start from at t = 0 with the same cam phase.
            nxt = [float(sec["theta_f"].iloc[-1]), float(sec["omega_f"].iloc[-1])]
        p = self.params
        return {
            "value_index": self.value_index,
            "ic": self.ic,
            "value": self.value,
            "seed": self.seed,
            "sim_index": self.sim_index,
            "theta_f0": math.nan if p.theta_f0 is None else float(p.theta_f0),
            "omega_f0": math.nan if p.omega_f0 is None else float(p.omega_f0),
            "continued": self.continued,
            "status": fields["status"],
            "label": fields["label"],
            "period": fields["period"],
            "n_points": int(len(sec)),
            "recorded_s": recorded_seconds(fields, self.duration, self.transient),
            "reasons": fields["reasons"],
            "warnings": fields["warnings"],
            "evidence": fields["evidence"],
            **{name: fields.get(name) for name in FATE_FIELDS},
            "section": {c: sec[c].tolist() for c in sec.columns},
            "next_state": nxt,
        }


def run_task(task: RealizationTask | BranchTask) -> dict[str, Any]:
    """Run one task (the function every backend calls)."""
    return task.run()
