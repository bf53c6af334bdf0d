"""Continuation of the model's periodic orbits in one parameter: :func:`continuation` follows a
period-n orbit of the stroboscopic map by pseudo-arclength through impacts, chattering and
sticking, with its multipliers and located bifurcations, into a :class:`Branch`; :func:`follow`
is the core, generic over a map ``(x, λ) -> (P(x), DP(x))`` (the bouncing ball's too);
:func:`curve` continues a fold or period doubling in two parameters into a :class:`Curve`."""

from ._branch import EVENT_KINDS, Branch, NoOrbitError, continuation, events_path, find_start
from ._core import CONTINUOUS, MapFailed, MapPoint, Settings, follow, null_vector
from ._curve import CURVE_KINDS, Curve, CurveMap, curve

__all__ = ["CONTINUOUS", "CURVE_KINDS", "EVENT_KINDS", "Branch", "Curve", "CurveMap", "MapFailed",
           "MapPoint", "NoOrbitError", "Settings", "continuation", "curve", "events_path",
           "find_start", "follow", "null_vector"]  # fmt: skip
