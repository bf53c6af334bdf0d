"""``chaoscam ensemble``'s parts, each in two phases: its launch (the members simulated) and
its labels (verdicts and the extensions of undetermined members, with ``--classify``) with
its files written.

On the CPU a part's two phases run one after the other, in the command's thread. Where a
GPU runs the members, the parts go through the sweeps' pipeline
(:class:`chaoscam.sweep._pipeline.PipelineBackend`): a part is launched in the command's
thread (the only one that uses the device, and the one a Ctrl-C reaches) while one labelling
thread labels and writes the part before it, two parts in flight, as a GPU sweep runs its
batches. Why: on an H100 (2026-11-28) a map's 2,048 members × 20 s took one 87-s launch, and
the extension of its 530 undetermined members took 12.8 s more on the host's 16 cores, with
the device idle; a part of 8,192 members has about four times those labels and extensions.
Not measured on a device: with a stand-in device (tests) the parts equal the CPU's, bit for
bit, and a launch overlaps the labels of the part before.

Every terminal line (the warnings each phase recorded, the part's rate) is printed by the
command's thread, in the parts' order, after the part is written; the progress bar is
advanced under a lock, as both threads move it.
"""

from __future__ import annotations

import threading
import time
from dataclasses import dataclass
from pathlib import Path
from typing import Any

__all__ = ["Finished", "Part", "PartRun", "backend_for", "both_phases"]


@dataclass(frozen=True)
class Launched:
    """A part after its launch: the ensemble, the warnings recorded and when it began."""

    start: int
    stop: int
    ens: Any
    caught: list
    began: float


@dataclass(frozen=True)
class Finished:
    """A part written: the warnings both phases recorded, the backend that ran it and when
    its launch began."""

    start: int
    stop: int
    caught: list
    backend: str
    began: float


class PartRun:
    """What every part of one command shares: its model, settings, progress bar and parts
    folder; :meth:`launch` and :meth:`label` are a part's two phases."""

    def __init__(self, args, params, duration, transient, parts: Path, names, bar, batch):
        self.args, self.params = args, params
        self.duration, self.transient = duration, transient
        self.parts, self.names, self.bar, self.batch = parts, names, bar, batch
        self._lock = threading.Lock()  # the bar is moved from both threads

    def update(self, n: int) -> None:
        with self._lock:
            self.bar.update(n)

    def extending(self, n: int, extending: int = 0, recorded_s: float | None = None) -> None:
        """classify_ensemble's progress: an extension round adds its members to the bar's
        total and says what it runs; its batches advance the bar."""
        with self._lock:
            if extending:
                self.bar.total += extending
                self.bar.set_description(
                    f"ensemble (extending {extending} undetermined to {recorded_s:g} s recorded)",
                    refresh=False,
                )
            self.bar.update(n)

    def launch(self, start: int, stop: int) -> Launched:
        """The members ``start`` .. ``stop - 1`` simulated (on the command's thread)."""
        from .._warn import recorded
        from ..integrate import simulate_ensemble

        began = time.perf_counter()
        a = self.args
        with recorded() as caught:
            ens = simulate_ensemble(
                self.params,
                range(start, stop),
                seed=a.seed,
                duration=self.duration,
                transient=self.transient,
                backend=a.backend,
                keep_impacts=a.keep_impacts,
                tangent=a.classify,
                resumable=a.classify,  # undetermined members are continued
                batch=self.batch,
                progress=self.update,
            )
        return Launched(start, stop, ens, list(caught), began)

    def label(self, launched: Launched) -> Finished:
        """The part's labels (with ``--classify``) and its files, written atomically with
        their ``.done`` marker (on the labelling thread where a GPU runs the members)."""
        import json

        from .._ensemble_verdicts import classify_ensemble
        from .._warn import recorded
        from ._ensemble_parts import atomic_text, fingerprint, write_table

        ens, start = launched.ens, launched.start
        with recorded() as caught:
            if self.args.classify:
                ens = classify_ensemble(ens, self.params, progress=self.extending)
        offset = start - self.args.first
        tables = {"members": ens.members, "sections": ens.sections, "impacts": ens.impacts}
        files = {}
        for name in self.names:
            table = tables[name].assign(member=tables[name]["member"] + offset)
            path = self.parts / f"{start:012d}.{name}.parquet"
            write_table(table, path)  # atomic, with the checksums of chaoscam._parquet
            files[name] = fingerprint(path)
        atomic_text(
            self.parts / f"{start:012d}.done",
            json.dumps({"files": files, "settings": ens.settings}, default=str),
        )
        return Finished(
            start,
            launched.stop,
            launched.caught + list(caught),
            ens.settings["backend"],
            launched.began,
        )


@dataclass(frozen=True)
class Part:
    """One part as a task of the sweeps' backends: ``launch`` and ``label`` are the two
    phases a :class:`~chaoscam.sweep._pipeline.PipelineBackend` runs apart; :func:`both_phases`
    runs both (the serial backend's call)."""

    start: int
    stop: int
    run: PartRun

    def launch(self) -> Launched:
        return self.run.launch(self.start, self.stop)

    def label(self, launched: Launched) -> Finished:
        return self.run.label(launched)


def both_phases(part: Part) -> Finished:
    """Both phases of ``part``, one after the other."""
    return part.label(part.launch())


def backend_for(backend: str):
    """The pipeline where a GPU runs the members (``backend`` settled: "gpu" with a usable
    GPU here), else the serial backend; the labelling thread gets this thread's numba thread
    count (``--workers``)."""
    import numba

    from ..integrate._gpu import runs_on_gpu
    from ..sweep._backends import SerialBackend
    from ..sweep._pipeline import PipelineBackend

    if runs_on_gpu(backend):
        return PipelineBackend(threads=numba.get_num_threads())
    return SerialBackend()
