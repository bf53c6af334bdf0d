"""Sphinx configuration of the chaoscam documentation.

Build it with ``python -m sphinx -W -b html docs docs/_build/html`` (warnings are errors;
``tests/test_docs_build.py`` runs the same). The build imports chaoscam for its docstrings and
runs nothing else: the gallery shows code and commands with their outputs described.
"""

from __future__ import annotations

import importlib
import sys
from pathlib import Path

from docutils import nodes
from sphinx.errors import PycodeError
from sphinx.ext.autodoc import DataDocumenter, ModuleDocumenter
from sphinx.pycode import ModuleAnalyzer
from sphinx.util.docutils import SphinxDirective

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

import chaoscam  # noqa: E402

project = "chaoscam"
author = "The chaoscam developers"
copyright = "the chaoscam developers (MIT License)"  # noqa: A001
release = chaoscam.__version__
version = ".".join(release.split(".")[:2])

extensions = ["myst_parser", "numpydoc", "sphinx.ext.autodoc", "sphinx.ext.mathjax"]

source_suffix = {".rst": "restructuredtext", ".md": "markdown"}
root_doc = "index"
exclude_patterns = ["_build"]

# The Markdown pages of docs/ are read on GitHub too: GitHub-style heading anchors make links
# such as verdicts.md#how-a-verdict-is-reached resolve in both places.
myst_heading_anchors = 6

# Docstrings: numpydoc sections; `name` links to the object where one of that name is
# documented, and stays plain text where none is.
default_role = "py:obj"
autodoc_member_order = "bysource"
autodoc_typehints = "none"
numpydoc_show_class_members = False
numpydoc_class_members_toctree = False
numpydoc_xref_param_type = False

html_theme = "alabaster"
html_title = f"chaoscam {release}"
html_theme_options = {"description": "Stochastic dynamics of a cam-follower oblique impact system"}


FACES = ("chaoscam", "chaoscam.analysis", "chaoscam.sweep", "chaoscam.report",
         "chaoscam.testsystems")  # fmt: skip
"""The packages whose public names the API pages document (``automodule`` of each face)."""


def _face_comment(face: str, name: str) -> list[str] | None:
    """The docstring of a constant that ``face`` re-exports, from the private module that
    defines it (autodoc reads a constant's docstring only in the module it documents)."""
    value = getattr(sys.modules[face], name)
    for sub in sorted(m for m in sys.modules if m.startswith(face + "._")):
        if getattr(sys.modules[sub], name, None) is not value:
            continue
        try:
            analyzer = ModuleAnalyzer.for_module(sub)
            analyzer.analyze()
        except PycodeError:
            continue
        if ("", name) in analyzer.attr_docs:
            return list(analyzer.attr_docs["", name])
    return None


class FaceDataDocumenter(DataDocumenter):
    """A constant of a face, with the docstring written beside it in its defining module."""

    priority = DataDocumenter.priority + 1

    @classmethod
    def can_document_member(cls, member, membername, isattr, parent) -> bool:
        if isinstance(parent, ModuleDocumenter) and parent.modname in FACES and not isattr:
            return _face_comment(parent.modname, membername) is not None
        return super().can_document_member(member, membername, isattr, parent)

    def get_module_comment(self, attrname: str) -> list[str] | None:
        found = super().get_module_comment(attrname)
        if found or self.modname not in FACES:
            return found
        return _face_comment(self.modname, attrname)


def _keep_documented_constants(app, what, name, obj, skip, options):
    """Keep a face's constant that has a docstring in its defining module (autodoc would skip
    it as undocumented)."""
    if what != "module" or not skip:
        return None
    for face in FACES:
        module = sys.modules.get(face)
        if module is not None and name in getattr(module, "__all__", ()):
            if getattr(module, name) is obj and _face_comment(face, name):
                return False
    return None


def _resolve(dotted: str) -> type:
    """The object a dotted name names, e.g. ``chaoscam.Params``."""
    module, _, name = dotted.rpartition(".")
    return getattr(importlib.import_module(module), name)


def _table(head: tuple[str, ...], widths: tuple[int, ...], rows: list[tuple[str, ...]]):
    """A docutils table, its first column as code; cells are plain text, never parsed."""

    def row(cells, code: bool) -> nodes.row:
        out = nodes.row()
        for i, text in enumerate(cells):
            inner = nodes.literal(text=text) if code and i == 0 else nodes.Text(text)
            out += nodes.entry("", nodes.paragraph("", "", inner))
        return out

    tgroup = nodes.tgroup(cols=len(head))
    for width in widths:
        tgroup += nodes.colspec(colwidth=width)
    tgroup += nodes.thead("", row(head, False))
    tgroup += nodes.tbody("", *(row(r, True) for r in rows))
    return nodes.table("", tgroup)


def _shown(value) -> str:
    return f"{value:.10g}" if isinstance(value, float) else repr(value)


class FieldTable(SphinxDirective):
    """``.. chaoscam-fields:: chaoscam.Params``: one row per field of a settings class (name,
    unit, default, allowed values, meaning) from the fields' own metadata, as ``chaoscam
    params`` prints them."""

    required_arguments = 1

    def run(self) -> list[nodes.Node]:
        from chaoscam._util import field_table

        rows = [
            (r["name"], r["unit"], _shown(r["default"]), r["range"], r["doc"])
            for r in field_table(_resolve(self.arguments[0]))
        ]
        head = ("field", "unit", "default", "allowed", "meaning")
        return [_table(head, (12, 8, 10, 14, 56), rows)]


class StatusTable(SphinxDirective):
    """``.. chaoscam-statuses::``: every :class:`chaoscam.Status` with its code, the label a
    sweep gives such a run, and the message a user reads."""

    def run(self) -> list[nodes.Node]:
        rows = [(s.name, str(int(s)), s.label or "(its verdict)", s.message)
                for s in chaoscam.Status]  # fmt: skip
        return [_table(("status", "code", "sweep label", "message"), (14, 6, 14, 66), rows)]


def setup(app):
    app.add_directive("chaoscam-fields", FieldTable)
    app.add_directive("chaoscam-statuses", StatusTable)
    app.add_autodocumenter(FaceDataDocumenter, override=True)
    app.connect("autodoc-skip-member", _keep_documented_constants)
    return {"parallel_read_safe": True, "parallel_write_safe": True}
