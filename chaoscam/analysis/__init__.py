"""Analysis of simulated motion: sections, spectrum, Lyapunov exponents, 0–1 test, verdict.

Everything here takes numpy arrays; nothing imports the model, the kernels or the simulation.
"""

from ._birkhoff import BirkhoffResult, birkhoff_weights, weighted_birkhoff
from ._classify import SAMPLING_DT, classify_signal
from ._classify_section import SECTION_OPTIONS, check_options, classify_section, section_options
from ._evidence import as_exponent, exponent_evidence, zero_one_evidence
from ._lyapunov_series import DoubtfulEstimateWarning, SeriesLyapunovResult, lyapunov_from_series
from ._periodicity import PeriodResult, RotationResult, embed_angles, rotation_order, section_period
from ._saltation import saltation_matrix
from ._sections import crossing_section, local_maxima
from ._set_measures import correlation_dimension, neighbour_expansion, stationarity_ratio
from ._spectrum import SpectrumResult, power_spectrum, spectrum_analysis
from ._tangent_spectrum import TangentSpectrum, spectrum_from_jacobians
from ._thresholds import Thresholds
from ._verdict import LABELS, VOTES, Evidence, Verdict, combine
from ._zero_one import ZeroOneResult, zero_one_test

__all__ = [
    "LABELS",
    "SAMPLING_DT",
    "SECTION_OPTIONS",
    "VOTES",
    "BirkhoffResult",
    "Thresholds",
    "DoubtfulEstimateWarning",
    "Evidence",
    "PeriodResult",
    "RotationResult",
    "SeriesLyapunovResult",
    "SpectrumResult",
    "TangentSpectrum",
    "Verdict",
    "ZeroOneResult",
    "as_exponent",
    "birkhoff_weights",
    "check_options",
    "classify_section",
    "classify_signal",
    "combine",
    "correlation_dimension",
    "crossing_section",
    "embed_angles",
    "exponent_evidence",
    "local_maxima",
    "lyapunov_from_series",
    "neighbour_expansion",
    "power_spectrum",
    "rotation_order",
    "saltation_matrix",
    "section_options",
    "section_period",
    "spectrum_analysis",
    "spectrum_from_jacobians",
    "stationarity_ratio",
    "weighted_birkhoff",
    "zero_one_evidence",
    "zero_one_test",
]
