"""A base BRDF times the Fresnel reflectance of a conductor at Theta_min (000 eq. 28's factor).

f_r(wi, wo) = f_base(wi, wo) F(eta + i k, Theta_min), cos(Theta_min) = max(N.wi, N.wo).

000 eq. 28 is this with the stretched Phong lobe (F = 1 lobe c cos^n(alpha) / cos(Theta_min),
000 eq. 7) as the base, i.e. ``metal``; with a *pumped* base it is one colour channel of the
colour-keeping pumped metal (:class:`pumpup.spectral.SpectralPumpedLobe`: the F = 1 lobe pumped,
001 eq. 16, then F per wavelength), which the path-traced scenes (:mod:`pumpup.scenes`) use per
RGB channel.  F(max(N.wi, N.wo)) is symmetric in wi and wo, so the product is reciprocal when the
base is; 0 <= F <= 1, so its albedo is at most the base's (energy conservation is inherited).
"""

from __future__ import annotations

import numpy as np
from numba import vectorize

from ..core import BRDF, MAX_INDEX, MIN_INDEX, Param, register
from .metal import _fresnel_real, fresnel, fresnel_levels

__all__ = ["FresnelWeighted"]


@vectorize(cache=True)
def _fresnel_ufunc(c, eta, k):  # pragma: no cover - compiled
    return _fresnel_real(c, eta, k)


@register("fresnel")
class FresnelWeighted(BRDF):
    """f_r = f_base(wi, wo) F(eta + i k, Theta_min) [1/sr], F the exact unpolarised Fresnel
    reflectance of a conductor (:func:`pumpup.models.metal.fresnel`) at cos(Theta_min) =
    max(N.wi, N.wo) (000 eq. 28).

    Reciprocal if the base is (F(Theta_min) is symmetric in wi, wo); albedo <= the base's,
    since 0 <= F <= 1.  ``{"type": "fresnel", "base": {"type": "stretched_phong", "n": n,
    "p": 1}, "eta": e, "k": k}`` equals ``{"type": "metal", "n": n, "eta": e, "k": k}``; with
    ``{"type": "pumped", "base": <that lobe>}`` as the base it is one channel of the
    colour-keeping pumped metal (:class:`pumpup.spectral.SpectralPumpedLobe`).

    Parameters
    ----------
    base : spec
        The single-channel BRDF weighted by F.
    eta : float, > 0
        Real part of the complex refractive index (this wavelength or channel).
    k : float, >= 0, default 0
        Extinction coefficient (imaginary part of the index).

    Examples
    --------
    >>> import math, pumpup
    >>> f = pumpup.load({"type": "fresnel", "base": {"type": "phong", "n": 20}, "eta": 0.2, "k": 3.0})
    >>> F0 = ((0.2 - 1) ** 2 + 9) / ((0.2 + 1) ** 2 + 9)  # Fresnel at normal incidence
    >>> round(float(f.eval([0, 0, 1], [0, 0, 1])) / (22 / (2 * math.pi) * F0), 12)
    1.0
    """

    params = {
        "base": Param(kind="spec", doc="the BRDF weighted by F(Theta_min)"),
        "eta": Param(lo=MIN_INDEX, hi=MAX_INDEX, doc="refractive index, real part"),
        "k": Param(0.0, lo=0.0, hi=MAX_INDEX, doc="extinction coefficient"),
    }
    constant = None
    examples = [
        {"base": {"type": "phong", "n": 20}, "eta": 0.2, "k": 3.0},
        {"base": {"type": "stretched_phong", "n": 100, "p": 1.0}, "eta": 1.1, "k": 6.0},
        {"base": {"type": "lambert", "albedo": 0.8}, "eta": 1.5},
    ]

    def __init__(self, **kwargs):
        super().__init__(**kwargs)
        self.reciprocal = bool(self.p["base"].reciprocal)

    @property
    def base(self) -> BRDF:
        """The BRDF that F(Theta_min) multiplies."""
        return self.p["base"]

    def _eval(self, wi, wo):
        f = np.asarray(self.base._eval(wi, wo), dtype=np.float64)
        mx = np.clip(np.maximum(wi[..., 2], wo[..., 2]), 0.0, 1.0)  # cos(Theta_min)
        return np.where(f != 0.0, f * _fresnel_ufunc(mx, self.p["eta"], self.p["k"]), 0.0)  # 000 eq. 28

    def reference(self, wi, wo):
        """The plain numpy f_r: the base's reference times F(max(N.wi, N.wo)) in complex arithmetic (000 eq. 28)."""
        wi = np.asarray(wi, dtype=np.float64)
        wo = np.asarray(wo, dtype=np.float64)
        f = np.asarray(self.base.reference(wi, wo), dtype=np.float64)
        mx = np.maximum(wi[..., 2], wo[..., 2])
        return np.where(f != 0.0, f * fresnel(mx, self.p["eta"], self.p["k"]), 0.0)  # 000 eq. 28, complex form

    def lobe(self, mu):
        """The base's Lobe hint with the levels N.wo = mu and F's own kink added."""
        # F(max(N.wi, N.wo)) adds a kink at N.wo = mu, and one where F has its own
        return self.base.lobe(mu).with_levels((float(mu),), fresnel_levels(self.p["eta"], self.p["k"]))

    def albedo_terms(self):
        """F(Theta_min) times each of the base's linear terms (F sum w_k f_k = sum w_k F f_k), each term with its own
        hint (:class:`_FresnelTerm`); itself where the base is one term.  As one term, fresnel over plastic (n 34.4, eta
        1.88, ad 0.33) had the specular lobe's hint (the power map about the mirror, n = 34) for its Lambert part too,
        and the engines lost part of it with estimates of 1e-9 (0.2908 for 0.4060 at mu = 0.306, eta 0.232), and over a
        2-level pumped plastic half of it (0.468 for 0.959 at mu = 1; scripts/studies/fuzz_engines.py --registry 47 and
        48).
        """
        terms = self.base.albedo_terms()
        if len(terms) == 1 and terms[0][1] is self.base:
            return [(1.0, self)]
        return [(w, _FresnelTerm(t, self.p["eta"], self.p["k"])) for w, t in terms]

    def albedo_breaks(self):
        """F's kink and the base's breaks, sorted."""
        return tuple(sorted({*fresnel_levels(self.p["eta"], self.p["k"]), *self.base.albedo_breaks()}))

    def sampling_lobe(self, mu):
        """The base's sampling hint (F only rescales the base)."""
        return self.base.sampling_lobe(mu)  # F only rescales the base

    def azimuth_range(self):
        """The base's (F depends on N.wi and N.wo only)."""
        return self.base.azimuth_range()  # F depends on N.wi and N.wo only

    def fresnel_one(self):
        """The base: this wrapper with F = 1."""
        return self.base

    def azimuth_hint(self):
        """The base's hint times F(max(N.wi, N.wo)) (000 eq. 28), or None without one."""
        from ..core.hints import FresnelAtMax

        hint = self.base.azimuth_hint()
        return None if hint is None else hint.times(FresnelAtMax(self.p["eta"], self.p["k"]))


class _FresnelTerm(FresnelWeighted):
    """One linear term of the ``fresnel`` wrapper over a sum: F(Theta_min) f_k, f_k any term of the base (a model, or a
    part of a pumped or compensated model, which has no spec of the registry), with f_k's own hint.
    """

    type = "fresnel-term"

    def __init__(self, term: BRDF, eta: float, k: float):  # noqa: D107 - bypasses the registry's parameter parsing
        self.p = {"base": term, "eta": float(eta), "k": float(k)}
        self.reciprocal = bool(term.reciprocal)

    @property
    def spec(self) -> dict:
        return {"type": self.type, "base": self.base.spec, "eta": self.p["eta"], "k": self.p["k"]}

    def albedo_terms(self):
        return [(1.0, self)]
