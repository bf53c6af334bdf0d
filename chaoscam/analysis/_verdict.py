"""The verdict: evidence from several methods combined into one label, never a guess."""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from .._util import FrozenDict

__all__ = ["LABELS", "VOTES", "Evidence", "Verdict", "combine"]

LABELS = ("periodic", "quasiperiodic", "chaotic", "undetermined")
"""The labels a verdict can carry."""

VOTES: dict[str | None, frozenset[str]] = {
    "periodic": frozenset({"periodic"}),
    "quasiperiodic": frozenset({"quasiperiodic"}),
    "chaotic": frozenset({"chaotic"}),
    "not_chaotic": frozenset({"periodic", "quasiperiodic"}),
    "not_periodic": frozenset({"quasiperiodic", "chaotic"}),
    None: frozenset({"periodic", "quasiperiodic", "chaotic"}),
}
"""The labels each vote admits. None abstains (the method could not decide)."""


def _json_value(v):
    """A JSON-safe copy of an evidence value (NaN and inf become None)."""
    if v is None or isinstance(v, bool | str):
        return v
    if isinstance(v, int | np.integer):
        return int(v)
    if isinstance(v, float | np.floating):
        f = float(v)
        return f if math.isfinite(f) else None
    if isinstance(v, tuple | list | np.ndarray):
        return [_json_value(u) for u in v]
    return str(v)


@dataclass(frozen=True)
class Evidence:
    """One method's finding: ``name``, headline ``value`` (period, K, λ₁, ...), ``vote`` (a key
    of `VOTES`; None abstains) and a ``detail`` saying what was measured and why it votes."""

    name: str
    value: float | int | None
    vote: str | None
    detail: str

    def __post_init__(self):
        if self.vote not in VOTES:
            raise ValueError(f"unknown vote {self.vote!r}; expected one of {list(VOTES)}")

    def to_dict(self) -> dict:
        """JSON-serialisable form."""
        return dict(
            name=self.name, value=_json_value(self.value), vote=self.vote, detail=self.detail
        )


@dataclass(frozen=True)
class Verdict:
    """A classification of the dynamics, traceable to its evidence and settings.

    Attributes
    ----------
    label : str
        One of `LABELS`.
    period : int or None
        For "periodic": in iterates of the section map (forcing periods if stroboscopic).
    evidence : tuple of Evidence
        Every method's finding, including those that abstained.
    reasons : tuple of str
        Why the label is "undetermined" (disagreement, too little data), or what limits it.
    settings : dict
        Each method's settings and ``"thresholds"`` (`Thresholds` as a dict); a ``FrozenDict``.
    """

    label: str
    period: int | None
    evidence: tuple[Evidence, ...]
    reasons: tuple[str, ...] = ()
    settings: dict = field(default_factory=dict)

    def __post_init__(self):
        if self.label not in LABELS:
            raise ValueError(f"unknown label {self.label!r}; expected one of {LABELS}")
        object.__setattr__(self, "settings", FrozenDict(self.settings))

    @property
    def used(self) -> tuple[str, ...]:
        """Names of the evidence that voted (the rest abstained and did not count)."""
        return tuple(e.name for e in self.evidence if e.vote is not None)

    def to_dict(self) -> dict:
        """JSON-serialisable dict with keys label, period, evidence, reasons (not `settings`)."""
        return dict(
            label=self.label,
            period=None if self.period is None else int(self.period),
            evidence=[e.to_dict() for e in self.evidence],
            reasons=list(self.reasons),
        )


def combine(
    evidence: tuple[Evidence, ...] | list[Evidence],
    periods: dict[str, int] | None = None,
    reasons: tuple[str, ...] | list[str] = (),
    settings: dict | None = None,
) -> Verdict:
    """Combine votes into a verdict: the one label every vote admits, with direct support.

    The label must lie in every cast vote's set of `VOTES` and be named by at least one vote
    (exclusions alone do not make a label); else, or with no vote or several labels left,
    it is "undetermined" and `reasons` says why. A "periodic" verdict takes the section's
    period (`periods`, by evidence name); a spectral period must divide it (the spectrum may
    miss weak subharmonics); any other disagreement is undetermined.
    """
    evidence = tuple(evidence)
    label, period, why = _label(evidence, periods or {})
    reasons = (*reasons, why) if why else tuple(reasons)
    return Verdict(label, period, evidence, reasons, dict(settings or {}))


def _label(evidence: tuple[Evidence, ...], periods: dict) -> tuple[str, int | None, str]:
    """(label, period, why it is undetermined or "") by the rules of `combine`."""
    cast = [e for e in evidence if e.vote is not None]
    if not cast:
        why = "no method could decide (see the evidence for why each abstained)"
        return "undetermined", None, why
    admitted = frozenset({"periodic", "quasiperiodic", "chaotic"})
    for e in cast:
        admitted = admitted & VOTES[e.vote]
    votes_txt = ", ".join(f"{e.name}: {e.vote}" for e in cast)
    if not admitted:
        return "undetermined", None, f"the evidence disagrees ({votes_txt})"
    if len(admitted) > 1:
        why = f"the evidence does not separate {' / '.join(sorted(admitted))} ({votes_txt})"
        return "undetermined", None, why
    (label,) = admitted
    if not any(e.vote == label for e in cast):
        why = f"only exclusions point to {label} ({votes_txt}); no method supports it directly"
        return "undetermined", None, why
    if label != "periodic":
        return label, None, ""
    periods = {k: int(v) for k, v in periods.items() if v is not None}
    exact = {k: v for k, v in periods.items() if k.startswith("section")}
    spectral = {k: v for k, v in periods.items() if not k.startswith("section")}
    if len(set(exact.values())) > 1:
        return "undetermined", None, f"the section periods disagree: {exact}"
    if exact:
        period = next(iter(exact.values()))
        bad = {k: v for k, v in spectral.items() if period % v != 0}
        if bad:
            why = f"the spectral period {bad} does not divide the section period {period}"
            return "undetermined", None, why
        return label, period, ""
    if len(set(spectral.values())) > 1:
        return "undetermined", None, f"the periods disagree: {spectral}"
    return label, next(iter(spectral.values()), 1), ""
