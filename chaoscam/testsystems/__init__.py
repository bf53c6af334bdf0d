"""Known dynamical systems that validate the analysis layer (maps, flows, bouncing ball), each
with the values the literature gives for it; nothing here depends on the cam-follower model."""

from ._ball import (
    BallRun,
    ball_impact_map,
    ball_period_one_theory,
    bouncing_ball,
    period_one_orbit,
    period_one_thresholds,
)
from ._flows import FlowSystem, flow_reference, flow_trajectory, lorenz, rossler, ueda
from ._maps import (
    circle_map_orbit,
    circle_map_rotation_number,
    henon_jacobian,
    henon_orbit,
    henon_step,
    logistic_jacobian,
    logistic_orbit,
    logistic_step,
)
from ._signals import GOLDEN, torus_section, torus_signal

__all__ = [
    "GOLDEN",
    "BallRun",
    "FlowSystem",
    "ball_impact_map",
    "ball_period_one_theory",
    "bouncing_ball",
    "circle_map_orbit",
    "circle_map_rotation_number",
    "flow_reference",
    "flow_trajectory",
    "henon_jacobian",
    "henon_orbit",
    "henon_step",
    "logistic_jacobian",
    "logistic_orbit",
    "logistic_step",
    "lorenz",
    "period_one_orbit",
    "period_one_thresholds",
    "rossler",
    "torus_section",
    "torus_signal",
    "ueda",
]
