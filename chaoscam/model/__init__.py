"""The model: parameters, geometry, forces, stiffness and the line-length process."""

from .._util import ParameterError
from ._forces import angular_acceleration, friction_torque, normal_force, stiffness_array
from ._geometry import (
    cam_angle,
    cam_centre,
    contact_angle,
    contact_angle_rate,
    contact_period,
    gap,
    gap_rate,
    lever_arm,
    normal_cam_speed,
    slip_speed,
)
from ._linelength import LineLengthStream, realization_rng, realizations_identical, truncated_mass
from ._params import FIELD_DOCS, Params, field_names, params_arg, parse_value
from ._stiffness import composite_modulus, fractal_areas, fractal_stiffness, hertz_line_stiffness

__all__ = [
    "FIELD_DOCS", "LineLengthStream", "ParameterError", "Params", "angular_acceleration",
    "cam_angle", "cam_centre", "composite_modulus", "contact_angle", "contact_angle_rate",
    "contact_period", "field_names", "fractal_areas", "fractal_stiffness", "friction_torque",
    "gap", "gap_rate", "hertz_line_stiffness", "lever_arm", "normal_cam_speed", "normal_force",
    "params_arg", "parse_value", "realization_rng", "realizations_identical", "slip_speed",
    "stiffness_array", "truncated_mass",
]  # fmt: skip
