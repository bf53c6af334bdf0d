"""Sweep axes, grid validation and the realization-index scheme."""

import numpy as np
import pytest

from chaoscam import Numerics, ParameterError, Params
from chaoscam.sweep import Axis, SweepError, parse_range, realization_index
from chaoscam.sweep._grid import validate_grid


def test_fig4_axis_has_69_values_step_quarter_mm():
    """Fig. 4's l_lambda from 0.001 to 0.018 m in 0.00025 m steps is 0.001:0.018:69."""
    a = Axis.parse("l_lambda=0.001:0.018:69")
    assert len(a) == 69 and a.values[0] == 0.001 and a.values[-1] == 0.018
    assert np.allclose(np.diff(a.values), 0.00025, rtol=1e-9)


@pytest.mark.parametrize(
    "text", ["1:2", "a:2:3", "1:2:x", "1:2:0", "1:2:-3", "2:1:3", "1:2:1", "1:1:3", "1:inf:2"]
)
def test_bad_ranges_are_refused(text):
    """NUM < 1, stop < start, malformed or degenerate ranges raise SweepError."""
    with pytest.raises(SweepError):
        parse_range(text)


@pytest.mark.filterwarnings("error")
def test_a_range_too_wide_for_a_float_is_refused_without_numpy_warnings():
    """STOP - START beyond the largest float: a SweepError naming the range, no overflow
    warning from numpy first (found by the fuzz test)."""
    with pytest.raises(SweepError, match="overflows"):
        Axis.parse("-1.7e308:1.7e308:3", name="xi")


def test_single_point_range():
    """START:START:1 is one value."""
    assert parse_range("0.5:0.5:1") == (0.5, 0.5, 1)
    assert Axis.parse("0.5:0.5:1", name="xi").values == (0.5,)


def test_axis_names_are_checked():
    """An unknown field is a ParameterError with a suggestion; a text field cannot be swept."""
    with pytest.raises(ParameterError, match="omega"):
        Axis("omegaa", (1.0,))
    with pytest.raises(SweepError):
        Axis("stiffness", (1.0,))


def test_realization_index_is_a_bijection_independent_of_grid_shape():
    """Cantor pairing: distinct (cell, index) give distinct indices, fixed formula."""
    keys = [(c, i) for c in range(60) for i in range(60)]
    idx = {realization_index(c, i) for c, i in keys}
    assert len(idx) == len(keys)
    assert realization_index(0, 0) == 0 and realization_index(3, 2) == 17
    with pytest.raises(SweepError):
        realization_index(-1, 0)


def test_grid_validation_names_the_bad_point():
    """sigma < 0 and mu <= 0 are refused before any run, naming the field."""
    with pytest.raises(ParameterError, match="l_lambda_sigma"):
        validate_grid(
            Params(), Numerics(), [Axis("l_lambda", (0.008,)), Axis("l_lambda_sigma", (-1e-3,))]
        )
    with pytest.raises(ParameterError, match="l_lambda"):
        validate_grid(Params(), Numerics(), [Axis("l_lambda", (0.0, 0.008)), Axis("xi", (0.4,))])
    with pytest.raises(SweepError, match="repeat"):
        validate_grid(Params(), Numerics(), [Axis("xi", (0.4,)), Axis("xi", (0.5,))])


def test_axes_can_name_exact_values():
    """NAME=V1,V2,... sweeps exactly those values (the paper's mu = 8, 15, 23 mm); a value
    that is not a number is refused with the axis named."""
    assert Axis.parse("l_lambda=0.008,0.015,0.023").values == (0.008, 0.015, 0.023)
    assert Axis.parse("0.42", name="xi").values == (0.42,)
    with pytest.raises(SweepError, match="xi values"):
        Axis.parse("xi=0.1,abc")


def test_an_axis_without_its_name_is_named_in_the_message():
    """'l_lambda' (no '=') is refused with what was given, not an empty axis ''."""
    with pytest.raises(SweepError, match=r"axis 'l_lambda': expected NAME=START:STOP:NUM"):
        Axis.parse("l_lambda")


def test_a_value_given_twice_is_refused():
    """A repeated value would be a second column of the same parameters, simulated again
    under other indices and drawn over the first: refused, naming the axis and the value."""
    with pytest.raises(SweepError, match=r"axis l_lambda: the value 0.008 appears more than once"):
        Axis.parse("l_lambda=0.008,0.015,0.008")
    with pytest.raises(SweepError, match="xi"):
        Axis("xi", (0.2, 0.3, 0.2, 0.3))
    assert Axis("xi", (0.3, 0.2)).values == (0.3, 0.2)  # any order, each value once
