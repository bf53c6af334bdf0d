"""``chaoscam ensemble``: many realizations in compiled batches (CPU threads or a GPU).

Each chunk of realizations is written to ``FILE.parts/`` as soon as it is done (written to a
temporary name, then renamed), so an interrupted run keeps what it finished; ``--resume``
skips the chunks already there, after checking that they belong to the same configuration.
When all chunks are done they are joined into ``FILE.parquet`` (one row per member),
``FILE.sections.parquet`` and, with ``--keep-impacts``, ``FILE.impacts.parquet``, and the parts
are removed.

The outputs are written as one commit: each to a temporary name first, then renamed, the
members file last, and only then are the parts removed (renamed away in one step). A run
killed at any moment can therefore be finished with ``--resume``. Each part's ``.done``
marker records the size and SHA-256 of the part's files; a part that does not match (torn,
altered) is computed again, with a one-line notice. The run holds an OS lock on its output,
so a second process on the same output is refused.
"""

from __future__ import annotations

import argparse
import json
import os
import shutil
import sys
import time
import warnings
from pathlib import Path

from ._ensemble_parts import (
    atomic_text,
    check_outputs,
    commit_parts,
    config_digest,
    finished_run,
    manifest,
    output_paths,
    part_done,
    readable_table,
    recorded_config,
)
from ._ensemble_run import Part, PartRun, backend_for, both_phases
from ._options import add_run_options, path_arg

__all__ = ["register"]

CPU_CHUNK = 128
"""Members per saved part on the CPU: 10-25 s of work on 2 cores for 20 s runs with their
labels, so an interruption loses at most that (the parts' size changes no result; 64, 128
and 1,024 members per part took the same time for the README's 300 members, measured)."""

GPU_CHUNK = 8_192
"""Members per saved part on a GPU, where one thread is slow and the rate comes from many in
flight (measured on an H200, 2026-11-27: 64 members of 0.25 s took 1.09 s of launch, 8,448
took 1.80 s, a full wave of 33,792 took 5.1 s), so a part must be large; a quarter of an
H200's wave keeps a part's device time and its host labels near a minute or two each for
20-s runs, at 0.71 of a full wave's rate a member. As a sweep's GPU batches
(``sweep._batch.GPU_MAP_BATCH``)."""


def register(sub) -> None:
    p = sub.add_parser(
        "ensemble",
        help="simulate many realizations in parallel (CPU or GPU), keep sections and labels",
        description="Simulate realizations FIRST .. FIRST+MEMBERS-1 of one model in compiled "
        "batches (numba threads over the cores, or one CUDA thread each on a GPU) and keep "
        "their stroboscopic sections, statuses, impact counts and, on request, impacts and "
        "section labels. Interrupted runs resume with --resume.",
    )
    p.add_argument("--members", type=int, required=True, help="number of realizations")
    p.add_argument("--first", type=int, default=0, help="first realization index (default 0)")
    add_run_options(p, transient=None)
    p.add_argument(
        "--backend",
        "--device",
        dest="backend",
        choices=("cpu", "gpu", "auto"),
        default="cpu",
        help="cpu (default), gpu (falls back to the CPU with a notice), or auto (the GPU "
        "where one runs and --members is 4,096 or more; --device, as the sweeps call it, is "
        "the same option)",
    )
    p.add_argument(
        "--workers",
        type=int,
        default=None,
        metavar="N",
        help="CPU threads (default: every core numba may use, NUMBA_NUM_THREADS)",
    )
    p.add_argument("--classify", action="store_true", help="label each member from its section")
    p.add_argument("--keep-impacts", action="store_true", help="also write every impact")
    p.add_argument(
        "--chunk",
        type=int,
        default=None,
        help=f"realizations per saved part (default {CPU_CHUNK} on the CPU, {GPU_CHUNK} on a "
        "GPU): an interruption loses at most the part under way",
    )
    p.add_argument("--resume", action="store_true", help="continue an interrupted run")
    p.add_argument(
        "--force",
        action="store_true",
        help="start over: replace existing outputs and discard unfinished parts",
    )
    p.add_argument("--quiet", action="store_true", help="no progress lines")
    p.add_argument("--out", type=path_arg, required=True, help="members to FILE.parquet")
    p.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    from .._outputs import check_output, lock_all
    from . import UsageError

    out: Path = args.out
    if out.suffix != ".parquet":
        raise UsageError(f"--out {out}: the output must end in .parquet")
    if args.force and args.resume:
        raise UsageError("--force starts over and --resume continues: give one of them")
    if args.workers is not None:
        import numba

        most = numba.config.NUMBA_NUM_THREADS
        if not 1 <= args.workers <= most:
            raise UsageError(
                f"--workers {args.workers}: must be in [1, {most}] (the threads numba may "
                "use here: NUMBA_NUM_THREADS)"
            )
    for path in output_paths(out):
        check_output(path, force=True)  # folder and path now; existence under the lock
    from ..sweep._batch import numba_threads

    # The thread count for this run only (fork-safe layer first), restored after.
    with lock_all(output_paths(out)), numba_threads(args.workers):
        return _run_locked(args)


def _run_locked(args: argparse.Namespace) -> int:
    from .._checks import COUNT_MAX, whole
    from .._provenance import code_identity
    from ..sweep._checkpoint import (
        differences,
        discard_checkpoint,
        file_identity,
        not_a_folder,
        remove_leftovers,
    )
    from ..sweep._common import run_settings
    from . import UsageError, interrupts_ignored, parse_assignments, stop_word

    out: Path = args.out
    members_n = whole("--members", args.members, low=1)
    whole("--first", args.first, high=COUNT_MAX - (members_n - 1))  # every index fits int64
    args.backend = _settled(args.backend, members_n)
    params = parse_assignments(args.set)
    duration, transient = run_settings(args.duration, args.transient, args.seed)
    out, sections_path, impacts_path = output_paths(out)
    parts = out.with_suffix(".parts")
    chunk = _chunk(args, parts)
    _check_budget(params, duration, transient, members_n, chunk, args.workers)
    config = {
        "params": params.to_dict(),
        "seed": args.seed,
        "duration": duration,
        "transient": transient,
        "first": args.first,
        "members": args.members,
        "chunk": chunk,
        "classify": args.classify,
        "keep_impacts": args.keep_impacts,
        "code": code_identity(),
    }
    digest = config_digest(config)
    # What the finished members file is stamped with: the part size decides where the run is
    # saved on the way, not what it computes, so a finished run is recognised under any.
    result = config_digest({k: v for k, v in config.items() if k != "chunk"})
    # Of a run killed while it created or deleted its parts, or wrote its outputs.
    for path in (parts, out, sections_path, impacts_path):
        remove_leftovers(path)
    if args.force:
        discard_checkpoint(parts)
    elif args.resume and not parts.exists() and finished_run(out, (result, digest)):
        for path in (sections_path, impacts_path)[: 1 + args.keep_impacts]:
            if not readable_table(path):
                raise UsageError(
                    f"{out} is this configuration's finished run, but {path} is missing or "
                    "damaged; pass --force (without --resume) to compute the run again"
                )
        print(f"already finished: {out} (same configuration); nothing to do")
        return 0
    elif not (args.resume and parts.exists()):  # a resume's outputs: checked with its parts
        for path in (out, sections_path, impacts_path):
            if path.exists() and not args.force:
                # The part size is not recorded: it decides where a run is saved, not what
                # it computes.
                what = differences(
                    recorded_config(out), {k: v for k, v in config.items() if k != "chunk"}
                )
                why = (
                    " and was made by another configuration"
                    + (what or " (or is not a finished chaoscam ensemble)")
                    + ": --resume continues only the same command"
                    if args.resume
                    else ""
                )
                raise FileExistsError(
                    f"{path} exists{why}; choose another --out, remove it, or pass --force to "
                    "replace it"
                )
    if not_a_folder(parts):
        raise FileExistsError(
            f"{parts} is a file where this run keeps its parts folder: move it away, or pass "
            "--force to replace it"
        )
    if parts.exists():
        if not args.resume:
            raise FileExistsError(
                f"{parts} holds an unfinished run; add --resume to continue it (or --force "
                "to start over)"
            )
        if manifest(parts).get("digest") != digest:
            why = differences(manifest(parts).get("config"), config)
            raise UsageError(
                f"{parts} belongs to another configuration{why} (or has no readable "
                "config.json); not resumed: use the original command, or --force to start over"
            )
        check_outputs(parts, (out, sections_path, impacts_path))
    else:
        tmp = parts.with_name(f".tmp-{os.getpid()}-{parts.name}")
        shutil.rmtree(tmp, ignore_errors=True)
        tmp.mkdir()
        replaces = {  # what --force replaces, as it is now (a resume replaces no other)
            p.name: file_identity(p) for p in (out, sections_path, impacts_path) if p.exists()
        }
        saved = {"digest": digest, "config": config, "replaces": replaces}
        atomic_text(tmp / "config.json", json.dumps(saved, indent=1))
        os.replace(tmp, parts)
    for tmp in parts.glob(".tmp-*"):
        tmp.unlink(missing_ok=True)
    # Outputs there now are --force's or this run's (a commit cut short); one that appears
    # while the members run is not replaced at the end.
    ours = {p for p in (out, sections_path, impacts_path) if p.exists()}

    said = _say_before(params, members_n)
    t0 = time.perf_counter()
    done_before = 0
    bar = _bar(args, args.members)
    noticed = []  # the GPU fallback notice is printed once, on one line
    last = args.first + args.members
    starts = range(args.first, last, chunk)
    names = ("members", "sections") + (("impacts",) if args.keep_impacts else ())
    run = PartRun(args, params, duration, transient, parts, names, bar,
                  _progress_batch(args.backend))  # fmt: skip
    backend = backend_for(args.backend)  # on a GPU: the next part launched while one is labelled
    pending = []
    try:
        for start in starts:
            stop = min(start + chunk, last)
            if part_done(parts, start, names):
                done_before += stop - start
                run.update(stop - start)
                continue
            bar.set_description(_SIMULATING, refresh=False)
            pending.append(backend.submit(both_phases, Part(start, stop, run)))
            while len(pending) > 1 or (pending and pending[0].done()):
                _said(backend.result(pending.pop(0)), args, bar, said, noticed)
        while pending:
            _said(backend.result(pending.pop(0)), args, bar, said, noticed)
    except KeyboardInterrupt:
        with interrupts_ignored():  # a second Ctrl-C: the labels under way stop all the same
            backend.cancel(pending)
            backend.close()  # they stop at their next compiled call or member
        bar.close()
        # a part's marker is written last: parts finished here, on the labelling thread,
        # or by an earlier run
        kept = sum(min(s + chunk, last) - s for s in starts if (parts / f"{s:012d}.done").exists())
        print(
            f"chaoscam: {stop_word()}; {kept} of {args.members} members are finished and "
            f"kept in {parts} (parts of {chunk}): run the same command with --resume to "
            "continue",
            file=sys.stderr,
        )
        return 130  # the one message (the sweeps' rule); 143 after SIGTERM
    finally:
        backend.close()
    bar.close()

    members = commit_parts(parts, starts, names, out, result, ours, config)
    wall = time.perf_counter() - t0
    counts = members["label" if args.classify else "status"].value_counts().to_dict()
    print(
        f"{args.members} members ({done_before} from an earlier run) in {wall:.1f} s: "
        + ", ".join(f"{k} {v}" for k, v in sorted(counts.items()))
    )
    print(f"members: {out}")
    print(f"sections: {sections_path}")
    if args.keep_impacts:
        print(f"impacts: {impacts_path}")
    return 0


def _say_before(params, members: int) -> set[str]:
    """Print, once, the warnings every member would get (each part would repeat them), and
    say when the members are all the same run; return the warnings' texts."""
    from .._run_warnings import run_warnings
    from ..model import realizations_identical
    from . import show_warning

    said = run_warnings(params)
    for text in said:
        show_warning(text)
    if members > 1 and realizations_identical(params):
        why = (
            "l_lambda_sigma = 0"
            if params.l_lambda_sigma == 0.0
            else "the fractal stiffness does not depend on the line length"
        )
        show_warning(
            f"{why}: every member is the same deterministic run (an index draws only line "
            "lengths); one member is enough"
        )
    return set(said)


PROGRESS_PER_THREAD = 16
"""CPU members per compiled call in the command: about 2 s of work on each thread for 20 s
runs, so that the progress bar moves (and Ctrl-C is honoured) every few seconds; the
threads' idle tail at the end of each call costs a few per cent."""


def _chunk(args: argparse.Namespace, parts: Path) -> int:
    """Members per saved part: ``--chunk``; else, resuming, the part size the interrupted run
    in ``parts`` started with (so that a run begun with another default, or on a GPU, can be
    resumed by the same command); else :data:`CPU_CHUNK` or :data:`GPU_CHUNK` for the
    backend that will run (``gpu`` or ``auto``: the GPU where one can run, else the CPU)."""
    from .._checks import whole

    if args.chunk is not None:
        return whole("--chunk", args.chunk, low=1)
    if args.resume and not args.force:
        saved = manifest(parts).get("config")
        stored = saved.get("chunk") if isinstance(saved, dict) else None
        if isinstance(stored, int) and not isinstance(stored, bool) and stored >= 1:
            return stored
    from ..integrate._gpu import runs_on_gpu

    return GPU_CHUNK if runs_on_gpu(args.backend) else CPU_CHUNK


def _said(done, args, bar, said: set[str], noticed: list) -> None:
    """What a written part says on the terminal (the command's thread, in the parts'
    order): its recorded warnings (the GPU fallback once, on one line; not those said before
    the run) and its rate."""
    from ..integrate._gpu import GPUFallbackWarning

    for w in done.caught:
        if issubclass(w.category, GPUFallbackWarning):
            if not noticed:
                print(f"chaoscam: {w.message}", file=sys.stderr, flush=True)
                noticed.append(True)
        elif str(w.message) not in said:
            warnings.warn_explicit(w.message, w.category, w.filename, w.lineno)
    if not args.quiet:
        bar.write(
            f"members {done.start}..{done.stop - 1}: {done.backend}, "
            f"{(done.stop - done.start) / (time.perf_counter() - done.began):.1f} members/s"
            + (" with their labels" if args.classify else "")
        )


def _settled(backend: str, members: int) -> str:
    """The backend every part runs on: ``auto`` settled once for the whole run, by its size
    (:func:`chaoscam.integrate._gpu.by_size`) and the GPU here, so that a short last part
    does not move to the other device."""
    from ..integrate._gpu import by_size, runs_on_gpu

    backend = by_size(backend, members)
    if backend == "auto":
        return "gpu" if runs_on_gpu(backend) else "cpu"
    return backend


def _progress_batch(backend: str) -> int | None:
    """Members per compiled call: small on the CPU (progress), the default where a GPU runs
    them (``gpu`` or ``auto`` with a GPU here; without one both run on the CPU)."""
    from ..integrate._driver import thread_count
    from ..integrate._gpu import runs_on_gpu

    if runs_on_gpu(backend):
        return None

    return PROGRESS_PER_THREAD * thread_count()


_SIMULATING = "ensemble (simulated)"


def _bar(args, total: int):
    """A progress bar over the runs on stderr, with rate and ETA (none with --quiet): one
    per member, and one more per extension of an undetermined member (its total grows when
    the classifier extends some)."""
    from tqdm.auto import tqdm

    return tqdm(
        total=total,
        unit="run",
        desc=_SIMULATING,
        file=sys.stderr,
        disable=args.quiet,
        dynamic_ncols=True,
        smoothing=0.1,
        mininterval=0.5,
    )


def _check_budget(
    params, duration: float, transient: float, members: int, chunk: int, workers=None
) -> None:
    """Refuse an ensemble whose joined tables cannot fit in memory; warn about hours."""
    from .._budget import JobEstimate, check_budget, estimate
    from ..sweep._backends import default_workers

    one = estimate(params, duration=duration, transient=transient)
    cores = workers or default_workers()
    job = JobEstimate((one.bytes * (members + min(chunk, members)), one.seconds * members / cores))
    check_budget(
        job,
        what="this ensemble",
        reduce="--members or --duration",
        run=dict(params=params, duration=duration, what="each member"),
    )
