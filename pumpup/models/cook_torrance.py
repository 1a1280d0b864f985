"""Microfacet models: Cook-Torrance (001 eq. 9-10) and Lewis's Torrance-Sparrow shaders (002 eq. 10).

Shared quantities, with S = L + V (S_z > 0 when both directions are above the horizon)
and H = S / |S|:

* t = tan^2 delta = (S_x / S_z)^2 + (S_y / S_z)^2, cos^2 delta = (N.H)^2 = 1 / (1 + t),
  and 1 / cos^4 delta = (1 + t)^2 (no cancellation near the highlight, no 0/0 at grazing).
* c = V.H = L.H = |S| / 2 (for unit L and V, |S|^2 = 2 + 2 L.V and V.S = 1 + L.V), the
  same number for (L, V) and (V, L), so the models are reciprocal to the last bit.
* The geometry factor G = min(1, 2 (N.H)(N.V) / (V.H), 2 (N.H)(N.L) / (V.H)) (001 eq. 10,
  002 sec. 3.2) becomes min(1, 4 min(N.L, N.V) / (S_z (1 + t))), since
  2 (N.H) / (V.H) = 4 S_z / |S|^2 = 4 / (S_z (1 + t)).
* The dielectric Fresnel factor for unpolarised light (002 sec. 3.2, after Cook and
  Torrance) with index of refraction n: F = (g - c)^2 / (2 (g + c)^2)
  [1 + (c (g + c) - 1)^2 / (c (g - c) + 1)^2], g = sqrt(n^2 + c^2 - 1); F = 1 when no
  index is given (the kernels receive n = 0 for that).
"""

from __future__ import annotations

import math

import numpy as np
from numba import vectorize

from ..core import BRDF, MAX_EXPONENT, MAX_INDEX, MAX_WIDTH, MIN_WIDTH, Lobe, Param, SpecError, register
from ..physics.fresnel import dielectric_reference as _fresnel_reference
from ..physics.fresnel import dielectric_scalar as _fresnel
from ..physics.fresnel import fresnel_dielectric as fresnel  # noqa: F401  (pumpup.models.cook_torrance.fresnel)
from ._half import tan2_half

# ----------------------------------------------------------------------------------------
# Shared pieces: Fresnel, geometry factor, and the kinks of G for the albedo engine
# ----------------------------------------------------------------------------------------


#: the incidence mu = 1 / sqrt(2) where the albedo of every model with the geometry factor G of 001 eq. 10
#: (Cook-Torrance, Torrance-Sparrow with any D) has a jump in its second derivative: at the retro direction wo = wi both
#: of G's terms are 2 mu^2 and meet the level N.wo = mu where G switches between them, so the region G < 1 reaches
#: across that level for mu below it and not above.  Measured by one-sided fits of a(mu) at rtol 1e-13
#: (tests/models/test_cook_torrance_retro_break.py): a'' = 0.864 below and 0.952 above for Cook-Torrance m = 0.538, 2.28
#: and 2.68 for Torrance-Sparrow D1 e = 2.  A table's spline went across it, its knots bunched there, and an engine
#: integrating 1 / U(N.wo) of a 1/E scaling across those knots under-reported: scaled Cook-Torrance m = 0.538 at mu =
#: 0.9999 was 4.4e-10 off with an estimate of 8.2e-11 at rtol 1e-8 and 1e-10 (scripts/studies/fuzz_engines.py --registry
#: 49 found m = 0.428 at mu = 1, 1.04 x)
RETRO_BREAK = math.sqrt(0.5)


def _g_kinks(mu, s, cos_a, sin_a):
    """Where the geometry factor G (001 eq. 10) switches branch, for the albedo engine.

    In the half-vector parametrisation h = (sin_a cos phi, sin_a sin phi, cos_a) with
    wi = (s, 0, mu), s = sqrt(1 - mu^2): wi.h = s sin_a cos phi + mu cos_a and
    N.V = wo_z = s sin(2a) cos phi + mu cos(2a).  G = min(1, 2 cos_a wo_z / wi.h,
    2 cos_a mu / wi.h) switches branch where 2 cos_a wo_z = wi.h, where 2 cos_a mu = wi.h,
    and (between its last two terms) where wo_z = mu.  Each is a + b cos(phi) = 0.

    Returns
    -------
    list of (a, b) pairs of ndarrays
    """
    mu = np.asarray(mu, dtype=np.float64)
    s = np.asarray(s, dtype=np.float64)
    cos_a = np.asarray(cos_a, dtype=np.float64)
    sin_a = np.asarray(sin_a, dtype=np.float64)
    c2 = cos_a * cos_a
    return [
        (mu * cos_a * (4.0 * c2 - 3.0), s * sin_a * (4.0 * c2 - 1.0)),  # 2 cos_a wo_z - wi.h
        (mu * cos_a, -s * sin_a),  # 2 cos_a mu - wi.h
        (-2.0 * mu * sin_a * sin_a, 2.0 * s * sin_a * cos_a),  # wo_z - mu
    ]


def _halfway(wi, wo):
    """The values t = tan^2 delta, c = V.H and the geometry factor G (001 eq. 10) as arrays."""
    s = wi + wo
    lz, vz = wi[..., 2], wo[..., 2]
    qx = s[..., 0] / s[..., 2]  # h_x / h_z
    qy = s[..., 1] / s[..., 2]  # h_y / h_z
    t = qx * qx + qy * qy  # tan^2 delta
    c = 0.5 * np.sqrt(s[..., 0] ** 2 + s[..., 1] ** 2 + s[..., 2] ** 2)  # V.H = L.H = |L + V| / 2
    g = np.minimum(1.0, 4.0 * np.minimum(lz, vz) / (s[..., 2] * (1.0 + t)))  # 001 eq. 10
    return t, c, g


def _up(wi, wo):
    return (wi[..., 2] > 0) & (wo[..., 2] > 0)


def _ior_arg(ior):
    return 0.0 if ior is None else float(ior)


_IOR = Param(None, lo=1.0, lo_open=True, hi=MAX_INDEX, doc="real index of refraction (None: Fresnel factor 1)")


# ----------------------------------------------------------------------------------------
# Cook-Torrance
# ----------------------------------------------------------------------------------------


@vectorize(cache=True)
def _ct_kernel(lx, ly, lz, vx, vy, vz, m, ior):  # pragma: no cover - compiled
    if lz <= 0.0 or vz <= 0.0:
        return 0.0
    sx = lx + vx
    sy = ly + vy
    sz = lz + vz
    t = tan2_half(lx, ly, lz, vx, vy, vz)  # tan^2 delta
    e = math.exp(-t / (m * m))
    if e == 0.0:
        return 0.0
    d = e * ((1.0 + t) * (1.0 + t)) / (4.0 * math.pi * m * m)  # exp(-tan^2/m^2) / (4 pi m^2 cos^4), 001 eq. 9
    g = min(1.0, 4.0 * min(lz, vz) / (sz * (1.0 + t)))  # 001 eq. 10
    f = _fresnel(0.5 * math.sqrt(sx * sx + sy * sy + sz * sz), ior)  # 002 sec. 3.2, c = V.H
    return f * d * g / (lz * vz)  # 001 eq. 9


def _ct_reference(wi, wo, m, ior):
    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
        t, c, g = _halfway(wi, wo)
        e = np.exp(-t / (m * m))
        d = e * ((1.0 + t) * (1.0 + t)) / (4.0 * np.pi * m * m)  # 001 eq. 9
        f = _fresnel_reference(c, ior) * d * g / (wi[..., 2] * wo[..., 2])  # 001 eq. 9
    return np.where(_up(wi, wo) & (e > 0), f, 0.0)


@register("cook_torrance")
class CookTorrance(BRDF):
    """Cook-Torrance with the Beckmann distribution [1/sr] (001 eq. 9-10).

    f_r = F exp(-tan^2 delta / m^2) / (4 pi m^2 cos^4 delta) G / ((N.L)(N.V)),
    G = min(1, 2 (N.H)(N.V) / (V.H), 2 (N.H)(N.L) / (V.H)) (001 eq. 10), delta the
    angle between N and H, and F the dielectric Fresnel factor of 002 sec. 3.2 at
    c = V.H (F = 1 when ``ior`` is not given, as in 001).  Equal to
    ``torrance_sparrow`` with d = "D4" (002 eq. 10).  Its albedo diverges at grazing
    incidence (001 sec. 2.1).

    Parameters
    ----------
    m : float, in (0, inf)
        RMS surface slope (dimensionless).
    ior : float, in (1, inf), optional
        Real index of refraction; omitted (None) means Fresnel factor 1.

    Examples
    --------
    >>> import math, pumpup
    >>> f = pumpup.load({"type": "cook_torrance", "m": 0.2})
    >>> round(float(f.eval([0, 0, 1], [0, 0, 1])) * 4 * math.pi * 0.2**2, 12)  # G = 1, F = 1
    1.0
    """

    params = {
        "m": Param(lo=MIN_WIDTH, hi=MAX_WIDTH, doc="RMS slope"),
        "ior": _IOR,
    }
    constant = None
    examples = [{"m": 0.1}, {"m": 0.3, "ior": 1.5}, {"m": 0.02}, {"m": 0.6, "ior": 20.0}]
    kernel = staticmethod(_ct_kernel)
    reference_fn = staticmethod(_ct_reference)

    def kernel_args(self):
        """(m, ior) for the compiled kernel, ior 0 without a Fresnel factor."""
        return (self.p["m"], _ior_arg(self.p["ior"]))

    def albedo_breaks(self):
        """(:data:`RETRO_BREAK`,): the geometry factor G (001 eq. 10) kinks the albedo at mu = 1 / sqrt(2)."""
        return (RETRO_BREAK,)  # G's two terms meet the level N.wo = mu at wo = wi there

    def lobe(self, mu):
        """The Lobe hint: a Beckmann lobe of slope m about the half vector, cut where G switches branch."""
        return Lobe(axis="half", radial="beckmann", sharpness=self.p["m"], kinks=_g_kinks)

    def fresnel_one(self):
        """The same model with F = 1 (no ior), or None without a Fresnel factor."""
        return None if self.p["ior"] is None else self.with_params(ior=None)

    def azimuth_hint(self):
        """The azimuth hint: the V-cavity lobe under the Beckmann weight, with the Fresnel factor F(wi.h) where ``ior``
        is given (001 eq. 9).
        """
        from ..core.hints import AzimuthHint, Fresnel, VCavityLobe

        m = self.p["m"]
        # 001 eq. 9: F exp(-tan^2 / m^2) / (4 pi m^2 cos^4) G / (N.L N.V); the azimuth of h in closed form for F = 1
        # (G's minimum of three lines in wi.h), by a rule on its arc with F(wi.h); the Beckmann weight in
        # t = tan^2(alpha) / m^2
        f_at_h = Fresnel(ior=self.p["ior"]) if self.p["ior"] else None
        return AzimuthHint(VCavityLobe(n=m, radial="beckmann", fresnel=f_at_h),
                           scale=lambda mu: 1.0 / (4.0 * math.pi * m * m * np.asarray(mu, float)))


# ----------------------------------------------------------------------------------------
# Torrance-Sparrow shaders with Lewis's facet distributions D1-D4
# ----------------------------------------------------------------------------------------

_D_CODES = {"D1": 1, "D2": 2, "D3": 3, "D4": 4}


@vectorize(cache=True)
def _ts_kernel(lx, ly, lz, vx, vy, vz, d, s, b, ior):  # pragma: no cover - compiled
    if lz <= 0.0 or vz <= 0.0:
        return 0.0
    sx = lx + vx
    sy = ly + vy
    sz = lz + vz
    t = tan2_half(lx, ly, lz, vx, vy, vz)  # tan^2 alpha
    cos2 = 1.0 / (1.0 + t)  # cos^2 alpha = (N.H)^2
    if d == 1:
        dist = b * cos2 ** (0.5 * s)  # D1 = b cos^e alpha, 002 sec. 3.2
    elif d == 2:
        a = math.atan(math.sqrt(t))  # alpha
        dist = b * math.exp(-(s * a) * (s * a))  # D2 = b exp(-(c2 alpha)^2), 002 sec. 3.2
    elif d == 3:
        sin2 = t * cos2 if t <= 1.0 else 1.0 - cos2
        q = s * s / (s * s * cos2 + sin2)  # c3^2 / (cos^2 alpha (c3^2 - 1) + 1)
        dist = b * q * q  # D3, 002 sec. 3.2
    else:
        e = math.exp(-t / (s * s))
        if e == 0.0:
            return 0.0
        dist = e * ((1.0 + t) * (1.0 + t)) / (4.0 * s * s)  # D4 (Beckmann), 002 sec. 3.2
    g = min(1.0, 4.0 * min(lz, vz) / (sz * (1.0 + t)))  # G, 002 sec. 3.2 (001 eq. 10)
    f = _fresnel(0.5 * math.sqrt(sx * sx + sy * sy + sz * sz), ior)  # F, 002 sec. 3.2, c = V.H
    return f * g * dist / (math.pi * (lz * vz))  # 002 eq. 10


def _ts_reference(wi, wo, d, s, b, ior):
    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
        t, c, g = _halfway(wi, wo)
        cos2 = 1.0 / (1.0 + t)
        keep = _up(wi, wo)
        if d == 1:
            dist = b * cos2 ** (0.5 * s)  # D1
        elif d == 2:
            dist = b * np.exp(-((s * np.arctan(np.sqrt(t))) ** 2))  # D2
        elif d == 3:
            sin2 = np.where(t <= 1.0, t * cos2, 1.0 - cos2)
            q = s * s / (s * s * cos2 + sin2)
            dist = b * q * q  # D3
        else:
            e = np.exp(-t / (s * s))
            dist = e * ((1.0 + t) * (1.0 + t)) / (4.0 * s * s)  # D4
            keep = keep & (e > 0)
        f = _fresnel_reference(c, ior) * g * dist / (np.pi * (wi[..., 2] * wo[..., 2]))  # 002 eq. 10
    return np.where(keep, f, 0.0)


@register("torrance_sparrow")
class TorranceSparrow(BRDF):
    """Torrance-Sparrow shader, f_r = F G D / (pi (N.S)(N.V)) [1/sr] (002 eq. 10).

    F is the dielectric Fresnel factor and G the geometry factor of 002 sec. 3.2
    (G as in 001 eq. 10); D is one of Lewis's facet distributions, with alpha the angle
    between N and H and a single shape parameter ``s``:

    * "D1": D = b cos^e alpha, s = e >= 0 (Blinn's Phong-like distribution);
    * "D2": D = b exp(-(c2 alpha)^2), s = c2 > 0 (Torrance and Sparrow's Gaussian);
    * "D3": D = b [c3^2 / (cos^2 alpha (c3^2 - 1) + 1)]^2, s = c3 > 0 (Trowbridge-Reitz;
      peaks at alpha = 0 for c3 < 1, uniform for c3 = 1);
    * "D4": D = exp(-(1 - cos^2 alpha) / (m^2 cos^2 alpha)) / (4 m^2 cos^4 alpha), s = m > 0
      (Beckmann; no b: with D4 this model equals ``cook_torrance``).

    Parameters
    ----------
    d : {"D1", "D2", "D3", "D4"}
        Facet distribution.
    s : float
        Shape parameter: e (D1, >= 0), c2 (D2, > 0, in 1/rad), c3 (D3, > 0) or the RMS
        slope m (D4, > 0); all dimensionless except c2.
    b : float, >= 0, default 1
        Scale of D1-D3 (dimensionless).  D4 has no such constant (002 sec. 3.2): it must
        be left at 1 there.
    ior : float, in (1, inf), optional
        Real index of refraction; omitted (None) means Fresnel factor 1.

    Examples
    --------
    >>> import pumpup
    >>> f = pumpup.load({"type": "torrance_sparrow", "d": "D1", "s": 10, "b": 2.0})
    >>> round(float(f.eval([0, 0, 1], [0, 0, 1])) * 3.141592653589793, 12)  # F = G = 1, D = b
    2.0
    """

    params = {
        "d": Param(kind="str", choices=tuple(_D_CODES), doc="facet distribution"),
        "s": Param(lo=0.0, doc="shape parameter: e (D1), c2 (D2), c3 (D3) or m (D4)"),
        "b": Param(1.0, lo=0.0, doc="scale of D1-D3"),
        "ior": _IOR,
    }
    constant = "b"
    examples = [
        {"d": "D1", "s": 20},
        {"d": "D2", "s": 5.0, "ior": 1.5},
        {"d": "D3", "s": 0.3},
        {"d": "D3", "s": 2.0, "b": 0.5},
        {"d": "D4", "s": 0.1},
        {"d": "D4", "s": 0.4, "ior": 1.33},
    ]
    kernel = staticmethod(_ts_kernel)
    reference_fn = staticmethod(_ts_reference)

    def _validate(self):
        d, s = self.p["d"], self.p["s"]
        if d != "D1" and not s > 0:
            name = {"D2": "c2", "D3": "c3", "D4": "m"}[d]
            raise SpecError(
                f"torrance_sparrow: parameter 's' ({name} of {d}) = {s:g} is outside its allowed range (0, inf)"
            )
        # the range where the engine is accurate (core.MIN_WIDTH): D1's exponent e; D2's c2 is an inverse
        # width (1/rad; c2 = 5e-324 divided by zero in the radial map, and below 1e-2 the Gaussian map
        # degenerates: c2 = 1e-6 gave an error estimate of 5.6e-6 at mu = 1e-8); D3's c3 and D4's m are widths
        lo, hi = {"D1": (0.0, MAX_EXPONENT), "D2": (1e-2, 1.0 / MIN_WIDTH)}.get(d, (MIN_WIDTH, MAX_WIDTH))
        if not lo <= s <= hi:
            name = {"D1": "e", "D2": "c2", "D3": "c3", "D4": "m"}[d]
            raise SpecError(
                f"torrance_sparrow: parameter 's' ({name} of {d}) = {s:g} is outside its allowed range [{lo:g}, {hi:g}]"
            )
        if d == "D4" and self.p["b"] != 1.0:
            raise SpecError(
                f"torrance_sparrow: parameter 'b' = {self.p['b']:g} is not used by D4 (Beckmann has no "
                "arbitrary constant, 002 sec. 3.2); leave it at 1 or use D1-D3"
            )

    def kernel_args(self):
        """(D's code 1-4, s, b, ior) for the compiled kernel, ior 0 without a Fresnel factor."""
        return (_D_CODES[self.p["d"]], self.p["s"], self.p["b"], _ior_arg(self.p["ior"]))

    def albedo_breaks(self):
        """(:data:`RETRO_BREAK`,): the geometry factor G kinks the albedo at mu = 1 / sqrt(2)."""
        return (RETRO_BREAK,)  # G's two terms meet the level N.wo = mu at wo = wi there

    def lobe(self, mu):
        """The Lobe hint about the half vector, the radial map of D (D1 power, D2 Gaussian, D3 GGX, D4 Beckmann), cut
        where G switches branch.
        """
        d, s = self.p["d"], self.p["s"]
        if d == "D1":
            return Lobe(axis="half", radial="power", sharpness=s, kinks=_g_kinks)
        if d == "D2":
            return Lobe(axis="half", radial="gaussian", sharpness=s, kinks=_g_kinks)
        if d == "D3":
            # D3 = b r [r / (1 - (1 - r) cos^2)^2] with r = c3^2: Schlick's form; c3 > 1 peaks at
            # grazing half vectors, where r = 1 (uniform in sin^2 alpha) is the neutral map
            return Lobe(axis="half", radial="ggx", sharpness=min(s * s, 1.0), kinks=_g_kinks)
        return Lobe(axis="half", radial="beckmann", sharpness=s, kinks=_g_kinks)

    def fresnel_one(self):
        """The same model with F = 1 (no ior), or None without a Fresnel factor."""
        return None if self.p["ior"] is None else self.with_params(ior=None)

    def azimuth_hint(self):
        """The azimuth hint: the V-cavity lobe under D's weight (002 eq. 10), or None for D2, which the nested engine
        integrates.
        """
        d, e, b = self.p["d"], self.p["s"], self.p["b"]
        if d == "D2":
            return None  # D2 = b exp(-(c2 alpha)^2) has no weight of the 1-D path: the nested engine
        from ..core.hints import AzimuthHint, Fresnel, VCavityLobe

        # 002 eq. 10: F G D / (pi (N.S)(N.V)); the azimuth of h in closed form for F = 1
        # (pumpup.engine.half_frames._k_vcavity), by a rule on its arc with F(wi.h)
        f_at_h = Fresnel(ior=self.p["ior"]) if self.p["ior"] else None
        if d == "D1":  # D = b cos^e(alpha): the power weight u^e
            return AzimuthHint(VCavityLobe(n=e, fresnel=f_at_h), scale=lambda mu: b / (math.pi * np.asarray(mu, float)))
        if d == "D3":  # D3 = b (c3^2 / (c3^2 cos^2 + sin^2))^2 = b / (cos^4 (1 + tan^2 / c3^2)^2): the GGX weight
            return AzimuthHint(VCavityLobe(n=e, radial="ggx", fresnel=f_at_h),
                               scale=lambda mu: b / (math.pi * np.asarray(mu, float)))
        # D4 = exp(-tan^2 / m^2) / (4 m^2 cos^4): Cook-Torrance's
        return AzimuthHint(VCavityLobe(n=e, radial="beckmann", fresnel=f_at_h),
                           scale=lambda mu: 1.0 / (4.0 * math.pi * e * e * np.asarray(mu, float)))
