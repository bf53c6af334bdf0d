"""Continuation of the model's periodic orbits in one parameter: :func:`continuation` follows a
period-n orbit of the stroboscopic map by pseudo-arclength through impacts, chattering and
sticking, with its multipliers and located bifurcations, into a :class:`Branch`; :func:`follow`
is the core, generic over a map ``(x, λ) -> (P(x), DP(x))`` (the bouncing ball's too)."""

from ._branch import EVENT_KINDS, Branch, NoOrbitError, continuation, events_path, find_start
from ._core import CONTINUOUS, MapFailed, MapPoint, Settings, follow

__all__ = ["CONTINUOUS", "EVENT_KINDS", "Branch", "MapFailed", "MapPoint", "NoOrbitError",
           "Settings", "continuation", "events_path", "find_start", "follow"]  # fmt: skip
