"""The one loop that drives a single trajectory through the compiled kernel.

The kernel (:func:`._ensemble.run_one` → :func:`._advance.advance`) advances until the end
step or until an output buffer or the line-length draws need attention, and returns
``NEED_BUFFER`` then. :func:`drive` is the loop every single-trajectory caller goes
through (``chaoscam.simulate``, the periodic-orbit shooting of :mod:`chaoscam.tangent`, the
two-trajectory exponent of :mod:`chaoscam.lyapunov`): it hands the filled rows of each buffer
to the caller, resets the buffer, asks the caller for draws when they run short, and calls
the kernel again. A resumed call is bit-identical to one that was not interrupted (the
kernel keeps everything it needs in ``y`` and ``cnt``), so how often the loop pauses does
not change a result.

The ensemble paths run many members per call (:func:`._ensemble._run_on_cpu`,
:func:`._gpu.run_on_gpu`); their loops differ in what they keep per member, not in the
kernel they call.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from . import _kernel as k
from ._ensemble import run_one

__all__ = ["Buffers", "drive"]

_OUTPUTS = (("series", k.I_N_SERIES), ("section", k.I_N_SECTION), ("impacts", k.I_N_IMPACT))


@dataclass
class Buffers:
    """The kernel's output buffers for one trajectory: rows of ``SERIES_COLS``,
    ``SECTION_COLS`` and ``IMPACT_COLS`` columns (a series of one row when none is kept)."""

    series: np.ndarray
    section: np.ndarray
    impacts: np.ndarray

    @classmethod
    def empty(cls, series_rows: int, section_rows: int, impact_rows: int) -> Buffers:
        return cls(
            np.empty((max(series_rows, 1), k.SERIES_COLS)),
            np.empty((section_rows, k.SECTION_COLS)),
            np.empty((impact_rows, k.IMPACT_COLS)),
        )


def drive(
    y: np.ndarray,
    cnt: np.ndarray,
    c: np.ndarray,
    n_stop: int,
    lam: np.ndarray,
    buffers: Buffers,
    *,
    on_rows: Callable[[str, np.ndarray], None],
    more_draws: Callable[[np.ndarray], np.ndarray],
    run: Callable[..., int] = run_one,
) -> int:
    """Advance one trajectory (``y``, ``cnt``, ``c``) to grid step ``n_stop``; returns the
    kernel's final status code.

    ``on_rows(name, rows)`` receives each buffer's filled rows ("series", "section",
    "impacts"; a view, to be copied if kept) after every kernel call, and the buffer is
    emptied. When the kernel stops for room, ``more_draws(lam)`` returns the draws to go on
    with, and must leave ``cnt[I_LAM_POS]`` pointing at the draw in use in them. ``run`` is
    the compiled call (:func:`._ensemble.run_one`; the two-trajectory exponent passes
    :func:`._advance.advance`, the same kernel without the one-member batch).
    """
    while True:
        t_before, pos_before = y[k.Y_TIME], cnt[k.I_LAM_POS]
        code = run(y, cnt, c, n_stop, lam, buffers.series, buffers.section, buffers.impacts)
        filled = False
        for name, i in _OUTPUTS:
            if cnt[i]:
                on_rows(name, getattr(buffers, name)[: cnt[i]])
                cnt[i] = 0
                filled = True
        if code != k.NEED_BUFFER:
            return int(code)
        if not filled and y[k.Y_TIME] == t_before and cnt[k.I_LAM_POS] == pos_before == 0:
            raise RuntimeError("internal: the kernel asked for buffers but made no progress")
        lam = more_draws(lam)
