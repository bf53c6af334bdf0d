"""Where the report's sweeps keep their results, so that an interrupted report resumes.

Every sweep of a stage writes its tables straight into the data folder through the sweep's
own output (``out=``): it checkpoints its finished runs as it goes (``FILE.parquet.ckpt/``),
and a resumed sweep reuses a finished output of the same configuration or finishes an
interrupted one from its checkpoint (``resume=True``; an output of another configuration,
e.g. other code, is refused by name). So ``chaoscam paper
--resume`` after a Ctrl-C, a SIGTERM or a SIGKILL redoes only the sweep that was under way,
from its checkpoint, and what is cheap (figures, single runs, the step audit) again.

:func:`store_mode` sets how the sweeps of one report treat their files; :func:`stored` gives
a sweep its output keywords.
"""

from __future__ import annotations

import contextlib
import contextvars
from pathlib import Path

__all__ = ["store_mode", "stored"]

_MODE = contextvars.ContextVar("chaoscam_paper_store", default="new")


@contextlib.contextmanager
def store_mode(*, force: bool = False, resume: bool = False):
    """Within it, :func:`stored` resumes (``resume``), starts over (``force``) or writes new
    files (neither: the report checked that none exists)."""
    token = _MODE.set("resume" if resume else "force" if force else "new")
    try:
        yield
    finally:
        _MODE.reset(token)


def stored(path: Path) -> dict:
    """The output keywords of a stage's sweep writing ``path`` (and its companion table)."""
    mode = _MODE.get()
    if mode == "resume":
        return {"out": path, "resume": True, "force": True}
    return {"out": path, "force": mode == "force"}
