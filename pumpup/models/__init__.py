"""The built-in models, one module per family; importing this package registers them."""

from . import blinn, cook_torrance, diffuse, he_torrance, lafortune, lambert  # noqa: F401
from . import lewis, metal, microfacet, phong, schlick, ward  # noqa: F401
from . import ashikhmin_shirley  # noqa: F401
from . import mix  # noqa: F401  (after the models it mixes)
from . import fresnel  # noqa: F401  (a base BRDF x F(Theta_min), 000 eq. 28's factor)
