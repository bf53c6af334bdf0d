"""``chaoscam ensemble``: many realizations in compiled batches (CPU threads or a GPU).

Each chunk of realizations is written to ``FILE.parts/`` as soon as it is done (written to a
temporary name, then renamed), so an interrupted run keeps what it finished; ``--resume``
skips the chunks already there, after checking that they belong to the same configuration.
When all chunks are done they are joined into ``FILE.parquet`` (one row per member),
``FILE.sections.parquet`` and, with ``--keep-impacts``, ``FILE.impacts.parquet``, and the parts
are removed.
"""

from __future__ import annotations

import argparse
import hashlib
import json
import shutil
import sys
import time
import warnings
from pathlib import Path

__all__ = ["register"]

_CHUNK = 1024


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
    p.add_argument("--seed", type=int, default=0, help="master seed of the line-length process")
    p.add_argument("--duration", type=float, default=20.0, help="end time [s] (default 20)")
    p.add_argument("--transient", type=float, default=None,
                   help="discarded start [s] (default: half the duration)")
    p.add_argument(
        "--set", action="append", metavar="NAME=VALUE", default=[],
        help="override a model parameter (repeatable), e.g. --set l_lambda_sigma=0.002",
    )
    p.add_argument("--backend", choices=("cpu", "gpu", "auto"), default="cpu",
                   help="cpu (default), gpu (falls back to the CPU with a notice), or auto")
    p.add_argument("--classify", action="store_true", help="label each member from its section")
    p.add_argument("--keep-impacts", action="store_true", help="also write every impact")
    p.add_argument("--chunk", type=int, default=_CHUNK,
                   help=f"realizations per saved part (default {_CHUNK})")
    p.add_argument("--resume", action="store_true", help="continue an interrupted run")
    p.add_argument("--quiet", action="store_true", help="no progress lines")
    p.add_argument("--out", type=Path, required=True, help="members to FILE.parquet")
    p.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    import pandas as pd

    from .cli import UsageError, parse_assignments
    from .integrate import simulate_ensemble
    from .integrate._gpu import GPUFallbackWarning
    from .sweep._common import run_settings

    out: Path = args.out
    if out.suffix != ".parquet":
        raise UsageError(f"--out {out}: the output must end in .parquet")
    if args.members < 1:
        raise UsageError(f"--members = {args.members} must be >= 1")
    if args.first < 0:
        raise UsageError(f"--first = {args.first} must be >= 0")
    if args.chunk < 1:
        raise UsageError(f"--chunk = {args.chunk} must be >= 1")
    params = parse_assignments(args.set)
    duration, transient = run_settings(args.duration, args.transient, args.seed)

    sections_path = out.with_suffix(".sections.parquet")
    impacts_path = out.with_suffix(".impacts.parquet")
    parts = out.with_suffix(".parts")
    for path in (out, sections_path, impacts_path):
        if path.exists():
            raise FileExistsError(f"{path} exists; choose another --out or remove it")
    config = {
        "params": params.to_dict(),
        "seed": args.seed,
        "duration": duration,
        "transient": transient,
        "first": args.first,
        "members": args.members,
        "chunk": args.chunk,
        "classify": args.classify,
        "keep_impacts": args.keep_impacts,
    }
    digest = hashlib.sha256(json.dumps(config, sort_keys=True).encode()).hexdigest()[:16]
    manifest = parts / "config.json"
    if parts.exists():
        if not args.resume:
            raise FileExistsError(
                f"{parts} holds an unfinished run; add --resume to continue it"
            )
        old = json.loads(manifest.read_text()) if manifest.exists() else {}
        if old.get("digest") != digest:
            raise UsageError(f"{parts} belongs to another configuration; not resumed")
    else:
        parts.mkdir(parents=True)
        manifest.write_text(json.dumps({"digest": digest, "config": config}, indent=1))

    t0 = time.perf_counter()
    done_before = 0
    noticed = False  # the GPU fallback notice is printed once, on one line
    last = args.first + args.members
    starts = range(args.first, last, args.chunk)
    for start in starts:
        stop = min(start + args.chunk, last)
        mark = parts / f"{start:012d}.done"
        if mark.exists():
            done_before += stop - start
            continue
        try:
            with warnings.catch_warnings(record=True) as caught:
                warnings.simplefilter("always", GPUFallbackWarning)
                ens = simulate_ensemble(
                    params, range(start, stop), seed=args.seed, duration=duration,
                    transient=transient, backend=args.backend, keep_impacts=args.keep_impacts,
                    classify=args.classify,
                )
            for w in caught:
                if issubclass(w.category, GPUFallbackWarning) and not noticed:
                    print(f"chaoscam: {w.message}", file=sys.stderr, flush=True)
                    noticed = True
                elif not issubclass(w.category, GPUFallbackWarning):
                    warnings.warn_explicit(w.message, w.category, w.filename, w.lineno)
        except KeyboardInterrupt:
            print(f"chaoscam: interrupted; the finished parts are in {parts}: run the same "
                  "command with --resume to continue", file=sys.stderr)
            raise
        offset = start - args.first
        tables = {"members": ens.members, "sections": ens.sections, "impacts": ens.impacts}
        for name, table in tables.items():
            if table is None:
                continue
            table = table.assign(member=table["member"] + offset)
            tmp = parts / f"{start:012d}.{name}.tmp"
            table.to_parquet(tmp, index=False)
            tmp.rename(parts / f"{start:012d}.{name}.parquet")
        mark.write_text(json.dumps(ens.settings, default=str))
        if not args.quiet:
            print(f"members {start}..{stop - 1}: {ens.settings['backend']}, "
                  f"{(stop - start) / ens.settings['wall_time_s']:.1f} traj/s", flush=True)

    def joined(name: str) -> pd.DataFrame:
        return pd.concat(
            [pd.read_parquet(parts / f"{s:012d}.{name}.parquet") for s in starts],
            ignore_index=True,
        )

    members = joined("members")
    members.to_parquet(out, index=False)
    joined("sections").to_parquet(sections_path, index=False)
    if args.keep_impacts:
        joined("impacts").to_parquet(impacts_path, index=False)
    shutil.rmtree(parts)
    wall = time.perf_counter() - t0
    counts = members["label" if args.classify else "status"].value_counts().to_dict()
    print(f"{args.members} members ({done_before} from an earlier run) in {wall:.1f} s: "
          + ", ".join(f"{k} {v}" for k, v in sorted(counts.items())))
    print(f"members: {out}")
    print(f"sections: {sections_path}")
    if args.keep_impacts:
        print(f"impacts: {impacts_path}")
    return 0
