"""A GPU sweep's local backend: the device runs the next batch while the host labels the last.

A sweep's GPU batch has two phases (:mod:`._batch_run`): its launch, where the host mostly
waits for the device, and its labels (verdicts, the extensions of undetermined members and
the fate runs, which go to the CPU for so few members: ``_ensemble_verdicts.EXTEND_BACKEND``),
where the device would wait for the host. One after another, as the serial backend runs
them, neither overlaps. :class:`PipelineBackend` launches a batch at submission, in the
driver's thread (so numba-cuda is used from that thread only, and Ctrl-C stops a launch as
on the serial backend, when it returns), and hands its labels to one labelling thread; the
engine keeps two batches in flight, so the next launch runs while the last is labelled.

Estimated on the H200's measurements (2026-11-27/28), not measured on a device: a batch of
8,192 members × 20 s takes about 80 s of launch (a quarter wave at 0.71 of a wave's rate),
its labels about 2.8 ms a member on one core (23 s: verdict 1.8 ms, record 1 ms, measured on
the 2-core machine) plus the extensions; the pipeline hides
the shorter of the two. The records are those of the serial backend, bit for bit (tested):
a record depends on its member only.
"""

from __future__ import annotations

import concurrent.futures as cf
from collections.abc import Callable
from typing import Any

from ._backends import SerialBackend, ThreadBackend

__all__ = ["PipelineBackend"]


class PipelineBackend(ThreadBackend):
    """Launches in the driver's thread, labels on one labelling thread (see the module);
    waits, cancels and closes as a :class:`._backends.ThreadBackend` of one thread.

    ``threads``: numba's thread count for the labelling thread's CPU work (the driver's is
    set by the sweep; numba's count is per thread). A task without the two phases
    (``launch``, ``label``) runs whole at submission, as on :class:`._backends.SerialBackend`.
    """

    name = "pipeline"

    def __init__(self, threads: int | None = None) -> None:
        # the engine keeps 2 x workers tasks in flight: one labelled, one launched
        super().__init__(1, prefix="chaoscam-labels")
        self.threads = threads

    def _label(self, task: Any, launched: Any) -> Any:
        import numba

        from ..integrate._driver import fork_safe_threads, stop_on

        if self.threads is not None:
            fork_safe_threads()  # set_num_threads starts the threads: the layer first
            numba.set_num_threads(self.threads)  # numba's count is per thread
        with stop_on(self._stop):  # stops between two compiled calls when cancelled
            return task.label(launched)

    def submit(self, fn: Callable, arg: Any) -> cf.Future:
        now = SerialBackend()  # runs a call here, as a finished future
        if not (hasattr(arg, "launch") and hasattr(arg, "label")):
            return now.submit(fn, arg)
        launched = now.submit(type(arg).launch, arg)  # here: the driver's thread, the device's
        if launched.exception() is not None:
            return launched
        return self._pool.submit(self._label, arg, launched.result())
