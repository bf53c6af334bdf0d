"""Drawings of sweeps: regime-map heatmaps (seaborn) and bifurcation diagrams.

Every function takes the tidy tables of :mod:`chaoscam.sweep` and draws on an Axes, or
returns a matplotlib ``Figure`` built without pyplot (nothing opens a window); seaborn and
matplotlib are imported inside the functions.
"""

from __future__ import annotations

import numpy as np
import pandas as pd

__all__ = ["LABEL_COLORS", "SETTLED_MARK", "TRANSIENT_MARK", "all_deterministic", "axis_label"]
__all__ += ["band_zoom", "bifurcation_figure", "mark_without_points", "percent"]
__all__ += ["plot_bifurcation"]
__all__ += ["plot_diagram"]
__all__ += ["plot_dominant", "plot_interval_width", "plot_probability", "regime_map_figure"]
__all__ += ["sweep_diagram"]

# Okabe-Ito colours: distinguishable with the common colour-vision deficiencies.
LABEL_COLORS = {
    "periodic": "#0072B2",
    "quasiperiodic": "#009E73",
    "chaotic": "#D55E00",
    "undetermined": "#BBBBBB",
    "left_reach": "#CC79A7",
    "diverged": "#000000",
}
_OTHER = "#E69F00"

LOG_AXIS_SPAN = 100.0
"""A swept value spanning more than this ratio is drawn on a log axis."""

ANNOTATION_PT = 10
"""Point size of the numbers written in heatmap cells: ~12 px at the report's width."""

ANNOTATE_CELLS = 64
"""Heatmaps with at most this many cells are annotated (larger ones would not fit the text)."""

ANNOTATE_PERIODS = 400
"""Dominant-label maps with at most this many cells get their periods written in."""

TRANSIENT_MARK = "↗"
"""Written in a dominant-label cell where a ``fate`` horizon found runs that leave the cam's
reach later (transient chaos; see :func:`chaoscam.sweep.regime_map`)."""
SETTLED_MARK = "→"
"""Before Pn in a cell where a fate horizon found runs periodic (n) on the continued run's
last half, after the recorded window its label describes."""

BAND_ZOOM = 0.02
"""A diagram zooms on a band of n-band chaos narrower than this share of its full scale."""

_SYMBOLS = {"l_lambda": "l_λ", "omega": "ω", "xi": "ξ", "beta": "β", "mu_f": "μ_f",
            "theta_f": "θ_f", "omega_f": "θ̇_f"}  # fmt: skip


def axis_label(name: str, *, role: str | None = None) -> str:
    """``"symbol (name) [unit]"`` for a parameter or a section coordinate; ``role="mean"``
    names l_lambda as the mean mu of the random line length."""
    from ..model import FIELD_DOCS

    units = {"theta_f": "rad", "omega_f": "rad/s", "t": "s", "l_lambda_used": "m"}
    unit = FIELD_DOCS[name]["unit"] if name in FIELD_DOCS else units.get(name, "")
    if name == "l_lambda" and role == "mean":
        text = "mean line length μ (l_lambda)"
    elif name == "l_lambda_sigma":
        text = "line-length spread σ (l_lambda_sigma)"
    else:
        text = f"{_SYMBOLS[name]} ({name})" if name in _SYMBOLS else name
    return f"{text} [{unit}]" if unit and unit != "-" else text


def percent(confidence: float) -> str:
    """A confidence level as the report writes it: 0.95 -> "95%"."""
    return f"{100 * confidence:.4g}%"


def _grid(cells: pd.DataFrame, x: str, y: str, values) -> pd.DataFrame:
    """``values`` (a column name, or a Series beside the cells) as a matrix: rows = y values,
    top row the largest, columns = x values."""
    if not isinstance(values, str):
        cells, values = cells.assign(_v=values), "_v"
    m = cells.pivot(index=y, columns=x, values=values)
    return m.sort_index(ascending=False).sort_index(axis=1)


def _deterministic(cells: pd.DataFrame) -> pd.Series:
    """Whether each cell is deterministic (sigma = 0: one run); False without the column."""
    if "deterministic" not in cells:
        return pd.Series(False, index=cells.index)
    return cells["deterministic"].fillna(False).astype(bool)


def all_deterministic(cells: pd.DataFrame) -> bool:
    """Whether every cell of a map is deterministic (sigma = 0: one run, no probabilities)."""
    return "deterministic" in cells and bool(cells["deterministic"].astype(bool).all())


def _heatmap(ax, m: pd.DataFrame, x: str, y: str, **kw) -> None:
    """``sns.heatmap`` of ``m`` (its NaN cells blank), with at most ~10 ticks an axis."""
    import seaborn as sns

    sns.heatmap(m, ax=ax, mask=m.isna(), **kw)
    sx, sy = max(1, m.shape[1] // 10), max(1, m.shape[0] // 10)
    xs, ys = [f"{v:.4g}" for v in m.columns[::sx]], [f"{v:.4g}" for v in m.index[::sy]]
    ax.set_xticks(np.arange(len(xs)) * sx + 0.5, xs, rotation=45, ha="right")
    ax.set_yticks(np.arange(len(ys)) * sy + 0.5, ys, rotation=0)
    role = "mean" if x == "l_lambda" and y == "l_lambda_sigma" else None
    ax.set_xlabel(axis_label(x, role=role))
    ax.set_ylabel(axis_label(y))


def plot_dominant(cells: pd.DataFrame, x: str, y: str, ax) -> None:
    """Heatmap of each cell's dominant label, with a legend of the labels present; periodic
    cells carry ``Pn`` (period n), and cells where a fate horizon saw runs leave the cam's
    reach later carry :data:`TRANSIENT_MARK`."""
    from matplotlib.colors import ListedColormap

    present = [lab for lab in cells["dominant"].unique() if lab]
    order = [lab for lab in LABEL_COLORS if lab in present]
    order += sorted(set(present) - set(LABEL_COLORS))
    code = {lab: i for i, lab in enumerate(order)}
    m = _grid(cells, x, y, cells["dominant"].map(code).astype(float))
    colors = [LABEL_COLORS.get(lab, _OTHER) for lab in order] or ["#FFFFFF"]
    annot = _dominant_text(cells, x, y, m.shape) if m.size <= ANNOTATE_PERIODS else False
    size = ANNOTATION_PT if m.size <= ANNOTATE_CELLS else ANNOTATION_PT - 2
    _heatmap(
        ax, m, x, y, cmap=ListedColormap(colors), vmin=-0.5, vmax=len(colors) - 0.5, cbar=False,
        linewidths=0.2 if m.size <= 400 else 0, linecolor="white", annot=annot, fmt="",
        annot_kws={"fontsize": size, "color": "white", "fontweight": "bold"},
    )  # fmt: skip
    for t in ax.texts:  # the arrow glyph is small at the numbers' size
        if t.get_text() == TRANSIENT_MARK:
            t.set_fontsize(1.6 * t.get_fontsize())
    shown = annot is not False and bool(np.any(np.char.startswith(annot, "P")))
    ax.set_title("dominant label (Pn: periodic, period n)" if shown else "dominant label")
    kw = dict(loc="upper left", bbox_to_anchor=(1.01, 1.0), frameon=False, fontsize="small")
    ax.legend(handles=_dominant_handles(order, annot), **kw)


def _dominant_text(cells: pd.DataFrame, x: str, y: str, shape) -> np.ndarray:
    """Each cell's text on a dominant-label map: ``Pn`` for a periodic cell,
    :data:`TRANSIENT_MARK` after it where runs stop later, ``→Pn`` where they settle."""
    text = np.full(shape, "", dtype=object)
    dom = _grid(cells, x, y, "dominant").to_numpy()

    def grid_of(name: str) -> np.ndarray:
        return _grid(cells, x, y, cells[name].astype(float)).to_numpy()

    if "period" in cells:
        per = grid_of("period")
        periodic = (dom == "periodic") & np.isfinite(per)
        text[periodic] = ["P" + str(int(v)) for v in per[periodic]]
    if "n_transient" in cells:
        later = grid_of("n_transient") > 0
        text[later] = [t + TRANSIENT_MARK for t in text[later]]
    if "settled_period" in cells:  # a transient that settles: the period it settles on
        per = grid_of("settled_period")
        late = np.isfinite(per) & (dom != "periodic")
        text[late] = [
            f"{t}{SETTLED_MARK}P{int(v)}" for t, v in zip(text[late], per[late], strict=True)
        ]
    return text.astype(str)


def _dominant_handles(order: list[str], annot) -> list:
    """The legend of a dominant-label map: a patch per label, and the marks its cells use."""
    from matplotlib.lines import Line2D
    from matplotlib.patches import Patch

    handles = [Patch(color=LABEL_COLORS.get(lab, _OTHER), label=lab) for lab in order]
    if annot is False:
        return handles
    for mark, label, used in (
        (TRANSIENT_MARK, "stops later: leaves the\ncam's reach or diverges\n(transient)",
         np.char.endswith(annot, TRANSIENT_MARK)),
        (SETTLED_MARK, "→Pn: runs periodic (n)\nlater (transient)",
         np.char.find(annot, SETTLED_MARK) >= 0),
    ):  # fmt: skip
        if np.any(used):
            handles.append(Line2D([], [], ls="", marker=f"${mark}$", color="#000000",
                                  markersize=9, label=label))  # fmt: skip
    return handles


def plot_probability(
    cells: pd.DataFrame, x: str, y: str, ax, *, label: str = "chaotic", annotate=None,
    confidence: float = 0.95,
) -> None:  # fmt: skip
    """Heatmap of P(label) per cell; ``annotate`` (None: grids of at most
    :data:`ANNOTATE_CELLS` cells) writes ``p`` and its Wilson interval ``[lo, hi]`` at the
    map's ``confidence``, which the title names."""
    m = _grid(cells, x, y, f"p_{label}")
    if annotate is None:
        annotate = m.size <= ANNOTATE_CELLS
    annot = False
    if annotate:
        p, lo, hi = (_grid(cells, x, y, f"p_{label}{s}").to_numpy() for s in ("", "_lo", "_hi"))
        det = _grid(cells, x, y, _deterministic(cells)).fillna(False).to_numpy(dtype=bool)
        text = [
            f"{a:.2f}\none run" if d else f"{a:.2f}\n[{b:.2f}, {c:.2f}]"
            for a, b, c, d in zip(p.flat, lo.flat, hi.flat, det.flat, strict=True)
        ]
        annot = np.array(text).reshape(p.shape)
    _heatmap(
        ax, m, x, y, cmap="rocket_r", vmin=0.0, vmax=1.0, annot=annot, fmt="",
        annot_kws={"fontsize": ANNOTATION_PT - 1}, cbar_kws={"label": f"P({label})"},
    )  # fmt: skip
    level = percent(confidence)
    ax.set_title(f"P({label})" + (f" with {level} Wilson interval" if annotate else ""))


def plot_interval_width(
    cells: pd.DataFrame, x: str, y: str, ax, *, label="chaotic", confidence: float = 0.95
) -> None:
    """Heatmap of the width hi - lo of the Wilson interval of P(label) (at ``confidence``).

    A deterministic cell (sigma = 0: one run) has no interval: it is left blank and marked
    "one run", not coloured as a width (a width of ~0 would read as the narrowest)."""
    det = _deterministic(cells)
    width = (cells[f"p_{label}_hi"] - cells[f"p_{label}_lo"]).mask(det)
    m = _grid(cells, x, y, width)
    _heatmap(ax, m, x, y, cmap="mako_r", vmin=0.0, vmax=1.0, cbar_kws={"label": "interval width"})
    one = _grid(cells, x, y, det).fillna(False).to_numpy(dtype=bool)
    for i, j in zip(*np.nonzero(one), strict=True):
        ax.text(j + 0.5, i + 0.5, "one run", ha="center", va="center", fontsize=ANNOTATION_PT)
    ax.set_title(f"{percent(confidence)} interval width of P({label})")


def regime_map_figure(
    cells: pd.DataFrame, *, x: str, y: str, label: str = "chaotic", confidence: float = 0.95
):
    """A regime map at the size a report shows it (~1,200 px wide, text >= 10 px there).

    Four panels: the dominant label (with periods), P(label) and P(periodic) (with Wilson
    intervals at ``confidence`` on small grids), and the interval width. A map of only
    deterministic cells (sigma = 0) has one panel: the label and period of each cell.
    """
    from matplotlib.figure import Figure

    if all_deterministic(cells):
        fig = Figure(figsize=(9.5, 6.5), layout="constrained")
        plot_dominant(cells, x, y, fig.subplots())
        return fig
    fig = Figure(figsize=(13, 10), layout="constrained")
    (a, b), (c, d) = fig.subplots(2, 2)
    plot_dominant(cells, x, y, a)
    plot_probability(cells, x, y, b, label=label, confidence=confidence)
    plot_interval_width(cells, x, y, c, label=label, confidence=confidence)
    if f"p_{label}" in cells and "p_periodic" in cells and label != "periodic":
        plot_probability(cells, x, y, d, label="periodic", confidence=confidence)
    else:
        d.set_axis_off()
    return fig


def plot_bifurcation(
    points: pd.DataFrame, ax, *, coordinate: str = "theta_f", color_by: str = "label",
    size: float | None = None,
) -> None:  # fmt: skip
    """Section points over the swept value, rasterised (tens of thousands stay light).

    ``color_by`` = "label" (the verdict), "ic" (the initial condition) or None. Several
    initial conditions per value are drawn side by side on a linear axis (each shifted by at
    most a third of the values' spacing), so that one's label does not hide another's.
    """
    param = str(points["param"].iloc[0]) if len(points) else "value"
    x = _dodged(points) if len(points) else points.get("value")
    groups = [(None, points)] if color_by is None else list(points.groupby(color_by, sort=True))
    if size is None:  # dots that stay visible for a few points and do not merge for 1e5
        size = float(np.clip(6e4 / max(len(points), 1), 0.5, 10.0))
    for key, g in groups:
        color = LABEL_COLORS.get(key, _OTHER) if color_by == "label" else None
        color = "#000000" if color_by is None else color
        ax.scatter(
            x[g.index], g[coordinate], s=size, c=color,
            marker="o", linewidths=0, rasterized=True, label=None if key is None else str(key),
        )  # fmt: skip
    ax.set_xlabel(axis_label(param) if len(points) else "value")
    ax.set_ylabel(axis_label(coordinate))
    if _log_axis(points):
        ax.set_xscale("log")  # values over several decades (a stiffness sweep)
    if color_by is not None and groups:
        scale = float(np.sqrt(40.0 / size))  # legend dots of ~40 pt² whatever the size
        ax.legend(markerscale=scale, frameon=False, fontsize="small", title=color_by)


def _log_axis(points: pd.DataFrame) -> bool:
    """Whether the swept values span more than :data:`LOG_AXIS_SPAN` (a log axis)."""
    v = points["value"].to_numpy(dtype=float) if len(points) else np.empty(0)
    return bool(v.size and v.min() > 0 and v.max() / v.min() > LOG_AXIS_SPAN)


def _dodged(points: pd.DataFrame) -> pd.Series:
    """Each point's x: its value, shifted by initial condition when there are several and
    the values are spaced for a linear axis."""
    values = np.unique(points["value"].to_numpy(dtype=float))
    ics = np.unique(points["ic"]) if "ic" in points else []
    if len(ics) < 2 or len(values) < 2 or _log_axis(points):
        return points["value"].astype(float)
    rank = pd.Series(np.arange(len(ics)), index=ics)[points["ic"]].to_numpy()
    width = np.diff(values).min() / 3.0
    return points["value"] + (rank / (len(ics) - 1) - 0.5) * width


def mark_without_points(ax, points: pd.DataFrame, verdicts: pd.DataFrame, x="value") -> bool:
    """An x on the top edge at each run of ``verdicts`` (``x``, ic, label) that left no
    section point (out of the cam's reach, diverged), labelled for the legend; True when
    there was one (the caller then draws its legend again)."""
    drawn = set(zip(points[x], points["ic"], strict=True)) if len(points) else set()
    gone = verdicts[[k not in drawn for k in zip(verdicts[x], verdicts["ic"], strict=True)]]
    if len(gone):
        what = ", ".join(sorted(set(map(str, gone["label"]))))
        ax.scatter(gone[x], [ax.get_ylim()[1]] * len(gone), marker="x", s=40, color="black",
                   clip_on=False, label=f"no section point ({what})")  # fmt: skip
    return bool(len(gone))


def plot_diagram(points, ax, *, verdicts=None, **kw):
    """:func:`plot_bifurcation` (``kw``: its options), and with the sweep's ``verdicts`` an x
    on the top edge at each run without a section point, named in the legend; returns ax."""
    plot_bifurcation(points, ax, **kw)
    if verdicts is not None and mark_without_points(ax, points, verdicts):
        scale = ax.get_legend().markerscale if ax.get_legend() else 1.0  # the diagram's dots
        title = kw.get("color_by", "label")
        ax.legend(markerscale=scale, frameon=False, fontsize="small", title=title)
    return ax


def band_zoom(points: pd.DataFrame, verdicts: pd.DataFrame | None, coordinate: str = "theta_f"):
    """The band a diagram zooms on: ``(value, ic, n, lo, hi)`` of the widest of the n bands
    of the n-band chaos run (``ev_banded_chaos`` of ``verdicts``) at the median such value,
    its points split into n bands at their n - 1 widest gaps; None when no run is n-band
    chaos or its bands are wider than :data:`BAND_ZOOM` of the diagram's range."""
    if verdicts is None or "ev_banded_chaos" not in verdicts or not len(points):
        return None
    banded = verdicts[(verdicts["label"] == "chaotic") & (verdicts["ev_banded_chaos"] > 1)]
    if not len(banded):
        return None
    row = banded.sort_values("value").iloc[len(banded) // 2]
    n = int(row["ev_banded_chaos"])
    mine = points[(points["value"] == row["value"]) & (points["ic"] == row["ic"])]
    y = np.sort(mine[coordinate].to_numpy(dtype=float))
    if len(y) < 2 * n:
        return None
    cuts = np.sort(np.argsort(np.diff(y))[len(y) - n :] + 1)  # the n - 1 widest gaps
    bands = [b for b in np.split(y, cuts) if len(b)]
    widest = max(bands, key=lambda b: b[-1] - b[0])
    lo, hi = float(widest[0]), float(widest[-1])
    full = float(points[coordinate].max() - points[coordinate].min())
    if not (0 < hi - lo < BAND_ZOOM * full):
        return None
    return float(row["value"]), int(row["ic"]), n, lo, hi


def _draw_zoom(ax, zax, points, zoom, coordinate: str, color_by: str) -> None:
    """One band of ``zoom`` (:func:`band_zoom`) drawn on ``zax`` over the nearest values,
    its place marked on the diagram ``ax``."""
    value, _, n, lo, hi = zoom
    values = np.unique(points["value"].to_numpy(dtype=float))
    at = int(np.searchsorted(values, value))
    near = values[max(0, at - 3) : at + 4]
    pad = hi - lo
    window = points[points["value"].isin(near)]
    window = window[window[coordinate].between(lo - pad, hi + pad)]
    plot_bifurcation(window, zax, coordinate=coordinate, color_by=color_by, size=14.0)
    if zax.get_legend():
        zax.get_legend().remove()
    zax.set_ylim(lo - pad, hi + pad)
    zax.ticklabel_format(axis="y", useOffset=False)
    zax.set_title(f"one of the {n} bands, zoomed:\n{hi - lo:.2g} rad wide at {value:.4g}")
    zax.set_ylabel(f"{axis_label(coordinate)}, zoomed")
    ax.indicate_inset_zoom(zax, edgecolor="#000000", alpha=0.8)


def bifurcation_figure(
    points: pd.DataFrame, *, coordinate: str = "theta_f", color_by: str = "label",
    note: str = "", verdicts: pd.DataFrame | None = None,
):  # fmt: skip
    """The bifurcation diagram of ``coordinate`` over the swept parameter, with a panel
    zoomed on one band where n-band chaos lies on bands too narrow to see at full scale
    (:func:`band_zoom`).

    ``note`` (e.g. "G = 1e-10 m") goes into the title, to tell panels of one figure apart.
    With the sweep's ``verdicts``, a run that left no section point after the transient (out
    of the cam's reach, diverged) is an x on the top edge, named in the legend.
    """
    from matplotlib.figure import Figure

    zoom = band_zoom(points, verdicts, coordinate)
    fig = Figure(figsize=(12, 5) if zoom else (9, 5), layout="constrained")
    ax, zax = fig.subplots(1, 2, width_ratios=(3, 1)) if zoom else (fig.subplots(), None)
    plot_diagram(points, ax, coordinate=coordinate, color_by=color_by, verdicts=verdicts)
    if zoom:
        _draw_zoom(ax, zax, points, zoom, coordinate, color_by)
    what = str(points["param"].iloc[0]) if len(points) else ""
    what += f" ({note})" if note else ""
    ax.set_title(f"bifurcation diagram over {what}: stroboscopic section after the transient")
    return fig


def sweep_diagram(bif, *, note: str = ""):
    """:func:`bifurcation_figure` of a finished bifurcation sweep, its verdicts marking the
    runs without a section point."""
    return bifurcation_figure(bif.points, note=note, verdicts=bif.verdicts)
