"""Arguments of the Python API that were accepted and ignored, or failed deep inside numpy
or pandas (found by an API review): each now gives an error naming the argument, or does
what it says."""

import math

import numpy as np
import pytest

import chaoscam
from chaoscam import Numerics, ParameterError, Params
from chaoscam.sweep import SweepError, bifurcation, regime_map


@pytest.mark.parametrize(
    "ic",
    [[(1, 2, 3)], [(0.1,)], [0.1, 0.2], [("a", 1)], [(math.nan, 0.0)], "abc", 2.5, True],
)
def test_a_malformed_initial_condition_is_named(ic):
    with pytest.raises(SweepError, match="initial_conditions"):
        bifurcation("xi", [0.2], initial_conditions=ic, duration=1.0, workers=1)


@pytest.mark.parametrize("sweep", ["bifurcation", "regime_map"])
def test_a_sweeps_base_must_be_params(sweep):
    run = {
        "bifurcation": lambda base: bifurcation("xi", [0.2], base=base, duration=1.0),
        "regime_map": lambda base: regime_map("xi=0.2:0.3:2", "omega=25:30:2", base=base),
    }[sweep]
    with pytest.raises(TypeError, match=r"base must be a chaoscam.Params, got a dict: use Params"):
        run({"omega": 30.0})
    with pytest.raises(TypeError, match="base must be a chaoscam.Params or None, got str"):
        run("x")


@pytest.mark.parametrize("extend_to", [-1, math.nan, True, "x"])
def test_classify_checks_extend_to(extend_to):
    """classify of several members checks extend_to as for one run."""
    sol = chaoscam.solve(Params(), indices=[0, 1], duration=1.0, tangent=True)
    with pytest.raises(ParameterError, match="extend_to"):
        chaoscam.classify(sol, extend_to=extend_to)


def test_solve_names_bad_indices_and_progress_before_running():
    with pytest.raises(TypeError, match=r"indices must be a sequence .* got int 5"):
        chaoscam.solve(Params(), indices=5, duration=0.5)
    with pytest.raises(TypeError, match="progress must be callable"):
        chaoscam.solve(Params(), indices=[0], duration=0.5, progress=5)


def test_periodic_orbit_from_a_seed_off_the_model_is_not_a_crash():
    """A seed whose map leaves the cam's reach (or penetrates): not converged, NaN
    multipliers and the status, instead of numpy's LinAlgError."""
    for x0, status in (((3.0, 100.0), "LEFT_REACH"), ((-1.0, 0.0), "PENETRATION")):
        orbit = chaoscam.periodic_orbit(Params(), x0, 1)
        assert not orbit.converged and np.isnan(orbit.multipliers).all()
        assert orbit.settings["seed_status"] == status


@pytest.fixture(scope="module")
def tangent_run():
    return chaoscam.simulate(Params(xi=0.2), duration=4.0, transient=2.0, tangent=True)


@pytest.mark.parametrize(
    "kw",
    [dict(numerics=Numerics()), dict(duration=5.0), dict(transient=1.0), dict(seed=1),
     dict(index=3)],
    ids=["numerics", "duration", "transient", "seed", "index"],
)  # fmt: skip
def test_lyapunov_spectrum_refuses_settings_it_would_ignore(tangent_run, kw):
    """Given a solution, lyapunov_spectrum takes its exponents from that run: a run setting
    given with it would be ignored, and is refused by name."""
    with pytest.raises(ParameterError, match="|".join(kw)):
        chaoscam.lyapunov_spectrum(tangent_run, **kw)


def test_lyapunov_spectrum_says_what_a_solution_lacks(tmp_path, tangent_run):
    """A run too short for a standard error is warned about; a run without Jacobians (a
    file keeps none) and one without a section point after its start are refused, saying
    so."""
    with pytest.warns(RuntimeWarning, match="too few for its standard error"):  # 9 periods
        assert chaoscam.lyapunov_spectrum(tangent_run).exponents[0] < 0
    tangent_run.to_parquet(tmp_path / "t.parquet")  # a file keeps no Jacobians: said so
    with pytest.raises(ValueError, match="no Jacobians .* read from a file"):
        chaoscam.lyapunov_spectrum(chaoscam.load_trajectory(tmp_path / "t.parquet"))
    short = chaoscam.simulate(duration=0.1, tangent=True)
    with pytest.raises(ValueError, match="no section point after its start"):
        chaoscam.lyapunov_spectrum(short)


def test_load_inputs_takes_one_path(tmp_path):
    from chaoscam.report import load_inputs

    chaoscam.simulate(duration=0.3).to_parquet(tmp_path / "run.parquet")
    assert len(load_inputs(str(tmp_path / "run.parquet")).trajectories) == 1


def test_build_report_names_what_it_takes():
    """build_report reads the paths it is given (a missing one named) and refuses anything
    that is neither a path nor a result, naming what it takes."""
    from chaoscam.report import InputError, build_report

    with pytest.raises(InputError, match="run.parquet: no such file"):
        build_report(["run.parquet"])
    with pytest.raises(TypeError, match="takes paths, results .* not a dict"):
        build_report([{}])


def test_an_exponent_without_a_standard_error_is_warned():
    """Two periods recorded give exponents with a NaN standard error: a warning naming the
    number of periods (they came without a word); a run long enough gets none."""
    import warnings

    with pytest.warns(RuntimeWarning, match=r"rests on 4 cam period\(s\), too few"):
        chaoscam.lyapunov_spectrum(duration=1.0, transient=0.0)
    with warnings.catch_warnings():
        warnings.simplefilter("error", RuntimeWarning)
        chaoscam.lyapunov_spectrum(duration=10.0, transient=0.0)
