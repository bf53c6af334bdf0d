"""``chaoscam ensemble``: outputs, refusal of bad input, and resuming an interrupted run."""

import re

import numpy as np
import pandas as pd
import pytest

from chaoscam import Params, classify_ensemble
from chaoscam.cli import main
from chaoscam.integrate import simulate_ensemble

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
    "--chunk",
    "2",
    "--quiet",
]


def test_writes_members_sections_impacts_equal_to_the_api(tmp_path):
    out = tmp_path / "ens.parquet"
    assert main([*ARGS, "--classify", "--keep-impacts", "--out", str(out)]) == 0
    members = pd.read_parquet(out)
    sections = pd.read_parquet(tmp_path / "ens.sections.parquet")
    impacts = pd.read_parquet(tmp_path / "ens.impacts.parquet")
    assert not (tmp_path / "ens.parts").exists()
    p = Params(l_lambda_sigma=0.002)
    api = classify_ensemble(
        simulate_ensemble(
            p, range(5), seed=4, duration=1.0, transient=0.5, keep_impacts=True, tangent=True
        ),
        p,
    )
    assert list(members["index"]) == list(range(5)) and list(members["member"]) == list(range(5))
    assert np.array_equal(sections.to_numpy(), api.sections.to_numpy())
    assert np.array_equal(impacts.to_numpy(), api.impacts.to_numpy())
    assert list(members.label) == list(api.members.label)
    assert list(members.reasons) == list(api.members.reasons)


def _interrupted(tmp_path, monkeypatch, extra=()) -> None:
    """Run ARGS into tmp_path/ens.parquet, Ctrl-C'd on its second part."""
    import chaoscam.integrate as integrate

    real = integrate.simulate_ensemble
    calls = []

    def interrupted_on_the_second_part(*args, **kwargs):
        calls.append(1)
        if len(calls) == 2:
            raise KeyboardInterrupt
        return real(*args, **kwargs)

    monkeypatch.setattr(integrate, "simulate_ensemble", interrupted_on_the_second_part)
    assert main([*ARGS, *extra, "--out", str(tmp_path / "ens.parquet")]) == 130
    monkeypatch.setattr(integrate, "simulate_ensemble", real)


def test_an_interrupted_run_resumes_to_the_same_result(tmp_path, monkeypatch, capsys):
    """Ctrl-C after the first part keeps it; --resume finishes to the uninterrupted result."""
    whole = tmp_path / "whole.parquet"
    assert main([*ARGS, "--out", str(whole)]) == 0
    out = tmp_path / "ens.parquet"
    _interrupted(tmp_path, monkeypatch)
    err = capsys.readouterr().err
    said = [line for line in err.splitlines() if "interrupted" in line]
    assert len(said) == 1 and "--resume" in said[0]  # one message, with the resume hint
    assert "2 of 5 members are finished" in said[0]  # what is kept, counted
    assert not out.exists() and len(list((tmp_path / "ens.parts").glob("*.done"))) == 1
    assert main([*ARGS, "--out", str(out)]) == 2  # an unfinished run is not overwritten
    assert main([*ARGS, "--set", "xi=0.3", "--resume", "--out", str(out)]) == 2  # not its config
    # resumed without --chunk: the part size the run started with (2), not today's default
    unsized = [a for i, a in enumerate(ARGS) if "--chunk" not in ARGS[max(i - 1, 0) : i + 1]]
    assert main([*unsized, "--resume", "--out", str(out)]) == 0
    assert pd.read_parquet(out).equals(pd.read_parquet(whole))
    a = pd.read_parquet(tmp_path / "ens.sections.parquet")
    assert a.equals(pd.read_parquet(tmp_path / "whole.sections.parquet"))


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
    """--resume over a finished run whose sections file is cut short (or gone) said
    "already finished"; the report then failed on it. Now: exit 2 naming the file."""
    out = tmp_path / "ens.parquet"
    assert main([*ARGS, "--out", str(out)]) == 0
    sections = tmp_path / "ens.sections.parquet"
    sections.write_bytes(sections.read_bytes()[:500])
    assert main([*ARGS, "--resume", "--out", str(out)]) == 2
    assert "ens.sections.parquet is missing or damaged" in capsys.readouterr().err
    sections.unlink()
    assert main([*ARGS, "--resume", "--out", str(out)]) == 2


def test_sigterm_says_terminated_once(tmp_path, monkeypatch, capsys):
    """SIGTERM during the members (what chaoscam.cli's handler does: a KeyboardInterrupt
    after noting the signal): one "terminated" line with what is kept and the resume hint,
    exit 143."""
    import chaoscam.cli as cli
    import chaoscam.integrate as integrate

    def terminated(*args, **kwargs):
        cli._SIGTERM["seen"] = True
        raise KeyboardInterrupt

    monkeypatch.setattr(integrate, "simulate_ensemble", terminated)
    assert main([*ARGS, "--out", str(tmp_path / "ens.parquet")]) == 143
    err = capsys.readouterr().err
    assert "interrupted" not in err
    said = [line for line in err.splitlines() if "terminated" in line]
    assert len(said) == 1 and "--resume" in said[0] and "0 of 5 members" in said[0]


def test_resuming_a_finished_run_under_another_part_size_does_nothing(tmp_path, capsys):
    """--resume on a finished output says "already finished" whatever the part size (it
    decides where the run is saved, not what it computes); another configuration is still
    refused, and the output is left as it was."""
    out = tmp_path / "e.parquet"
    assert main([*ARGS, "--out", str(out)]) == 0
    before = out.read_bytes()
    capsys.readouterr()
    unsized = [a for i, a in enumerate(ARGS) if "--chunk" not in ARGS[max(i - 1, 0) : i + 1]]
    for args in (ARGS, unsized, [*unsized, "--chunk", "3"]):
        assert main([*args, "--resume", "--out", str(out)]) == 0
        assert "already finished" in capsys.readouterr().out
    assert main([*ARGS, "--set", "xi=0.3", "--resume", "--out", str(out)]) == 2
    # ... saying what differs (it did not), and not the part size, which is not recorded
    err = capsys.readouterr().err
    assert "exists and was made by another configuration (it differs in: params)" in err
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


def test_gpu_fallback_is_one_line(tmp_path, capsys, monkeypatch):
    """--backend gpu without a usable GPU: one stderr line with the reason, CPU results."""
    from chaoscam.integrate import _gpu

    monkeypatch.setattr(_gpu, "gpu_status", lambda: (False, "no CUDA device (test)"))
    out = tmp_path / "e.parquet"
    assert main([*ARGS, "--backend", "gpu", "--out", str(out)]) == 0
    err = [line for line in capsys.readouterr().err.splitlines() if line.strip()]
    assert len(err) == 1 and "no CUDA device (test)" in err[0] and "CPU" in err[0]
    assert len(pd.read_parquet(out)) == 5


@pytest.mark.parametrize(
    "backend, gpu, chunk", [("cpu", True, 128), ("gpu", True, 8192), ("gpu", False, 128),
                            ("auto", False, 128), ("auto", True, 8192)]
)  # fmt: skip
def test_default_part_size_follows_the_backend_that_runs(
    tmp_path, monkeypatch, backend, gpu, chunk
):
    """Without --chunk a part holds 128 members on the CPU (an interruption loses little),
    8,192 where a GPU runs them (not where --backend gpu falls back to the CPU); an explicit
    --chunk wins, and a bad one is refused."""
    import argparse

    from chaoscam.cli import _ensemble
    from chaoscam.integrate import _gpu
    from chaoscam.model import ParameterError

    monkeypatch.setattr(_gpu, "gpu_status", lambda: (gpu, "test"))

    def ns(size, resume=False):
        return argparse.Namespace(backend=backend, chunk=size, resume=resume, force=False)

    assert _ensemble._chunk(ns(None), tmp_path / "none.parts") == chunk
    assert _ensemble._chunk(ns(None, resume=True), tmp_path / "none.parts") == chunk
    assert _ensemble._chunk(ns(7), tmp_path / "none.parts") == 7
    with pytest.raises(ParameterError, match="--chunk"):
        _ensemble._chunk(ns(0), tmp_path / "none.parts")


def test_auto_settles_once_by_the_run_size(tmp_path, monkeypatch):
    """--backend auto is settled once for the whole run: the CPU below AUTO_GPU_MIN members
    even with a GPU here, else the GPU where one runs, so that a short last part does not
    move to the other device; cpu and gpu are kept as asked."""
    from chaoscam.cli import _ensemble
    from chaoscam.integrate import _gpu

    for gpu, small, large in [(True, "cpu", "gpu"), (False, "cpu", "cpu")]:
        monkeypatch.setattr(_gpu, "gpu_status", lambda gpu=gpu: (gpu, "test"))
        assert _ensemble._settled("auto", _gpu.AUTO_GPU_MIN - 1) == small
        assert _ensemble._settled("auto", _gpu.AUTO_GPU_MIN) == large
        assert _ensemble._settled("gpu", 1) == "gpu" and _ensemble._settled("cpu", 10**6) == "cpu"
    monkeypatch.setattr(_gpu, "gpu_status", lambda: (True, "test"))
    out = tmp_path / "a.parquet"
    assert main([*ARGS, "--backend", "auto", "--out", str(out)]) == 0  # 5 members: the CPU
    assert len(pd.read_parquet(out)) == 5


def test_progress_counts_every_member_from_the_first_batch(tmp_path, capsys):
    """The progress bar (stderr) has the total from the start and reaches it; the compiled
    calls are small batches, so it moves before the first part is done."""
    out = tmp_path / "p.parquet"
    loud = [a for a in ARGS if a != "--quiet"]
    assert main([*loud, "--chunk", "5", "--out", str(out)]) == 0
    err = capsys.readouterr().err
    assert "ensemble (simulated):" in err and "/5" in err and "5/5" in err


def test_progress_counts_the_extensions_too(tmp_path, capsys):
    """With --classify, members undetermined after the run are extended: the bar says so,
    its total grows by them, and it still ends full (no silent phase after 100 %)."""
    out = tmp_path / "x.parquet"
    args = ["ensemble", "--members", "2", "--duration", "20", "--transient", "10"]
    sets = ["--set", "omega=26", "--set", "xi=0.3", "--seed", "1", "--classify"]
    assert main([*args, *sets, "--out", str(out)]) == 0
    err = capsys.readouterr().err
    grown = re.findall(r"extending (\d+) undetermined to 40 s recorded\)?:.*?(\d+)/(\d+)", err)
    assert grown, err
    extended = int(grown[-1][0])
    assert f"{2 + extended}/{2 + extended}" in err  # the final count is the grown total
    members = pd.read_parquet(out)
    assert "undetermined" not in set(members["label"])


def test_a_too_coarse_step_is_warned_once_and_sigma_zero_is_named(tmp_path, capsys):
    """The warnings every member would get are printed once, not once per part (here 3
    parts), and a sigma = 0 ensemble says that its members are one run; the API warns as
    simulate() does, once per distinct warning."""
    out = tmp_path / "w.parquet"
    args = ["ensemble", "--members", "3", "--chunk", "1", "--duration", "0.5", "--quiet"]
    assert main([*args, "--set", "dt=2e-5", "--out", str(out)]) == 0
    err = capsys.readouterr().err
    assert err.count("resolves the contact oscillation") == 1, err
    assert err.count("every member is the same deterministic run") == 1
    with pytest.warns(RuntimeWarning, match="resolves the contact oscillation") as caught:
        simulate_ensemble(Params(dt=2e-5), range(3), duration=0.2)
    assert len([w for w in caught if "contact oscillation" in str(w.message)]) == 1
    two = tmp_path / "s.parquet"
    assert main([*args, "--set", "l_lambda_sigma=0.002", "--out", str(two)]) == 0
    assert "deterministic" not in capsys.readouterr().err


def test_force_removes_the_replaced_runs_impacts(tmp_path):
    """--force over a run kept with --keep-impacts, now without it: the old impacts file
    goes with the output it belonged to (it stayed, passing for the new run's)."""
    out = tmp_path / "e.parquet"
    base = ["ensemble", "--members", "2", "--duration", "0.5", "--quiet", "--out", str(out)]
    assert main([*base, "--keep-impacts"]) == 0
    assert (tmp_path / "e.impacts.parquet").exists()
    assert main([*base, "--force"]) == 0
    assert sorted(p.name for p in tmp_path.iterdir()) == ["e.parquet", "e.sections.parquet"]


def test_a_file_where_the_parts_folder_goes(tmp_path, capsys):
    """A file at FILE.parts: exit 2 saying so (it said the file held an unfinished run);
    --force replaces it and leaves only the outputs."""
    out = tmp_path / "e.parquet"
    (tmp_path / "e.parts").write_text("not mine")
    base = ["ensemble", "--members", "2", "--duration", "0.5", "--quiet", "--out", str(out)]
    assert main(base) == 2
    assert "e.parts is a file where this run keeps its parts folder" in capsys.readouterr().err
    assert main([*base, "--force"]) == 0
    assert sorted(p.name for p in tmp_path.iterdir()) == ["e.parquet", "e.sections.parquet"]


def test_workers_and_device_on_the_ensemble_command(tmp_path, capsys, monkeypatch):
    """--workers N sets the CPU threads for the run only (restored after; the same members
    as with every core) and is checked against the threads numba may use; --device is the
    sweeps' name for --backend (both were 'unrecognized arguments')."""
    import numba

    import chaoscam.cli._ensemble as ens_cli

    base = ["ensemble", "--members", "3", "--duration", "0.5", "--quiet"]
    threads = numba.get_num_threads()
    seen = []
    run = ens_cli._run_locked

    def spy(args):
        seen.append(numba.get_num_threads())
        return run(args)

    monkeypatch.setattr(ens_cli, "_run_locked", spy)
    a_out = str(tmp_path / "a.parquet")
    assert main([*base, "--workers", "1", "--device", "cpu", "--out", a_out]) == 0
    assert seen == [1] and numba.get_num_threads() == threads
    assert main([*base, "--out", str(tmp_path / "b.parquet")]) == 0
    assert seen == [1, threads]
    a, b = (pd.read_parquet(tmp_path / f"{n}.parquet") for n in "ab")
    assert a.equals(b)
    assert main([*base, "--workers", "0", "--out", str(tmp_path / "c.parquet")]) == 2
    assert "--workers 0: must be in [1, " in capsys.readouterr().err
    assert not (tmp_path / "c.parquet").exists()


@pytest.mark.parametrize(
    "backend, gpu, on_gpu",
    [("cpu", True, False), ("gpu", True, True), ("gpu", False, False), ("auto", True, True),
     ("auto", False, False)],
)  # fmt: skip
def test_members_per_call_follow_the_backend_that_runs(monkeypatch, backend, gpu, on_gpu):
    """A GPU takes a part in one call (None: the ensemble's default); the CPU takes small
    calls, so that the progress bar moves, also where --backend gpu or auto falls back."""
    from chaoscam.cli import _ensemble
    from chaoscam.integrate import _gpu

    monkeypatch.setattr(_gpu, "gpu_status", lambda: (gpu, "test"))
    size = _ensemble._progress_batch(backend)
    assert (size is None) == on_gpu
    assert on_gpu or size >= _ensemble.PROGRESS_PER_THREAD
