"""An ensemble (:func:`chaoscam.ensemble`) in the report: its members' section, the share of
each label with its 95 % Wilson interval, why members stayed undetermined, its configuration.

A member's label is its verdict or, unclassified, its run status
(:func:`chaoscam.sweep.member_labels`). With ``l_lambda_sigma = 0`` or the fractal stiffness
every member is the same deterministic run, so the shares are those of one run and get no
sampling interval, as a regime map's deterministic cells.
"""

from __future__ import annotations

from collections import Counter
from typing import Any

from ..io import code_rows
from ..sweep import classified, label_shares

__all__ = ["classified", "ensemble_figure", "ensemble_settings", "label_shares", "top_reasons"]

TOP_REASONS = 8
"""Most distinct reasons for an undetermined label listed in the report (the rest counted)."""


def ensemble_figure(ens, *, title: str = ""):
    """Two panels (:meth:`chaoscam.sweep.Ensemble.plot`): every member's stroboscopic
    section coloured by its label, and the share of each label with its 95 % Wilson interval
    (none when every member is the same run)."""
    from matplotlib.figure import Figure

    fig = Figure(figsize=(12, 5), layout="constrained")
    a, b = fig.subplots(1, 2, width_ratios=(3, 2))
    ens.plot(a, kind="section")
    ens.plot(b, kind="shares")
    if title:
        fig.suptitle(title)
    return fig


def _reasons(members) -> list[tuple[str, int]]:
    """Why members are undetermined: each reason and how many members give it."""
    if not classified(members):
        return []
    undetermined = members[members["label"] == "undetermined"]
    counts = Counter(
        r.strip() for text in undetermined["reasons"] for r in str(text).split(";") if r.strip()
    )
    return counts.most_common()


def top_reasons(members) -> list[tuple[str, int]]:
    """:func:`_reasons`, the :data:`TOP_REASONS` most common and the rest counted together."""
    reasons = _reasons(members)
    shown, rest = reasons[:TOP_REASONS], sum(c for _, c in reasons[TOP_REASONS:])
    return shown + [(f"{len(reasons) - TOP_REASONS} other reasons", rest)] if rest else shown


def ensemble_settings(cfg: dict, ens) -> dict[str, Any]:
    """The provenance rows of an ensemble's configuration."""
    p, num = cfg.get("params") or {}, cfg.get("numerics") or {}
    first = cfg.get("first", 0)
    rows = {
        "kind": "ensemble",
        "package version": cfg.get("version"),
        "device": cfg.get("device"),
        "seed": cfg.get("seed"),
        "realization indices": f"{first} .. {first + cfg.get('members', len(ens.members)) - 1}",
        "duration [s]": cfg.get("duration"),
        "transient [s]": cfg.get("transient"),
        "classifier": cfg.get("classifier"),
    }
    rows.update(code_rows(cfg.get("code")))
    units = {"dt": " [s]", "l_lambda": " [m]", "l_lambda_sigma": " [m]", "omega": " [rad/s]"}
    for source, keys in (
        (num, ("integrator", "dt")),
        (p, ("stiffness", "l_lambda", "l_lambda_sigma", "resample", "omega", "xi")),
    ):
        rows.update({k + units.get(k, ""): source[k] for k in keys if k in source})
    return rows
