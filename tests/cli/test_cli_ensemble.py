"""``chaoscam ensemble``: outputs, refusal of bad input, and resuming an interrupted run."""

import threading

import numpy as np
import pandas as pd
import pytest

import chaoscam
from chaoscam import Numerics, Params
from chaoscam.cli import main
from chaoscam.sweep import _engine, checkpoint_dir, read_ensemble
from chaoscam.sweep._store import decode_part

ARGS = [
    "ensemble",
    "--members",
    "5",
    "--duration",
    "1.0",
    "--transient",
    "0.5",
    "--set",
    "l_lambda_sigma=0.002",
    "--seed",
    "4",
    "--workers",
    "1",
    "--quiet",
]


def test_writes_members_and_sections_equal_to_solve_and_classify(tmp_path):
    """The members' sections are chaoscam.solve's of the same realizations, their labels and
    reasons chaoscam.classify's; the checkpoint is gone once the outputs are written."""
    out = tmp_path / "ens.parquet"
    assert main([*ARGS, "--classify", "--out", str(out)]) == 0
    members = pd.read_parquet(out)
    sections = pd.read_parquet(tmp_path / "ens.sections.parquet")
    assert not checkpoint_dir(out).exists()
    p = Params(l_lambda_sigma=0.002)
    sol = chaoscam.solve(p, indices=range(5), seed=4, duration=1.0, transient=0.5, tangent=True)
    verdicts = chaoscam.classify(sol)
    assert list(members["index"]) == list(range(5)) and list(members["member"]) == list(range(5))
    assert list(sections.columns) == list(sol.sections.columns)
    assert np.array_equal(sections.to_numpy(), sol.sections.to_numpy())
    assert list(members["label"]) == [v.label for v in verdicts]
    assert list(members["reasons"]) == ["; ".join(v.reasons) for v in verdicts]
    assert list(members["n_impacts"]) == list(sol.members["n_impacts"])


def _interrupted(tmp_path, monkeypatch, extra=()) -> None:
    """Run ARGS into tmp_path/ens.parquet in batches of 2 members, Ctrl-C'd in its second
    batch."""
    monkeypatch.setattr(_engine, "batch_size", lambda *a, **k: 2)
    real = _engine.run_batch
    calls = []

    def interrupted_in_the_second_batch(batch):
        calls.append(1)
        if len(calls) == 2:
            raise KeyboardInterrupt
        return real(batch)

    monkeypatch.setattr(_engine, "run_batch", interrupted_in_the_second_batch)
    assert main([*ARGS, *extra, "--out", str(tmp_path / "ens.parquet")]) == 130
    monkeypatch.setattr(_engine, "run_batch", real)


def test_an_interrupted_run_resumes_to_the_same_result(tmp_path, monkeypatch, capsys):
    """Ctrl-C after the first batch keeps it; --resume finishes to the uninterrupted result."""
    whole = tmp_path / "whole.parquet"
    assert main([*ARGS, "--out", str(whole)]) == 0
    out = tmp_path / "ens.parquet"
    _interrupted(tmp_path, monkeypatch)
    err = capsys.readouterr().err
    said = [line for line in err.splitlines() if "interrupted" in line]
    assert len(said) == 1 and "--resume" in said[0]  # one message, with the resume hint
    assert "2 of 5 runs are saved" in said[0]  # what is kept, counted
    parts = checkpoint_dir(out).glob("part-*.jsonl")
    assert not out.exists() and sum(len(decode_part(p.read_bytes())) for p in parts) == 2
    assert main([*ARGS, "--out", str(out)]) == 2  # an unfinished run is not overwritten
    assert main([*ARGS, "--set", "xi=0.3", "--resume", "--out", str(out)]) == 2  # not its config
    assert main([*ARGS, "--resume", "--out", str(out)]) == 0
    assert pd.read_parquet(out).equals(pd.read_parquet(whole))
    a = pd.read_parquet(tmp_path / "ens.sections.parquet")
    assert a.equals(pd.read_parquet(tmp_path / "whole.sections.parquet"))
    assert not checkpoint_dir(out).exists()


@pytest.mark.parametrize("name", ["ens.parquet", "ens.sections.parquet"])
def test_a_file_made_at_the_output_after_the_interruption_is_kept(
    tmp_path, monkeypatch, name, capsys
):
    """Ctrl-C, another command writes the free output name, --resume: refused, the file kept
    (the resume replaced it silently); a --force run's own replaced output is replaced."""
    _interrupted(tmp_path, monkeypatch)
    made = tmp_path / name
    made.write_bytes(b"someone else's")
    out = tmp_path / "ens.parquet"
    assert main([*ARGS, "--resume", "--out", str(out)]) == 2
    assert "not there, or not as it is now" in capsys.readouterr().err
    assert made.read_bytes() == b"someone else's"
    # the same file, there before a --force run that was interrupted: that run replaces it
    _interrupted(tmp_path, monkeypatch, ["--force"])
    assert main([*ARGS, "--resume", "--out", str(out)]) == 0
    assert made.read_bytes() != b"someone else's" and pd.read_parquet(out).shape[0] == 5


def test_a_finished_run_with_a_damaged_companion_is_not_reused(tmp_path, capsys):
    """--resume over a finished run whose sections file is cut short: exit 2 naming the run
    and --force (not "already finished", after which the report failed on it); with the
    sections file gone, --resume computes the run again, to the same tables."""
    out = tmp_path / "ens.parquet"
    assert main([*ARGS, "--out", str(out)]) == 0
    members = pd.read_parquet(out)
    sections = tmp_path / "ens.sections.parquet"
    whole = pd.read_parquet(sections)
    sections.write_bytes(sections.read_bytes()[:500])
    assert main([*ARGS, "--resume", "--out", str(out)]) == 2
    err = capsys.readouterr().err
    assert "ens.parquet is this configuration's finished run, but it or its companion" in err
    assert "--force" in err
    sections.unlink()
    assert main([*ARGS, "--resume", "--out", str(out)]) == 0
    pd.testing.assert_frame_equal(pd.read_parquet(sections), whole)
    pd.testing.assert_frame_equal(pd.read_parquet(out), members)


def test_sigterm_says_terminated_once(tmp_path, monkeypatch, capsys):
    """SIGTERM during the members (what chaoscam.cli's handler does: a KeyboardInterrupt
    after noting the signal): one "terminated" line with what is kept and the resume hint,
    exit 143."""
    import chaoscam.cli as cli

    def terminated(batch):
        cli._SIGTERM["seen"] = True
        raise KeyboardInterrupt

    monkeypatch.setattr(_engine, "run_batch", terminated)
    assert main([*ARGS, "--out", str(tmp_path / "ens.parquet")]) == 143
    err = capsys.readouterr().err
    assert "interrupted" not in err
    said = [line for line in err.splitlines() if "terminated" in line]
    assert len(said) == 1 and "--resume" in said[0] and "0 of 5 runs" in said[0]


def test_resuming_a_finished_run_with_other_workers_does_nothing(tmp_path, capsys):
    """--resume on a finished output says "already finished" whatever the worker count (it
    decides where the runs go, not what they compute); another configuration is still
    refused, saying what differs, and the output is left as it was."""
    out = tmp_path / "e.parquet"
    assert main([*ARGS, "--out", str(out)]) == 0
    before = out.read_bytes()
    capsys.readouterr()
    loud = [a for a in ARGS if a != "--quiet"]
    for workers in ("1", "2"):
        args = [*loud[: loud.index("--workers") + 1], workers, *loud[loud.index("--workers") + 2 :]]
        assert main([*args, "--resume", "--out", str(out)]) == 0
        assert "already finished" in capsys.readouterr().err
    assert main([*ARGS, "--set", "xi=0.3", "--resume", "--out", str(out)]) == 2
    err = capsys.readouterr().err
    assert "was made by a different configuration (it differs in: params)" in err
    assert out.read_bytes() == before


@pytest.mark.parametrize(
    "extra, needle",
    [
        (["--members", "0"], "members"),
        (["--set", "omgea=3"], "omgea"),
        (["--duration", "-1"], "duration"),
        (["--transient", "5"], "transient"),
    ],
)
def test_bad_input_exits_2_naming_the_field(tmp_path, capsys, extra, needle):
    out = tmp_path / "e.parquet"
    assert main([*ARGS, *extra, "--out", str(out)]) == 2
    assert needle in capsys.readouterr().err
    assert not out.exists()


def test_an_existing_output_is_not_overwritten(tmp_path):
    out = tmp_path / "e.parquet"
    out.write_text("keep")
    assert main([*ARGS, "--out", str(out)]) == 2
    assert out.read_text() == "keep"


def _gpu_here(monkeypatch, ready: bool, why: str) -> None:
    """gpu_status says (ready, why), wherever the engine and solve ask."""
    import chaoscam.kernel
    from chaoscam.kernel import _gpu
    from chaoscam.simulation import _solve

    status = lambda: (ready, why)  # noqa: E731
    for module in (_gpu, _solve, chaoscam.kernel):
        monkeypatch.setattr(module, "gpu_status", status, raising=False)


def test_gpu_fallback_is_one_line(tmp_path, capsys, monkeypatch):
    """--device gpu without a usable GPU: one stderr line with the reason, CPU results."""
    _gpu_here(monkeypatch, False, "no CUDA device (test)")
    out = tmp_path / "e.parquet"
    assert main([*ARGS, "--device", "gpu", "--out", str(out)]) == 0
    err = [line for line in capsys.readouterr().err.splitlines() if line.strip()]
    assert len(err) == 1 and "no CUDA device (test)" in err[0] and "CPU" in err[0]
    assert len(pd.read_parquet(out)) == 5
    assert read_ensemble(out).config["device"] == "cpu"


def test_auto_settles_once_by_the_run_size(tmp_path, monkeypatch):
    """--device auto is settled once for the whole run: the CPU below AUTO_GPU_MIN members
    even with a GPU here, else the GPU where one runs, so that a short last batch does not
    move to the other device; cpu and gpu are kept as asked."""
    from chaoscam.kernel import AUTO_GPU_MIN, by_size
    from chaoscam.sweep._runs import Judge

    for gpu, small, large in [(True, "cpu", "gpu"), (False, "cpu", "cpu")]:
        _gpu_here(monkeypatch, gpu, "test")
        for members, want in ((AUTO_GPU_MIN - 1, small), (AUTO_GPU_MIN, large)):
            run = (Params(), Numerics(), (1.0, 0.5), 1, None)
            eng = _engine.resolve_engine(Judge(), by_size("auto", members), *run)
            assert eng.device == want, (gpu, members)
        assert by_size("gpu", 1) == "gpu" and by_size("cpu", 10**6) == "cpu"
    _gpu_here(monkeypatch, True, "test")
    out = tmp_path / "a.parquet"
    assert main([*ARGS, "--device", "auto", "--out", str(out)]) == 0  # 5 members: the CPU
    assert len(pd.read_parquet(out)) == 5
    assert read_ensemble(out).config["device"] == "cpu"


def test_progress_counts_every_member(tmp_path, capsys):
    """The progress bar (stderr) has the total from the start and reaches it."""
    out = tmp_path / "p.parquet"
    loud = [a for a in ARGS if a != "--quiet"]
    assert main([*loud, "--out", str(out)]) == 0
    err = capsys.readouterr().err
    assert "ensemble:" in err and "/5" in err and "5/5" in err


def test_progress_ends_full_after_the_extensions(tmp_path, capsys):
    """With --classify, members undetermined after the run are extended before their
    record counts: the bar ends full when the extended verdicts are in (no silent phase
    after 100 %), and no member is left undetermined."""
    out = tmp_path / "x.parquet"
    args = ["ensemble", "--members", "2", "--duration", "20", "--transient", "10"]
    sets = ["--set", "omega=27", "--set", "xi=0.5", "--seed", "1", "--classify"]
    assert main([*args, *sets, "--out", str(out)]) == 0
    err = capsys.readouterr().err
    assert "2/2" in err, err
    members = pd.read_parquet(out)
    assert "undetermined" not in set(members["label"])
    assert (members["recorded_s"] > 10.0).all()  # their verdicts needed the extension


def test_a_too_coarse_step_is_warned_once_and_sigma_zero_is_named(tmp_path, capsys, monkeypatch):
    """The warnings every member would get are printed once, not once per batch (here 3
    batches), and a sigma = 0 ensemble says that its members are one run; the API warns as
    simulate() does, once per distinct warning."""
    monkeypatch.setattr(_engine, "batch_size", lambda *a, **k: 1)
    out = tmp_path / "w.parquet"
    args = ["ensemble", "--members", "3", "--workers", "1", "--duration", "0.5", "--quiet"]
    assert main([*args, "--set", "dt=2e-5", "--out", str(out)]) == 0
    err = capsys.readouterr().err
    assert err.count("resolves the contact oscillation") == 1, err
    assert err.count("every member is the same deterministic run") == 1
    with pytest.warns(RuntimeWarning, match="resolves the contact oscillation") as caught:
        chaoscam.solve(Params(), Numerics(dt=2e-5), indices=range(3), duration=0.2)
    assert len([w for w in caught if "contact oscillation" in str(w.message)]) == 1
    two = tmp_path / "s.parquet"
    assert main([*args, "--set", "l_lambda_sigma=0.002", "--out", str(two)]) == 0
    assert "deterministic" not in capsys.readouterr().err


def test_a_file_where_the_checkpoint_folder_goes(tmp_path, capsys):
    """A file at FILE.parquet.ckpt: exit 2 saying so (not that the file held an unfinished
    run); --force replaces it and leaves only the outputs."""
    out = tmp_path / "e.parquet"
    checkpoint_dir(out).write_text("not mine")
    base = ["ensemble", "--members", "2", "--duration", "0.5", "--quiet", "--out", str(out)]
    assert main(base) == 2
    assert "e.parquet.ckpt is a file where this run keeps its checkpoint folder" in (
        capsys.readouterr().err
    )
    assert main([*base, "--force"]) == 0
    assert sorted(p.name for p in tmp_path.iterdir()) == ["e.parquet", "e.sections.parquet"]


def test_workers_and_device_on_the_ensemble_command(tmp_path, capsys, monkeypatch):
    """--workers N runs the batches on N threads (1: in the command's own thread), numba's
    thread count restored after; the members are the same as with every core; --workers 0
    is refused naming it; --device is accepted."""
    import numba

    base = ["ensemble", "--members", "3", "--duration", "0.5", "--quiet"]
    threads = numba.get_num_threads()
    seen = set()
    real = _engine.run_batch

    def spy(batch):
        seen.add(threading.current_thread().name)
        return real(batch)

    monkeypatch.setattr(_engine, "run_batch", spy)
    a_out = str(tmp_path / "a.parquet")
    assert main([*base, "--workers", "1", "--device", "cpu", "--out", a_out]) == 0
    assert seen == {threading.main_thread().name} and numba.get_num_threads() == threads
    seen.clear()
    assert main([*base, "--workers", "2", "--out", str(tmp_path / "b.parquet")]) == 0
    assert seen and all(n.startswith("chaoscam-batch") for n in seen)
    assert numba.get_num_threads() == threads
    a, b = (pd.read_parquet(tmp_path / f"{n}.parquet") for n in "ab")
    assert a.equals(b)
    assert main([*base, "--workers", "0", "--out", str(tmp_path / "c.parquet")]) == 2
    assert "--workers 0" in capsys.readouterr().err
    assert not (tmp_path / "c.parquet").exists()
