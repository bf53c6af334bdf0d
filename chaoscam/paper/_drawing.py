"""The report's figures, drawn on one thread while the next sweep runs (``chaoscam paper``).

A stage hands each figure to :func:`draw` as the function that builds it and its arguments.
Inside :func:`drawing` (what :func:`._run.run_paper` opens around its stages) the figure is
built, rendered and written on one drawing thread, and :func:`draw` returns a
:class:`Drawing` at once, so the stage goes on to its next sweep meanwhile, and the next
stage after it; :func:`settle` swaps every drawing of a stage's result for its PNG once every
stage has run, raising a drawing's error there (the stage then fails, as if it had drawn the
figure itself). Outside it (the ``analyses/`` scripts, the tests) :func:`draw` draws at once
and returns the PNG.

All of a report's Matplotlib work goes through :func:`draw`, so one thread does it all:
Matplotlib is not thread-safe, and the figures are built there too, not only rendered.
Rendering is single-threaded Python (about 0.5 s a figure, 20 figures in the quick report),
which the sweeps' threads would otherwise wait for between sweeps.
"""

from __future__ import annotations

import contextlib
import contextvars
import dataclasses
from collections.abc import Callable, Iterator
from concurrent.futures import Future, ThreadPoolExecutor
from pathlib import Path
from typing import Any

__all__ = ["Drawing", "draw", "drawing", "png_of", "settle", "uri_of"]

_DRAWER: contextvars.ContextVar[ThreadPoolExecutor | None] = contextvars.ContextVar(
    "chaoscam_drawer", default=None
)
"""The drawing thread of the :func:`drawing` block this thread is in (None outside one; a
new thread starts outside)."""


@dataclasses.dataclass(frozen=True)
class Drawing:
    """A figure under way on the drawing thread; :func:`png_of` waits for its PNG."""

    future: Future


def _draw_now(path: Path, dpi: int, build: Callable, args: tuple, kwargs: dict) -> bytes:
    """Build the figure, render it once at ``dpi`` and write it to ``path`` (atomically);
    returns the PNG, which the report embeds as it is."""
    from ..io import atomic_write_bytes
    from ..report import png_bytes

    png = png_bytes(build(*args, **kwargs), dpi=dpi)
    atomic_write_bytes(path, png)
    return png


def draw(path: Path, build: Callable, *args: Any, dpi: int = 110, **kwargs: Any):
    """The figure ``build(*args, **kwargs)`` rendered to ``path``: its PNG (bytes), or inside
    :func:`drawing` a :class:`Drawing` of it, drawn on the drawing thread. ``build`` and its
    arguments must not change until the drawing is settled (the sweeps' results are
    frozen)."""
    pool = _DRAWER.get()
    if pool is None:
        return _draw_now(Path(path), dpi, build, args, kwargs)
    return Drawing(pool.submit(_draw_now, Path(path), dpi, build, args, kwargs))


@contextlib.contextmanager
def drawing() -> Iterator[None]:
    """A block whose :func:`draw` calls draw on one thread beside it. On the way out (an
    error or Ctrl-C included) the drawings not begun are dropped and the one under way is
    waited for (under a second), so no thread outlives the block."""
    pool = ThreadPoolExecutor(1, thread_name_prefix="chaoscam-draw")
    token = _DRAWER.set(pool)
    try:
        yield
    finally:
        _DRAWER.reset(token)
        pool.shutdown(wait=True, cancel_futures=True)


def png_of(png) -> bytes:
    """The PNG of ``png``: bytes as they are, a :class:`Drawing` once it is drawn (its
    error raised here)."""
    return png.future.result() if isinstance(png, Drawing) else png


def uri_of(png):
    """A figure's data URI for a :class:`chaoscam.report.FigureItem`: now for a PNG, at
    :func:`settle` for a :class:`Drawing` (which stands in the item until then)."""
    from ..report import png_uri

    return png if isinstance(png, Drawing) else png_uri(png)


def settle(result) -> None:
    """Wait for the drawings of ``result`` (a :class:`._stage.FigureResult`) and put their
    PNGs (and the figure items' URIs) in their place, in place."""
    from ..report import png_uri

    for name in ("bifurcations", "regime_maps", "trajectories"):
        rows = getattr(result, name)
        rows[:] = [(path, found, png_of(png), *rest) for path, found, png, *rest in rows]
    for name in ("figures", "why_figures"):
        items = getattr(result, name)
        items[:] = [
            dataclasses.replace(item, uri=png_uri(png_of(item.uri)))
            if isinstance(item.uri, Drawing)
            else item
            for item in items
        ]
