"""Signals and orphans: SIGTERM is handled like Ctrl-C (saved, resume hint, exit 143), and
pool workers never outlive their driver, even one killed with SIGKILL."""

import os
import signal
import time
from pathlib import Path

import pytest

from .test_sw_cli import MAP, SLOW, _start, _wait_for_parts


def _children(pid: int) -> list[int]:
    kids = []
    for entry in Path("/proc").iterdir():
        if entry.name.isdigit():
            try:
                stat = (entry / "stat").read_text()
            except OSError:
                continue
            if int(stat.rsplit(")", 1)[1].split()[1]) == pid:
                kids.append(int(entry.name))
    return kids


def _alive(pids, timeout=10.0) -> list[int]:
    t0 = time.monotonic()
    while True:
        left = [
            p
            for p in pids
            if Path(f"/proc/{p}").exists()
            and "Z" not in (Path(f"/proc/{p}/stat").read_text().rsplit(")", 1)[1][:3])
        ]
        if not left or time.monotonic() - t0 > timeout:
            return left
        time.sleep(0.05)


def _two_worker_run(tmp_path):
    out = tmp_path / "m.parquet"
    args = [*MAP, "--workers", "2", "--checkpoint-interval", "0", "--out", str(out)]
    args[args.index("tests.sweep._helpers:SpreadClassifier")] = SLOW
    proc = _start(args)
    _wait_for_parts(out, 2, proc)
    return proc, args


@pytest.mark.skipif(not Path("/proc/self/stat").exists(), reason="needs Linux /proc")
def test_sigkilled_driver_takes_its_workers_along(tmp_path):
    """SIGKILL of the driver alone (not its process group): its pool workers exit too."""
    proc, _ = _two_worker_run(tmp_path)
    workers = _children(proc.pid)
    assert len(workers) >= 2
    os.kill(proc.pid, signal.SIGKILL)
    proc.communicate(timeout=30)
    left = _alive(workers)
    for pid in left:  # never leave them behind, even when the test fails
        os.kill(pid, signal.SIGKILL)
    assert left == []


def test_sigterm_saves_and_says_how_to_resume(tmp_path):
    """SIGTERM to the driver: finished runs saved, the resume hint printed, exit 143, no
    traceback, no worker left; --resume then finishes."""
    proc, args = _two_worker_run(tmp_path)
    workers = _children(proc.pid)
    os.kill(proc.pid, signal.SIGTERM)
    _, err = proc.communicate(timeout=60)
    assert proc.returncode == 143, err
    assert "--resume" in err and "Traceback" not in err
    assert "terminated;" in err and "interrupted" not in err
    assert _alive(workers) == []
    proc = _start([*args, "--resume"])
    _, err = proc.communicate(timeout=120)
    assert proc.returncode == 0, err
