"""A stage's independent single runs side by side on the local cores.

The report's single trajectories (Figs. 7–10's six responses) spend their time in the
compiled kernel, which runs without the GIL (:func:`chaoscam.integrate._driver.run_one`), so
threads of this process run them on every core, each the same bits as alone. One after
another they left a core idle for about a second of the quick report.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from typing import Any

__all__ = ["side_by_side"]


def side_by_side(fn: Callable[[Any], Any], items: Sequence[Any], workers=None) -> list[Any]:
    """``[fn(x) for x in items]``, computed on up to ``workers`` threads (every core when
    None; :func:`chaoscam.sweep.local_workers` checks it), in the order of ``items``: the
    ensemble verdicts' thread pool (:func:`chaoscam._ensemble_verdicts._threaded`, each call
    in a copy of this thread's context).

    The first error (or a Ctrl-C in the calling thread) is raised once the runs under way
    have ended; the runs not begun are dropped. Each is a single trajectory, so that takes
    under a second in the report.
    """
    from .._ensemble_verdicts import _threaded
    from ..sweep._backends import local_workers

    return _threaded(fn, list(items), local_workers(workers), prefix="chaoscam-side")[0]
