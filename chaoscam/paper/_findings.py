"""The words of the findings: verdicts turned into the tags and runs a sentence quotes.

Shared by the sensitivity sweeps (:mod:`._sensitivity`) and the sweeps over what the paper
leaves open (:mod:`._choices`); nothing here computes a result.
"""

from __future__ import annotations

import pandas as pd

__all__ = [
    "band_counts",
    "band_number",
    "first_ic",
    "frame_tags",
    "label_runs",
    "paper_regimes",
    "regimes",
    "runs_text",
    "step_finding",
    "verdict_tag",
]


def band_number(label, period, bands=None) -> int | None:
    """n of a motion on n narrow bands: a periodic verdict's period, or the band count of a
    chaotic one on narrow bands (``ev_banded_chaos``); None for any other verdict."""
    if label == "periodic" and period is not None and pd.notna(period):
        return int(period)
    if label == "chaotic" and bands is not None and pd.notna(bands) and bands > 1:
        return int(bands)
    return None


def verdict_tag(label, period, bands=None) -> str:
    """A verdict in a finding's words: "period 8" for a periodic one with its period, "8-band
    chaos" for a chaotic one whose section lies on 8 narrow bands (``ev_banded_chaos``), else
    the label ("chaotic", "undetermined", "left_reach", ...)."""
    n = band_number(label, period, bands)
    if n is None:
        return str(label)
    return f"period {n}" if label == "periodic" else f"{n}-band chaos"


def band_counts(v: pd.DataFrame):
    """The band counts of a verdict table (None where it has no ``ev_banded_chaos``)."""
    return v["ev_banded_chaos"] if "ev_banded_chaos" in v else [None] * len(v)


def frame_tags(v: pd.DataFrame) -> list[str]:
    """:func:`verdict_tag` of every row of a verdict table (label, period, bands)."""
    return [verdict_tag(*t) for t in zip(v["label"], v["period"], band_counts(v), strict=True)]


def label_runs(values, labels, periods, bands=None) -> list[tuple[str, float, float]]:
    """Consecutive equal tags (:func:`verdict_tag`) along sorted values:
    [(text, first, last), ...]."""
    out: list[tuple[str, float, float]] = []
    bands = [None] * len(labels) if bands is None else bands
    for v, lab, per, nb in zip(values, labels, periods, bands, strict=True):
        t = verdict_tag(lab, per, nb)
        if out and out[-1][0] == t:
            out[-1] = (t, out[-1][1], float(v))
        else:
            out.append((t, float(v), float(v)))
    return out


def runs_text(runs, fmt="{:.3g}") -> str:
    parts = []
    for t, a, b in runs:
        span = fmt.format(a) if a == b else f"{fmt.format(a)}–{fmt.format(b)}"
        parts.append(f"{t} ({span})")
    return " → ".join(parts)


def regimes(tags) -> list[str]:
    """The distinct regimes among tags, in order, leaving "undetermined" out (it is no
    regime: the evidence did not decide)."""
    return [t for t in dict.fromkeys(tags) if t != "undetermined"]


def paper_regimes(found: list[str], where: str) -> str:
    """The clause saying whether the paper's period 2 or a quasiperiodic motion is among the
    regimes ``found`` (``where``: "there", "among them")."""
    paper = [t for t in ("period 2", "quasiperiodic") if t in found]
    if not paper:
        return f"; neither the paper's period 2 nor a quasiperiodic motion appears {where}."
    return f"; the paper's {' and '.join(paper)} appear{'s' * (len(paper) == 1)} {where}."


def step_finding(rows: pd.DataFrame, where) -> str:
    """The sentence on the step check of one sweep's runs (``rows`` with ``ev_step_check``:
    1 kept, 0 changed, empty when not checked): how many verdicts were checked, and where
    they changed (``where(row)`` names a run). Empty when no run was checked."""
    if "ev_step_check" not in rows or not rows["ev_step_check"].notna().any():
        return ""
    checked = rows[rows["ev_step_check"].notna()]
    changed = checked[checked["ev_step_check"] == 0]
    held = len(checked) - len(changed)
    head = f" Checked at half the step, {held} of {len(checked)} " + (
        "verdict holds" if len(checked) == 1 else "verdicts hold"
    )
    if not len(changed):
        return head + "."
    one = len(changed) == 1
    runs = ", ".join(map(where, changed.itertuples()))
    return head + (
        f"; {len(changed)} change{'s' * one} there and {'is' if one else 'are'} undetermined "
        f"({runs})."
    )


def first_ic(bif) -> pd.DataFrame:
    return bif.verdicts[bif.verdicts["ic"] == 0].sort_values("value")
