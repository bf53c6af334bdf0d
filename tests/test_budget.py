"""Time estimates before a run: the adaptive path's cost of following a stiff contact is
estimated from the contact's period; hours are refused (exit 2, the fields named), minutes
warned about before the work starts, ordinary runs left alone."""

import os
import signal
import subprocess
import sys
import time
import warnings
from pathlib import Path

import pytest

from chaoscam import Numerics, ParameterError, Params, simulate
from chaoscam.cli import main
from chaoscam.simulation._budget import (
    RUN_REFUSE_SECONDS,
    RUN_WARN_SECONDS,
    adaptive_seconds,
    check_run,
    persistent_contact,
    run_seconds,
)
from chaoscam.sweep import regime_map

ROOT = Path(__file__).resolve().parents[1]
TINY_J = Params(J=1e-9)  # contact period 1.4e-8 s
ADAPTIVE = Numerics(integrator="adaptive")


def test_tiny_inertia_refused_through_the_api():
    """simulate() with J = 1e-9 on the adaptive path: refused before any work, the message
    naming J, the stiffness, rtol and the estimate."""
    assert run_seconds(TINY_J, ADAPTIVE, 20.0) > RUN_REFUSE_SECONDS
    t0 = time.perf_counter()
    with pytest.raises(ParameterError, match=r"J = 1e-09 kg m\^2.*rtol.*refused") as err:
        simulate(TINY_J, ADAPTIVE)
    assert time.perf_counter() - t0 < 1.0
    assert "will take about" in str(err.value) and "years" in str(err.value)


def test_minutes_warned_about_ordinary_runs_not():
    """1e-4 s at J = 1e-9 (measured 85-110 s): a warning naming J; the default model, on
    either integrator, and a stiff fractal contact with flights: no warning."""
    with pytest.warns(RuntimeWarning, match=r"will take about .*\(J = 1e-09"):
        check_run(TINY_J, ADAPTIVE, 1e-4)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        for p, num in (
            (Params(), Numerics()),
            (Params(), ADAPTIVE),
            (Params(stiffness="fractal"), ADAPTIVE),
        ):
            check_run(p, num, 20.0)
            assert run_seconds(p, num, 20.0) < RUN_WARN_SECONDS


def test_estimate_scales_as_the_formula_says():
    """adaptive_seconds is linear in the duration, grows as 1/T_c^2 (J / 100 -> x100 at
    fixed stiffness) and falls with a looser rtol."""
    p, num = Params(J=1e-6), ADAPTIVE
    one = adaptive_seconds(p, num, 1.0)
    assert adaptive_seconds(p, num, 2.0) == pytest.approx(2 * one)
    assert adaptive_seconds(p.replace(J=1e-8), num, 1.0) == pytest.approx(100 * one)
    assert adaptive_seconds(p, num.replace(rtol=1e-8), 1.0) < one / 100


def test_estimate_within_an_order_of_magnitude_of_a_measured_run():
    """Cross-check against the clock: J = 1e-6 (persistent contact, T_c = 4.4e-7 s) for
    2e-4 s of model time; the estimate is within 10x either way of the wall time."""
    p = Params(J=1e-6)
    simulate(p, ADAPTIVE, duration=2e-6, series=False)  # load the compiled kernel
    t0 = time.perf_counter()
    simulate(p, ADAPTIVE, duration=2e-4, series=False)
    wall = time.perf_counter() - t0
    assert 0.1 < adaptive_seconds(p, ADAPTIVE, 2e-4) / wall < 10.0


@pytest.mark.parametrize(("changes", "holds"), [({"omega": 15.0}, True), ({}, False)])
def test_persistent_contact_criterion_matches_the_contact_fraction(changes, holds):
    """m g l / (2 J) >= e omega^2 / l_1 predicts riding the cam (contact fraction ~1) at
    omega = 15 rad/s, and flights (a small fraction) at the default 28.7 rad/s."""
    p = Params(**changes)
    assert persistent_contact(p) is holds
    fraction = simulate(p, ADAPTIVE, duration=1.0, series=False).stats["contact_fraction"]
    assert (fraction > 0.9) if holds else (fraction < 0.5)


def test_cli_refuses_hours_with_exit_2(tmp_path, capsys):
    """simulate, regime-map and ensemble with the adaptive path at J = 1e-9: exit 2, one
    line naming J and the estimate, nothing written."""
    adaptive = ["--set", "integrator=adaptive", "--set", "J=1e-9"]
    cases = [
        ["simulate", *adaptive, "--out", str(tmp_path / "s.parquet")],
        [
            "regime-map",
            "--mu",
            "0.006:0.008:2",
            "--sigma",
            "0:0.001:2",
            *adaptive,
            "--workers",
            "1",
            "--quiet",
            "--out",
            str(tmp_path / "m.parquet"),
        ],
        ["ensemble", "--members", "2", *adaptive, "--quiet", "--out", str(tmp_path / "e.parquet")],
    ]
    for args in cases:
        assert main(args) == 2
        err = capsys.readouterr().err
        assert err.startswith("chaoscam: error:") and "J = 1e-09" in err, err
        assert "refused" in err and "Traceback" not in err
    assert list(tmp_path.iterdir()) == []


def test_api_sweep_refuses_hours():
    """regime_map over an adaptive base with J = 1e-9: refused before any run."""
    with pytest.raises(ParameterError, match="J = 1e-09"):
        regime_map(("l_lambda", [0.008]), ("xi", [0.42]), base=TINY_J, numerics=ADAPTIVE, workers=1)


def test_cli_warns_before_the_work():
    """`chaoscam simulate` at J = 1e-9 for 1e-4 s: the warning with the estimate is the
    first thing on stderr, while the run is still going (then Ctrl-C: exit 130)."""
    code = "import sys; from chaoscam.cli import main; sys.exit(main(sys.argv[1:]))"
    proc = subprocess.Popen(
        [
            sys.executable,
            "-c",
            code,
            "simulate",
            "--set",
            "integrator=adaptive",
            "--set",
            "J=1e-9",
            "--duration",
            "1e-4",
        ],
        cwd=ROOT,
        env=dict(os.environ, PYTHONPATH=str(ROOT)),
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
    )
    try:
        first = proc.stderr.readline()
        running = proc.poll() is None
        proc.send_signal(signal.SIGINT)
        _, rest = proc.communicate(timeout=60)
    finally:
        proc.kill()
    assert first.startswith("chaoscam: warning: this run (duration = 0.0001 s) will take")
    assert "J = 1e-09" in first and "rtol" in first
    assert running
    assert proc.returncode == 130, rest


def test_the_extensions_the_estimate_leaves_out_are_warned_about(monkeypatch):
    """A map of 0.5 s runs was estimated at 5.6 h and took ~83 h: nearly every run, with
    0.25 s recorded, was undetermined and extended to 120 s. The check now warns with the
    bound when the runs record less than the extension cap; it stays quiet when they record
    as much, or when nothing extends (a classifier of one's own, or extend_to=None)."""
    import chaoscam.sweep._regime as regime
    from chaoscam.sweep import Axis

    class Stop(Exception):
        pass

    def stop_after_the_check(*args, **kwargs):  # the config step after the budget check
        raise Stop

    monkeypatch.setattr(regime, "code_identity", stop_after_the_check)
    grid = (Axis("l_lambda", (0.005, 0.01)), Axis("l_lambda_sigma", (0.0, 0.001)))
    with pytest.warns(RuntimeWarning) as caught, pytest.raises(Stop):
        regime_map(*grid, realizations=10**6, duration=0.5, workers=1)
    said = [str(w.message) for w in caught]
    assert any("will take about" in m for m in said)  # the estimate itself
    assert any("records 0.25 s per run; an undetermined run is extended up to 120 s" in m
               for m in said)  # fmt: skip
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        with pytest.raises(Stop):  # 120 s recorded: nothing left out
            regime_map(*grid, realizations=10, duration=240.0, workers=1)

    def own(run):  # a classifier of one's own: the sweep extends nothing for it
        return "periodic", 1

    for never in (dict(classify=own), dict(extend_to=None)):
        with pytest.warns(RuntimeWarning) as caught, pytest.raises(Stop):  # these never extend
            regime_map(*grid, realizations=10**6, duration=0.5, workers=1, **never)
        assert any("will take about" in str(w.message) for w in caught)
        assert not any("extended up to" in str(w.message) for w in caught)
