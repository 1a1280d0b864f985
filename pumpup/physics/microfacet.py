"""Smith's shadowing for the Beckmann and GGX microfacet distributions (Walter et al. 2007; Heitz 2014), shared by the
microfacet models and the albedo engine: the projected area P = z (1 + Lambda) = z / G1 of a direction (x, y, z),
compiled (:func:`projected`) and in plain numpy (:func:`projected_reference`), and where Walter's rational G1 switches
to 1 (:func:`walter_level`).
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

__all__ = ["projected", "projected_reference", "walter_level", "W_CUT"]

SQRT_PI = math.sqrt(math.pi)
#: Walter et al. 2007 eq. 27: G1 ~ (3.535 a + 2.181 a^2) / (1 + 2.276 a + 2.577 a^2) for a < 1.6, else 1
W_A1, W_A2, W_B1, W_B2, W_CUT = 3.535, 2.181, 2.276, 2.577, 1.6


@njit(cache=True, inline="always")
def projected(x, y, z, dist, g1, alpha):  # pragma: no cover - compiled
    """P = z (1 + Lambda) = z / G1 for a direction (x, y, z) with z > 0 (see the module docstring)."""
    s = math.sqrt(x * x + y * y)  # sin theta (times |w|)
    if dist == 1:  # z / G1, G1 = 2 / (1 + sqrt(1 + alpha^2 tan^2)), Walter eq. 34
        # (a unit vector, MIN_ALPHA <= alpha <= MAX_WIDTH: z^2 + w^2 neither overflows nor underflows, so a plain root
        # instead of math.hypot, which took ~20 ns a call)
        w = alpha * s
        return 0.5 * (z + math.sqrt(z * z + w * w))
    if s == 0.0:
        return z  # normal incidence: Lambda = 0
    a = z / (alpha * s)  # a = 1 / (alpha tan theta), Walter eq. 27
    if g1 == 0:
        return 0.5 * (z * (1.0 + math.erf(a)) + alpha * s * math.exp(-a * a) / SQRT_PI)  # Walter eq. 27 (exact)
    if a >= W_CUT:
        return z  # rational fit: G1 = 1 for a >= 1.6, Walter eq. 27
    return alpha * s * (1.0 + W_B1 * a + W_B2 * a * a) / (W_A1 + W_A2 * a)  # z / G1, Walter eq. 27 (rational)


def projected_reference(w, dist, g1, alpha):
    """Plain numpy twin of :func:`projected`: P = z / G1 of the directions ``w`` (..., 3), GGX for ``dist`` 1 (Walter
    eq. 34), else Beckmann, exact (``g1`` 0, Walter eq. 27) or Walter's rational fit; P = z at the normal.
    """
    from scipy.special import erf

    x, y, z = w[..., 0], w[..., 1], w[..., 2]
    s = np.sqrt(x * x + y * y)
    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
        if dist == 1:
            return 0.5 * (z + np.hypot(z, alpha * s))  # Walter eq. 34
        a = z / (alpha * s)  # inf at normal incidence
        if g1 == 0:
            p = 0.5 * (z * (1.0 + erf(a)) + alpha * s * np.exp(-a * a) / SQRT_PI)  # Walter eq. 27
        else:
            p = np.where(a >= W_CUT, z, alpha * s * (1.0 + W_B1 * a + W_B2 * a * a) / (W_A1 + W_A2 * a))
    return np.where(s == 0.0, z, p)


def walter_level(alpha: float) -> float:
    """N.w where Walter's rational G1 switches to 1 (a = 1.6): 1.6 alpha / sqrt(1 + 2.56 alpha^2).

    The fit jumps there by 5.7e-5 (relative), so the albedo engine gets it as a breakpoint.
    """
    return W_CUT * alpha / math.sqrt(1.0 + (W_CUT * alpha) ** 2)
