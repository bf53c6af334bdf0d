"""Suggestions for a misspelt name (a parameter, a keyword)."""

from __future__ import annotations

__all__ = ["close_names", "unknown_message"]


def close_names(name: str, names) -> list[str]:
    """Up to three of ``names`` close to ``name``: the same but for case first (OMEGA ->
    omega), then by difflib's similarity."""
    import difflib

    same = [n for n in names if n.lower() == name.lower() and n != name]
    close = difflib.get_close_matches(name, list(names), n=3)
    return list(dict.fromkeys(same + close))[:3]


def unknown_message(name: str, names) -> str:
    """The refusal of an unknown parameter name, with what it was probably meant to be."""
    close = close_names(name, names)
    hint = f" Did you mean {', '.join(close)}?" if close else ""
    return f"unknown parameter {name!r}.{hint} Known: {', '.join(names)}"
