"""What the models, the engine and the renderer plugins share: quadrature rules and their error calibration
(:mod:`.quadrature`).
"""

from .._lazy import submodules

__getattr__ = submodules(__name__)
