"""A stage's independent work side by side on the local cores (the compiled kernel runs
without the GIL; each run is the same bits as alone): :func:`side_by_side` for single runs,
:func:`beside` for a whole sweep while the stage runs its others."""

from __future__ import annotations

import contextlib
import contextvars
import threading
from collections.abc import Callable, Iterator, Sequence
from concurrent.futures import Future, ThreadPoolExecutor
from typing import Any


def side_by_side(
    fn: Callable[[Any], Any], items: Sequence[Any], workers=None, *, prefix="chaoscam-side"
) -> list[Any]:
    """``[fn(x) for x in items]`` on up to ``workers`` threads named ``prefix`` (every core
    when None), in order, each in a copy of this thread's context and inside
    :func:`chaoscam.kernel.members_on_this_thread`. The first error, a Ctrl-C or a stop asked
    of the calling thread stops the runs under way and drops those not begun."""
    from ..kernel import members_on_this_thread, stop_on, stops_here
    from ..sweep import local_workers

    items, stop, threads = list(items), threading.Event(), local_workers(workers)
    watched = (*stops_here(), stop)

    def call(x: Any) -> Any:
        with contextlib.ExitStack() as held:
            for event in watched:
                held.enter_context(stop_on(event))
            held.enter_context(members_on_this_thread())
            return fn(x)

    ctx = contextvars.copy_context()
    pool = ThreadPoolExecutor(max(1, min(threads, len(items))), thread_name_prefix=prefix)
    try:
        futures = [pool.submit(ctx.copy().run, call, x) for x in items]
        return [f.result() for f in futures]
    except BaseException:
        stop.set()
        raise
    finally:
        pool.shutdown(wait=True, cancel_futures=True)


@contextlib.contextmanager
def beside(workers, fn: Callable[..., Any], /, *args: Any, **kwargs: Any) -> Iterator[Future]:
    """A block during which ``fn(*args, **kwargs)`` runs on a thread of its own, in a copy of
    this thread's context; the block reads its value with the future's ``.result()``. With
    fewer ``workers`` than cores, ``fn`` runs on the calling thread at the first ``.result()``
    (or the block's end). A block that fails asks ``fn`` to stop (a sweep checkpoints its
    finished runs), waits, and raises its own error; one that ends normally raises ``fn``'s."""
    from ..kernel import stop_on
    from ..sweep import default_workers, local_workers

    if workers is not None and local_workers(workers) < default_workers():
        later = _Later(lambda: fn(*args, **kwargs))
        yield later
        later.result()
        return
    stop = threading.Event()

    def run() -> Any:
        with stop_on(stop):
            return fn(*args, **kwargs)

    pool = ThreadPoolExecutor(1, thread_name_prefix="chaoscam-beside")
    future = pool.submit(contextvars.copy_context().run, run)
    try:
        yield future
    except BaseException:
        stop.set()
        raise
    finally:
        pool.shutdown(wait=True)
    future.result()


class _Later(Future):
    """A future whose call runs on the thread that first asks for its result."""

    def __init__(self, call: Callable[[], Any]) -> None:
        super().__init__()
        self._call = call

    def result(self, timeout=None):
        if not self.done():
            try:
                self.set_result(self._call())
            except BaseException as err:  # a Ctrl-C too: raised below, as the call's
                self.set_exception(err)
        return super().result(timeout)
