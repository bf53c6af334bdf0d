"""Figures of single runs (paper Figs. 7-10) and the PNG data URIs the HTML embeds.

matplotlib's object API (no pyplot: nothing opens a window, the Agg canvas renders); scatter
layers are rasterised so that thousands of points stay light.
"""

from __future__ import annotations

import base64
import io

import numpy as np

from ..plot import (  # the report's face names the sweeps' figures, drawn in chaoscam.plot
    LABEL_COLORS,
    SETTLED_MARK,
    TRANSIENT_MARK,
    bifurcation_figure,
    mark_without_points,
    regime_map_figure,
    sweep_diagram,
)

__all__ = ["LABEL_COLORS", "SETTLED_MARK", "TRANSIENT_MARK", "bifurcation_figure"]
__all__ += ["mark_without_points", "png_bytes", "png_uri", "regime_map_figure"]
__all__ += ["response_figure", "sweep_diagram"]


def png_bytes(fig, dpi: int = 96) -> bytes:
    """The figure rendered to PNG bytes with the Agg canvas."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg

    FigureCanvasAgg(fig)
    buf = io.BytesIO()
    fig.savefig(buf, format="png", dpi=dpi)
    return buf.getvalue()


def png_uri(png: bytes) -> str:
    """``data:image/png;base64,...`` of PNG bytes (:func:`png_bytes`), for an ``<img src>``
    that needs no network."""
    return "data:image/png;base64," + base64.b64encode(png).decode("ascii")


def response_figure(run, title: str = ""):
    """Four panels of one run (a one-member :class:`chaoscam.Solution`): θ_f and θ_fc over
    the last 2 s of the kept series, the phase portrait of the whole series, the stroboscopic
    section at t = k 2π/ω, and the periodogram of θ_f
    (:func:`chaoscam.analysis.power_spectrum`) with the cam frequency ω/2π marked."""
    from matplotlib.figure import Figure

    from ..analysis import power_spectrum
    from ..plot import axis_label, plot_section, plot_series

    fig = Figure(figsize=(11, 7.5), layout="constrained")
    (a, b), (c, d) = fig.subplots(2, 2)
    s, sec = run.series, run.section
    f_cam = run.params.omega / (2 * np.pi)
    if s is not None and len(s) > 2:
        plot_series(s, a, last=2.0)
        b.plot(s["theta_f"], s["omega_f"], lw=0.3, color="#555555", rasterized=True)
        f, pw = power_spectrum(s["theta_f"].to_numpy(), float(s["t"].diff().median()))
        keep = (f > 0) & (f <= 10 * f_cam)
        d.semilogy(f[keep], pw[keep] + 1e-300, lw=0.7, color="#0072B2")
        d.axvline(f_cam, color="#D55E00", lw=0.8, ls=":", label=f"cam ω/2π = {f_cam:.3g} Hz")
        d.legend(frameon=False, fontsize="small")
    else:
        for ax in (a, b, d):
            ax.text(
                0.5, 0.5, "no time series kept", ha="center", va="center", transform=ax.transAxes
            )
    plot_section(sec, c)
    b.set(xlabel=axis_label("theta_f"), ylabel=axis_label("omega_f"), title="phase portrait")
    d.set(xlabel="frequency [Hz]", ylabel="power of θ_f [rad²·s, arbitrary scale]",
          title="spectrum of θ_f")  # fmt: skip
    if title:
        fig.suptitle(title)
    return fig
