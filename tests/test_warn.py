"""Warnings name the user's line, whatever the depth of chaoscam beneath it
(chaoscam._warn): a fixed stacklevel named a line of chaoscam whenever the warning came
from a nested call (simulate inside a sweep, a budget check inside classify)."""

import warnings

import pytest

import chaoscam
from chaoscam import Params
from chaoscam._warn import user_stacklevel
from chaoscam.sweep import bifurcation

# A spread that cannot act (fractal K_n does not depend on the line length): every run of it
# warns before it starts, and is cheap.
IGNORED_SIGMA = Params(stiffness="fractal", l_lambda_sigma=0.001)


def _caught(call):
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        call()
    return [w for w in caught if issubclass(w.category, RuntimeWarning)]


@pytest.mark.parametrize(
    "call",
    [
        lambda: chaoscam.simulate(IGNORED_SIGMA, duration=0.05, series=False),
        lambda: bifurcation("xi", [0.1], base=IGNORED_SIGMA, duration=0.05, workers=1),
    ],
    ids=["simulate", "bifurcation"],
)
def test_a_warning_names_the_callers_file(call):
    """The same model warning, raised one call deep (simulate) and several deep (a sweep's
    run re-emitted by the sweep), names this file and not chaoscam's."""
    caught = _caught(call)
    assert any("no effect with stiffness = 'fractal'" in str(w.message) for w in caught)
    assert {w.filename for w in caught} == {__file__}


def test_an_adaptive_verdict_warning_names_the_callers_file():
    """classify_trajectory's RK4-grid warning, raised three calls down in classify.py,
    names the line that called classify_trajectory."""
    tr = chaoscam.simulate(Params(e=0.02, integrator="adaptive"), duration=0.2, series=False)
    caught = _caught(lambda: chaoscam.classify_trajectory(tr))
    assert any("RK4 grid" in str(w.message) for w in caught)
    assert {w.filename for w in caught} == {__file__}


def test_user_stacklevel_counts_the_frames_of_chaoscam_only():
    """Called from outside chaoscam, the level is 2: the caller of the function that warns."""

    def warns_here():
        return user_stacklevel()

    assert warns_here() == 2
