"""Input holes of a review, each refused with a message naming the field (or file, or
address) and its range, exit 2, never a traceback or a run that should not start."""

import dataclasses
import errno
import pathlib
import socket
import threading

import numpy as np
import pytest

from chaoscam import Numerics, ParameterError, Params
from chaoscam.cli import main

NUMERIC = [
    (cls, f.name)
    for cls in (Params, Numerics)
    for f in dataclasses.fields(cls)
    if f.metadata["choices"] is None
]
BIF = ["bifurcation", "--param", "l_lambda", "--values", "0.006:0.008:2", "--duration", "0.3"]
BIF += ["--workers", "1", "--quiet"]


def _refused(capsys, argv, *named):
    """``argv`` exits 2 with one message naming each of ``named``, no traceback."""
    assert main(argv) == 2
    err = capsys.readouterr().err
    assert "chaoscam: error:" in err and "Traceback" not in err, err
    for text in named:
        assert text in err, err
    return err


@pytest.mark.parametrize("cls, name", NUMERIC, ids=[n for _, n in NUMERIC])
def test_every_numeric_field_has_a_finite_range_that_refuses_absurd_values(cls, name):
    """(0, inf) let Y_f = 1e-300, J = 1e300 or v_eps = 1e300 through, and R = 1e300 or mu_f =
    1e300 ended in NON_FINITE advising "lower dt": every field's range is finite, holds its
    default, and refuses 1e300 and -1e300 naming the field and the range."""
    f = next(g for g in dataclasses.fields(cls) if g.name == name)
    lo, hi = f.metadata["range"][:2]
    assert np.isfinite([lo, hi]).all() and (f.default is None or lo <= f.default <= hi)
    huge = 10**300 if f.type == "int" else 1e300
    for value in (huge, -huge):
        with pytest.raises(ParameterError, match=rf"^{name} = .* outside the allowed range"):
            cls(**{name: value})


@pytest.mark.parametrize("value", ["1e300", "1e200"])
def test_an_overflowing_radius_is_refused_naming_its_range(capsys, value):
    """--set r=1e300 (or 1e200) was an OverflowError traceback (r**2 in the inertia)."""
    argv = ["simulate", "--duration", "0.05", "--set", f"r={value}"]
    _refused(capsys, argv, "r = 1e+", "outside the allowed range [1e-06, 10.0]")


def test_a_huge_integer_is_refused_with_the_range_not_its_400_digits():
    with pytest.raises(ParameterError, match=r"^l = 100000\.\.\. \(401 digits\) \[m\] is outside"):
        Params(l=10**400)


def test_a_bifurcation_over_absurd_values_is_refused(tmp_path, capsys):
    """l_lambda 1e300:1e301 ran, exit 0, advising "use dt <= 0 s"."""
    argv = [*BIF[:4], "1e300:1e301:2", *BIF[5:], "--out", str(tmp_path / "b.parquet")]
    _refused(capsys, argv, "l_lambda = 1e+300 [m] is outside the allowed range")


@pytest.mark.parametrize("command", ["regime-map", "ensemble", "bifurcation"])
def test_every_command_refuses_a_duration_shorter_than_one_step(tmp_path, capsys, command):
    """--duration 1e-300, refused by simulate, was a task failure (exit 1) in the sweeps: one
    rule for every command, before any run."""
    args = {
        "regime-map": ["regime-map", "--mu", "0.006:0.008:2", "--sigma", "0:0.001:2"],
        "ensemble": ["ensemble", "--members", "2"],
        "bifurcation": BIF[:5],
    }[command]
    argv = [*args, "--duration", "1e-300", "--quiet", "--out", str(tmp_path / "o.parquet")]
    _refused(capsys, argv, "duration = 1e-300 s is shorter than one step dt = 2e-06 s")
    assert list(tmp_path.iterdir()) == []


@pytest.mark.parametrize(
    "extra, named",
    [
        (["--dt", "1e-300"], "--dt 1e-300: the sampling interval must be in [1e-12, 1e+06] s"),
        (["--dt", "0.01", "--forcing-period", "1e-300"], "--forcing-period 1e-300: must be"),
    ],
    ids=["dt", "forcing-period"],
)
def test_classify_series_refuses_absurd_sampling(tmp_path, capsys, extra, named):
    """--dt 1e-300 or --forcing-period 1e-300 gave verdicts; the API refuses them too."""
    from chaoscam.analysis import classify_signal

    path = tmp_path / "s.csv"
    path.write_text("x\n" + "\n".join(f"{np.sin(0.05 * i):.6f}" for i in range(2000)) + "\n")
    _refused(capsys, ["classify-series", str(path), "--column", "x", *extra], named)
    x = np.sin(0.05 * np.arange(2000))
    for dt, period in ((1e-300, None), (0.01, 1e-300), (0.01, 1e3)):
        with pytest.raises(ValueError, match="dt" if period is None else "forcing_period"):
            classify_signal(x, dt, period)


def _disk_full(*args, **kwargs):
    raise OSError(errno.ENOSPC, "No space left on device")


def test_a_full_disk_names_the_report_it_could_not_write(tmp_path, capsys, monkeypatch):
    """report printed a bare "[Errno 28] No space left on device"."""
    run = tmp_path / "r.parquet"
    assert main(["simulate", "--duration", "0.3", "--out", str(run)]) == 0
    capsys.readouterr()
    monkeypatch.setattr(pathlib.Path, "write_bytes", _disk_full)
    out = tmp_path / "r.html"
    _refused(capsys, ["report", str(run), "--out", str(out)], f"cannot write {out}: No space")
    assert not out.exists()


def test_a_full_disk_in_an_ensemble_names_the_file_and_what_is_kept(tmp_path, capsys, monkeypatch):
    """The final table: the file that failed, the checkpoint kept and --resume; the
    checkpoint itself: nothing was saved (it said "kept in" a folder that was never made),
    and no half-made folder is left behind."""
    import pyarrow.parquet as pq

    out = tmp_path / "e.parquet"
    argv = ["ensemble", "--members", "2", "--duration", "0.3", "--quiet", "--out", str(out)]
    with monkeypatch.context() as m:
        m.setattr(pq, "write_table", _disk_full)
        err = _refused(capsys, argv, f"cannot write {out}: No space", "--resume")
        assert f"kept in {out}.ckpt" in err and (tmp_path / "e.parquet.ckpt").is_dir()
    other = tmp_path / "f.parquet"
    monkeypatch.setattr(pathlib.Path, "write_bytes", _disk_full)
    _refused(capsys, [*argv[:-1], str(other)], "manifest.json: No space", "nothing was saved")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["e.parquet.ckpt"]


def test_a_full_disk_in_the_paper_names_the_file_and_the_resume(tmp_path, capsys, monkeypatch):
    """paper printed a bare "[Errno 28]" without the file or how to go on."""
    monkeypatch.setattr(pathlib.Path, "write_bytes", _disk_full)
    out = tmp_path / "p.html"
    argv = ["paper", "--quick", "--figures", "3", "--out", str(out)]
    _refused(capsys, argv, f"cannot write {out}: No space", "--resume")


@pytest.fixture
def not_dask():
    """A TCP peer that answers in another protocol (an SSH banner), and its port."""
    server = socket.create_server(("127.0.0.1", 0))
    server.settimeout(30)

    def answer():
        try:
            while True:
                peer, _ = server.accept()
                peer.sendall(b"SSH-2.0-OpenSSH_9.6 not dask\r\n" * 8)
        except OSError:
            return

    threading.Thread(target=answer, daemon=True).start()
    yield server.getsockname()[1]
    server.close()


def test_a_peer_that_is_not_dask_is_named_so(tmp_path, capsys, not_dask):
    """It was reported as "out of memory" (Dask read a garbage frame length)."""
    pytest.importorskip("distributed")
    address = f"tcp://127.0.0.1:{not_dask}"
    argv = [*BIF[:7], "--quiet", "--scheduler", address, "--out", str(tmp_path / "b.parquet")]
    _refused(capsys, argv, f"'{address}' answered, but not as a Dask scheduler")


def test_an_invalid_port_is_refused_at_once(tmp_path, capsys):
    """tcp://127.0.0.1:99999 waited Dask's 30 s before "cannot reach"; checked before any run."""
    argv = [*BIF[:7], "--quiet", "--scheduler", "tcp://127.0.0.1:99999"]
    argv += ["--out", str(tmp_path / "b.parquet")]
    _refused(capsys, argv, "port must be a whole number in 1..65535")


def test_a_refused_million_cell_map_builds_no_cell_first(monkeypatch):
    """A 10^6-cell map beyond memory built and checked every cell's model (65 s of silence)
    before the budget check refused it: now the budget comes first."""
    from chaoscam.simulation import _budget
    from chaoscam.sweep import _grid, _regime, regime_map

    def built(*args, **kwargs):
        raise AssertionError("a cell's model was built before the budget check")

    monkeypatch.setattr(_budget, "available_memory", lambda: 2.0**30)
    for module in (_grid, _regime):
        monkeypatch.setattr(module, "cell_params", built)
    x, y = (
        ("l_lambda", np.linspace(0.006, 0.008, 1000)),
        ("l_lambda_sigma", np.linspace(0, 1e-3, 1000)),
    )
    with pytest.raises(ParameterError, match="needs about .* of memory"):
        regime_map(x, y)
