"""The Ashikhmin-Shirley anisotropic Phong BRDF (M. Ashikhmin and P. Shirley, "An Anisotropic Phong BRDF
Model", Journal of Graphics Tools 5(2), 2000; "AS 2000" below).

k1 = wi (towards the light), k2 = wo (towards the viewer), h = (k1 + k2) / |k1 + k2|, u = x and v = y the
tangent axes.  With the unnormalised S = k1 + k2 (S_z > 0 above the horizon):

* h.k = k1.h = k2.h = |S| / 2, symmetric in k1 and k2 to the last bit;
* the exponent of eq. 4, (nu (h.u)^2 + nv (h.v)^2) / (1 - (N.h)^2), is (nu S_x^2 + nv S_y^2) / (S_x^2 + S_y^2)
  (h_x^2 / (1 - h_z^2) = S_x^2 / (S_x^2 + S_y^2): no cancellation in 1 - (N.h)^2 near the highlight), and
  (N.h)^e = exp(-e log(1 + t) / 2) with t = tan^2 theta_h = (S_x^2 + S_y^2) / S_z^2 (log1p: no rounding of
  N.h raised to a large power); where S is along N, (N.h)^e = 1 whatever the limit of e;
* 1 - h.k = |k1 - k2|^2 / (4 (1 + h.k)) (from (h.k)^2 = (1 + k1.k2) / 2), so Schlick's (1 - h.k)^5 keeps its
  relative accuracy near retro-reflection;
* the diffuse factors 1 - (1 - N.k / 2)^5 = -expm1(5 log1p(-N.k / 2)), accurate at grazing angles.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit, vectorize

from ..core import BRDF, MAX_EXPONENT, Lobe, Param, register


@njit(cache=True, inline="always")
def _half_power(sx, sy, sz, nu, nv):  # pragma: no cover - compiled; see _half_power_np
    """(N.h)^e with e = (nu S_x^2 + nv S_y^2) / (S_x^2 + S_y^2) (AS 2000 eq. 4's exponent), S = k1 + k2, S_z > 0."""
    sx2 = sx * sx
    sy2 = sy * sy
    ss = sx2 + sy2
    if ss == 0.0:
        return 1.0  # h = N: (N.h)^e = 1 for every e
    e = (nu * sx2 + nv * sy2) / ss  # nu cos^2 phi_h + nv sin^2 phi_h
    if e == 0.0:
        return 1.0
    szz = sz * sz
    # t = tan^2 theta_h > 1e300 (or S_z^2 underflowed): log(1 + t) = log(S_x^2 + S_y^2) - 2 log(S_z)
    if ss > 1e300 * szz:
        lg = math.log(ss) - 2.0 * math.log(sz)
    else:
        lg = math.log1p(ss / szz)  # -2 log(N.h) = log(1 + tan^2 theta_h)
    return math.exp(-0.5 * e * lg)


@njit(cache=True, inline="always")
def _half_norm(sx, sy, sz):  # pragma: no cover - compiled
    """|S| / 2 = h.k, scaled where the squares would underflow (a mirror pair at N.k < 1e-154)."""
    n2 = sx * sx + sy * sy + sz * sz
    if n2 >= 1e-290:
        return 0.5 * math.sqrt(n2)
    m = max(abs(sx), abs(sy), sz)
    ax, ay, az = sx / m, sy / m, sz / m
    return 0.5 * m * math.sqrt(ax * ax + ay * ay + az * az)


def _half_norm_np(s):
    """Plain numpy twin of :func:`_half_norm` on S (..., 3)."""
    n2 = s[..., 0] * s[..., 0] + s[..., 1] * s[..., 1] + s[..., 2] * s[..., 2]
    with np.errstate(divide="ignore", invalid="ignore"):
        m = np.maximum(np.maximum(np.abs(s[..., 0]), np.abs(s[..., 1])), s[..., 2])
        a = s / m[..., None]
        scaled = 0.5 * m * np.sqrt(a[..., 0] * a[..., 0] + a[..., 1] * a[..., 1] + a[..., 2] * a[..., 2])
    return np.where(n2 >= 1e-290, 0.5 * np.sqrt(n2), scaled)


@njit(cache=True, inline="always")
def _schlick_tail(lx, ly, lz, vx, vy, vz, hk):  # pragma: no cover - compiled
    """1 - h.k = |k1 - k2|^2 / (4 (1 + h.k))."""
    dx = lx - vx
    dy = ly - vy
    dz = lz - vz
    return (dx * dx + dy * dy + dz * dz) / (4.0 * (1.0 + hk))


@njit(cache=True, inline="always")
def _diffuse_factor(mu):  # pragma: no cover - compiled
    """1 - (1 - mu / 2)^5 (AS 2000 eq. 5)."""
    return -math.expm1(5.0 * math.log1p(-0.5 * mu))


@vectorize(cache=True)
def _kernel(lx, ly, lz, vx, vy, vz, nu, nv, rs, rd):  # pragma: no cover - compiled
    if lz <= 0.0 or vz <= 0.0:
        return 0.0
    sx = lx + vx
    sy = ly + vy
    sz = lz + vz
    hk = _half_norm(sx, sy, sz)  # h.k = |k1 + k2| / 2
    q = _schlick_tail(lx, ly, lz, vx, vy, vz, hk)  # 1 - h.k
    fresnel = rs + (1.0 - rs) * q**5  # Ashikhmin-Shirley 2000 eq. 5 (Schlick's F(h.k))
    d = _half_power(sx, sy, sz, nu, nv)
    norm = math.sqrt((nu + 1.0) * (nv + 1.0)) / (8.0 * math.pi)
    spec = norm * d * fresnel / hk / max(lz, vz)  # Ashikhmin-Shirley 2000 eq. 4
    if rd == 0.0:
        return spec
    kd = 28.0 * rd / (23.0 * math.pi) * (1.0 - rs)
    return spec + kd * (_diffuse_factor(lz) * _diffuse_factor(vz))  # Ashikhmin-Shirley 2000 eq. 5


def _half_power_np(s, nu, nv):
    """Plain numpy twin of :func:`_half_power` on S = k1 + k2 (..., 3)."""
    sx2 = s[..., 0] * s[..., 0]
    sy2 = s[..., 1] * s[..., 1]
    ss = sx2 + sy2
    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
        e = (nu * sx2 + nv * sy2) / ss  # nu cos^2 phi_h + nv sin^2 phi_h
        szz = s[..., 2] * s[..., 2]
        # log(1 + tan^2 theta_h)
        lg = np.where(ss > 1e300 * szz, np.log(ss) - 2.0 * np.log(s[..., 2]), np.log1p(ss / szz))
        d = np.exp(-0.5 * e * lg)
    return np.where((ss == 0.0) | (e == 0.0), 1.0, d)


def _reference(wi, wo, nu, nv, rs, rd):
    up = (wi[..., 2] > 0) & (wo[..., 2] > 0)
    s = wi + wo
    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
        hk = _half_norm_np(s)  # h.k = |k1 + k2| / 2
        dd = wi - wo
        q = (dd[..., 0] * dd[..., 0] + dd[..., 1] * dd[..., 1] + dd[..., 2] * dd[..., 2]) / (4.0 * (1.0 + hk))
        fresnel = rs + (1.0 - rs) * q**5  # Ashikhmin-Shirley 2000 eq. 5 (Schlick's F(h.k))
        mx = np.maximum(wi[..., 2], wo[..., 2])
        norm = math.sqrt((nu + 1.0) * (nv + 1.0)) / (8.0 * math.pi)
        f = norm * _half_power_np(s, nu, nv) * fresnel / hk / mx  # Ashikhmin-Shirley 2000 eq. 4
        if rd != 0.0:
            gi = -np.expm1(5.0 * np.log1p(-0.5 * wi[..., 2]))  # 1 - (1 - N.k1 / 2)^5
            go = -np.expm1(5.0 * np.log1p(-0.5 * wo[..., 2]))
            kd = 28.0 * rd / (23.0 * math.pi) * (1.0 - rs)
            f = f + kd * (gi * go)  # Ashikhmin-Shirley 2000 eq. 5
    return np.where(up, f, 0.0)


# --- the diffuse term alone, for the albedo engine and the sampler --------------------------------------------


@vectorize(cache=True)
def _diffuse_kernel(lx, ly, lz, vx, vy, vz):  # pragma: no cover - compiled
    if lz <= 0.0 or vz <= 0.0:
        return 0.0
    # rd (1 - rs) = 1:
    return 28.0 / (23.0 * math.pi) * (_diffuse_factor(lz) * _diffuse_factor(vz))  # Ashikhmin-Shirley 2000 eq. 5


def _diffuse_reference(wi, wo):
    up = (wi[..., 2] > 0) & (wo[..., 2] > 0)
    with np.errstate(invalid="ignore", divide="ignore"):
        gi = -np.expm1(5.0 * np.log1p(-0.5 * wi[..., 2]))
        go = -np.expm1(5.0 * np.log1p(-0.5 * wo[..., 2]))
        f = 28.0 / (23.0 * math.pi) * (gi * go)  # Ashikhmin-Shirley 2000 eq. 5, rd (1 - rs) = 1
    return np.where(up, f, 0.0)


def diffuse_albedo(mu):
    """The albedo of eq. 5's diffuse term with rd (1 - rs) = 1: 1 - (1 - mu / 2)^5.

    The integral over wo of (28 / (23 pi)) (1 - (1 - N.wo / 2)^5) N.wo d omega_o is
    (28 / (23 pi)) 2 pi (1/2 - 5/56) = (28 / (23 pi)) 2 pi (23 / 56) = 1 (the integral of x (1 - x/2)^5 over
    [0, 1] is 5/56), so the albedo is the factor of k1 = wi alone; the term's albedo is rd (1 - rs) times this.
    """
    mu = np.asarray(mu, dtype=np.float64)
    return -np.expm1(5.0 * np.log1p(-0.5 * mu))


class _Diffuse(BRDF):
    """The diffuse term of AS 2000 eq. 5 with rd (1 - rs) = 1 [1/sr] (one linear term of
    :meth:`AshikhminShirley.albedo_terms`; not registered: it is not a model of its own).

    Its albedo is closed-form (:func:`diffuse_albedo`), and it is isotropic.
    """

    type = "ashikhmin_shirley-diffuse"
    params = {}
    constant = None
    kernel = staticmethod(_diffuse_kernel)
    reference_fn = staticmethod(_diffuse_reference)

    def lobe(self, mu):
        return Lobe(axis="normal", radial="cosine")

    def azimuth_hint(self):
        from ..core.hints import AzimuthHint, ClosedForm

        # 1 - (1 - mu/2)^5 by log1p and expm1: a few ulps
        return AzimuthHint(ClosedForm(ulps=8.0), scale=diffuse_albedo)


def _ridge_cuts(nu: float, nv: float):
    """The kinks of an anisotropic lobe's hint: the y axis (beta = pi / 2: 0 + 1 cos(beta) = 0), and cuts of beta graded
    geometrically towards the axis the lobe is a ridge along (the x axis, beta = 0 and pi, where nv > nu; the y axis
    where nu > nv),
    from pi / 4 down to a tenth of the ridge's width sqrt(min / max) (the lobe (N.h)^(nu cos^2 + nv sin^2) at the wide
    exponent's polar angle 1 / sqrt(min) falls as exp(-max beta^2 / (2 min)) across the ridge).  Without the grading
    the 2-D cubature met nu = 10, nv = 1000 at mu = 0.5 with 0.34106804 +- 3.3e-12 against 0.341068116566 of two
    independent quadratures (tests/reference/ashikhmin_shirley.py).
    """
    lo, hi = min(nu, nv), max(nu, nv)
    offsets = []
    w = math.pi / 4
    while w > 0.1 * math.sqrt(lo / hi):
        w *= 0.5
        offsets.append(w)
    if nv > nu:  # ridge along x: cos(beta) = +-cos(w)
        cuts = [(0.0, 1.0)] + [(-math.cos(w), 1.0) for w in offsets] + [(math.cos(w), 1.0) for w in offsets]
    else:  # ridge along y: cos(beta) = +-sin(w)
        cuts = [(0.0, 1.0)] + [(-math.sin(w), 1.0) for w in offsets] + [(math.sin(w), 1.0) for w in offsets]

    def kinks(mu, s, cos_a, sin_a):
        return cuts

    return kinks


@register("ashikhmin_shirley")
class AshikhminShirley(BRDF):
    """Ashikhmin-Shirley's anisotropic Phong BRDF, f_r = rho_s + rho_d [1/sr] (AS 2000 eq. 4, 5).

    rho_s = sqrt((nu + 1)(nv + 1)) / (8 pi) (N.h)^((nu (h.u)^2 + nv (h.v)^2) / (1 - (N.h)^2))
    / ((h.k) max(N.k1, N.k2)) F(h.k), with Schlick's F(h.k) = rs + (1 - rs)(1 - h.k)^5, and
    rho_d = (28 rd / (23 pi)) (1 - rs) (1 - (1 - N.k1 / 2)^5) (1 - (1 - N.k2 / 2)^5);
    h = (k1 + k2) / |k1 + k2|, h.k = k1.h = k2.h, u and v the tangent x and y axes.  Reciprocal.
    With F = 1 (rs = 1) the specular albedo is at most 1 at every incidence: in half-vector
    coordinates it is the integral of p_h(h) N.k2 / max(N.k1, N.k2) <= p_h(h), the density of eq. 6-9.

    Parameters
    ----------
    nu, nv : float, in [0, 1e6]
        Phong exponents along the tangent x (u) and y (v) axes (dimensionless); nu = nv is isotropic.
    rs : float, in [0, 1]
        Specular reflectance at normal incidence (Schlick's F(0)).
    rd : float, in [0, 1], default 0
        Diffuse reflectance; the diffuse albedo is rd (1 - rs) (1 - (1 - mu / 2)^5).

    References
    ----------
    .. [1] M. Ashikhmin and P. Shirley, "An Anisotropic Phong BRDF Model", Journal of Graphics
       Tools 5(2) (2000) 25-32: eq. 4 (specular), eq. 5 (Schlick's Fresnel factor and the diffuse
       term), eq. 6-9 (sampling the half vector).

    Examples
    --------
    A mirror pair at 60 degrees: h = N, h.k = N.k1 = N.k2 = 1/2, F = rs + (1 - rs) / 32, so with
    nu = nv = 10 and rs = 1/2, f = (11 / (8 pi)) (33 / 64) / (1/2)^2 = 11 * 33 / (128 pi):

    >>> import math, pumpup
    >>> f = pumpup.load({"type": "ashikhmin_shirley", "nu": 10, "nv": 10, "rs": 0.5})
    >>> wi = [3**0.5 / 2, 0, 0.5]; wo = [-3**0.5 / 2, 0, 0.5]
    >>> round(float(f.eval(wi, wo)) * 128 * math.pi / (11 * 33), 12)
    1.0

    At wi = wo = N, F = rs and each diffuse factor is 1 - 1/32, so with rd = 1/2,
    pi f = 11 / 16 + (7 / 23) (31 / 32)^2:

    >>> g = pumpup.load({"type": "ashikhmin_shirley", "nu": 10, "nv": 10, "rs": 0.5, "rd": 0.5})
    >>> round(float(g.eval([0, 0, 1], [0, 0, 1])) * math.pi - (11 / 16 + 7 / 23 * (31 / 32) ** 2), 12)
    0.0
    """

    params = {
        "nu": Param(lo=0.0, hi=MAX_EXPONENT, doc="Phong exponent along the tangent x axis"),
        "nv": Param(lo=0.0, hi=MAX_EXPONENT, doc="Phong exponent along the tangent y axis"),
        "rs": Param(lo=0.0, hi=1.0, doc="specular reflectance at normal incidence"),
        "rd": Param(0.0, lo=0.0, hi=1.0, doc="diffuse reflectance"),
    }
    constant = None  # rs and rd change the shape of f, there is no single scale
    examples = [
        {"nu": 10, "nv": 10, "rs": 1.0},
        {"nu": 100, "nv": 100, "rs": 0.05, "rd": 0.8},
        {"nu": 10, "nv": 1000, "rs": 0.5},
        {"nu": 0, "nv": 0, "rs": 0.2, "rd": 0.5},
        {"nu": 5000, "nv": 200, "rs": 0.9, "rd": 0.1},
    ]
    kernel = staticmethod(_kernel)
    reference_fn = staticmethod(_reference)
    own_sampler = True  # AS 2000 eq. 6-9 (sample_wi, pdf_wi): pumpup.sample and pumpup.mc_albedo draw with them

    def diffuse_probability(self) -> float:
        """P_d = rd (1 - rs) / (1 + rd (1 - rs)): the diffuse term's albedo bound rd (1 - rs) against 1,
        the bound of the specular term's albedo (F <= 1); at most 1/2 (rd = 1, rs = 0), where pbrt-v3's
        FresnelBlend (this model) always takes 1/2; 0 when rd = 0 or rs = 1 (no diffuse term).  The
        same weights as :meth:`albedo_terms`, so ``pumpup.sample`` mixes its strategies alike.
        """
        w = self.p["rd"] * (1.0 - self.p["rs"])
        return w / (1.0 + w)

    def albedo_terms(self):
        """The specular term alone, plus the diffuse term rd (1 - rs) apart where it does not vanish."""
        w = self.p["rd"] * (1.0 - self.p["rs"])
        if w == 0.0:  # (rd = 0, or rs = 1 where the diffuse term vanishes)
            return [(1.0, self)]
        # the diffuse term apart: its albedo is closed-form (rd (1 - rs) (1 - (1 - mu/2)^5)), and in the specular
        # lobe's power map about h, x = (N.h)^(n+1), it would behave as x^(1/(n+1) - 1), singular at x = 0
        # (unsplit, nu = nv = 100, rs = 0.05, rd = 0.8 at mu = 0.3 came out 0.4259 +- 4.5e-4, with a warning,
        # against 0.565209)
        return [(1.0, self.with_params(rd=0.0)), (w, _Diffuse())]

    def azimuth_hint(self):
        """Isotropic with no diffuse term: Ashikhmin and Shirley's family (AS 2000 eq. 4), whose albedo in half-vector
        coordinates is (n + 1) / (8 pi) times the integral of (N.h)^n 4 F(wi.h) N.wo / max(N.wi, N.wo) over h (the
        1 / (h.k) cancels the Jacobian 4 (wo.h)); None otherwise (anisotropic: the nested engine; a diffuse term: the
        terms have their own).
        """
        from ..core.hints import AshikhminShirleyLobe, AzimuthHint

        nu, nv, rs, rd = self.p["nu"], self.p["nv"], self.p["rs"], self.p["rd"]
        if nu != nv or rd * (1.0 - rs) != 0.0:
            return None
        norm = math.sqrt((nu + 1.0) * (nv + 1.0)) / (8.0 * math.pi)  # AS 2000 eq. 4
        return AzimuthHint(AshikhminShirleyLobe(n=float(nu), rs=float(rs)),
                           scale=lambda mu: np.full(np.shape(mu), norm))

    def lobe(self, mu):
        """The Lobe hint: a power lobe about the half vector with the smaller exponent min(nu, nv), a kink at N.wo = mu,
        and the y axis cut when anisotropic.
        """
        # (N.h)^e(phi_h), e = nu cos^2 phi_h + nv sin^2 phi_h, in x = (N.h)^(n+1) ("power" about h) behaves as
        # x^((e + 1) / (n + 1) - 1): bounded in every azimuth for n = min(nu, nv) (e >= n), while the larger
        # exponent would make it singular at x = 0 across the wide axis (as WardAniso.lobe explains for its
        # slopes; with max(nu, nv), nu = 10, nv = 1000 at mu = 0.5 came out 0.47800 +- 3.2e-4, with a warning,
        # against 0.666664).  The 1 / (h.k) of eq. 4 cancels the half-vector Jacobian 4 (k2.h), and
        # max(N.k1, N.k2) kinks at N.k2 = mu (a level).  The y axis cuts beta when anisotropic (as WardAniso's):
        # a lobe narrow across one axis is a ridge along the other
        nu, nv = self.p["nu"], self.p["nv"]
        return Lobe(axis="half", radial="power", sharpness=min(nu, nv), levels=(mu,), symmetric=True,
                    kinks=None if nu == nv else _ridge_cuts(nu, nv))

    def azimuth_range(self):
        """None when isotropic (nu = nv), else pi / 2 (the albedo is even in x and in y)."""
        # f is even in the x and y components of k1 + k2 and k1 - k2: a(phi) = a(-phi) = a(pi - phi)
        return None if self.p["nu"] == self.p["nv"] else math.pi / 2

    # --- the paper's importance sampling (AS 2000 eq. 6-9), mixed with the cosine-weighted hemisphere ----------

    def sample_wi(self, wo, u1, u2):
        """Draw wi given wo: h by the paper's sampling of the half vector (AS 2000 eq. 6-9), wi = 2 (wo.h) h - wo;
        with probability :meth:`diffuse_probability` the cosine-weighted hemisphere instead.

        Parameters
        ----------
        wo : array_like, shape (3,)
            Unit vector towards the viewer.
        u1, u2 : array_like, shape (n,)
            Uniform numbers in [0, 1).

        Returns
        -------
        wi : ndarray, shape (n, 3)
            Unit vectors towards the light; (0, 0, 0) for a rejected draw (wi at or below the horizon,
            or wo at or below it).
        pdf : ndarray, shape (n,)
            The density of wi [1/sr, solid angle], the mixture's (equal to :meth:`pdf_wi`); 0 where rejected.

        Notes
        -----
        AS 2000 eq. 6-9: phi_h = arctan(sqrt((nu + 1) / (nv + 1)) tan(pi xi / 2)) in each quadrant (xi the
        position of u1 in its quarter of [0, 1), the other quadrants reached by reflections, under which the
        density is even), computed as (cos, sin) = (cos a, k sin a) / sqrt(cos^2 a + k^2 sin^2 a), a = pi xi / 2,
        k = sqrt((nu + 1) / (nv + 1)); cos theta_h = (1 - u2)^(1 / (nu cos^2 phi_h + nv sin^2 phi_h + 1)).  The
        density of h is p_h(h) = sqrt((nu + 1)(nv + 1)) / (2 pi) (N.h)^(nu cos^2 phi_h + nv sin^2 phi_h) (it
        integrates to 1: the integral of d phi / ((nu + 1) cos^2 + (nv + 1) sin^2) is 2 pi / sqrt((nu + 1)(nv + 1)))
        and that of wi p_h(h) / (4 (wo.h)).  When the lobe alone is sampled (P_d = 0) the returned pdf is computed
        from (phi_h, theta_h) as drawn, not by :meth:`pdf_wi`, so ``pumpup.testing.chi2_test``'s comparison of the
        two checks the sampler.
        """
        wo = np.asarray(wo, dtype=np.float64)
        u1 = np.asarray(u1, dtype=np.float64)
        u2 = np.asarray(u2, dtype=np.float64)
        n = u1.shape[0]
        nu, nv = self.p["nu"], self.p["nv"]
        pd = self.diffuse_probability()
        wi = np.zeros((n, 3))
        pdf = np.zeros(n)
        if not wo[2] > 0:
            return wi, pdf
        diffuse = u1 < pd
        below1 = np.nextafter(1.0, 0.0)
        # the choice's share of u1 reused for the chosen strategy
        v1 = np.where(diffuse, u1 / pd if pd > 0 else 0.0, np.minimum((u1 - pd) / (1.0 - pd), below1))

        # specular: h by AS 2000 eq. 6-9, one quadrant of phi_h per quarter of v1
        q = np.minimum(np.floor(4.0 * v1), 3.0)
        a = 0.5 * math.pi * (4.0 * v1 - q)
        k = math.sqrt((nu + 1.0) / (nv + 1.0))
        ca, sa = np.cos(a), k * np.sin(a)
        r = np.hypot(ca, sa)
        cphi = ca / r * np.where((q == 1) | (q == 2), -1.0, 1.0)
        sphi = sa / r * np.where(q >= 2, -1.0, 1.0)
        e = nu * cphi * cphi + nv * sphi * sphi
        lc = np.log1p(-u2) / (e + 1.0)  # log cos theta_h (AS 2000 eq. 6-9)
        ct = np.exp(lc)
        st = np.sqrt(-np.expm1(lc) * (1.0 + ct))  # sin theta_h = sqrt((1 - cos)(1 + cos))
        h = np.stack([st * cphi, st * sphi, ct], axis=-1)
        oh = h @ wo
        ws = 2.0 * oh[:, None] * h - wo
        ph = math.sqrt((nu + 1.0) * (nv + 1.0)) / (2.0 * math.pi) * np.exp(e * lc)  # p_h(h), AS 2000 eq. 6-9
        with np.errstate(divide="ignore", invalid="ignore"):
            ps = ph / (4.0 * oh)  # the density of wi, p_h(h) / (4 (wo.h)) (AS 2000 eq. 6-9)

        # diffuse: the cosine-weighted hemisphere
        rr = np.sqrt(v1)
        phd = 2.0 * math.pi * u2
        wd = np.stack([rr * np.cos(phd), rr * np.sin(phd), np.sqrt(np.maximum(1.0 - v1, 0.0))], axis=-1)

        wi = np.where(diffuse[:, None], wd, ws)
        ok = wi[:, 2] > 0
        # the mixture's density: a lobe draw's from AS 2000 eq. 6-9 above, plus P_d N.wi / pi; a diffuse draw could
        # have come from the lobe too, its lobe density from h = (wi + wo) / |wi + wo| (pdf_wi)
        pdf = (1.0 - pd) * ps + pd * wi[:, 2] / math.pi
        if diffuse.any():
            pdf[diffuse] = self.pdf_wi(wi[diffuse], wo)
        pdf = np.where(ok, pdf, 0.0)
        wi[~ok] = 0.0
        return wi, pdf

    def pdf_wi(self, wi, wo):
        """The density [1/sr] of :meth:`sample_wi`'s wi given wo: (1 - P_d) p_h(h) / (4 (wo.h)) + P_d N.wi / pi,
        P_d = :meth:`diffuse_probability`, h = (wi + wo) / |wi + wo|; 0 where wi or wo is at or below the horizon.

        Broadcasts over the leading axes of ``wi`` and ``wo`` (directions on the last axis).
        """
        wi = np.asarray(wi, dtype=np.float64)
        wo = np.asarray(wo, dtype=np.float64)
        nu, nv = self.p["nu"], self.p["nv"]
        s = wi + wo
        with np.errstate(divide="ignore", invalid="ignore"):
            hk = _half_norm_np(s)  # wo.h = |wi + wo| / 2
            p = math.sqrt((nu + 1.0) * (nv + 1.0)) / (8.0 * math.pi) * _half_power_np(s, nu, nv) / hk  # AS 2000 eq. 6-9
        pd = self.diffuse_probability()
        if pd > 0:
            p = (1.0 - pd) * p + pd * wi[..., 2] / math.pi
        return np.where((wi[..., 2] > 0) & (wo[..., 2] > 0), p, 0.0)
