"""pumpup: physically plausible reflectance models, their albedo, and the albedo pumping-up operator.

See DESIGN.md for the conventions (N = (0, 0, 1), wi towards the light, wo towards the
viewer, f_r without the cosine factor, mu = cos(theta_i)).
"""

from ._version import __version__
from . import albedo as albedo_module
from .albedo import albedo
from . import _polar  # noqa: F401  (the 1-D albedo path; pumpup._polar.two_d_only() for the 2-D reference)
from . import reproduce
from . import testing
from . import render
from .divergence import divergence
from .pumping import Pumped, load_pumped, pump, save_pumped
from .compensate import KullaConty, Scaled, compensate, furnace, load_compensated, save_compensated
from . import sampling
from .sampling import mc_albedo, mc_radiance, sample
from .tables import AlbedoTable, max_albedo, max_constant, mean_albedo, open_table, tabulate, write_table
from .sweeps import sweep
from . import luts as lut_module
from .luts import audit, lut
from .fitting import FitResult, fit
from .core import (
    BRDF,
    Lobe,
    Param,
    ReciprocityResult,
    SpecError,
    check_reciprocity,
    from_function,
    load,
    register,
    registry,
)

__all__ = [
    "__version__",
    "albedo_module",
    "reproduce",
    "render",
    "albedo",
    "divergence",
    "sampling",
    "sample",
    "mc_albedo",
    "mc_radiance",
    "Pumped",
    "pump",
    "save_pumped",
    "load_pumped",
    "compensate",
    "furnace",
    "KullaConty",
    "Scaled",
    "save_compensated",
    "load_compensated",
    "AlbedoTable",
    "max_albedo",
    "max_constant",
    "mean_albedo",
    "open_table",
    "tabulate",
    "sweep",
    "lut",
    "audit",
    "lut_module",
    "fit",
    "FitResult",
    "write_table",
    "BRDF",
    "Lobe",
    "Param",
    "ReciprocityResult",
    "SpecError",
    "check_reciprocity",
    "from_function",
    "load",
    "register",
    "registry",
]
