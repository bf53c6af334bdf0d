"""Stiffness models: composite modulus (7), Hertz (18), fractal (15)/(17)."""

import numpy as np
import pytest

from chaoscam import ParameterError, Params
from chaoscam.model import composite_modulus, fractal_stiffness, hertz_line_stiffness


def test_composite_modulus_of_table1():
    """E = 1.137e11 Pa for Table 1 (eq. (7))."""
    assert Params().E == pytest.approx(1.137e11, rel=1e-3)


def test_composite_modulus_of_equal_materials_is_half_plane_strain_modulus():
    """For equal materials 1/E = 2 (1 - nu^2)/Y."""
    assert composite_modulus(0.25, 1e9, 0.25, 1e9) == pytest.approx(1e9 / (2 * (1 - 0.0625)))


def test_hertz_is_linear_in_line_length():
    """K_n = (pi/4) E l_lambda: doubling l_lambda doubles K_n."""
    E = Params().E
    assert hertz_line_stiffness(E, 0.016) == pytest.approx(2 * hertz_line_stiffness(E, 0.008))
    assert hertz_line_stiffness(E, 0.008) == pytest.approx(np.pi / 4 * E * 0.008)


def test_fractal_stiffness_rises_with_D_and_falls_with_G():
    """Fig. 5: over D in [1.36, 1.56], K_n grows with D and falls with G."""
    p = Params()
    Ds = np.linspace(1.36, 1.56, 21)
    table = np.array(
        [
            [fractal_stiffness(p.E, D, G, p.k, p.phi, p.A_r) for D in Ds]
            for G in (1e-9, 1e-10, 1e-11)
        ]
    )
    assert np.all(table > 0)
    assert np.all(np.diff(table, axis=1) > 0), "K_n must rise with D"
    assert np.all(np.diff(table, axis=0) > 0), "K_n must fall as G grows (rows: G decreasing)"


def test_fractal_model_outside_validity_names_the_field():
    """D outside (1, 2) or a_c >= a_1 is a clear error."""
    p = Params()
    with pytest.raises(ParameterError, match="D"):
        fractal_stiffness(p.E, 2.0, 1e-10, p.k, p.phi, p.A_r)
    with pytest.raises(ParameterError, match="a_c"):
        fractal_stiffness(p.E, 1.45, 1e-6, p.k, p.phi, p.A_r)


def test_params_select_the_model():
    """stiffness='fractal' ignores the line length; 'hertz' uses it."""
    p = Params(stiffness="fractal")
    assert p.stiffness_at(0.001) == p.stiffness_at(0.02)
    assert Params().stiffness_at(0.004) < Params().stiffness_at(0.008)
