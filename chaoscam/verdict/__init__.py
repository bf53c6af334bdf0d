"""The verdict on a run: :func:`classify` labels every member of a solution from its section
and tangent dynamics (the analysis layer's evidence, the model-level :data:`RULES`, the
periodic-orbit certificate, extension, the step check), with the tangent dynamics' own results
(:func:`lyapunov_spectrum`, :func:`periodic_orbit`, :func:`kick_test`, :func:`stroboscopic_map`)
and, for a random line length, the common-noise twins (:func:`twin_test`)."""

from ._certificate import MODEL_ATOL, Certificate, certify, on_orbit
from ._classify import EXTEND_TO, classify, judge_member, judge_points
from ._orbits import (
    KickTest,
    PeriodicOrbit,
    iterate_map,
    kick_test,
    lyapunov_spectrum,
    map_runner,
    periodic_orbit,
    stroboscopic_map,
)
from ._rules import RULES, Rule, apply_rules, extensible, extension_stopped
from ._twins import TWIN_DELTA, TWIN_DURATION, TwinTest, twin_test

__all__ = ["EXTEND_TO", "MODEL_ATOL", "RULES", "TWIN_DELTA", "TWIN_DURATION", "Certificate",
           "KickTest", "PeriodicOrbit", "Rule", "TwinTest", "apply_rules", "certify", "classify",
           "extensible", "extension_stopped", "iterate_map", "judge_member", "judge_points",
           "kick_test", "lyapunov_spectrum", "map_runner", "on_orbit", "periodic_orbit",
           "stroboscopic_map", "twin_test"]  # fmt: skip
