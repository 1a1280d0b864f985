"""The albedo engine: directional albedo a(mu) of any BRDF with an error estimate that bounds the truth.

Its routes: the 2-D adaptive cubature (:mod:`.cubature`, which also holds the public :func:`albedo`), the nested
quadrature on smooth arcs (:mod:`.nested`), the 1-D paths with the azimuth in closed form (:mod:`.polar`) and slope
space for anisotropic Ward (:mod:`.slope`).
"""

from .._lazy import submodules
from .cubature import DEFAULT_ATOL, DEFAULT_RTOL, AlbedoWarning, albedo, check_mu, check_phi

__all__ = ["albedo", "check_mu", "check_phi", "AlbedoWarning", "DEFAULT_RTOL", "DEFAULT_ATOL"]

__getattr__ = submodules(__name__)  # the routes' modules on first use (pumpup.engine.polar)
