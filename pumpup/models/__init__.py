"""The built-in models, one module per family; importing this package registers them."""

from . import lambert, phong  # noqa: F401
