"""The package's shape (docs/architecture.md): imports only go down the layers, no module
imports itself back through others, and no module grows past ~500 lines."""

import ast
from pathlib import Path

import pytest

PACKAGE = Path(__file__).resolve().parents[1] / "chaoscam"

# Bottom to top: a module may import from its own layer and those before it, never after.
LAYERS = (
    "chaoscam._version",
    "chaoscam._provenance",
    "chaoscam._lazy",
    "chaoscam._numba_cache",
    "chaoscam._warn",
    "chaoscam._parquet",
    "chaoscam._frozen",
    "chaoscam.model",
    "chaoscam._checks",
    "chaoscam._outputs",
    "chaoscam._budget",
    "chaoscam._run_warnings",
    "chaoscam.integrate",
    "chaoscam._simulate",
    "chaoscam._extend",
    "chaoscam._trajectory_io",
    "chaoscam.testsystems",
    "chaoscam.analysis",
    "chaoscam.tangent",
    "chaoscam.lyapunov",
    "chaoscam._certify",
    "chaoscam._model_rules",
    "chaoscam._step_check",
    "chaoscam.classify",
    "chaoscam._ensemble_verdicts",
    "chaoscam.sweep",
    "chaoscam.report",
    "chaoscam.experiments",
    "chaoscam.cli",
)
MAX_LINES = 500


def _modules() -> dict[str, Path]:
    out = {}
    for f in PACKAGE.rglob("*.py"):
        parts = list(f.relative_to(PACKAGE.parent).with_suffix("").parts)
        if parts[-1] == "__init__":
            parts = parts[:-1]
        out[".".join(parts)] = f
    return out


MODULES = _modules()


def _imports(name: str) -> tuple[set[str], set[str]]:
    """(imported at module level, imported inside functions): chaoscam modules only."""
    path = MODULES[name]
    package = name if path.name == "__init__.py" else name.rpartition(".")[0]
    tree = ast.parse(path.read_text())
    top_level = {id(n) for n in ast.walk(tree) if isinstance(n, ast.Import | ast.ImportFrom)}
    for node in ast.walk(tree):
        if isinstance(node, ast.FunctionDef | ast.AsyncFunctionDef):
            top_level -= {
                id(n) for n in ast.walk(node) if isinstance(n, ast.Import | ast.ImportFrom)
            }
    eager, lazy = set(), set()
    for node in ast.walk(tree):
        if isinstance(node, ast.ImportFrom):
            if node.level:
                base = package.split(".")[: len(package.split(".")) - node.level + 1]
                module = ".".join(base + ([node.module] if node.module else []))
            else:
                module = node.module or ""
            names = [module] + [f"{module}.{a.name}" for a in node.names]
        elif isinstance(node, ast.Import):
            names = [a.name for a in node.names]
        else:
            continue
        targets = {n for n in names if n in MODULES and n != name}
        (eager if id(node) in top_level else lazy).update(targets)
    return eager, lazy


def _layer(name: str) -> int | None:
    found = None
    for i, prefix in enumerate(LAYERS):
        if name == prefix or name.startswith(prefix + "."):
            found = i
    return found


GRAPH = {name: _imports(name) for name in MODULES}


@pytest.mark.parametrize(
    "name", sorted(n for n in MODULES if n not in ("chaoscam", "chaoscam.__main__"))
)
def test_imports_only_go_down(name):
    """Every import, eager or inside a function, points to the module's layer or below."""
    assert _layer(name) is not None, f"{name} is in no layer of LAYERS"
    eager, lazy = GRAPH[name]
    upward = sorted(t for t in eager | lazy if t != "chaoscam" and _layer(t) > _layer(name))
    assert not upward, f"{name} imports from a higher layer: {upward}"


def test_no_import_cycle_at_module_level():
    """No module reaches itself again through the imports its loading runs."""
    state: dict[str, int] = {}  # 1 on the current path, 2 done

    def visit(name: str, path: list[str]) -> None:
        state[name] = 1
        for t in sorted(GRAPH[name][0]):
            if state.get(t) == 1 and t != "chaoscam":
                cycle = path[path.index(t) :] + [t]
                pytest.fail("import cycle: " + " -> ".join(cycle))
            if t not in state:
                visit(t, [*path, t])
        state[name] = 2

    for name in sorted(MODULES):
        if name not in state:
            visit(name, [name])


def test_no_module_is_longer_than_about_500_lines():
    long = {n: len(p.read_text().splitlines()) for n, p in MODULES.items()}
    assert max(long.values()) <= MAX_LINES, sorted(long.items(), key=lambda kv: -kv[1])[:3]
