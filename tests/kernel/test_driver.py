"""The one buffer-refill loop (kernel/_driver.py) and the compiled entry points it drives."""

import numpy as np
import pytest

from chaoscam import Numerics, Params, simulate
from chaoscam.kernel import _adaptive, _rk4, drive_members
from chaoscam.kernel import layout as k


def test_drive_members_relaunches_exactly_those_that_asked():
    """Member j needs j refills: each launch gets the members still running, each refill the
    ones that asked, and the loop stops when none asks."""
    left = np.array([0, 1, 3, 2])  # refills each member still needs
    launches, refills = [], []

    def launch(need):
        launches.append(need.tolist())
        return np.where(left[need] > 0, k.NEED_BUFFER, k.OK)

    def refill(need):
        refills.append(need.tolist())
        left[need] -= 1

    drive_members(4, launch, refill)
    assert launches == [[0, 1, 2, 3], [1, 2, 3], [2, 3], [2]]
    assert refills == [[1, 2, 3], [2, 3], [2]]
    assert left.tolist() == [0, 0, 0, 0]


def test_drive_members_with_nothing_to_refill_launches_once():
    """Members that all end in their first launch are launched once and never refilled."""
    calls = []
    drive_members(3, lambda need: calls.append(need.size) or np.zeros(need.size, int), None)
    assert calls == [3]


RK4 = Numerics()


def _one_member(p: Params, tangent: bool, num: Numerics = RK4):
    from chaoscam.kernel import initial_counters, initial_state, kernel_constants

    y = initial_state(p)[None].copy()
    cnt = initial_counters()[None].copy()
    c = kernel_constants(p, num, t_record=0.0, stride=50, tangent=tangent)[None]
    lam = np.full((1, 64), p.l_lambda)
    bufs = [np.zeros((1, 4096, n)) for n in (k.SERIES_COLS, k.SECTION_COLS, k.IMPACT_COLS)]
    return y, cnt, c, lam, bufs


@pytest.mark.parametrize("tangent", [False, True])
def test_rk4_entry_point_is_the_generic_one_bit_for_bit(tangent):
    """run_members_rk4 (what an all-RK4 batch runs) gives the very bits run_members gives
    (state, counters and every buffer), over impacts and a chattering phase."""
    from chaoscam.kernel._driver import members_kernel, run_members, run_members_rk4

    p = Params(xi=0.3)
    runs = []
    for entry in (run_members, run_members_rk4):
        y, cnt, c, lam, bufs = _one_member(p, tangent)
        status = np.zeros(1, dtype=np.int64)
        n_stop = int(round(0.3 / RK4.dt))
        entry(y, cnt, c, n_stop, lam, *bufs, status)
        runs.append((y, cnt, status, *bufs))
    assert runs[1][1][0, k.I_N_IMPACT] > 10  # impacts were applied
    for a, b in zip(*runs, strict=True):
        assert np.array_equal(a, b, equal_nan=True)
    assert members_kernel(_one_member(p, tangent)[2]) is run_members_rk4
    adaptive = Numerics(integrator="adaptive")
    assert members_kernel(_one_member(p, tangent, adaptive)[2]) is run_members


def test_an_rk4_run_never_compiles_the_adaptive_kernel():
    """A fresh process that only simulates with RK4 leaves the adaptive kernel (and the
    dispatch between both) untouched: nothing of it is compiled or loaded."""
    import subprocess
    import sys

    code = (
        "import chaoscam\n"
        "from chaoscam.kernel._adaptive import run_chunk_adaptive\n"
        "from chaoscam.kernel._driver import advance\n"
        "chaoscam.simulate(duration=0.05, tangent=True)\n"
        "print(len(run_chunk_adaptive.signatures), len(advance.signatures))\n"
    )
    out = subprocess.run([sys.executable, "-c", code], check=True, capture_output=True, text=True)
    assert out.stdout.split() == ["0", "0"]


def test_rk4_verdicts_and_exponents_never_compile_the_adaptive_kernel():
    """A fresh process that classifies an RK4 run (tangent exponent, periodic-orbit shooting)
    and takes its Lyapunov spectrum compiles neither the adaptive kernel nor the dispatch
    between both (on a fresh install that took ~10 s for nothing), nor a parallel kernel: a
    single run is not a prange launch over a batch of one."""
    import subprocess
    import sys

    code = (
        "import chaoscam\n"
        "from chaoscam.kernel._adaptive import run_chunk_adaptive\n"
        "from chaoscam.kernel._driver import advance, run_members, run_members_rk4\n"
        "p = chaoscam.Params(xi=0.2)\n"
        "t = chaoscam.simulate(p, duration=4.0, transient=2.0, tangent=True)\n"
        "v, = chaoscam.classify(t)\n"
        "chaoscam.lyapunov_spectrum(p, duration=1.0, transient=0.5)\n"
        "print(v.label, any(e.name == 'periodic_orbit' for e in v.evidence))\n"
        "print(len(run_chunk_adaptive.signatures), len(advance.signatures), "
        "len(run_members.signatures), len(run_members_rk4.signatures))\n"
    )
    out = subprocess.run([sys.executable, "-c", code], check=True, capture_output=True, text=True)
    shot, compiled = out.stdout.splitlines()[-2:]
    assert shot.split()[1] == "True"  # the certificate's shooting ran
    assert compiled.split() == ["0", "0", "0", "0"]


def test_single_trajectory_entry_points_pick_rk4_and_agree_bit_for_bit():
    """run_alone_rk4 (what shooting an RK4 orbit runs) gives the very bits run_alone gives,
    and alone_kernel picks it only for RK4 constants."""
    from chaoscam.kernel._driver import alone_kernel, run_alone, run_alone_rk4

    p = Params(xi=0.3)
    runs = []
    for entry in (run_alone, run_alone_rk4):
        y, cnt, c, lam, bufs = _one_member(p, True)
        n_stop = int(round(0.3 / RK4.dt))
        code = entry(y[0], cnt[0], c[0], n_stop, lam[0], bufs[0][0], bufs[1][0], bufs[2][0])
        runs.append((y, cnt, np.array([code]), *bufs))
    assert runs[1][1][0, k.I_N_IMPACT] > 10
    for a, b in zip(*runs, strict=True):
        assert np.array_equal(a, b, equal_nan=True)
    assert alone_kernel(_one_member(p, True)[2][0]) is run_alone_rk4
    adaptive = Numerics(integrator="adaptive")
    assert alone_kernel(_one_member(p, True, adaptive)[2][0]) is run_alone


def test_a_ctrl_c_inside_a_c_callback_of_a_launch_is_not_lost():
    """SIGINT that arrives while a launch runs Python inside a C callback (numba's LLVM
    object cache while a kernel compiles) is held and raised as KeyboardInterrupt once the
    launch returns, instead of being printed as "Exception ignored" and lost."""
    import ctypes
    import signal

    callback = ctypes.CFUNCTYPE(None)(lambda: signal.raise_signal(signal.SIGINT))
    seen = []

    def launch(need):
        callback()
        seen.append("returned")
        return np.zeros(need.size, dtype=np.int64)

    with pytest.raises(KeyboardInterrupt):
        drive_members(2, launch, None)
    assert seen == ["returned"]
    assert signal.getsignal(signal.SIGINT) is signal.default_int_handler  # restored


@pytest.mark.parametrize("integrator, budget", [("rk4", 1000), ("adaptive", 200)])
def test_a_compiled_call_hands_back_after_its_step_budget(monkeypatch, integrator, budget):
    """A compiled call returns to Python after at most C_CALL_STEPS loop iterations (so that
    Ctrl-C and SIGTERM are seen between calls however many steps a cam period holds), and the
    many hand-backs change no bit of the run."""
    from chaoscam.kernel import _constants

    p = Params(omega=10.0)  # all contact: one grid step per iteration
    num = Numerics(integrator=integrator)
    whole = simulate(p, num, duration=0.5, series=False)
    monkeypatch.setitem(_constants.CALL_STEPS, integrator, budget)
    c = _constants.kernel_constants(p, num)
    assert c[k.C_CALL_STEPS] == budget
    y, cnt = _constants.initial_state(p), _constants.initial_counters()
    bufs = [np.zeros((4096, n)) for n in (k.SERIES_COLS, k.SECTION_COLS, k.IMPACT_COLS)]
    lam = np.full(4096, p.l_lambda)
    run = _rk4.run_chunk if integrator == "rk4" else _adaptive.run_chunk_adaptive
    code = run(y, cnt, c, int(round(0.5 / num.dt)), lam, *bufs)
    assert code == k.NEED_BUFFER and 0.0 < y[k.Y_TIME] < 0.01  # far from the end, buffers empty
    assert integrator != "rk4" or cnt[k.I_STEP] <= budget
    chunked = simulate(p, num, duration=0.5, series=False)
    assert chunked.section.equals(whole.section) and chunked.impacts.equals(whole.impacts)
