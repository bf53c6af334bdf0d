"""The work of a sweep: :class:`Realization` tasks solved in batches (:meth:`Batch.launch`),
judged, continued to a ``fate`` horizon and recorded (:meth:`Batch.label`; a GPU sweep launches
the next meanwhile). A record is a JSON-safe dict, a pure function of its task."""

from __future__ import annotations

import functools
import hashlib
import importlib
import inspect
import math
import numbers
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field, is_dataclass
from typing import Any

import numpy as np

from .._util import quiet, recorded
from ..analysis import LABELS, spectrum_from_jacobians
from ..kernel import Status
from ..model import Params, truncated_mass
from ..numerics import Numerics
from ..simulation import Solution, extend, run_warnings, solve
from ..verdict import EXTEND_TO, classify, judge_points
from ._stats import SECTION_QUANTILES

FATE_LABELS = frozenset({"chaotic", "quasiperiodic", "undetermined"})
"""Labels whose runs a ``fate`` horizon continues: not a certified attracting orbit, so the
motion may still leave the cam's reach or settle later."""

FATE_LATE = 0.5
"""The part of a fate run (its last half) on which its verdict at the horizon is taken."""

FATE_FIELDS = ("fate", "left_at", "fate_label", "fate_period")
"""A record's fate fields; None in a run not continued."""

SECTION_KEYS = ("k", "t", "theta_f", "omega_f", "l_lambda")
"""The section columns a record keeps for the plans that ask for them."""


@dataclass(frozen=True)
class Judge:
    """How a sweep labels its runs: the package's verdict (``custom`` None) or
    ``custom(solution) -> verdict`` on each one-member solution (with its series unless it
    declares ``needs_series = False``); ``lyapunov`` records the tangent spectrum (evidence
    ``lyapunov_1``, ``lyapunov_1_stderr``, ``lyapunov_2`` [1/s]); ``check_step`` and
    ``extend_to`` as for :func:`chaoscam.classify`; ``labels`` False: no verdict at all."""

    custom: Callable | None = None
    lyapunov: bool = False
    check_step: bool = False
    extend_to: float | None = EXTEND_TO
    labels: bool = True

    @property
    def series(self) -> bool:
        """Whether the runs keep their series (for a classifier of one's own that asks)."""
        return self.custom is not None and bool(getattr(self.custom, "needs_series", True))

    def identity(self) -> str:
        """A stable text naming the classifier and its settings (in the configuration)."""
        if not self.labels:
            return "none"
        name = "chaoscam.classify" if self.custom is None else classifier_identity(self.custom)
        return (
            f"{name}(extend_to={self.extend_to}, check_step={self.check_step}, "
            f"lyapunov={self.lyapunov})"
        )

    def fields(self, sol: Solution) -> list[dict[str, Any]]:
        """The verdict fields of every member of ``sol`` (a failed run's: its status's)."""
        if not self.labels:
            return [status_fields(None) for _ in range(len(sol))]
        if self.custom is None:
            verdicts = classify(sol, extend_to=self.extend_to, check_step=self.check_step)
        else:
            verdicts = [self.custom(sol[i]) if _ok(sol, i) else None for i in range(len(sol))]
        out = []
        for i, v in enumerate(verdicts):
            status = Status[sol.members["status"].iat[i]]
            f = status_fields(status) if status is not Status.OK else verdict_fields(v)
            if self.lyapunov or (self.custom is None and v is not None):
                f["evidence"].update(_spectrum_evidence(v, sol, i))
            twins = (getattr(v, "settings", None) or {}).get("twins") if v is not None else None
            if twins is not None:
                f["evidence"]["synchronised"] = float(twins["outcome"] == "synchronised")
            out.append(f)
        return out


def _ok(sol: Solution, i: int) -> bool:
    return sol.members["status"].iat[i] == Status.OK.name


def _spectrum_evidence(v, sol: Solution, i: int) -> dict[str, float]:
    """Member ``i``'s tangent spectrum [1/s]: its verdict's, or from the run's Jacobians."""
    rec = (getattr(v, "settings", None) or {}).get("tangent") if v is not None else None
    if rec is None and sol.jacobians is not None and _ok(sol, i):
        rows = sol.sections["member"].to_numpy() == i
        rows &= sol.sections["k"].to_numpy() > 0
        rows &= sol.sections["t"].to_numpy() >= sol.settings["transient"]
        if rows.sum() >= 2:
            spec = spectrum_from_jacobians(sol.jacobians[rows], sol.models[i].cam_period)
            rec = {"exponents": list(spec.exponents), "stderr": list(spec.stderr)}
    if rec is None:
        return {}
    return {"lyapunov_1": float(rec["exponents"][0]),
            "lyapunov_1_stderr": float(rec["stderr"][0]),
            "lyapunov_2": float(rec["exponents"][1])}  # fmt: skip


def classifier_identity(classify: Callable) -> str:
    """A stable text naming a classifier: ``module.qualname`` (a lambda's or local function's
    with a digest of code, defaults and closure), a bound method's instance, a partial's
    function and arguments, or an instance's class and ``repr``."""
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
    cells = tuple(_stable_repr(c.cell_contents) for c in (func.__closure__ or ()))
    extra = (func.__defaults__, func.__kwdefaults__, cells)
    return hashlib.sha256(repr((_code_key(code), extra)).encode()).hexdigest()[:16]


def load_classifier(spec: str) -> Callable:
    """``MODULE:NAME`` to a classifier: a function, or a class made without arguments."""
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
            "is a function, or a class whose instances are called, taking a solution of one "
            "run and returning a verdict"
        )
    return obj


def _number(v: Any) -> float:
    try:
        return float(v)
    except (TypeError, ValueError):
        return math.nan


def verdict_fields(verdict: Any) -> dict[str, Any]:
    """What a table keeps of a verdict: label, period, reasons, evidence values and
    ``recorded_s`` (of the extended run it was made on; None if not extended). Any object
    with ``label`` (one of ``LABELS``), ``period`` (whole >= 1 or None), ``evidence`` (items
    with ``name``, ``value``) and ``reasons``; another label or period is a ValueError."""
    evidence: dict[str, float] = {}
    for e in getattr(verdict, "evidence", ()) or ():
        evidence.setdefault(str(e.name), _number(e.value))
    label, period = verdict.label, getattr(verdict, "period", None)
    if label not in LABELS:  # a custom classifier's: it would become a cell's dominant label
        raise ValueError(f"the classifier's label {label!r} is not one of {', '.join(LABELS)}")
    number = isinstance(period, numbers.Real) and not isinstance(period, bool)
    if period is not None and not (number and float(period).is_integer() and period >= 1):
        raise ValueError(f"the classifier's period {period!r} is not a whole number >= 1 or None")
    settings = getattr(verdict, "settings", None)
    ext = settings.get("extended") if isinstance(settings, dict) else None
    return {
        "label": str(label),
        "period": None if period is None else int(period),
        "reasons": "; ".join(str(r) for r in (getattr(verdict, "reasons", ()) or ())),
        "evidence": evidence,
        "recorded_s": _number(ext["recorded_s"]) if isinstance(ext, dict) else None,
    }


def status_fields(status: Status | None) -> dict[str, Any]:
    """The verdict fields of a run not judged: labelled by its status (None: no label)."""
    label, reasons = (None, "") if status is None else (status.label, status.message)
    return {"label": label, "period": None, "reasons": reasons, "evidence": {}, "recorded_s": None}


@dataclass(frozen=True)
class Realization:
    """One realization a sweep runs: its place in the plan, what fixes the run, a ``fate``
    horizon, ``extra`` fields of its record and whether the record keeps the section."""

    key: tuple[int, int]
    params: Params
    numerics: Numerics
    seed: int
    sim_index: int
    duration: float
    transient: float
    fate: float | None = None
    extra: dict = field(default_factory=dict)
    sections: bool = False

    def group(self) -> tuple:
        """Tasks that share this can be one :func:`chaoscam.solve` call."""
        return (self.seed, self.duration, self.transient, self.numerics, self.params.omega,
                self.fate)  # fmt: skip

    def hint(self) -> str:
        """The :func:`chaoscam.simulate` call that reproduces the run alone."""
        p, num = self.params, self.numerics
        changed = {k: v for k, v in p.to_dict().items() if v != Params().to_dict()[k]}
        changed |= {k: v for k, v in num.to_dict().items() if v != Numerics().to_dict()[k]}
        args = ", ".join(f"{k}={v!r}" for k, v in changed.items())
        return (
            f"chaoscam.simulate({args + ', ' if args else ''}duration={self.duration!r}, "
            f"transient={self.transient!r}, seed={self.seed}, index={self.sim_index})"
        )

    def record(self, sol: Solution, i: int, fields: dict[str, Any]) -> dict[str, Any]:
        """The record from member ``i`` of ``sol`` and its verdict fields."""
        m, p = sol.members.iloc[i], self.params
        rows = sol.sections["member"].to_numpy() == i
        recorded = fields.get("recorded_s")
        rec = {
            **self.extra, "seed": self.seed, "sim_index": self.sim_index,
            "status": str(m["status"]), "label": fields["label"], "period": fields["period"],
            "n_section": int(rows.sum()),
            "recorded_s": float(self.duration - self.transient if recorded is None else recorded),
            "n_impacts": int(m["n_impacts"]), "contact_fraction": _number(m["contact_fraction"]),
            "truncated_mass": truncated_mass(p.l_lambda, p.l_lambda_sigma, p.l_min),
            "reasons": fields["reasons"], "warnings": fields["warnings"],
            "evidence": fields["evidence"], **{name: fields.get(name) for name in FATE_FIELDS},
        }  # fmt: skip
        late = rows & (sol.sections["t"].to_numpy() >= self.transient)
        if late.any():  # the recorded section's theta_f distribution, as quantiles
            q = np.quantile(sol.sections["theta_f"].to_numpy()[late], SECTION_QUANTILES)
            quantiles = {f"section_q{k}": float(v) for k, v in enumerate(q)}
            rec["evidence"] = {**rec["evidence"], **quantiles}
        if self.sections:
            sec = sol.sections[rows]
            rec["section"] = {c: sec[c].tolist() for c in SECTION_KEYS}
        return rec


@dataclass(frozen=True)
class Batch:
    """Tasks run together; :meth:`run` returns their records in order."""

    tasks: tuple[Realization, ...]
    judge: Judge
    backend: str = "cpu"

    def key(self) -> tuple[int, int]:
        return self.tasks[0].key

    def hint(self) -> str:
        return f"a batch of {len(self.tasks)} runs from {self.key()}: " + ", ".join(
            t.hint() for t in self.tasks[:3]
        )

    def run(self) -> list[dict[str, Any]]:
        return self.label(self.launch())

    def launch(self) -> list[tuple[list[int], Solution, list[str]]]:
        """The first phase: per group, (positions in the batch, solution, warnings)."""
        groups: dict[tuple, list[int]] = {}
        for i, t in enumerate(self.tasks):
            groups.setdefault(t.group(), []).append(i)
        out = []
        for (seed, duration, transient, num, _, fate), picks in groups.items():
            rk4 = num.integrator == "rk4"
            with recorded() as caught:  # catch_warnings is not safe on the batch threads
                sol = solve(
                    [self.tasks[i].params for i in picks], num,
                    indices=[self.tasks[i].sim_index for i in picks], seed=seed,
                    duration=duration, transient=transient, tangent=rk4,
                    series=self.judge.series, backend=self.backend,
                    resumable=rk4 and (self.judge.extend_to is not None or fate is not None),
                )  # fmt: skip
            out.append((picks, sol, [str(w.message) for w in caught]))
        return out

    def label(self, launched: list) -> list[dict[str, Any]]:
        """The second phase: verdicts, fates where asked, warnings, and the records."""
        records: list[dict[str, Any] | None] = [None] * len(self.tasks)
        for picks, sol, warned in launched:
            plist = list(sol.models)
            with recorded() as caught:
                fields = self.judge.fields(sol)
            fate = self.tasks[picks[0]].fate
            later = [j for j, f in enumerate(fields) if _ok(sol, j) and f["label"] in FATE_LABELS]
            if fate is not None and later:
                for j, more in zip(later, _fates(sol, later, fate), strict=True):
                    fields[j].update(more)
            # what the batch warned, less the models' own (each record adds its own model's)
            models = {w for q in set(plist) for w in run_warnings(q, sol.numerics)}
            said = [*warned, *(str(w.message) for w in caught)]
            shared = [w for w in said if w not in models]
            for j, i in enumerate(picks):
                seen = [w for w in (*run_warnings(plist[j], sol.numerics), *shared) if w]
                fields[j]["warnings"] = " | ".join(dict.fromkeys(seen))
                records[i] = self.tasks[i].record(sol, j, fields[j])
        return records  # type: ignore[return-value]


def _fates(sol: Solution, later: Sequence[int], fate: float) -> list[dict[str, Any]]:
    """The fate fields of members ``later`` run on to ``fate`` [s] (extended, or from t = 0)."""
    s = sol.settings
    period = max(p.cam_period for p in sol.models)
    continues = sol.resume is not None and (1.0 - FATE_LATE) * (fate - period) > (
        s["transient"] + period
    )
    backend = "cpu" if s["backend"] == "cpu" else "auto"
    with quiet():  # the model's warnings came with the first run (quiet: on batch threads)
        if continues:
            long = extend(sol, fate, members=list(later), backend=backend)
        else:
            long = solve(
                [sol.models[j] for j in later], sol.numerics,
                indices=[int(sol.members["index"].iat[j]) for j in later], seed=s["seed"],
                duration=fate, transient=0.0, backend=backend,
                tangent=sol.numerics.integrator == "rk4",
            )  # fmt: skip
    return [_fate_fields(long, i) for i in range(len(later))]


def _fate_fields(long: Solution, i: int) -> dict[str, Any]:
    """Member ``i``'s fate: status, ``left_at`` (NaN if it stayed), verdict on :data:`FATE_LATE`."""
    status = str(long.members["status"].iat[i])
    rows = long.sections["member"].to_numpy() == i
    t = long.sections["t"].to_numpy()[rows]
    stopped = status != Status.OK.name
    out = {"fate": status, "left_at": float(t[-1]) if stopped and len(t) else math.nan,
           "fate_label": None, "fate_period": None}  # fmt: skip
    if stopped or long.jacobians is None or not len(t):
        return out
    k = long.sections["k"].to_numpy()[rows]
    late = (t >= (1.0 - FATE_LATE) * t[-1]) & (k > 0)
    if not late.any():  # a horizon within a cam period or so: nothing to judge
        return out
    xy = long.sections[["theta_f", "omega_f"]].to_numpy(dtype=float)[rows][late]
    with quiet():  # a short late window warns like the first run did (on batch threads too)
        noise = {"seed": int(long.settings["seed"]), "index": int(long.members["index"].iat[i])}
        v = judge_points(xy, long.jacobians[rows][late], long.models[i], long.numerics, {}, **noise)
    return {**out, "fate_label": v.label, "fate_period": v.period}
