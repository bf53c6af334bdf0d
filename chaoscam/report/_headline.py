"""The report's answer: verdicts in words ("period 8", "8-band chaos"), their tallies, the
headline computed from them (which regimes occur where), and long texts folded."""

from __future__ import annotations

import re
from collections import Counter

import pandas as pd

__all__ = ["band_counts", "band_number", "fold", "frame_tags", "headline", "in_words"]
__all__ += ["mostly", "verdict_tag"]

WORDS = {"left_reach": "out of the cam's reach", "diverged": "diverged (the state left the model)"}
"""Labels that a sentence says in other words."""

_SENTENCE = r"(?<!\bFig)(?<!\bFigs)(?<!\bEq)(?<!\be\.g)(?<!\bi\.e)\. "  # not "Figs. 7"

FOLD_AT = 240
"""A text longer than this many characters is shown by its head, the rest folded."""


def band_number(label, period, bands=None) -> int | None:
    """n of a motion on n narrow bands (a period, or ``ev_banded_chaos``); None for others."""
    if label == "periodic" and period is not None and pd.notna(period):
        return int(period)
    if label == "chaotic" and bands is not None and pd.notna(bands) and bands > 1:
        return int(bands)
    return None


def verdict_tag(label, period, bands=None) -> str:
    """A verdict in a finding's words: "period 8", "8-band chaos", else the label."""
    n = band_number(label, period, bands)
    if n is None:
        return str(label)
    return f"period {n}" if label == "periodic" else f"{n}-band chaos"


def band_counts(v: pd.DataFrame):
    """The band counts of a verdict table (None where it has no ``ev_banded_chaos``)."""
    return v["ev_banded_chaos"] if "ev_banded_chaos" in v else [None] * len(v)


def frame_tags(v: pd.DataFrame) -> list[str]:
    """:func:`verdict_tag` of every row of a verdict table (label, period, bands)."""
    period = v["period"] if "period" in v else [None] * len(v)
    return [verdict_tag(*t) for t in zip(v["label"], period, band_counts(v), strict=True)]


def _and(items: list[str]) -> str:
    return items[0] if len(items) == 1 else ", ".join(items[:-1]) + " and " + items[-1]


def in_words(tags, what: str = "runs", most: int = 4, notes: dict | None = None) -> str:
    """A tally of verdict tags, commonest first: "Of the 5 runs, 3 are 8-band chaos, 1 is
    period 8 and 1 is undetermined" (at most ``most`` tags, the rest counted together;
    ``notes``: text after a tag)."""
    counts = Counter(WORDS.get(t, t) for t in tags).most_common()
    n, notes = sum(k for _, k in counts), notes or {}
    shown = [f"{k} {'is' if k == 1 else 'are'} {t}{notes.get(t, '')}" for t, k in counts[:most]]
    if rest := sum(k for _, k in counts[most:]):
        shown.append(f"{rest} {'is' if rest == 1 else 'are'} of {len(counts) - most} other kinds")
    return f"Of the {n} {what}, {_and(shown)}" if shown else f"No {what}"


def mostly(tags, what: str = "runs") -> str:
    """The commonest tag and its share, and the next: "8-band chaos in 23 of 25 runs,
    chaotic in 2"."""
    counts = Counter(WORDS.get(t, t) for t in tags).most_common()
    if not counts:
        return f"no {what}"
    (top, k), n = counts[0], sum(k for _, k in counts)
    text = f"{top} in {k} of {n} {what}"
    return text + (f", {counts[1][0]} in {counts[1][1]}" if len(counts) > 1 else "")


def fold(text: str, limit: int = FOLD_AT) -> tuple[str, str]:
    """``text`` as (head, rest): whole when short, else cut after its first sentence, clause
    or word within ``limit`` characters (the report shows the head, the rest folded)."""
    if len(text) <= limit:
        return text, ""
    for mark in (_SENTENCE, "; ", ": ", " "):
        ends = [m.end() for m in re.finditer(mark, text[:limit]) if m.start() >= 12]
        if ends:
            return text[: ends[-1]].rstrip(), text[ends[-1] :]
    return text[:limit], text[limit:]


def headline(found: list[dict]) -> list[str]:
    """The answer of a report of one's own results (``found``: per input its ``name``,
    ``what``, the ``tags`` of its verdicts (a map's: its cells') and their ``unit``, and a
    map's ``runs``: its realizations' tags): the regimes of all runs, then where each input's
    commonest regime lies."""
    if not found:
        return []
    tags = [t for f in found for t in f.get("runs", f["tags"])]
    units = {"run" if f["unit"] == "run" else f["unit"] for f in found if "runs" not in f}
    unit = "members" if units == {"members"} else "runs"
    where = [f"{f['name']} ({f['what']}): {mostly(f['tags'], f['unit'])}" for f in found[:4]]
    more = f"; {len(found) - 4} more below" if len(found) > 4 else ""
    first = in_words(tags, f"{unit} given") + "."
    band = next((t for t, _ in Counter(tags).most_common(1) if t.endswith("-band chaos")), None)
    if band:
        n = band.split("-")[0]
        first += f" {band.capitalize()} is chaos on {n} narrow bands: at full scale it looks "
        first += f"like period {n} (the diagrams zoom on a band)."
    return [first, "Where: " + "; ".join(where) + more + "."]
