"""The stroboscopic map's compiled calls (chaoscam.tangent._MapRunner) hand back every
MAP_ROWS cam periods with the same bits, and a sweep thread asked to stop stops a verdict's
shooting or kicks at its next call (a prompt Ctrl-C / SIGTERM during a long labelling)."""

import threading

import numpy as np
import pytest

from chaoscam import Params, tangent
from chaoscam.integrate._driver import StopRequested, members_on_this_thread

X = (0.03, 0.5)


def test_hand_backs_every_few_periods_keep_the_bits(monkeypatch):
    """Two map periods a call against one call for all: the same points and Jacobian."""
    p = Params(xi=0.45)
    whole = tangent.iterate_map(p, X, 9), tangent.stroboscopic_map(p, X, 9)
    monkeypatch.setattr(tangent, "MAP_ROWS", 2)
    pieces = tangent.iterate_map(p, X, 9), tangent.stroboscopic_map(p, X, 9)
    assert np.array_equal(whole[0], pieces[0])
    assert all(np.array_equal(a, b) for a, b in zip(whole[1], pieces[1], strict=True))


def test_a_thread_asked_to_stop_stops_the_map_at_its_next_call():
    stop = threading.Event()
    with members_on_this_thread(stop):
        assert np.isfinite(tangent.iterate_map(Params(), X, 2)).all()  # not asked: runs
        stop.set()
        with pytest.raises(StopRequested):
            tangent.kick_test(Params(), X, 1, periods=2)
