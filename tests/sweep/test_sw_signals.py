"""Signals: SIGTERM is handled like Ctrl-C (finished runs saved, a resume hint, exit 143)."""

import os
import signal

from chaoscam.sweep import checkpoint_dir

from .test_sw_cli import MAP, SLOW, _start, _wait_for_parts


def _two_worker_run(tmp_path):
    out = tmp_path / "m.parquet"
    args = [*MAP, "--workers", "2", "--checkpoint-interval", "0", "--out", str(out)]
    args[args.index("tests.sweep._helpers:SpreadClassifier")] = SLOW
    proc = _start(args)
    _wait_for_parts(out, 2, proc)
    return proc, args


def test_sigterm_saves_and_says_how_to_resume(tmp_path):
    """SIGTERM to the driver: finished runs saved, the resume hint printed, exit 143, no
    traceback; --resume then finishes."""
    proc, args = _two_worker_run(tmp_path)
    os.kill(proc.pid, signal.SIGTERM)
    _, err = proc.communicate(timeout=60)
    assert proc.returncode == 143, err
    assert "--resume" in err and "Traceback" not in err
    assert "terminated;" in err and "interrupted" not in err
    out = tmp_path / "m.parquet"
    assert not out.exists() and list(checkpoint_dir(out).glob("part-*.jsonl"))
    proc = _start([*args, "--resume"])
    _, err = proc.communicate(timeout=120)
    assert proc.returncode == 0, err
    assert out.exists() and not checkpoint_dir(out).exists()
