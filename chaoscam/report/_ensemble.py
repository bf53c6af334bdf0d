"""An ensemble (:func:`chaoscam.ensemble`) in the report: its members' section, the share of
each label with its 95 % Wilson interval, why members stayed undetermined, its configuration.

A member's label is its verdict or, unclassified, its run status. With ``l_lambda_sigma =
0`` or the fractal stiffness every member is the same deterministic run, so the shares are
those of one run and get no sampling interval, as a regime map's deterministic cells.
"""

from __future__ import annotations

import re
from collections import Counter
from typing import Any

import numpy as np

from ..io import code_rows
from ..sweep import LABEL_ORDER, wilson_interval

__all__ = ["classified", "deterministic", "ensemble_figure", "ensemble_settings"]
__all__ += ["label_shares", "top_reasons"]

TOP_REASONS = 8
"""Most distinct reasons for an undetermined label listed in the report (the rest counted)."""


def classified(members) -> bool:
    """Whether the members carry verdicts (an ensemble run with ``classify``)."""
    return "label" in members and bool(members["label"].notna().any())


def _labels(members) -> list[str]:
    """Each member's label: its verdict ("periodic (period 2)" with its period), or its
    status when the run was not classified."""
    if not classified(members):
        return [str(s) for s in members["status"]]
    import pandas as pd

    return [
        f"periodic (period {int(p)})" if lab == "periodic" and not pd.isna(p) else str(lab)
        for lab, p in zip(members["label"], members["period"], strict=True)
    ]


def _order(label: str) -> tuple[int, int, str]:
    head = label.partition(" ")[0]
    rank = LABEL_ORDER.index(head) if head in LABEL_ORDER else len(LABEL_ORDER)
    period = re.search(r"period (\d+)", label)
    return rank, int(period.group(1)) if period else 0, label


def deterministic(config: dict) -> bool:
    """Whether the configuration makes every member the same run
    (:func:`chaoscam.model.realizations_identical`)."""
    from ..model import Params, realizations_identical

    try:
        return realizations_identical(Params(**config["params"]))
    except (KeyError, TypeError, ValueError):  # a configuration this version cannot read
        return False


def label_shares(members, *, confidence: float = 0.95) -> list[dict[str, Any]]:
    """One row per label, in display order: label, count, share, and the share's Wilson
    interval (``lo``, ``hi``) over the members."""
    counts = Counter(_labels(members))
    n = sum(counts.values())
    rows = []
    for label in sorted(counts, key=_order):
        k = counts[label]
        lo, hi = wilson_interval(k, n, confidence)
        rows.append({"label": label, "count": k, "share": k / n, "lo": float(lo), "hi": float(hi)})
    return rows


def ensemble_figure(ens, *, title: str = ""):
    """Two panels: every member's stroboscopic section (θ_f, θ̇_f) coloured by its label, and
    the share of each label with its 95 % Wilson interval (none when deterministic)."""
    from matplotlib.figure import Figure

    from ._sweep_figures import _OTHER, LABEL_COLORS, axis_label

    def color(label: str) -> str:
        return LABEL_COLORS.get(label.partition(" ")[0], _OTHER)

    fig = Figure(figsize=(12, 5), layout="constrained")
    a, b = fig.subplots(1, 2, width_ratios=(3, 2))
    members, sec = ens.members, ens.sections
    labels = dict(zip(members["member"], _labels(members), strict=True))
    if sec is not None and len(sec):
        size = float(np.clip(3e4 / len(sec), 0.3, 6.0))
        lab = sec["member"].map(labels).fillna("?")
        for key in sorted(set(lab), key=_order):
            g = sec[lab == key]
            a.scatter(
                g["theta_f"], g["omega_f"], s=size, c=color(key), linewidths=0, rasterized=True
            )
            a.scatter([], [], s=30, c=color(key), label=key)
        a.legend(frameon=False, fontsize="small")
        a.set_xlabel(axis_label("theta_f"))
        a.set_ylabel(axis_label("omega_f"))
        a.set_title(f"stroboscopic section of {members['member'].nunique()} members")
    else:
        a.set_axis_off()
        a.text(0.5, 0.5, "no sections file beside the members file", ha="center")
    rows = label_shares(members)
    x = np.arange(len(rows))
    share = np.array([r["share"] for r in rows])
    colors = [color(r["label"]) for r in rows]
    if deterministic(ens.config):
        b.bar(x, share, color=colors)
        b.set_title("share of members (one deterministic run)")
    else:
        err = np.array([share - [r["lo"] for r in rows], [r["hi"] for r in rows] - share])
        b.bar(x, share, color=colors, yerr=err, capsize=4)
        b.set_title("share of members, 95 % Wilson interval")
    for xi, r in zip(x, rows, strict=True):
        b.text(xi, max(r["hi"], r["share"]) + 0.03, str(r["count"]), ha="center", fontsize=10)
    b.set_xticks(x, [r["label"] for r in rows], rotation=30, ha="right")
    b.set_ylim(0, 1.12)
    b.set_ylabel("share of members")
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
