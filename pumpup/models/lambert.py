"""Lambertian (ideal diffuse) reflection: f_r = albedo / pi."""

from __future__ import annotations

import math

import numpy as np
from numba import vectorize

from ..core import BRDF, Lobe, Param, register


@vectorize(cache=True)
def _kernel(lx, ly, lz, vx, vy, vz, albedo):  # pragma: no cover - compiled
    if lz <= 0.0 or vz <= 0.0:
        return 0.0
    return albedo / math.pi


def _reference(wi, wo, albedo):
    up = (wi[..., 2] > 0) & (wo[..., 2] > 0)
    return np.where(up, albedo / np.pi, 0.0)


@register("lambert")
class Lambert(BRDF):
    """Lambertian reflection, f_r = albedo / pi [1/sr] (002 sec. 3.1, the k_d term of eq. 8).

    Parameters
    ----------
    albedo : float, in [0, 1], default 1
        The directional albedo, the same for every incidence angle.

    Examples
    --------
    >>> import pumpup
    >>> round(float(pumpup.albedo(pumpup.load({"type": "lambert", "albedo": 0.3}), 0.5)), 12)
    0.3
    """

    params = {"albedo": Param(1.0, lo=0.0, hi=1.0, doc="directional albedo")}
    constant = "albedo"
    examples = [{}, {"albedo": 0.3}]
    kernel = staticmethod(_kernel)
    reference_fn = staticmethod(_reference)

    def lobe(self, mu):
        """The Lobe hint: the cosine map about the normal, exact for a constant f_r."""
        return Lobe(axis="normal", radial="cosine")

    def azimuth_hint(self):
        """The azimuth hint: a closed form, a(mu) = albedo at every incidence."""
        from ..core.hints import AzimuthHint, ClosedForm

        a = self.p["albedo"]
        return AzimuthHint(ClosedForm(), scale=lambda mu: np.full(np.shape(mu), a))  # albedo / pi * pi
