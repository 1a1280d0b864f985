"""The albedo engine: directional albedo a(mu) of any BRDF with an error estimate that bounds the truth.

One table chooses the route from what a model declares (:mod:`.routes`, printed by ``routes.describe()``).  The
routes: the 2-D adaptive cubature (:mod:`.cubature`, which also holds the public :func:`albedo`), the nested quadrature
on smooth arcs (:mod:`.nested`; the two share :mod:`.lobe_geometry` and :mod:`.arc_breaks`), the 1-D routes with the
azimuth in closed form or by a rule on known arcs (run by :mod:`.polar`, one module per frame: :mod:`.lobe_frame`,
:mod:`.half_frames`, :mod:`.half_arc`, :mod:`.lobe_fresnel`, :mod:`.normal_frame`, :mod:`.chain_frame`, with
:mod:`.outer_rule` and :mod:`.hint_view`) and slope space for anisotropic Ward (:mod:`.slope`).
"""

from .._lazy import submodules
from .cubature import DEFAULT_ATOL, DEFAULT_RTOL, AlbedoWarning, albedo, check_mu, check_phi

__all__ = ["albedo", "check_mu", "check_phi", "AlbedoWarning", "DEFAULT_RTOL", "DEFAULT_ATOL"]

__getattr__ = submodules(__name__)  # the routes' modules on first use (pumpup.engine.polar)
