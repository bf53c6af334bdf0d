"""A stage's independent work side by side on the local cores.

The report's runs spend their time in the compiled kernel, which runs without the GIL, so
threads of this process run them on every core, each the same bits as alone.

* :func:`side_by_side`: single runs (Figs. 7–10's six responses), each on a thread of its
  own, so that no core idles while the others finish theirs.
* :func:`beside`: a whole sweep on its own thread while the stage runs its other sweeps (the
  sensitivity stage's (ω, ξ) map; Figs. 7–10's responses beside their map). Each sweep
  ends on its slowest runs, one core working; beside each other, one sweep's end is the
  other's middle. Each sweep is deterministic per run, so the records are the same bits as
  one after another.
"""

from __future__ import annotations

import contextlib
import contextvars
import threading
from collections.abc import Callable, Iterator, Sequence
from concurrent.futures import Future, ThreadPoolExecutor
from typing import Any

__all__ = ["beside", "side_by_side"]


def side_by_side(
    fn: Callable[[Any], Any], items: Sequence[Any], workers=None, *, prefix="chaoscam-side"
) -> list[Any]:
    """``[fn(x) for x in items]``, computed on up to ``workers`` threads named ``prefix``
    (every core when None; :func:`chaoscam.sweep.local_workers` checks it), in order.

    Each call runs in a copy of this thread's context (the report's drawing thread, output
    mode and recorded warnings) and inside :func:`chaoscam.kernel.members_on_this_thread`:
    its runs go through the compiled nogil call on that thread, not numba's shared pool. The
    first error (or a Ctrl-C in the calling thread), or a stop asked of the calling thread
    (:func:`beside`), stops the runs under way at their next compiled call and drops those
    not begun; an error is raised once they have ended.
    """
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
    """A block during which ``fn(*args, **kwargs)`` runs on a thread of its own, in a copy
    of this thread's context (the report's drawing thread, output mode and warnings); the
    block reads its value with ``.result()`` of the future it gets (``workers`` and ``fn``
    are positional only: a ``workers=`` keyword is ``fn``'s).

    Only where the stage may use every core (``workers`` None, or at least the cores this
    process may use): two sweeps then share those cores. With fewer ``workers`` (a user
    leaving cores free) ``fn`` runs on the calling thread instead, when the block first
    reads its result (or at its end), so no more than ``workers`` cores are used.

    On its thread ``fn`` runs inside :func:`chaoscam.kernel.stop_on`: when the block ends
    with an error (a Ctrl-C, a SIGTERM or a failed sweep in the calling thread), ``fn`` is
    asked to stop and waited for. A sweep stops at its next compiled call with its finished
    runs checkpointed, like a sweep stopped by Ctrl-C, so ``chaoscam paper --resume`` goes on
    from both. Its error is then dropped: the block's own is raised. A block that ends
    normally waits for ``fn`` too; an error of ``fn`` not read by the block is raised then.
    """
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
