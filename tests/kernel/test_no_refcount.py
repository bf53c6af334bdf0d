"""The integrators' compiled call trees run without numba's reference counting.

Every function of the kernel modules that numba compiles on its own (not inlined into its
caller) carries ``_nrt=False``: with numba's runtime on, each call of such a function that
takes an array took a reference and let it go again (two atomic operations), 8 % of a regime
map's samples (``benchmarks/PROFILE.md``). Nothing there allocates an array, so nothing needs
the runtime; a function that did would not compile.
"""

import ast
import os
import subprocess
import sys
from pathlib import Path

import pytest

import chaoscam.kernel

# The modules whose functions the kernels (fixed-step and adaptive) call, and of ``_driver``
# the dispatch between them (``advance``). The driver's entry points keep the runtime: they
# take views of stacked arrays.
KERNEL_MODULES = (
    "_adaptive",
    "_dop853",
    "_events",
    "_physics",
    "_rk4",
    "_stages",
    "_steps",
    "_tangent",
)
KERNEL_FUNCTIONS = {"_driver": ("advance",)}


def _njit_options(path: Path):
    """(function name, keyword options) of each ``@njit(...)`` function in ``path``."""
    tree = ast.parse(path.read_text())
    for node in ast.walk(tree):
        if not isinstance(node, ast.FunctionDef):
            continue
        for dec in node.decorator_list:
            if isinstance(dec, ast.Call) and getattr(dec.func, "id", None) == "njit":
                yield node.name, {k.arg: ast.literal_eval(k.value) for k in dec.keywords}
            elif getattr(dec, "id", None) == "njit":
                yield node.name, {}


def test_every_kernel_function_compiled_apart_goes_without_the_runtime():
    """Inlined functions (``inline="always"``) take their caller's options; every other
    compiled function of the kernel modules says ``_nrt=False``."""
    here = Path(chaoscam.kernel.__file__).parent
    seen, missing = 0, []
    for name in (*KERNEL_MODULES, *KERNEL_FUNCTIONS):
        found = dict(_njit_options(here / f"{name}.py"))
        assert set(KERNEL_FUNCTIONS.get(name, ())) <= set(found), name
        for fn, options in found.items():
            if name in KERNEL_FUNCTIONS and fn not in KERNEL_FUNCTIONS[name]:
                continue
            if options.get("inline") == "always":
                continue
            seen += 1
            if options.get("_nrt", True) is not False:
                missing.append(f"{name}.{fn}")
    assert seen >= 30  # the walk found the kernels' functions
    assert missing == [], f"compiled with numba's reference counting: {missing}"


PROBE = """
import chaoscam
from chaoscam.kernel import _adaptive, _rk4
chaoscam.simulate(duration=0.05, tangent=True)
chaoscam.simulate(integrator="adaptive", duration=0.05, tangent=True)
for d in (_rk4.run_chunk, _adaptive.run_chunk_adaptive):
    code = d.inspect_asm(d.signatures[0])
    print(d.py_func.__name__, code.count("NRT_incref") + code.count("NRT_decref"))
"""


@pytest.mark.slow
def test_the_compiled_kernels_call_no_reference_counting(tmp_path):
    """In an empty cache (numba shows compiled code only when it compiled it), the machine
    code of each kernel with every callee it links calls neither ``NRT_incref`` nor
    ``NRT_decref``: a callee from a module the walk above does not read would show here.
    About 40 s: both kernels compiled from empty caches."""
    env = {**os.environ, "NUMBA_CACHE_DIR": str(tmp_path)}
    out = subprocess.run(
        [sys.executable, "-c", PROBE], env=env, check=True, capture_output=True, text=True
    ).stdout
    counts = dict(line.split() for line in out.splitlines())
    assert counts == {"run_chunk": "0", "run_chunk_adaptive": "0"}
