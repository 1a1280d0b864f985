"""Spectral plastics: the plastic / ceramic BRDF of 000 eq. 29 at several wavelengths.

f_r(L, V, lambda) = a_d(lambda) / pi + a_s (n + 2) / (2 pi) cos^n(alpha) / cos(Theta_min)
F(kappa(lambda), Theta_min)  (000 eq. 29), with the real index kappa(lambda) of a named
dielectric from :mod:`pumpup.spectral.optical` (PMMA, polycarbonate, polystyrene, BK7, fused silica,
from the refractiveindex.info database) or given per wavelength, and a diffuse albedo a_d
(the colour) per wavelength.  Without an index F = 1, 000 eq. 30 (the paper's RGB plastic:
``"wavelengths": "rgb"`` and ``"ad": [r, g, b]``).

One scalar :class:`pumpup.models.metal.Plastic` per wavelength does the work (its checks of n,
a_d, a_s and energy conservation, a_d + a_s max S <= 1, apply to every wavelength); they are
stacked on a trailing wavelength axis like :class:`pumpup.spectral.SpectralMetal`.

Examples
--------
>>> import pumpup
>>> f = pumpup.load({"type": "plastic", "material": "PMMA", "n": 100, "ad": 0.4, "a_s": 0.5})
>>> f.eval([0, 0, 1], [0, 0, 1]).shape
(8,)
"""

from __future__ import annotations

from typing import Any

import numpy as np

from ..core import SpecError
from ..core import load as _load_scalar
from . import RGB_WAVELENGTHS, Spectral, optical

__all__ = ["SpectralPlastic"]

#: the keys of a spectral plastic spec
PLASTIC_KEYS = ("material", "n", "ad", "a_s", "eta", "wavelengths")


def _per_wavelength(name: str, value: Any, m: int) -> list[float]:
    """``value`` as a list of ``m`` numbers: a number is repeated, a list must have length m (its
    entries are checked by the scalar models).
    """
    if isinstance(value, (list, tuple, np.ndarray)):
        if len(value) != m:
            raise SpecError(f"spectral plastic: parameter {name!r} must be a number or a list of {m} values (one "
                            f"per wavelength), got {len(value)} values")
        return [v.item() if isinstance(v, np.generic) else v for v in value]
    return [value.item() if isinstance(value, np.generic) else value] * m


class SpectralPlastic(Spectral):
    """The plastic of 000 eq. 29 at several wavelengths, f_r(wi, wo, lambda) [1/sr].

    Parameters
    ----------
    material : str, optional
        A dielectric of :data:`pumpup.spectral.optical.DIELECTRICS` (``"PMMA"``, ``"polycarbonate"``,
        ``"polystyrene"``, ``"BK7"``, ``"fused_silica"``): its measured real index n(lambda) gives F.
        Omit it to give ``eta``, or neither for F = 1 (000 eq. 30).
    n : float, >= 0
        Phong exponent, shared by all wavelengths.
    ad : float or list of float, in [0, 1], default 0.5
        Diffuse albedo a_d(lambda), one per wavelength (a number: the same at all).
    a_s : float or list of float, in [0, 1], default 0.5
        Weight of the specular lobe (000 eq. 29 has one for all wavelengths; a list is allowed).
        Every wavelength must conserve energy, a_d + a_s max S <= 1 (:class:`~pumpup.models.metal.Plastic`).
    eta : float or list of float, optional
        Real refractive index per wavelength (instead of ``material``).
    wavelengths : list of float or "rgb", optional
        Vacuum wavelengths [nm]; default :data:`pumpup.spectral.optical.DEFAULT_WAVELENGTHS` with
        ``material``, required without it; ``"rgb"`` stands for :data:`pumpup.spectral.RGB_WAVELENGTHS`.
    """

    kind = "plastic"

    def __init__(self, material: str | None = None, n: float | None = None, ad: Any = 0.5, a_s: Any = 0.5,
                 eta: Any = None, wavelengths: Any = None):
        if n is None:
            raise SpecError("spectral plastic: parameter 'n' (the exponent, >= 0) is required")
        if isinstance(wavelengths, str):
            if wavelengths != "rgb":
                raise SpecError("spectral plastic: parameter 'wavelengths' must be a list of nm or 'rgb', got "
                                f"{wavelengths!r}")
            wavelengths = RGB_WAVELENGTHS
        if material is not None:
            if eta is not None:
                raise SpecError("spectral plastic: give either 'material' or 'eta', not both")
            if isinstance(material, str) and material in optical.MATERIALS:
                raise SpecError(f"spectral plastic: parameter 'material' = {material!r} is a metal; "
                                "a plastic (000 eq. 29) has a dielectric's real index, "
                                f"one of {', '.join(optical.DIELECTRICS)} (or give 'eta')")
            w = optical.check_wavelengths(optical.DEFAULT_WAVELENGTHS if wavelengths is None else wavelengths)
            etas = [float(e) for e in optical.dielectric_index(material, w)[0]]
        else:
            if wavelengths is None:
                raise SpecError("spectral plastic: parameter 'wavelengths' is required without 'material' "
                                f"(a dielectric, one of {', '.join(optical.DIELECTRICS)})")
            w = optical.check_wavelengths(wavelengths)
            etas = None if eta is None else _per_wavelength("eta", eta, w.size)
        ads = _per_wavelength("ad", ad, w.size)
        a_ss = _per_wavelength("a_s", a_s, w.size)
        self.material = material
        self.wavelengths = w
        self.models = []
        for j in range(w.size):
            one: dict[str, Any] = {"type": "plastic", "n": n, "ad": ads[j], "a_s": a_ss[j]}
            if etas is not None:
                one["eta"] = etas[j]
            try:
                self.models.append(_load_scalar(one))  # checks n, ad, a_s, eta and energy conservation
            except SpecError as exc:
                raise SpecError(f"spectral plastic at {w[j]:g} nm: {exc}") from None
        self.n = self.models[0].p["n"]
        self.ad = np.array([m.p["ad"] for m in self.models])
        self.a_s = np.array([m.p["a_s"] for m in self.models])
        self.eta = None if etas is None else np.array([m.p["eta"] for m in self.models])
        self.k = None

    @classmethod
    def from_spec(cls, spec: dict) -> SpectralPlastic:
        """Build from ``{"type": "plastic", "material" | "eta", "n", "ad", "a_s", "wavelengths"}``."""
        kw = {k: v for k, v in spec.items() if k != "type"}
        if "k" in kw:
            raise SpecError("spectral plastic: parameter 'k' is not allowed: a plastic's index is real (000 eq. 29); "
                            "use type 'metal' for a complex index")
        bad = sorted(set(kw) - set(PLASTIC_KEYS))
        if bad:
            raise SpecError(f"spectral plastic: unknown parameter(s) {', '.join(map(repr, bad))}; allowed: "
                            f"{', '.join(PLASTIC_KEYS)}")
        return cls(**kw)

    def __repr__(self) -> str:
        what = self.material or ("explicit index" if self.eta is not None else "F = 1")
        return f"SpectralPlastic({what}, n={self.n:g}, wavelengths={self.wavelengths.tolist()})"

    @property
    def spec(self) -> dict:
        """A JSON-able description; ``pumpup.load(f.spec)`` rebuilds it."""
        out: dict[str, Any] = {"type": "plastic", "n": self.n, "ad": self.ad.tolist(),
                               "a_s": float(self.a_s[0]) if np.all(self.a_s == self.a_s[0]) else self.a_s.tolist(),
                               "wavelengths": self.wavelengths.tolist()}
        if self.material is not None:
            out["material"] = self.material
        elif self.eta is not None:
            out["eta"] = self.eta.tolist()
        return out

    def fresnel_normal(self) -> np.ndarray:
        """F at normal incidence of the dielectric, ((eta - 1) / (eta + 1))^2 per wavelength (1 without an index)."""
        if self.eta is None:
            return np.ones(self.wavelengths.size)
        return ((self.eta - 1.0) / (self.eta + 1.0)) ** 2
