"""Submodules imported on first attribute access (PEP 562), for the package and its subpackages."""

from __future__ import annotations

import importlib
from collections.abc import Callable
from typing import Any


def submodules(package: str) -> Callable[[str], Any]:
    """A module ``__getattr__`` for ``package`` that imports ``package.name`` when ``name`` is one of its
    submodules, so that ``pumpup.tables.provenance`` works after ``import pumpup``.
    """

    def __getattr__(name: str) -> Any:
        if name.startswith("__"):
            raise AttributeError(f"module {package!r} has no attribute {name!r}")
        try:
            return importlib.import_module(f"{package}.{name}")
        except ModuleNotFoundError as exc:
            if exc.name != f"{package}.{name}":
                raise
            raise AttributeError(f"module {package!r} has no attribute {name!r}") from None

    return __getattr__
