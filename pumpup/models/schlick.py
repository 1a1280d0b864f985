"""Schlick's isotropic rational BRDF (000 eq. 36).

With S = L + V and H = S / |S|: 1 - (1 - r)(N.H)^2 = r + (1 - r) sin^2 delta, with
t = tan^2 delta = (S_x / S_z)^2 + (S_y / S_z)^2, cos^2 delta = 1 / (1 + t) and
sin^2 delta = t cos^2 delta (t <= 1) or 1 - cos^2 delta (t > 1).  This keeps full
relative accuracy for small r near the highlight, where 1 - (1 - r)(N.H)^2 would
cancel, and stays finite down to the smallest representable N.L and N.V.
"""

from __future__ import annotations

import math

import numpy as np
from numba import vectorize

from ..core import BRDF, MIN_WIDTH, Lobe, Param, register
from ._half import tan2_half


@vectorize(cache=True)
def _kernel(lx, ly, lz, vx, vy, vz, r, c):  # pragma: no cover - compiled
    if lz <= 0.0 or vz <= 0.0:
        return 0.0
    t = tan2_half(lx, ly, lz, vx, vy, vz)  # tan^2 delta
    cos2 = 1.0 / (1.0 + t)
    sin2 = t * cos2 if t <= 1.0 else 1.0 - cos2
    d = r + (1.0 - r) * sin2  # 1 - (1 - r)(N.H)^2
    gl = r + (1.0 - r) * lz
    gv = r + (1.0 - r) * vz
    return c / (4.0 * math.pi) * (r / d / d) / (gl * gv)  # 000 eq. 36


def _reference(wi, wo, r, c):
    s = wi + wo
    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
        qx = s[..., 0] / s[..., 2]
        qy = s[..., 1] / s[..., 2]
        t = qx * qx + qy * qy  # tan^2 delta
        cos2 = 1.0 / (1.0 + t)
        sin2 = np.where(t <= 1.0, t * cos2, 1.0 - cos2)
        d = r + (1.0 - r) * sin2  # 1 - (1 - r)(N.H)^2
        gl = r + (1.0 - r) * wi[..., 2]
        gv = r + (1.0 - r) * wo[..., 2]
        f = c / (4.0 * np.pi) * (r / d / d) / (gl * gv)  # 000 eq. 36
    up = (wi[..., 2] > 0) & (wo[..., 2] > 0)
    return np.where(up, f, 0.0)


@register("schlick")
class Schlick(BRDF):
    """Schlick's isotropic model [1/sr] (000 eq. 36, with C_max = c).

    f_r = c / (4 pi) * r / (1 - (1 - r)(N.H)^2)^2 * 1 / (r + (1 - r)(N.L))
    * 1 / (r + (1 - r)(N.V)).

    Parameters
    ----------
    r : float, in (0, 1]
        Roughness (dimensionless): small r is shiny; r = 1 gives the constant c / (4 pi).
    c : float, >= 0, default 1
        Scale (dimensionless).  The largest energy-conserving value falls with r
        (000 sec. 6.2: 2.14 for r = 0.5, 0.72 for r = 0.1, 0.21 for r = 0.01).

    Examples
    --------
    >>> import math, pumpup
    >>> f = pumpup.load({"type": "schlick", "r": 0.1})
    >>> round(float(f.eval([0, 0, 1], [0, 0, 1])) * 4 * math.pi * 0.1, 12)  # c / (4 pi r) at wi = wo = N
    1.0
    """

    params = {
        "r": Param(lo=MIN_WIDTH**2, hi=1.0, doc="roughness (the lobe is about sqrt(r) wide)"),
        "c": Param(1.0, lo=0.0, doc="scale"),
    }
    examples = [{"r": 1.0}, {"r": 0.5, "c": 2.14}, {"r": 0.1}, {"r": 0.01, "c": 0.21}, {"r": 0.001}]
    kernel = staticmethod(_kernel)
    reference_fn = staticmethod(_reference)

    def lobe(self, mu):
        """The Lobe hint: a GGX lobe of r about the half vector (000 eq. 36)."""
        return Lobe(axis="half", radial="ggx", sharpness=self.p["r"])

    def azimuth_hint(self):
        """The azimuth hint: the GGX weight with alpha = sqrt(r) and 1 / (r + (1 - r) N.V) about the normal (000 eq.
        36).
        """
        from ..core.hints import AzimuthHint, SchlickLobe

        r, c = self.p["r"], self.p["c"]
        # 000 eq. 36: r / (1 - (1 - r) cos^2)^2 = 1 / (r cos^4 (1 + tan^2 / r)^2), the GGX weight with alpha = sqrt(r);
        # 1 / (r + (1 - r) N.V) about N, the weight's azimuth in closed form (pumpup.engine.normal_frame._integrate_n),
        # the rest in the scale
        return AzimuthHint(SchlickLobe(r=r),
                           scale=lambda mu: c / (4.0 * math.pi * r * (r + (1.0 - r) * np.asarray(mu, float))))
