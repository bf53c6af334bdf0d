"""One run's series θ_f(t) and stroboscopic section, and an ensemble's label shares, drawn on
a matplotlib Axes (a new pyplot figure's when none is given)."""

from __future__ import annotations

import numpy as np

from ._sweep import _OTHER, LABEL_COLORS, axis_label

__all__ = ["axes", "plot_section", "plot_series", "plot_shares"]


def axes(ax=None):
    """``ax``, else the Axes of a new pyplot figure (shown by a notebook or ``plt.show()``)."""
    if ax is None:
        import matplotlib.pyplot as plt

        ax = plt.figure(layout="constrained").add_subplot()
    return ax


def _color(label: str) -> str:
    return LABEL_COLORS.get(str(label).partition(" ")[0], _OTHER)


def plot_series(series, ax, *, last: float | None = None):
    """θ_f [rad] (solid) and θ_fc, the persistent-contact angle (dashed), over time t [s] of
    one member's series (``Solution.series``), its last ``last`` seconds when given."""
    if last is not None:
        series = series[series["t"] >= series["t"].iloc[-1] - last]
    ax.plot(series["t"], series["theta_f"], lw=0.8, color="#0072B2", label="θ_f (follower)")
    ax.plot(series["t"], series["theta_fc"], lw=0.8, ls="--", color="#D55E00",
            label="θ_fc (persistent contact)")  # fmt: skip
    ax.legend(frameon=False, fontsize="small", loc="upper right")
    title = "θ_f and θ_fc" + (f", last {last:g} s" if last is not None else "")
    ax.set(xlabel="time t [s]", ylabel="angle [rad]", title=title)
    return ax


def plot_section(section, ax, *, labels=None, order=None):
    """The stroboscopic section (θ_f [rad], θ̇_f [rad/s]) at t = k 2π/ω: black dots, or
    coloured by ``labels`` (one per row, e.g. each member's verdict), the legend in ``order``
    (default: sorted); the dots shrink as the points grow in number."""
    if labels is None:
        ax.scatter(section["theta_f"], section["omega_f"], s=6, color="#000000", linewidths=0,
                   rasterized=True)  # fmt: skip
    elif len(section):
        size = float(np.clip(3e4 / len(section), 0.3, 6.0))
        labels = np.asarray(labels, dtype=object)
        for key in order or sorted(set(labels)):
            g = section[labels == key]
            ax.scatter(g["theta_f"], g["omega_f"], s=size, c=_color(key), linewidths=0,
                       rasterized=True)  # fmt: skip
            ax.scatter([], [], s=30, c=_color(key), label=key)
        ax.legend(frameon=False, fontsize="small")
    ax.set(xlabel=axis_label("theta_f"), ylabel=axis_label("omega_f"),
           title=f"Poincaré section at t = k·2π/ω ({len(section)} points)")  # fmt: skip
    return ax


def plot_shares(rows, ax, *, interval: bool = True):
    """Bars of each label's share (rows of ``chaoscam.sweep.label_shares``: label, count,
    share, lo, hi) with the count above, and its Wilson interval when ``interval``."""
    x = np.arange(len(rows))
    share = np.array([r["share"] for r in rows])
    colors = [_color(r["label"]) for r in rows]
    if interval:
        err = np.array([share - [r["lo"] for r in rows], [r["hi"] for r in rows] - share])
        ax.bar(x, share, color=colors, yerr=err, capsize=4)
        ax.set_title("share of members, 95 % Wilson interval")
    else:
        ax.bar(x, share, color=colors)
        ax.set_title("share of members (one deterministic run)")
    for xi, r in zip(x, rows, strict=True):
        ax.text(xi, max(r["hi"], r["share"]) + 0.03, str(r["count"]), ha="center", fontsize=10)
    ax.set_xticks(x, [r["label"] for r in rows], rotation=30, ha="right")
    ax.set(ylim=(0, 1.12), xlabel="label", ylabel="share of members")
    return ax
