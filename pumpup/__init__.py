"""pumpup: physically plausible reflectance models, their albedo, and the albedo pumping-up operator.

Conventions: the surface normal is N = (0, 0, 1); ``wi`` points towards the light, ``wo`` towards
the viewer; ``BRDF.eval`` returns f_r in 1/sr without the cosine factor; ``mu`` = cos(theta_i)
(see :class:`pumpup.BRDF`).

``import pumpup`` is instant: each public name below is imported from its module the first time
it is used (PEP 562), so numba, scipy and xarray load only when a computation needs them.
"""

from __future__ import annotations

import importlib
import sys
import types

from ._lazy import submodules
from ._version import __version__

#: public name -> (module, attribute); attribute None means the module itself
_PUBLIC = {
    "albedo_module": ("engine.cubature", None),
    "albedo": ("engine", "albedo"),
    "reproduce": ("reproduce", None),
    "testing": ("testing", None),
    "render": ("render", None),
    "divergence": ("divergence", "divergence"),
    "Pumped": ("operators.pumping", "Pumped"),
    "load_pumped": ("operators.pumping", "load_pumped"),
    "pump": ("operators.pumping", "pump"),
    "save_pumped": ("operators.pumping", "save_pumped"),
    "KullaConty": ("operators.compensate", "KullaConty"),
    "Scaled": ("operators.compensate", "Scaled"),
    "compensate": ("operators.compensate", "compensate"),
    "furnace": ("operators.compensate", "furnace"),
    "load_compensated": ("operators.compensate", "load_compensated"),
    "save_compensated": ("operators.compensate", "save_compensated"),
    "sampling": ("sampling", None),
    "mc_albedo": ("sampling", "mc_albedo"),
    "mc_radiance": ("sampling", "mc_radiance"),
    "sample": ("sampling", "sample"),
    "AlbedoTable": ("tables", "AlbedoTable"),
    "max_albedo": ("tables", "max_albedo"),
    "max_constant": ("tables", "max_constant"),
    "mean_albedo": ("tables", "mean_albedo"),
    "open_table": ("tables", "open_table"),
    "tabulate": ("tables", "tabulate"),
    "write_table": ("tables", "write_table"),
    "sweep": ("sweeps", "sweep"),
    "lut_module": ("luts", None),
    "audit": ("luts", "audit"),
    "lut": ("luts", "lut"),
    "shader": ("shaders", "shader"),
    "conventions": ("conventions", None),
    "load_conventions": ("conventions", "load_conventions"),
    "furnace_prediction": ("renderer_furnace", "furnace_prediction"),
    "FitResult": ("fitting", "FitResult"),
    "fit": ("fitting", "fit"),
    "BRDF": ("core", "BRDF"),
    "Lobe": ("core", "Lobe"),
    "Param": ("core", "Param"),
    "ReciprocityResult": ("core", "ReciprocityResult"),
    "SpecError": ("core", "SpecError"),
    "check_reciprocity": ("core", "check_reciprocity"),
    "from_function": ("core", "from_function"),
    "load": ("core", "load"),
    "register": ("core", "register"),
    "registry": ("core", "registry"),
}

#: public functions named like the submodule that holds them (``divergence``): importing it must not replace them
_FUNCTIONS_NAMED_LIKE_MODULES = frozenset(name for name, (module, attr) in _PUBLIC.items() if name == module and attr)

__all__ = ["__version__", *_PUBLIC]

#: the modules whose types and loaders the registry imports on first use, in this order (:mod:`pumpup.core`)
PROVIDERS = ("pumpup.operators.pumping", "pumpup.operators.compensate", "pumpup.models", "pumpup.spectral",
             "pumpup.tables")


_submodule = submodules(__name__)


def __getattr__(name: str):
    """Import a public name (or a submodule, ``pumpup.tables``) on first use."""
    if name in _PUBLIC:
        module_name, attr = _PUBLIC[name]
        module = importlib.import_module(f"{__name__}.{module_name}")
        value = module if attr is None else getattr(module, attr)
    else:
        value = _submodule(name)
    globals()[name] = value
    return value


def __dir__() -> list[str]:
    return sorted(set(globals()) | set(__all__))


class _Package(types.ModuleType):
    """The package's module type: the import system's binding of a submodule (``pumpup.albedo``, the
    module) never replaces the public function of the same name (``pumpup.albedo``, the function).
    """

    def __setattr__(self, name: str, value) -> None:
        if name in _FUNCTIONS_NAMED_LIKE_MODULES and isinstance(value, types.ModuleType):
            return
        super().__setattr__(name, value)


sys.modules[__name__].__class__ = _Package
