"""Contact stiffness: composite modulus (7), Hertz line contact (18), fractal joint (15)/(17).

References
----------
Paper eqs. (7), (15), (17), (18). The fractal joint stiffness follows Majumdar & Bhushan,
"Fractal model of elastic-plastic contact between rough surfaces", J. Tribol. 113 (1991).
"""

from __future__ import annotations

import math

from .._util import ParameterError

__all__ = ["composite_modulus", "hertz_line_stiffness", "fractal_stiffness", "fractal_areas"]


def composite_modulus(nu_f: float, Y_f: float, nu_c: float, Y_c: float) -> float:
    """Composite Young's modulus E [Pa], eq. (7): ``1/E = (1 - nu_f^2)/Y_f + (1 - nu_c^2)/Y_c``
    (Table 1: E = 1.137e11 Pa)."""
    return 1.0 / ((1.0 - nu_f**2) / Y_f + (1.0 - nu_c**2) / Y_c)


def hertz_line_stiffness(E: float, l_lambda: float) -> float:
    """Hertz line-contact stiffness K_n = (pi/4) E l_lambda [N/m], eq. (18), for a contact-line
    length ``l_lambda`` [m] (Table 1: about 7.14e8 N/m)."""
    return 0.25 * math.pi * E * l_lambda


def fractal_areas(D: float, G: float, k: float, phi: float, A_r: float) -> tuple[float, float]:
    """The fractal model's largest contact area a_1 = ((2 - D)/D) A_r and critical area
    a_c = G^2 / (k phi / 2)^(2/(D - 1)) [m^2], eq. (15)."""
    a1 = (2.0 - D) / D * A_r
    ac = G**2 / (k * phi / 2.0) ** (2.0 / (D - 1.0))
    return a1, ac


def fractal_stiffness(E: float, D: float, G: float, k: float, phi: float, A_r: float) -> float:
    """Majumdar–Bhushan fractal joint normal stiffness K_n [N/m], eqs. (15)/(17).

    ``K_n = 2 E D / (sqrt(pi) (1 - D)) a_1^(D/2) (a_1^((1-D)/2) - a_c^((1-D)/2))``.

    Valid for 1 < D < 2 and a_c < a_1; outside that a :class:`ParameterError` names the
    offending field. The paper's Fig. 5 shows K_n rising with D and falling with G.
    """
    if not 1.0 < D < 2.0:
        raise ParameterError(f"D = {D!r} is outside the allowed range (1, 2) of the fractal model")
    if not G > 0.0:
        raise ParameterError(f"G = {G!r} m must be > 0 for the fractal model")
    a1, ac = fractal_areas(D, G, k, phi, A_r)
    if not ac < a1:
        raise ParameterError(
            f"G = {G!r} m with D = {D!r} gives critical area a_c = {ac:.3e} m^2 >= a_1 = "
            f"{a1:.3e} m^2: the fractal model (15)/(17) needs a_c < a_1 (lower G or raise A_r)"
        )
    x = (1.0 - D) / 2.0
    return 2.0 * E * D / (math.sqrt(math.pi) * (1.0 - D)) * a1 ** (D / 2.0) * (a1**x - ac**x)
