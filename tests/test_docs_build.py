"""The documentation site (docs/conf.py): it builds with warnings as errors, and its API pages
document every public class and function of the package's faces.

The build is what CI checks of the docs: a docstring that numpydoc or docutils cannot parse, a
broken cross-reference or a page left out of the table of contents is a warning, and a warning
fails it. Nothing is executed but the import of chaoscam (the gallery shows code, it does not
run it), so the build takes seconds.
"""

from __future__ import annotations

import importlib
import importlib.util
import inspect
import re
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
DOCS = ROOT / "docs"
TOOLS = ("sphinx", "numpydoc", "myst_parser")
MISSING = [name for name in TOOLS if importlib.util.find_spec(name) is None]
FACES = ("chaoscam", "chaoscam.analysis", "chaoscam.sweep", "chaoscam.report",
         "chaoscam.testsystems")  # fmt: skip

pytestmark = pytest.mark.skipif(
    bool(MISSING),
    reason=f"the docs build needs {', '.join(MISSING)} (pip install -e '.[docs]')",
)


def _build(out: Path) -> Path:
    """The site built into ``out`` with -W (every warning an error); its HTML folder."""
    command = [sys.executable, "-m", "sphinx", "-W", "--keep-going", "-j", "1", "-q",
               "-b", "html", "-d", str(out / "doctrees"), str(DOCS), str(out / "html")]  # fmt: skip
    done = subprocess.run(command, cwd=ROOT, capture_output=True, text=True, timeout=300)
    assert done.returncode == 0, f"the docs build failed:\n{done.stdout}\n{done.stderr}"
    return out / "html"


def _documented(html: Path) -> set[str]:
    """The object names the API pages hold an entry for."""
    text = "".join(page.read_text(encoding="utf-8") for page in (html / "api").glob("*.html"))
    return set(re.findall(r'<dt class="sig sig-object py" id="([\w.]+)"', text))


def _undocumented(documented: set[str]) -> list[str]:
    """The classes and functions of the faces without an entry under the face's name or (a
    re-export such as chaoscam.regime_map) the top-level one."""
    missing = []
    for face in FACES:
        module = importlib.import_module(face)
        for name in module.__all__:
            value = getattr(module, name)
            if not (inspect.isclass(value) or inspect.isfunction(value)):
                continue
            if f"{face}.{name}" not in documented and f"chaoscam.{name}" not in documented:
                missing.append(f"{face}.{name}")
    return missing


def test_the_site_builds_with_warnings_as_errors_and_documents_every_public_name(tmp_path):
    """One build (about half a minute on 2 cores) checks both: it has no warning, and each
    class or function a face exports has an API entry."""
    html = _build(tmp_path)
    pages = ["index", "model", "findings", "changelog", "gallery/fig4", "api/chaoscam"]
    assert all((html / f"{page}.html").is_file() for page in pages)
    missing = _undocumented(_documented(html))
    assert not missing, f"public names without an API entry: {missing}"
