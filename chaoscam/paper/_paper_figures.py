"""The drawings of the paper's Figs. 3 and 5 (the sweeps' figures are :mod:`chaoscam.report`'s).
Each builds a Matplotlib figure from a figure script's data; :func:`._drawing.draw` renders
it, on the report's drawing thread."""

from __future__ import annotations

__all__ = ["fig3_figure", "fig5_figure"]


def fig3_figure(series, mu: float, resample_dt: float):
    """Fig. 3: the line length l_λ(t) as drawn (``series``: columns t, l_lambda), a step
    plot around its mean ``mu`` [m]."""
    from matplotlib.figure import Figure

    fig = Figure(figsize=(9, 3.6), layout="constrained")
    ax = fig.subplots()
    ax.plot(series["t"], series["l_lambda"], lw=0.7, color="#0072B2", drawstyle="steps-post")
    ax.axhline(mu, color="#D55E00", ls="--", lw=0.8, label=f"μ = {mu} m")
    ax.set(
        xlabel="time t [s]",
        ylabel="contact line length l_λ [m]",
        title=f"l_λ ~ N(μ, σ²) truncated at l_min, resampled every {resample_dt} s",
    )
    ax.legend(frameon=False)
    return fig


def fig5_figure(table):
    """Fig. 5: K_n against D on a log axis, one curve per G (``table``: columns G, D,
    K_n)."""
    from matplotlib.figure import Figure

    fig = Figure(figsize=(8, 4.5), layout="constrained")
    ax = fig.subplots()
    for g, sub in table.groupby("G", sort=False):
        ax.semilogy(sub["D"], sub["K_n"], label=f"G = {g:g} m")
    ax.set(
        xlabel="fractal dimension D [-]",
        ylabel="normal stiffness K_n [N/m]",
        title="Majumdar–Bhushan joint stiffness, eqs. (15)/(17)",
    )
    ax.legend(frameon=False)
    return fig
