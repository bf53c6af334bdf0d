"""What a stage of ``chaoscam paper`` returns, how it saves its files (each figure drawn on one
thread while the next sweep runs: inside :func:`drawing`, :func:`draw` returns a
:class:`Drawing` that :func:`settle` swaps for its PNG once every stage has run), where its
sweeps keep their results (so that an interrupted report resumes), and shared settings."""

from __future__ import annotations

import contextlib
import contextvars
import dataclasses
from collections.abc import Callable, Iterator
from concurrent.futures import Future, ThreadPoolExecutor
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from .. import sweep
from ..io import atomic_write_bytes
from ..report import png_uri, regime_map_figure, sweep_diagram

QUICK_EXTEND_TO, FULL_EXTEND_TO = 40.0, 120.0
"""Recorded time [s] the quick and full reports extend undetermined runs to (quick Fig. 6: none)."""

RUN = {"duration": 20.0, "transient": 10.0}  # the run of every sweep but Fig. 6's quick one [s]

FATE_S = {True: 100.0, False: 300.0}
"""The fate horizon [s] of the ξ sweep and the (ω, ξ) map (quick, full): whether runs not
periodic stay in the cam's reach ((42.5 rad/s, 0.40) is chaotic for 229 s, then leaves)."""

SWEEP_FATE_S = {True: None, False: FATE_S[False]}
"""The fate horizon [s] of Fig. 4 and the other sensitivity diagrams, full report only (of 245
chaotic verdicts 5 are transient: analyses/fate_audit.py; Figs. 6 and 7-10: none, hours)."""


def judging(quick: bool, *, check_step: bool = False) -> dict[str, Any]:
    """The sweeps' verdict keywords (``extend_to``: :data:`QUICK_EXTEND_TO` or ``FULL_...``)."""
    return {"extend_to": QUICK_EXTEND_TO if quick else FULL_EXTEND_TO, "check_step": check_step}


@dataclass
class FigureResult:
    """What one stage produced: FigureItems, Comparisons, (data file, sweep, PNG) of its diagrams
    and maps, (data file, run, PNG, verdict) of its runs, and the findings (``why``)."""

    number: int
    title: str = ""
    figures: list[Any] = field(default_factory=list)
    comparisons: list[Any] = field(default_factory=list)
    bifurcations: list[tuple[str, Any, bytes]] = field(default_factory=list)
    regime_maps: list[tuple[str, Any, bytes]] = field(default_factory=list)
    trajectories: list[tuple[str, Any, bytes, Any]] = field(default_factory=list)
    why: list[str] = field(default_factory=list)
    why_figures: list[Any] = field(default_factory=list)
    seconds: float = 0.0

    @property
    def name(self) -> str:
        return self.title or f"Fig. {self.number}"


_DRAWER: contextvars.ContextVar[ThreadPoolExecutor | None] = contextvars.ContextVar(
    "chaoscam_drawer", default=None
)


Drawing = Future  # a figure under way on the drawing thread: png_of waits for its PNG


def _draw_now(path: Path, dpi: int, build: Callable, args: tuple, kwargs: dict) -> bytes:
    from ..report import png_bytes

    png = png_bytes(build(*args, **kwargs), dpi=dpi)
    atomic_write_bytes(path, png)
    return png


def draw(path: Path, build: Callable, *args: Any, dpi: int = 110, **kwargs: Any):
    """``build(*args, **kwargs)`` rendered to ``path``: its PNG, or in :func:`drawing` a Drawing."""
    pool = _DRAWER.get()
    if pool is None:
        return _draw_now(Path(path), dpi, build, args, kwargs)
    return pool.submit(_draw_now, Path(path), dpi, build, args, kwargs)


@contextlib.contextmanager
def drawing() -> Iterator[None]:
    """A block whose :func:`draw` calls draw on one thread beside it (none outlives it)."""
    pool = ThreadPoolExecutor(1, thread_name_prefix="chaoscam-draw")
    token = _DRAWER.set(pool)
    try:
        yield
    finally:
        _DRAWER.reset(token)
        pool.shutdown(wait=True, cancel_futures=True)


def png_of(png) -> bytes:
    """PNG bytes as they are, a :class:`Drawing`'s once drawn (its error raised here)."""
    return png.result() if isinstance(png, Drawing) else png


def uri_of(png):
    """A FigureItem's data URI: now for a PNG; a :class:`Drawing` stands in until settled."""
    return png if isinstance(png, Drawing) else png_uri(png)


def settle(result) -> None:
    """Put the PNGs of ``result``'s drawings, and its figure items' URIs, in their place."""
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


def swept(res, outdir: Path, stem: str, *args, kind="bifurcation", png="", note="", **kw):
    """``chaoscam.sweep.<kind>(*args, **kw)`` written to ``outdir/stem.parquet``, its figure saved
    as ``png`` (default ``stem``; None: none, and not added to ``res``) and added to ``res``."""
    path = outdir / f"{stem}.parquet"
    force, resume = _STORE.get()
    found = getattr(sweep, kind)(*args, **kw, out=path, force=force, resume=resume)
    if png is not None and kind == "regime_map":
        target = outdir / f"{png or stem}.png"
        drawn = draw(target, regime_map_figure, found.cells, x=found.x, y=found.y)
        res.regime_maps.append((str(path), found, drawn))
    elif png is not None:
        drawn = draw(outdir / f"{png or stem}.png", sweep_diagram, found, note=note)
        res.bifurcations.append((str(path), found, drawn))
    return found


_STORE = contextvars.ContextVar("chaoscam_paper_store", default=(False, False))


@contextlib.contextmanager
def store_mode(*, force: bool = False, resume: bool = False):
    """Within it, :func:`swept` resumes (a finished output of the same configuration reused, an
    interrupted one finished from its checkpoint), starts over (``force``) or writes new files."""
    token = _STORE.set((force or resume, resume))
    try:
        yield
    finally:
        _STORE.reset(token)
