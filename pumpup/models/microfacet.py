"""Microfacet BRDFs with Smith shadowing: Beckmann and GGX (Trowbridge-Reitz), isotropic.

f_r(wi, wo) = D(h) F(wi.h) G(wi, wo) / (4 (N.wi)(N.wo))   (Walter et al. 2007, eq. 20)

with h = (wi + wo) / |wi + wo| and alpha the roughness of Walter et al. 2007 (and of
Mitsuba 3, pbrt and most renderers):

* Beckmann: D = exp(-tan^2 delta / alpha^2) / (pi alpha^2 cos^4 delta) (Walter eq. 25);
  Smith Lambda(a) = (erf(a) - 1) / 2 + exp(-a^2) / (2 a sqrt(pi)), a = 1 / (alpha tan theta)
  (G1 = 1 / (1 + Lambda), Walter eq. 27), or Walter's rational fit of G1 (also eq. 27),
  G1 = (3.535 a + 2.181 a^2) / (1 + 2.276 a + 2.577 a^2) for a < 1.6 and 1 above, the one
  Mitsuba 3 uses.
* GGX: D = alpha^2 / (pi cos^4 delta (alpha^2 + tan^2 delta)^2) (Walter eq. 33);
  G1 = 2 / (1 + sqrt(1 + alpha^2 tan^2 theta)) (Walter eq. 34), Lambda = (sqrt(1 + alpha^2
  tan^2 theta) - 1) / 2.
* G = G1(wi) G1(wo) ("separable", Walter sec. 5, Smith 1967) or the height-correlated
  G = 1 / (1 + Lambda(wi) + Lambda(wo)) ("correlated", Heitz 2014, "Understanding the
  Masking-Shadowing Function in Microfacet-Based BRDFs", JCGT 3(2), sec. 6).
* F = 1, the dielectric Fresnel factor of ``cook_torrance`` (real ``ior``), or the exact
  conductor Fresnel factor of ``metal`` (complex index ``eta`` + i ``k``), at c = wi.h.

Numerics.  Everything is written in terms of the projected area P(w) = (N.w)(1 + Lambda(w))
= (N.w) / G1(w), which has no cancellation and no division by a small number for any
direction above the horizon (s = sin theta = |w_xy|, z = N.w, a = z / (alpha s)):

* Beckmann exact: P = (z (1 + erf(a)) + alpha s exp(-a^2) / sqrt(pi)) / 2;
* Beckmann rational fit: P = alpha s (1 + 2.276 a + 2.577 a^2) / (3.535 + 2.181 a) (a < 1.6),
  P = z (a >= 1.6);
* GGX: P = (z + sqrt(z^2 + alpha^2 s^2)) / 2.

Then f_r = D F / (4 P(wi) P(wo)) (separable) and f_r = D F / (4 ((N.wo) P(wi) + (N.wi) P(wo)
- (N.wi)(N.wo))) (correlated: the three terms are (N.wi)(N.wo)(1 + Lambda(wi) + Lambda(wo))
with the subtracted term at most half of the sum).  Both are symmetric in wi and wo to
the last bit, finite down to N.wi = N.wo = 1e-300 and tend to a finite limit as one
direction goes to grazing (G1 vanishes like N.w there).  tan^2 delta is formed from
S = wi + wo as in the other half-vector models (no 1 - (N.h)^2 cancellation).
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np
from numba import njit, vectorize

from ..core import BRDF, MAX_INDEX, MAX_WIDTH, MIN_ALPHA, MIN_INDEX, Lobe, Param, SpecError, register
from ..physics.lookups import g_levels_call, g_pair, g_product, g_split, upper_scalar
from ..physics.microfacet import projected, projected_reference, walter_level
from ._half import tan2_half
from .cook_torrance import _IOR, _fresnel, _fresnel_reference
from .metal import _fresnel_real
from .metal import fresnel as _fresnel_complex

__all__ = ["GGX", "Beckmann", "ndf", "smith_g1", "smith_lambda", "walter_level"]


_DIST = {"beckmann": 0, "ggx": 1}
_SHADOWING = {"separable": 0, "correlated": 1}
_G1 = {"exact": 0, "walter": 1}


# ----------------------------------------------------------------------------------------
# Compiled pieces
# ----------------------------------------------------------------------------------------


def _mf_value(lx, ly, lz, vx, vy, vz, dist, alpha, shadowing, g1, ior, eta, k):  # pragma: no cover - compiled
    if lz <= 0.0 or vz <= 0.0:
        return 0.0
    sx = lx + vx
    sy = ly + vy
    sz = lz + vz
    t = tan2_half(lx, ly, lz, vx, vy, vz)  # tan^2 delta
    a2 = alpha * alpha
    if dist == 0:
        e = math.exp(-t / a2)
        if e == 0.0:
            return 0.0
        d = e * ((1.0 + t) * (1.0 + t)) / (math.pi * a2)  # Beckmann D, Walter eq. 25
    else:
        cos2 = 1.0 / (1.0 + t)
        sin2 = t * cos2 if t <= 1.0 else 1.0 - cos2
        q = a2 * cos2 + sin2  # cos^2 delta (alpha^2 + tan^2 delta)
        d = a2 / (math.pi * q * q)  # GGX D, Walter eq. 33
    c = 0.5 * math.sqrt(sx * sx + sy * sy + sz * sz)  # wi.h = wo.h = |wi + wo| / 2
    if eta > 0.0:
        f = _fresnel_real(c, eta, k)  # conductor (metal.py)
    else:
        f = _fresnel(c, ior)  # dielectric, 1 when ior <= 0 (cook_torrance.py)
    pl = projected(lx, ly, lz, dist, g1, alpha)
    pv = projected(vx, vy, vz, dist, g1, alpha)
    if shadowing == 0:
        return d * f / (4.0 * pl * pv)  # D F G1(wi) G1(wo) / (4 N.wi N.wo), Walter eq. 20
    return d * f / (4.0 * (vz * pl + lz * pv - lz * vz))  # G = 1 / (1 + Lambda_i + Lambda_o), Heitz 2014


#: the kernel, over broadcast arrays
_mf_kernel = vectorize(cache=True)(_mf_value)
#: the kernel at one pair (the fused pumped kernel's)
_mf_scalar = njit(cache=True, nogil=True, inline="always")(_mf_value)


@njit(cache=True, nogil=True)
def _mf_divided(wi, wo, out, dist, alpha, shadowing, g1, ior, eta, k, offsets, logx, coef, v0, slope0, margin_lo, cap,
                controlled, increasing, mu0, index, index_lo, index_h_inv, pmlo, pcbase, pcell, plo, prow, pinv, qmlo,
                qshift, qcbase, qcell, qlo, qrow, rcells, rpattern, rfid, rhid, rshift, rcbase,
                rcell, rlo, rcoef):  # pragma: no cover - compiled
    """f_r / (g_1 ... g_k) (001 eq. 16) over the rows of (N, 3) arrays into ``out``: the kernel's value and the pumped
    chain's division in one pass, the same operations as the kernel followed by the chain kernel
    (``pumpup.operators.pumping._chain_kernel``; ``BRDF.eval_divided``).
    """
    for r in range(out.shape[0]):
        lz, vz = wi[r, 2], wo[r, 2]
        if lz <= 0.0 or vz <= 0.0:
            out[r] = 0.0
            continue
        f = _mf_scalar(wi[r, 0], wi[r, 1], lz, wo[r, 0], wo[r, 1], vz, dist, alpha, shadowing, g1, ior, eta, k)
        mmax, mmin = max(lz, vz), min(lz, vz)
        if mmin > pmlo:  # as pumpup.operators.pumping._chain_kernel chooses (physics.lookups.g_levels_call says why)
            out[r] = f * g_product(mmax, pcbase, pcell, plo, pinv)  # 001 eq. 16, all levels (times 1 / G)
        elif mmin > qmlo:
            g = 0.0
            if rcells > 0:  # the split table: one product F(mmin) H(mmax), 0 where the cell has no pattern
                g = g_split(mmin, mmax, rcells, rpattern, rfid, rhid, rshift, rcbase, rcell, rlo,
                            rcoef)
            if g == 0.0:
                g = g_pair(lz, vz, controlled, qshift, qcbase, qcell, qlo, qrow)
            out[r] = f / g  # 001 eq. 16, all levels
        elif f != 0.0:
            out[r] = f / g_levels_call(mmax, mmin, offsets, logx, coef, v0, slope0, margin_lo, cap, controlled,
                                       increasing, mu0, index, index_lo, index_h_inv)
        else:
            out[r] = 0.0


# ----------------------------------------------------------------------------------------
# The numpy reference and the public helper functions
# ----------------------------------------------------------------------------------------


def _mf_reference(wi, wo, dist, alpha, shadowing, g1, ior, eta, k):
    lz, vz = wi[..., 2], wo[..., 2]
    up = (lz > 0) & (vz > 0)
    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
        s = wi + wo
        qx = s[..., 0] / s[..., 2]
        qy = s[..., 1] / s[..., 2]
        t = qx * qx + qy * qy  # tan^2 delta
        a2 = alpha * alpha
        if dist == 0:
            e = np.exp(-t / a2)
            up = up & (e > 0)
            d = e * ((1.0 + t) * (1.0 + t)) / (np.pi * a2)  # Walter eq. 25
        else:
            cos2 = 1.0 / (1.0 + t)
            sin2 = np.where(t <= 1.0, t * cos2, 1.0 - cos2)
            q = a2 * cos2 + sin2
            d = a2 / (np.pi * q * q)  # Walter eq. 33
        c = 0.5 * np.sqrt(s[..., 0] ** 2 + s[..., 1] ** 2 + s[..., 2] ** 2)  # wi.h
        f = _fresnel_complex(c, eta, k) if eta > 0 else _fresnel_reference(c, ior)
        pl = projected_reference(wi, dist, g1, alpha)
        pv = projected_reference(wo, dist, g1, alpha)
        if shadowing == 0:
            val = d * f / (4.0 * pl * pv)  # Walter eq. 20, separable Smith
        else:
            val = d * f / (4.0 * (vz * pl + lz * pv - lz * vz))  # Heitz 2014, height-correlated Smith
    return np.where(up, val, 0.0)


def _check_kind(distribution: str, g1: str) -> tuple[int, int]:
    if distribution not in _DIST:
        raise SpecError(f"'distribution' must be one of {', '.join(map(repr, _DIST))}, got {distribution!r}")
    if g1 not in _G1:
        raise SpecError(f"'g1' must be one of {', '.join(map(repr, _G1))}, got {g1!r}")
    if distribution == "ggx" and g1 != "exact":
        raise SpecError("'g1' = 'walter' applies to the Beckmann distribution only (GGX's G1 is exact in closed form)")
    return _DIST[distribution], _G1[g1]


def _as_cos(cos_theta: Any, name: str = "cos_theta") -> np.ndarray:
    c = np.asarray(cos_theta, dtype=np.float64)
    if np.any(~np.isfinite(c) | (c <= 0) | (c > 1)):
        raise ValueError(f"{name} must be in (0, 1]")
    return c


def ndf(cos_theta_m: Any, alpha: float, distribution: str = "beckmann") -> np.ndarray:
    """The microfacet distribution D(m) [1/sr] (Walter et al. 2007, eq. 25 and 33).

    Parameters
    ----------
    cos_theta_m : array_like
        N.m, the cosine of the angle between the facet normal m and N, in (0, 1].
    alpha : float, > 0
        Roughness (dimensionless).
    distribution : {"beckmann", "ggx"}

    Returns
    -------
    ndarray
        D, normalised so that the integral of D (N.m) over the hemisphere is 1.

    Examples
    --------
    >>> import math
    >>> round(float(ndf(1.0, 0.5, "ggx")) * math.pi * 0.25, 12)  # 1 / (pi alpha^2) at m = N
    1.0
    """
    dist, _ = _check_kind(distribution, "exact")
    c = _as_cos(cos_theta_m, "cos_theta_m")
    c2 = c * c
    s2 = (1.0 - c) * (1.0 + c)
    a2 = float(alpha) ** 2
    if dist == 0:
        return np.exp(-s2 / (c2 * a2)) / (np.pi * a2 * c2 * c2)  # Walter eq. 25
    return a2 / (np.pi * (a2 * c2 + s2) ** 2)  # Walter eq. 33


def smith_lambda(cos_theta: Any, alpha: float, distribution: str = "beckmann", g1: str = "exact") -> np.ndarray:
    """Smith's Lambda(w) (Heitz 2014; for g1="walter", 1 / G1 - 1 of the rational fit).

    Parameters
    ----------
    cos_theta : array_like
        N.w, in (0, 1].
    alpha : float, > 0
        Roughness (dimensionless).
    distribution : {"beckmann", "ggx"}
    g1 : {"exact", "walter"}
        "walter": Walter et al.'s rational fit (eq. 27), Beckmann only.

    Returns
    -------
    ndarray
        Lambda >= 0 (0 at normal incidence, growing like 1 / cos_theta towards grazing).

    Examples
    --------
    >>> round(float(smith_lambda(0.6, 1.0, "ggx")), 12)  # (sqrt(1 + tan^2) - 1) / 2 = (1 / 0.6 - 1) / 2
    0.333333333333
    """
    dist, code = _check_kind(distribution, g1)
    c = _as_cos(cos_theta)
    w = np.stack([np.sqrt((1.0 - c) * (1.0 + c)), np.zeros_like(c), c], axis=-1)
    return projected_reference(w, dist, code, float(alpha)) / c - 1.0


def smith_g1(cos_theta: Any, alpha: float, distribution: str = "beckmann", g1: str = "exact") -> np.ndarray:
    """Smith's masking function G1(w) = 1 / (1 + Lambda(w)) (Walter et al. 2007, eq. 27 and 34).

    Parameters
    ----------
    cos_theta : array_like
        N.w, in (0, 1].
    alpha : float, > 0
        Roughness (dimensionless).
    distribution : {"beckmann", "ggx"}
    g1 : {"exact", "walter"}
        "walter": Walter et al.'s rational fit (eq. 27, Mitsuba 3's), Beckmann only.

    Returns
    -------
    ndarray
        G1 in (0, 1] (the rational fit slightly exceeds 1 just below a = 1.6).

    Examples
    --------
    >>> round(float(smith_g1(1.0, 0.3)), 12)
    1.0
    """
    dist, code = _check_kind(distribution, g1)
    c = _as_cos(cos_theta)
    w = np.stack([np.sqrt((1.0 - c) * (1.0 + c)), np.zeros_like(c), c], axis=-1)
    return c / projected_reference(w, dist, code, float(alpha))


# ----------------------------------------------------------------------------------------
# The models
# ----------------------------------------------------------------------------------------

_ALPHA = Param(lo=MIN_ALPHA, hi=MAX_WIDTH, doc="roughness alpha (Walter et al. 2007; Mitsuba's alpha)")
_SHADOW = Param("separable", kind="str", choices=tuple(_SHADOWING), doc="Smith G: G1 G1 or height-correlated")
_ETA = Param(None, lo=MIN_INDEX, hi=MAX_INDEX, doc="conductor: real part of the complex index (omitted: no conductor)")
_K = Param(None, lo=0.0, hi=MAX_INDEX, doc="conductor: extinction coefficient (with eta; default 0)")


class _WiHKink:
    """The Lobe hint's kink wi.h = x0 of a half-vector lobe (:func:`wih_kinks`), a + b cos(beta) = 0
    with a = mu cos(alpha) - x0, b = s sin(alpha) (a class, not a closure: a BRDF pickles for dask).
    """

    def __init__(self, x0: float):
        self.x0 = float(x0)

    def __call__(self, mu, s, cos_a, sin_a):
        return [(np.asarray(mu, dtype=np.float64) * cos_a - self.x0, np.asarray(s, dtype=np.float64) * sin_a)]


def wih_kinks(brdf, eta, k):
    """The ``kinks`` of ``brdf``'s Lobe hint where a Fresnel factor of eta + i k at wi.h (GGX, Beckmann; He-Torrance's
    bisector angle) has a kink or a near-kink, wi.h = x0 (:func:`pumpup.models.metal.fresnel_levels`), or None; one
    object per BRDF (the engine groups values of mu by it), kept in its ``__dict__``.
    """
    hit = brdf.__dict__.get("_f_kinks", False)
    if hit is False:
        from .metal import fresnel_levels

        lev = fresnel_levels(eta, k or 0.0) if eta is not None else ()
        hit = brdf.__dict__["_f_kinks"] = _WiHKink(lev[0]) if lev else None
    return hit


@njit(cache=True, nogil=True)
def _mf_kc(wi, wo, out, dist, alpha, shadowing, g1, ior, eta, k, scale, pmlo, pcbase, pcell, plo, prow, logx, coef,
           v0, slope0, margin_lo, margin, cap):  # pragma: no cover - compiled
    """f_r + scale D(mu_i) D(mu_o) (KC eq. 1) over the rows of (N, 3) arrays into ``out`` in one pass: the kernel's
    value and the Kulla-Conty lobe (``pumpup.operators.compensate._kc_kernel``'s operations; ``BRDF.eval_plus_lobe``).
    """
    for r in range(out.shape[0]):
        lz, vz = wi[r, 2], wo[r, 2]
        if lz <= 0.0 or vz <= 0.0:
            out[r] = 0.0
            continue
        f = _mf_scalar(wi[r, 0], wi[r, 1], lz, wo[r, 0], wo[r, 1], vz, dist, alpha, shadowing, g1, ior, eta, k)
        # U(mu_i), U(mu_o) (KC eq. 1)
        ui = (g_product(lz, pcbase, pcell, plo, prow) if lz > pmlo
              else upper_scalar(lz, logx, coef, v0, slope0, margin_lo, margin, cap))  # scale_bound
        uo = (g_product(vz, pcbase, pcell, plo, prow) if vz > pmlo
              else upper_scalar(vz, logx, coef, v0, slope0, margin_lo, margin, cap))  # scale_bound
        di, do = 1.0 - ui, 1.0 - uo
        if di > 0.0 and do > 0.0:
            f += scale * (di * do)  # KC eq. 1
        out[r] = f


class _Microfacet(BRDF):
    """Shared machinery of :class:`Beckmann` and :class:`GGX`."""

    distribution = "?"
    constant = None
    kernel = staticmethod(_mf_kernel)
    reference_fn = staticmethod(_mf_reference)

    def _validate(self) -> None:
        p = self.p
        if p["ior"] is not None and p["eta"] is not None:
            raise SpecError(
                f"{self.type}: give either 'ior' (a dielectric's real index) or 'eta' and 'k' (a conductor's complex "
                f"index), not both; got ior = {p['ior']:g}, eta = {p['eta']:g}"
            )
        if p["k"] is not None and p["eta"] is None:
            raise SpecError(f"{self.type}: parameter 'k' (extinction) needs 'eta', the real part of the complex index")

    def kernel_args(self) -> tuple:
        p = self.p
        return (
            _DIST[self.distribution],
            p["alpha"],
            _SHADOWING[p["shadowing"]],
            _G1[p.get("g1", "exact")],
            0.0 if p["ior"] is None else p["ior"],
            0.0 if p["eta"] is None else p["eta"],
            0.0 if p["k"] is None else p["k"],
        )

    def eval_divided(self, wi, wo, chain):
        """f_r / (g_1 ... g_k) of a pumped chain in one pass (:func:`_mf_divided`; ``BRDF.eval_divided``)."""
        if not (isinstance(wi, np.ndarray) and isinstance(wo, np.ndarray) and wi.shape == wo.shape and wi.ndim >= 2
                and wi.dtype == np.float64 == wo.dtype and wi.flags.c_contiguous and wo.flags.c_contiguous):
            return None
        out = np.empty(wi.shape[:-1])
        _mf_divided(wi.reshape(-1, 3), wo.reshape(-1, 3), out.reshape(-1), *self.kernel_args(), *chain)
        return out

    def eval_plus_lobe(self, wi, wo, scale, bound):
        """f_r plus a Kulla-Conty lobe in one pass (:func:`_mf_kc`; ``BRDF.eval_plus_lobe``)."""
        if not (isinstance(wi, np.ndarray) and isinstance(wo, np.ndarray) and wi.shape == wo.shape and wi.ndim >= 2
                and wi.dtype == np.float64 == wo.dtype and wi.flags.c_contiguous and wo.flags.c_contiguous):
            return None
        out = np.empty(wi.shape[:-1])
        _mf_kc(wi.reshape(-1, 3), wo.reshape(-1, 3), out.reshape(-1), *self.kernel_args(), scale, *bound)
        return out

    def fresnel_one(self):
        """The same distribution and G with F = 1 (no ior, no conductor), or None without a Fresnel factor."""
        if self.p["ior"] is None and self.p["eta"] is None:
            return None
        return self.with_params(ior=None, eta=None, k=None)

    def azimuth_hint(self):
        from ..core.hints import AzimuthHint, Fresnel, SmithLobe

        p, a = self.p, self.p["alpha"]
        fresnel = (Fresnel(ior=p["ior"]) if p["ior"] is not None
                   else Fresnel(eta=p["eta"], k=p["k"] or 0.0) if p["eta"] is not None else None)
        # Walter eq. 20: a(mu) = integral over h of D(h) (1 / 4) [4 (wi.h) F G / N.wi] (d omega_o = 4 (wo.h) d omega_h),
        # D = w(t) / (pi a^2 cos^4) with w = e^-t (eq. 25) or 1 / (1 + t)^2 (eq. 33), t = tan^2 / a^2
        return AzimuthHint(SmithLobe(distribution=self.distribution, alpha=a, g1=p.get("g1", "exact"),
                                     shadowing=p["shadowing"], fresnel=fresnel),
                           scale=lambda mu: np.full(np.shape(mu), 0.25 / (math.pi * a * a)))


@register("beckmann")
class Beckmann(_Microfacet):
    """Microfacet BRDF with the Beckmann distribution and Smith shadowing [1/sr].

    f_r = D F G / (4 (N.wi)(N.wo)) (Walter et al. 2007, eq. 20), with
    D = exp(-tan^2 delta / alpha^2) / (pi alpha^2 cos^4 delta) (Walter eq. 25), delta the
    angle between N and h; G = G1(wi) G1(wo) or 1 / (1 + Lambda(wi) + Lambda(wo)) (Heitz
    2014); G1 the exact Smith function, 2 / (1 + erf(a) + exp(-a^2) / (a sqrt(pi))),
    a = 1 / (alpha tan theta), or Walter's rational fit (eq. 27, as Mitsuba 3); F = 1 or
    a Fresnel factor at wi.h.  With Fresnel 1, separable G and g1="walter" this is Mitsuba 3's
    ``roughconductor`` with ``distribution: "beckmann"`` and the default ``material: "none"``.
    Equal in D to ``cook_torrance`` with m = alpha (which uses the V-cavity G instead).

    Parameters
    ----------
    alpha : float, in (0, inf)
        Roughness: the RMS slope of the facets (dimensionless; Mitsuba's ``alpha``).
    shadowing : {"separable", "correlated"}, default "separable"
        G1(wi) G1(wo) (Walter sec. 5), or the height-correlated Smith function (Heitz 2014).
    g1 : {"exact", "walter"}, default "exact"
        The Smith G1: exact (with erf), or Walter et al.'s rational fit (eq. 27, relative
        error up to about 0.35 % and a 5.7e-5 jump at a = 1.6; Mitsuba 3 uses it).
    ior : float, in (1, inf), optional
        Real index of refraction of a dielectric (the Fresnel factor of ``cook_torrance``).
    eta, k : float, optional
        Complex index eta + i k of a conductor, eta > 0, k >= 0 (the exact Fresnel factor of
        ``metal``); k defaults to 0.  Without ``ior`` and ``eta``, F = 1.

    Examples
    --------
    >>> import math, pumpup
    >>> f = pumpup.load({"type": "beckmann", "alpha": 0.2})
    >>> round(float(f.eval([0, 0, 1], [0, 0, 1])) * 4 * math.pi * 0.2**2, 12)  # D = 1 / (pi alpha^2), G = F = 1
    1.0
    """

    distribution = "beckmann"
    params = {
        "alpha": _ALPHA,
        "shadowing": _SHADOW,
        "g1": Param("exact", kind="str", choices=tuple(_G1), doc="Smith G1: exact, or Walter's rational fit"),
        "ior": _IOR,
        "eta": _ETA,
        "k": _K,
    }
    examples = [
        {"alpha": 0.1},
        {"alpha": 0.5, "shadowing": "correlated"},
        {"alpha": 0.3, "g1": "walter"},
        {"alpha": 0.02, "ior": 1.5},
        {"alpha": 1.0, "eta": 0.2, "k": 3.0, "shadowing": "correlated", "g1": "walter"},
    ]

    def lobe(self, mu: float) -> Lobe:
        """The Lobe hint: a Beckmann lobe of slope alpha about the half vector, with Walter's G1 switch as a level and
        the kinks of F at wi.h.
        """
        levels = (walter_level(self.p["alpha"]),) if self.p["g1"] == "walter" else ()
        return Lobe(axis="half", radial="beckmann", sharpness=self.p["alpha"], levels=levels,
                    kinks=wih_kinks(self, self.p["eta"], self.p["k"]))


@register("ggx")
class GGX(_Microfacet):
    """Microfacet BRDF with the GGX (Trowbridge-Reitz) distribution and Smith shadowing [1/sr].

    f_r = D F G / (4 (N.wi)(N.wo)) (Walter et al. 2007, eq. 20), with
    D = alpha^2 / (pi cos^4 delta (alpha^2 + tan^2 delta)^2) (Walter eq. 33);
    G = G1(wi) G1(wo), G1 = 2 / (1 + sqrt(1 + alpha^2 tan^2 theta)) (Walter eq. 34), or
    the height-correlated 1 / (1 + Lambda(wi) + Lambda(wo)) (Heitz 2014); F = 1 or a
    Fresnel factor at wi.h.  With Fresnel 1 and separable G this is Mitsuba 3's
    ``roughconductor`` with ``distribution: "ggx"`` and ``material: "none"``.

    Parameters
    ----------
    alpha : float, in (0, inf)
        Roughness (dimensionless; Mitsuba's ``alpha``).  D is Schlick's form
        r / (1 - (1 - r) cos^2 delta)^2 / (pi r) with r = alpha^2 (000 eq. 36).
    shadowing : {"separable", "correlated"}, default "separable"
        G1(wi) G1(wo), or the height-correlated Smith function (Heitz 2014).
    ior : float, in (1, inf), optional
        Real index of refraction of a dielectric (the Fresnel factor of ``cook_torrance``).
    eta, k : float, optional
        Complex index eta + i k of a conductor (the Fresnel factor of ``metal``); k defaults
        to 0.  Without ``ior`` and ``eta``, F = 1.

    Examples
    --------
    >>> import math, pumpup
    >>> f = pumpup.load({"type": "ggx", "alpha": 0.2})
    >>> round(float(f.eval([0, 0, 1], [0, 0, 1])) * 4 * math.pi * 0.2**2, 12)  # D = 1 / (pi alpha^2), G = F = 1
    1.0
    """

    distribution = "ggx"
    params = {"alpha": _ALPHA, "shadowing": _SHADOW, "ior": _IOR, "eta": _ETA, "k": _K}
    examples = [
        {"alpha": 0.1},
        {"alpha": 0.5, "shadowing": "correlated"},
        {"alpha": 0.02, "ior": 1.5},
        {"alpha": 1.0, "eta": 0.2, "k": 3.0},
        {"alpha": 2.0, "shadowing": "correlated", "eta": 1.5},
    ]

    def __init__(self, **kwargs: Any) -> None:
        if "g1" in kwargs:
            raise SpecError(
                f"ggx: parameter 'g1' = {kwargs['g1']!r} applies to the Beckmann distribution only "
                "(GGX's Smith G1 is exact in closed form, Walter et al. 2007 eq. 34)"
            )
        super().__init__(**kwargs)

    def lobe(self, mu: float) -> Lobe:
        """The Lobe hint: a GGX lobe about the half vector (r = alpha^2, at most 1), with the kinks of F at wi.h."""
        # D = (1 / (pi r)) r^2 / (1 - (1 - r) cos^2)^2 with r = alpha^2: the "ggx" radial map;
        # alpha > 1 peaks at grazing half vectors, where r = 1 (uniform in sin^2) is the neutral map
        return Lobe(axis="half", radial="ggx", sharpness=min(self.p["alpha"] ** 2, 1.0),
                    kinks=wih_kinks(self, self.p["eta"], self.p["k"]))
