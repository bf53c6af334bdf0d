"""The parameter set: defaults, derived quantities and validation."""

import math

import pytest

from chaoscam import ParameterError, Params
from chaoscam.model import FIELD_DOCS, field_names


def test_table1_defaults_and_decisions():
    """Defaults are Table 1 and the documented decisions (J, pivot)."""
    p = Params()
    assert (p.l, p.r, p.m, p.R, p.e, p.omega, p.xi, p.beta) == (
        0.6,
        0.005,
        0.3676,
        0.09,
        0.04,
        28.7,
        0.42,
        3.25,
    )
    assert p.inertia == pytest.approx(0.3676 * (0.36 / 3 + 0.005**2 / 4), rel=1e-15)
    assert p.pivot == (-0.5, 0.095)
    assert p.arm == p.r


def test_steel_rod_mass_matches_table():
    """The table's mass is a steel rod, rho pi r^2 l with rho = 7800 kg/m^3 (MODEL.md)."""
    p = Params()
    assert 7800 * math.pi * p.r**2 * p.l == pytest.approx(p.m, rel=1e-3)


def test_every_field_is_documented():
    """Each field carries a description and a unit."""
    for name in field_names():
        assert FIELD_DOCS[name]["doc"] and FIELD_DOCS[name]["unit"], name


@pytest.mark.parametrize(
    "changes, field",
    [
        ({"m": -1.0}, "m"),
        ({"omega": float("nan")}, "omega"),
        ({"l_lambda_sigma": -0.001}, "l_lambda_sigma"),
        ({"l_lambda": 0.0}, "l_lambda"),
        ({"l_lambda": -0.002}, "l_lambda"),
        ({"xi": 1.5}, "xi"),
        ({"nu_f": 0.5}, "nu_f"),
        ({"D": 2.1}, "D"),
        ({"D": 1.0}, "D"),
        ({"stiffness": "fractal", "G": 1e-5}, "G"),
        ({"stiffness": "fractal", "G": -1e-10}, "G"),
        ({"stiffness": "spring"}, "stiffness"),
        ({"e": float("inf")}, "e"),
        ({"J": -0.1}, "J"),
        ({"m": "heavy"}, "m"),
    ],
)
def test_invalid_values_are_refused_naming_the_field(changes, field):
    """A bad value raises ParameterError whose message names the field (its value, not an
    unknown name: the integrator's settings are Numerics', tested with it)."""
    with pytest.raises(ParameterError, match=rf"^{field} = "):
        Params(**changes)


def test_the_integrators_settings_are_not_the_models():
    """Params holds the physics only: dt is refused as an unknown parameter."""
    with pytest.raises(ParameterError, match=r"unknown parameter 'dt'"):
        Params(dt=1e-6)


def test_range_is_stated_in_the_message():
    """The message gives the allowed range."""
    with pytest.raises(ParameterError, match=r"\[0\.0, 1\.0\]"):
        Params(xi=2.0)


def test_unknown_name_suggests_close_ones():
    """replace() refuses unknown names and suggests the nearest field."""
    with pytest.raises(ParameterError, match="omega"):
        Params().replace(omgea=3.0)


def test_from_strings_parses_numbers_and_choices():
    """CLI strings convert to the field's type."""
    p = Params.from_strings({"omega": "30", "stiffness": "fractal", "J": "none"})
    assert p.omega == 30.0 and p.stiffness == "fractal" and p.J is None
    with pytest.raises(ParameterError, match="omega"):
        Params.from_strings({"omega": "fast"})


def test_frozen():
    """Parameters cannot be changed in place."""
    with pytest.raises(AttributeError):
        Params().omega = 3.0  # type: ignore[misc]
