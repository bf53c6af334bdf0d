"""A stage's single runs side by side on threads (paper._side_by_side)."""

import threading
import time

import pytest

from chaoscam import simulate
from chaoscam.model import Params
from chaoscam.paper._side_by_side import beside, side_by_side


def test_side_by_side_runs_on_threads_and_keeps_the_order():
    """Two calls run at once (each waits for the other to have started), and the results
    come back in the order of the items, not of completion."""
    started = threading.Barrier(2, timeout=10)

    def fn(x):
        started.wait()  # a BrokenBarrierError unless both run at the same time
        return x * 10

    assert side_by_side(fn, [1, 2], workers=2) == [10, 20]
    assert side_by_side(lambda x: x + 1, [3, 1, 2], workers=1) == [4, 2, 3]
    assert side_by_side(lambda x: x, [], workers=2) == []


def test_side_by_side_raises_the_first_error_and_drops_the_runs_not_begun():
    """An error is raised in the caller; items queued behind the running ones are not run."""
    ran = []

    def fn(x):
        ran.append(x)
        if x == 0:
            raise ValueError("run 0 failed")
        time.sleep(0.05)  # the queue behind would take 2.5 s on one thread
        return x

    with pytest.raises(ValueError, match="run 0 failed"):
        side_by_side(fn, [0] + list(range(1, 50)), workers=2)
    assert 0 in ran and len(ran) < 50
    assert not [t for t in threading.enumerate() if t.name.startswith("chaoscam-side")]


def test_side_by_side_checks_workers():
    with pytest.raises(ValueError, match="workers = 0 must be in"):
        side_by_side(lambda x: x, [1, 2], workers=0)


def test_figs_7_10_responses_side_by_side_are_the_bits_of_one_after_another():
    """Two of Figs. 7-10's responses (σ = 0 and σ > 0), shortened, on two threads: the same
    section, series and impacts as run alone."""
    cases = [(0.008, 0.0), (0.015, 0.004)]

    def response(case):
        p = Params(l_lambda=case[0], l_lambda_sigma=case[1])
        return simulate(p, duration=3.0, transient=1.0, seed=7)

    alone = [response(c) for c in cases]
    both = side_by_side(response, cases, workers=2)
    for a, b in zip(alone, both, strict=True):
        assert a.section.equals(b.section) and a.series.equals(b.series)
        assert a.impacts.equals(b.impacts)


def test_beside_runs_its_call_meanwhile_in_a_copy_of_the_context():
    """The call runs while the block does (each waits for the other), sees the caller's
    context variables, and its value is the future's."""
    import contextvars

    var = contextvars.ContextVar("var", default="unset")
    var.set("caller's")
    both = threading.Barrier(2, timeout=10)

    def fn(x):
        both.wait()
        return x, var.get()

    with beside(None, fn, 3) as fut:
        both.wait()  # a BrokenBarrierError unless fn runs meanwhile
        assert fut.result() == (3, "caller's")


def test_beside_asks_its_call_to_stop_when_the_block_fails():
    """An error in the block (a Ctrl-C, a failed sweep) sets the call's stop request, which
    :func:`check_stop` sees; the block's error is raised, no thread is left behind."""
    from chaoscam.kernel import StopRequested, check_stop

    seen = []

    def fn():
        while True:  # a sweep's loop: stops between two compiled calls
            try:
                check_stop()
            except StopRequested:
                seen.append("stopped")
                raise
            time.sleep(0.01)

    with pytest.raises(KeyboardInterrupt), beside(None, fn):
        raise KeyboardInterrupt
    assert seen == ["stopped"]
    assert not [t for t in threading.enumerate() if t.name.startswith("chaoscam-beside")]


def test_an_error_of_the_call_beside_is_raised_when_the_block_ends():
    def fn():
        raise ValueError("the map failed")

    with pytest.raises(ValueError, match="the map failed"), beside(None, fn):
        pass


def test_beside_with_fewer_workers_than_cores_runs_its_call_here_when_asked():
    """A user who leaves cores free gets no second sweep's threads: with one worker the
    call runs on the calling thread, at the block's first .result() (or at its end)."""
    ran = []

    def fn():
        ran.append(threading.current_thread())
        return 7

    with beside(1, fn) as fut:
        assert ran == []
        assert fut.result() == 7 and fut.result() == 7
    assert ran == [threading.current_thread()]
    with beside(1, fn):
        pass
    assert len(ran) == 2
    with pytest.raises(ValueError, match="workers = 0 must be in"), beside(0, fn):
        pass
