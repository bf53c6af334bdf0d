"""Warnings name the user's line, whatever the depth of chaoscam beneath it
(chaoscam._util.user_stacklevel): a fixed stacklevel named a line of chaoscam whenever the
warning came from a nested call (simulate inside a sweep, a budget check inside classify)."""

import warnings

import pytest

import chaoscam
from chaoscam import Params
from chaoscam._util import user_stacklevel
from chaoscam.sweep import bifurcation

# A spread that cannot act (fractal K_n does not depend on the line length): every run of it
# warns before it starts, and is cheap.
IGNORED_SIGMA = Params(stiffness="fractal", l_lambda_sigma=0.001)


def _caught(call):
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        call()
    return [w for w in caught if issubclass(w.category, RuntimeWarning)]


@pytest.mark.parametrize(
    "call",
    [
        lambda: chaoscam.simulate(IGNORED_SIGMA, duration=0.05, series=False),
        lambda: bifurcation("xi", [0.1], base=IGNORED_SIGMA, duration=0.05, workers=1),
    ],
    ids=["simulate", "bifurcation"],
)
def test_a_warning_names_the_callers_file(call):
    """The same model warning, raised one call deep (simulate) and several deep (a sweep's
    run re-emitted by the sweep), names this file and not chaoscam's."""
    caught = _caught(call)
    assert any("no effect with stiffness = 'fractal'" in str(w.message) for w in caught)
    assert {w.filename for w in caught} == {__file__}


def test_an_adaptive_verdict_warning_names_the_callers_file():
    """classify's RK4-grid warning, raised calls down in the verdict package, names the
    line that called classify."""
    tr = chaoscam.simulate(Params(e=0.02), duration=0.2, series=False, integrator="adaptive")
    caught = _caught(lambda: chaoscam.classify(tr))
    assert any("RK4 grid" in str(w.message) for w in caught)
    assert {w.filename for w in caught} == {__file__}


def test_user_stacklevel_counts_the_frames_of_chaoscam_only():
    """Called from outside chaoscam, the level is 2: the caller of the function that warns."""

    def warns_here():
        return user_stacklevel()

    assert warns_here() == 2


def _printer_state() -> tuple:
    return warnings.showwarning, warnings._showwarnmsg_impl, list(warnings.filters)


def test_recorded_is_safe_on_threads_that_leave_out_of_order():
    """Two threads record: A begins, B begins, A ends, B ends (the order that left a dead
    list as the process's printer with catch_warnings). Each list holds its own thread's
    warnings, a third thread's go where they went before, and the state is restored."""
    import threading

    from chaoscam._util import recorded

    before = _printer_state()
    a_in, b_in, a_out = threading.Event(), threading.Event(), threading.Event()
    got: dict[str, list[str]] = {}

    def a() -> None:
        with recorded() as log:
            a_in.set()
            b_in.wait(10)
            warnings.warn("from A", stacklevel=1)
        got["a"] = [str(m.message) for m in log]
        a_out.set()

    def b() -> None:
        a_in.wait(10)
        with recorded() as log:
            b_in.set()
            a_out.wait(10)
            warnings.warn("from B", stacklevel=1)
        got["b"] = [str(m.message) for m in log]

    with warnings.catch_warnings(record=True) as outside:
        warnings.simplefilter("always")
        threads = [threading.Thread(target=a), threading.Thread(target=b)]
        for t in threads:
            t.start()
        b_in.wait(10)
        warnings.warn("from the main thread", stacklevel=1)  # while both record
        for t in threads:
            t.join(10)
        inner = _printer_state()
    assert got == {"a": ["from A"], "b": ["from B"]}
    assert [str(m.message) for m in outside] == ["from the main thread"]
    assert inner[1] is not None and _printer_state()[:2] == before[:2]
    assert _printer_state()[2] == before[2]


def test_a_verdict_threads_warnings_are_recorded_with_their_batch():
    """The verdicts' pool threads run in a copy of the batch thread's context, so what they
    warn is recorded with the batch, not printed."""
    from chaoscam._util import recorded
    from chaoscam.verdict._classify import _threaded

    def judge(x: int) -> int:
        warnings.warn(f"member {x}", stacklevel=1)
        return x

    with warnings.catch_warnings(record=True) as outside:
        warnings.simplefilter("always")
        with recorded() as log:
            assert _threaded(judge, list(range(6)), 3, [6, 7]) == (list(range(6)), [6, 7])
    assert sorted(str(m.message) for m in log) == [f"member {x}" for x in range(8)]
    assert outside == []


def test_no_library_module_swaps_the_warnings_state_itself():
    """``warnings.catch_warnings`` swaps process-wide state and is not safe where a sweep's
    batches run on threads; the library records and silences warnings through
    chaoscam._util.recorded / quiet. Only the top-level drivers (the command line, the
    paper's experiments), which run on the main thread, use it directly."""
    import ast
    from pathlib import Path

    root = Path(chaoscam.__file__).parent
    drivers = ("cli", "paper")
    found = []
    for path in sorted(root.rglob("*.py")):
        rel = path.relative_to(root)
        if rel.parts[0] in drivers or rel.name == "_warn.py":
            continue
        for node in ast.walk(ast.parse(path.read_text())):
            if isinstance(node, ast.Attribute) and node.attr == "catch_warnings":
                found.append(f"{rel}:{node.lineno}")
    assert found == []
