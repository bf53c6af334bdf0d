"""Validation of the classifiers on systems whose dynamics is known."""

import json
import math
import time

import numpy as np
import pytest

from chaoscam.analysis import classify_section, classify_signal, crossing_section
from chaoscam.testsystems import (
    circle_map_orbit,
    flow_trajectory,
    henon_orbit,
    logistic_orbit,
    lorenz,
    rossler,
    torus_section,
    torus_signal,
    ueda,
)

TWO_PI = 2 * math.pi


@pytest.mark.parametrize("r, period", [(3.2, 2), (3.5, 4), (3.83, 3)])
@pytest.mark.parametrize("n", [60, 1000])
def test_logistic_periodic_windows(r, period, n):
    """Logistic map at r = 3.2, 3.5, 3.83 is periodic with period 2, 4, 3 (60 or 1000 iterates)."""
    v = classify_section(logistic_orbit(r, n))
    assert (v.label, v.period) == ("periodic", period)


@pytest.mark.parametrize("r", [3.9, 4.0])
def test_logistic_chaos(r):
    """Logistic map at r = 3.9 and 4 is chaotic from 1000 iterates."""
    v = classify_section(logistic_orbit(r, 1000))
    assert v.label == "chaotic", v.reasons


def test_logistic_chaos_from_few_points_needs_the_exponent():
    """60 chaotic iterates alone are undetermined (never periodic); with λ₁ > 0 chaotic."""
    x = logistic_orbit(3.9, 60)
    assert classify_section(x).label == "undetermined"
    assert classify_section(x, lyapunov=0.49).label == "chaotic"


def test_henon_chaos():
    """The Hénon attractor (a = 1.4, b = 0.3) is chaotic."""
    assert classify_section(henon_orbit(1000)).label == "chaotic"


def test_circle_map_quasiperiodic():
    """The sine circle map at K = 0.5, Ω = golden mean is quasiperiodic (angle in turns)."""
    v = classify_section(circle_map_orbit(1000), angle_periods=[1.0])
    assert v.label == "quasiperiodic", v.reasons


@pytest.mark.parametrize("n", [100, 1000])
def test_torus_section_quasiperiodic(n):
    """Stroboscopic points of the two-torus signal are quasiperiodic."""
    assert classify_section(torus_section(n)).label == "quasiperiodic"


def test_torus_signal_quasiperiodic():
    """The two-torus signal (forced at f1 = 1) with 90 section points is quasiperiodic."""
    t = np.arange(20_000) * 0.01
    v = classify_signal(torus_signal(t), 0.01, 1.0, section=torus_section(90))
    assert v.label == "quasiperiodic", v.reasons


@pytest.fixture(scope="module")
def rossler_runs():
    """Rössler x(t) at dt = 0.05 and its section x = 0 (downwards), points (y, z)."""
    runs = {}
    for c in (2.5, 3.5, 5.7):
        t, s = flow_trajectory(
            rossler(c=c), [1.0, 1.0, 0.0], dt=0.01, n_samples=100_000, transient_time=500.0
        )
        _, pts = crossing_section(t, s, index=0, level=0.0, direction=-1)
        runs[c] = (s[::5, 0], pts[:, 1:])
    return runs


@pytest.mark.parametrize(
    "c, label, period", [(2.5, "periodic", 1), (3.5, "periodic", 2), (5.7, "chaotic", None)]
)
def test_rossler(rossler_runs, c, label, period):
    """Rössler a = b = 0.2: c = 2.5 period 1, c = 3.5 period 2, c = 5.7 chaotic."""
    x, section = rossler_runs[c]
    v = classify_signal(x, 0.05, section=section)
    assert (v.label, v.period) == (label, period), v.reasons


def test_lorenz_signal_chaotic():
    """Lorenz x(t) (10, 28, 8/3) is chaotic."""
    _, s = flow_trajectory(
        lorenz(), [1.0, 1.0, 20.0], dt=0.005, n_samples=20_000, sample_every=2, transient_time=50.0
    )
    v = classify_signal(s[:, 0], 0.01)
    assert v.label == "chaotic", v.reasons


@pytest.fixture(scope="module")
def ueda_run():
    """Ueda x(t) sampled 100 times per forcing period, and 100 stroboscopic points."""
    y0 = [2.5, 0.0, 0.0]
    _, s = flow_trajectory(
        ueda(), y0, dt=TWO_PI / 400, n_samples=20_000, sample_every=4, transient_time=100 * TWO_PI
    )
    return s[:, 0], s[::100, :2]


def test_ueda_chaotic(ueda_run):
    """Ueda (k = 0.05, B = 7.5) with 200 section points is chaotic."""
    x, section = ueda_run
    v = classify_signal(x, TWO_PI / 100, TWO_PI, section=section)
    assert v.label == "chaotic", v.reasons


def test_ueda_chaotic_with_cam_sized_section(ueda_run):
    """With only 60 section points (a cam run) the signal evidence still calls chaos."""
    x, section = ueda_run
    v = classify_signal(x[:6000], TWO_PI / 100, TWO_PI, section=section[:60])
    assert v.label == "chaotic", v.reasons
    assert any("too few" in e.detail for e in v.evidence if e.name == "section_rotation")


def test_forced_period_two_signal():
    """A forced response with a subharmonic and a matching section is periodic, period 2."""
    t = np.arange(20_000) * 0.01
    x = np.cos(TWO_PI * t) + 0.1 * np.cos(np.pi * t + 0.3) + 0.05 * np.sin(3 * TWO_PI * t)
    k = np.arange(90)
    section = np.column_stack([1 + 0.1 * np.cos(np.pi * k + 0.3), np.zeros(90)])
    v = classify_signal(x, 0.01, 1.0, section=section)
    assert (v.label, v.period) == ("periodic", 2), v.reasons


def test_disagreement_is_reported_not_guessed():
    """A periodic signal with an externally given positive exponent is undetermined."""
    t = np.arange(20_000) * 0.01
    v = classify_signal(np.cos(TWO_PI * t), 0.01, 1.0, lyapunov=0.5)
    assert v.label == "undetermined" and "disagrees" in v.reasons[-1]


def test_nan_input_raises():
    """NaN in the signal or the section is a ValueError, not a verdict."""
    x = np.sin(np.arange(1000) * 0.1)
    x[5] = np.nan
    with pytest.raises(ValueError, match="NaN"):
        classify_signal(x, 0.1)
    with pytest.raises(ValueError, match="NaN"):
        classify_section(np.array([[0.0, np.nan]] * 20))
    with pytest.raises(ValueError, match="NaN"):
        classify_signal(np.sin(np.arange(1000) * 0.1), 0.1, section=[[np.nan, 1.0]] * 20)


def test_degenerate_input_never_crashes():
    """Constant or short inputs give documented verdicts with reasons, never crashes (inputs
    too small to hold an oscillation are refused instead: see the next test)."""
    const_signal = classify_signal(np.full(5000, 0.3), 0.01, 1.0)
    assert const_signal.label == "undetermined" and "constant" in const_signal.reasons[0]
    const_section = classify_section(np.full((40, 2), 0.3))
    assert (const_section.label, const_section.period) == ("periodic", 1)
    v = classify_signal(np.sin(np.arange(30.0)), 0.1)
    assert v.label == "undetermined" and v.reasons
    assert classify_section(np.arange(3.0)).label == "undetermined"


def test_verdict_records_settings_and_serialises():
    """The verdict keeps the settings used and its dict form is valid JSON."""
    v = classify_section(logistic_orbit(3.5, 100), rtol=2e-3)
    assert v.settings["rtol"] == 2e-3
    assert json.loads(json.dumps(v.to_dict(), allow_nan=False))["period"] == 4


def test_classify_signal_is_fast():
    """A 20 000-sample signal plus 100 section points is classified in well under 2 s."""
    t = np.arange(20_000) * 0.01
    x = torus_signal(t)
    classify_signal(x[:2000], 0.01, 1.0, section=torus_section(100))  # imports, warm-up
    t0 = time.perf_counter()
    classify_signal(x, 0.01, 1.0, section=torus_section(100))
    assert time.perf_counter() - t0 < 2.0


def test_too_little_data_is_an_error_not_a_verdict():
    """An empty or nearly empty signal or section is refused ("too little data"), not
    called an equilibrium."""
    from chaoscam.analysis import classify_section, classify_signal

    for x in ([], [1.0], np.arange(10.0)):
        with pytest.raises(ValueError, match="too little data"):
            classify_signal(x, 0.01)
    with pytest.raises(ValueError, match="too little data"):
        classify_section(np.empty((0, 2)))
