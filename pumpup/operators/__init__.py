"""Operators that take a BRDF and return a BRDF: the albedo pumping-up operator (:mod:`.pumping`) and energy
compensation (:mod:`.compensate`).
"""

from .._lazy import submodules

__getattr__ = submodules(__name__)  # pumpup.operators.pumping, pumpup.operators.compensate on first use
