"""A sweep thread asked to stop stops a verdict's shooting or kicks at the stroboscopic map's
next compiled call (chaoscam/verdict/_orbits.py): a prompt Ctrl-C / SIGTERM during a long
labelling."""

import threading

import numpy as np
import pytest

from chaoscam import Params
from chaoscam.kernel import StopRequested, members_on_this_thread
from chaoscam.verdict import iterate_map, kick_test

X = (0.03, 0.5)


def test_a_thread_asked_to_stop_stops_the_map_at_its_next_call():
    """Not asked, the map runs; asked, the kicks' next map run raises StopRequested."""
    stop = threading.Event()
    with members_on_this_thread(stop):
        assert np.isfinite(iterate_map(Params(), X, 2)).all()  # not asked: runs
        stop.set()
        with pytest.raises(StopRequested):
            kick_test(Params(), X, 1, periods=2)
