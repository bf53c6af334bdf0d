"""Lazy package faces (PEP 562): a package's ``__init__`` lists ``{name: (submodule, attribute)}``
and takes ``__getattr__`` and ``__dir__`` from :func:`lazy_face`, so ``import chaoscam`` loads no
numba, pandas or scipy until a name needing them is used. A submodule must not share a public
name of its package (the import system would bind the module over the name)."""

from __future__ import annotations

import importlib
from collections.abc import Callable


def lazy_face(
    package: str, table: dict[str, tuple[str, str]]
) -> tuple[Callable[[str], object], Callable[[], list[str]]]:
    """``(__getattr__, __dir__)`` for ``package`` resolving the names of ``table`` lazily."""
    import sys

    def __getattr__(name: str):
        try:
            module, attr = table[name]
        except KeyError:
            raise AttributeError(f"module {package!r} has no attribute {name!r}") from None
        value = getattr(importlib.import_module(module, package), attr)
        setattr(sys.modules[package], name, value)
        return value

    def __dir__() -> list[str]:
        return sorted(set(vars(sys.modules[package])) | set(table))

    return __getattr__, __dir__
