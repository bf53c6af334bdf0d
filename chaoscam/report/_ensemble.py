"""An ensemble (:func:`chaoscam.ensemble`, ``chaoscam ensemble --out``) in the report: its
members' section, the share of each label with its 95 % Wilson interval, why members stayed
undetermined, and the run's configuration.

A member's label is its verdict or, unclassified, its run status. With ``l_lambda_sigma =
0``, or the fractal stiffness, every member is the same deterministic run (the members
differ only in their realization index, whose draws change nothing), so the shares are those
of one run and get no sampling interval, as a regime map's deterministic cells.
"""

from __future__ import annotations

import re
from collections import Counter
from pathlib import Path
from typing import Any

import numpy as np

from ..io import code_rows
from ..sweep import LABEL_ORDER, wilson_interval
from ._figures import png_bytes, png_uri

__all__ = ["classified", "deterministic", "ensemble_entry", "ensemble_figure", "label_shares"]

TOP_REASONS = 8
"""Most distinct reasons for an undetermined label listed in the report (the rest counted)."""


def classified(members) -> bool:
    """Whether the members carry verdicts (an ensemble run with ``classify``)."""
    return "label" in members and bool(members["label"].notna().any())


def _labels(members) -> list[str]:
    """Each member's label: its verdict, or its status when the run was not classified; a
    periodic verdict with its period ("periodic (period 2)")."""
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
    """True when the configuration says every member is the same run: ``l_lambda_sigma =
    0``, or the fractal stiffness (:func:`chaoscam.model.realizations_identical`)."""
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

    fig = Figure(figsize=(12, 5), layout="constrained")
    a, b = fig.subplots(1, 2, width_ratios=(3, 2))
    members, sec = ens.members, ens.sections
    labels = dict(zip(members["member"], _labels(members), strict=True))
    if sec is not None and len(sec):
        size = float(np.clip(3e4 / len(sec), 0.3, 6.0))
        lab = sec["member"].map(labels).fillna("?")
        for key in sorted(set(lab), key=_order):
            g = sec[lab == key]
            color = LABEL_COLORS.get(key.partition(" ")[0], _OTHER)
            a.scatter(g["theta_f"], g["omega_f"], s=size, c=color, linewidths=0, rasterized=True)
            a.scatter([], [], s=30, c=color, label=key)
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
    colors = [LABEL_COLORS.get(r["label"].partition(" ")[0], _OTHER) for r in rows]
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


def _settings(cfg: dict, ens) -> dict[str, Any]:
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
    for source, k, unit in (
        (num, "integrator", ""),
        (num, "dt", " [s]"),
        (p, "stiffness", ""),
        (p, "l_lambda", " [m]"),
        (p, "l_lambda_sigma", " [m]"),
        (p, "resample", ""),
        (p, "omega", " [rad/s]"),
        (p, "xi", ""),
    ):
        if k in source:
            rows[f"{k}{unit}"] = source[k]
    return rows


def ensemble_entry(path: str, ens, *, png: bytes | None = None) -> dict[str, Any]:
    """What the report shows of one ensemble: ``figure`` (title, uri, alt, caption), the
    label table ``rows``, the undetermined members' ``reasons`` with their counts, the
    ``settings`` for the provenance section and a ``summary`` line (``png``: the figure
    already rendered, else drawn here)."""
    name = Path(path).name
    rows = label_shares(ens.members)
    fixed = deterministic(ens.config)
    if png is None:
        png = png_bytes(ensemble_figure(ens, title=name))
    n = len(ens.members)
    reasons = _reasons(ens.members)
    shown = reasons[:TOP_REASONS]
    rest = sum(c for _, c in reasons[TOP_REASONS:])
    if rest:
        shown.append((f"{len(reasons) - TOP_REASONS} other reasons", rest))
    what = "verdicts" if classified(ens.members) else "run statuses (not classified)"
    counts = "; ".join(f"{r['label']}: {r['count']}" for r in rows)
    return {
        "figure": {
            "title": f"Ensemble of {n} members ({name})",
            "uri": png_uri(png),
            "alt": f"Left: the stroboscopic section theta_f, omega_f of every member, coloured "
            f"by its label. Right: the share of each label among {n} members"
            + ("." if fixed else " with its 95% Wilson interval."),
            "caption": f"{n} members, {what}"
            + (
                "; every member is the same deterministic run (l_lambda_sigma = 0 or the fractal "
                "stiffness)."
                if fixed
                else "."
            ),
        },
        "rows": [
            (
                r["label"],
                r["count"],
                f"{r['share']:.3f}",
                "none: one deterministic run" if fixed else f"[{r['lo']:.3f}, {r['hi']:.3f}]",
            )
            for r in rows
        ],
        "reasons": shown,
        "settings": _settings(ens.config, ens),
        "summary": f"{name}: ensemble of {n} members, {what}: {counts}"
        + (" (σ = 0: one deterministic run)." if fixed else "."),
    }
