"""Results in memory: ``.plot`` on the four result types, ``to_xarray`` through netCDF,
``build_report`` without files, and ``chaoscam simulate --plot``."""

from __future__ import annotations

import sys

import matplotlib
import numpy as np
import pytest

import chaoscam
from chaoscam.cli import main
from chaoscam.sweep import Axis, bifurcation, ensemble, regime_map
from tests.sweep._helpers import SpreadClassifier

matplotlib.use("Agg")
PNG_SIGNATURE = b"\x89PNG\r\n\x1a\n"


@pytest.fixture(scope="module")
def results():
    """A run (with its series), and a tiny regime map, bifurcation diagram and ensemble (two
    initial conditions; labelled by a fast stand-in classifier)."""
    quick = dict(duration=2.0, transient=1.0, workers=1, classify=SpreadClassifier())
    return {
        "run": chaoscam.simulate(duration=3.0, transient=1.0),
        "map": regime_map(Axis("l_lambda", (0.006, 0.008)),
                          Axis("l_lambda_sigma", (0.0, 0.001)), realizations=2, **quick),
        "bif": bifurcation("l_lambda", "0.006:0.010:2", initial_conditions=2, **quick),
        "ens": ensemble(chaoscam.Params(l_lambda_sigma=0.002), members=3, **quick),
    }  # fmt: skip


KINDS = [("run", "section"), ("run", "series"), ("bif", None), ("map", "dominant"),
         ("map", "probability"), ("map", "width"), ("ens", "shares"),
         ("ens", "section")]  # fmt: skip


@pytest.mark.parametrize(("name", "kind"), KINDS)
def test_plot_returns_the_axes_it_drew_on(results, name, kind):
    """Each kind draws something on a new figure's Axes, or on the Axes it is given, and
    returns that Axes with both axes named."""
    from matplotlib import pyplot as plt
    from matplotlib.axes import Axes
    from matplotlib.figure import Figure

    kw = {} if kind is None else {"kind": kind}
    ax = results[name].plot(**kw)
    assert isinstance(ax, Axes) and ax.get_xlabel() and ax.get_ylabel()
    assert ax.collections or ax.lines or ax.patches
    plt.close(ax.figure)
    given = Figure().subplots()
    assert results[name].plot(given, **kw) is given and given.has_data()


def test_plot_refuses_what_it_cannot_draw(results):
    """An unknown kind is refused naming the kinds; a run without a series, or of several
    members, says what to do."""
    for name in ("run", "map", "ens"):
        with pytest.raises(ValueError, match="kind = 'nope'"):
            results[name].plot(kind="nope")
    with pytest.raises(ValueError, match="series=True"):
        chaoscam.simulate(duration=1.0, series=False).plot(kind="series")
    two = chaoscam.solve(chaoscam.Params(), indices=[0, 1], duration=1.0, transient=0.5)
    with pytest.raises(ValueError, match=r"use solution\[i\]"):
        two.plot()


def test_regime_map_to_xarray_round_trips_through_netcdf(results, tmp_path):
    """Dims are the map's fields, the cells' columns and each realization's label are
    variables placed at their cell, and netCDF gives the same dataset back."""
    xr = pytest.importorskip("xarray")
    rm = results["map"]
    ds = rm.to_xarray()
    assert dict(ds.sizes) == {"l_lambda": 2, "l_lambda_sigma": 2, "realization": 2}
    for row in rm.cells.to_dict("records"):
        at = ds.sel(l_lambda=row["l_lambda"], l_lambda_sigma=row["l_lambda_sigma"])
        assert str(at["dominant"].item()) == row["dominant"] and at["n"] == row["n"]
        assert at["p_chaotic"] == row["p_chaotic"]
    for row in rm.realizations.to_dict("records"):
        at = ds.sel(l_lambda=row["l_lambda"], l_lambda_sigma=row["l_lambda_sigma"])
        assert at["label"].sel(realization=row["index"]).item() == row["label"]
    assert ds.attrs["kind"] == "regime_map"
    ds.to_netcdf(tmp_path / "map.nc")
    with xr.open_dataset(tmp_path / "map.nc") as back:
        xr.testing.assert_identical(back.load(), ds)


def test_bifurcation_to_xarray_round_trips_through_netcdf(results, tmp_path):
    """Dims are the swept field, the initial condition and the point index; every section
    point is there once, each run's verdict at its (value, ic), and netCDF gives it back."""
    xr = pytest.importorskip("xarray")
    bif = results["bif"]
    ds = bif.to_xarray()
    assert set(ds.sizes) == {"l_lambda", "ic", "point"}
    np.testing.assert_array_equal(ds["l_lambda"], sorted(bif.verdicts["value"].unique()))
    assert int(ds["theta_f"].notnull().sum()) == len(bif.points)
    np.testing.assert_array_equal(np.sort(ds["theta_f"].values[ds["theta_f"].notnull().values]),
                                  np.sort(bif.points["theta_f"].to_numpy()))  # fmt: skip
    for row in bif.verdicts.to_dict("records"):
        assert ds["label"].sel(l_lambda=row["value"], ic=row["ic"]).item() == row["label"]
    ds.to_netcdf(tmp_path / "bif.nc")
    with xr.open_dataset(tmp_path / "bif.nc") as back:
        xr.testing.assert_identical(back.load(), ds)


def test_to_xarray_without_xarray_names_the_extra(results, monkeypatch):
    """Without xarray installed the error says which extra installs it."""
    monkeypatch.setitem(sys.modules, "xarray", None)  # import xarray now raises ImportError
    for name in ("map", "bif"):
        with pytest.raises(ImportError, match=r"chaoscam\[xarray\]"):
            results[name].to_xarray()


def test_build_report_takes_results_in_memory(results, tmp_path):
    """Results in memory (mixed with a path) fill every section, each named by its kind and
    place; the report is written."""
    from chaoscam.report import build_report, write_report

    results["run"].to_parquet(tmp_path / "run.parquet")
    r = results
    parts = build_report([r["map"], r["bif"], r["ens"], r["run"], tmp_path / "run.parquet"])
    assert (len(parts.regime_maps), len(parts.bifurcations), len(parts.ensembles)) == (1, 1, 1)
    # one run given twice: one panel, standing for both runs
    assert len(parts.responses) == 1 and len(parts.responses[0]["runs"]) == 2
    assert len(parts.evidence) == 2 and not parts.missing
    assert parts.listing[0].startswith("regime map 1:")
    assert {p["source"] for p in parts.provenance} >= {"run 4", str(tmp_path / "run.parquet")}
    out = write_report(parts, tmp_path / "r.html", title="in memory")
    assert out.read_text().count("data:image/png;base64,") >= 4


def test_simulate_plot_writes_a_png(tmp_path, capsys):
    """``--plot FILE.png`` writes the run's figure; an existing one is kept without --force;
    another suffix is refused."""
    png = tmp_path / "run.png"
    args = ["simulate", "--duration", "1.5", "--transient", "0.5", "--plot", str(png)]
    assert main(args) == 0
    assert (
        png.read_bytes().startswith(PNG_SIGNATURE) and f"figure: {png}" in capsys.readouterr().out
    )
    assert main(args) == 2 and "--force" in capsys.readouterr().err
    assert main([*args[:-1], str(tmp_path / "run.jpg")]) == 2
