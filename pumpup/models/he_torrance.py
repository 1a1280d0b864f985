"""He, Torrance, Sillion and Greenberg's physical-optics model (SIGGRAPH 1991), "HTSG".

Checked against an independent source (the paper itself was not available here): Westin's
reference implementation (heBRDF, Cornell; as reproduced in github.com/bsdfbenchmark/bbm,
``unittest/he/bin/he_westin.cpp``), whose functions are labelled by the paper's equations
(24, 70, 73-84): every formula below matches it, and so do the values (30 direction pairs to
1e-13 with Westin's series summed to a relative 1e-17, the specular weight to 1e-14;
``tests/data/he_torrance_westin.json``).  Two places where sources differ: the shadowing uses the errata's exp(-c^2)
factor in Lambda (the printed eq. 25 lacks it; bsdfbenchmark's ``he.h`` says so), and D keeps k^2 = (2 pi /
lambda)^2 in v_xy^2 tau^2 / (4 m) as Westin does (a variant without it is dimensionally
inconsistent with tau in micrometres).  Westin switches to a Beckmann shortcut for g > 18.5;
pumpup always sums the series.

The paper's BRDF is the sum of three parts (HTSG sec. 2, eq. "rho_bd = rho_sp + rho_dd +
rho_ud"):

* specular: a delta in the mirror direction carrying the fraction |F(theta_i)|^2 e^(-g) S
  of the incident flux (HTSG: rho_sp = |F|^2 e^(-g) S Delta / (cos theta_i d omega_i));
* directional diffuse: rho_dd = |F|^2 / pi * G S D / (cos theta_i cos theta_r) with
  D = pi^2 tau^2 / (4 lambda^2) * sum_{m>=1} g^m e^(-g) / (m! m) exp(-v_xy^2 tau^2 / (4 m));
* uniform diffuse: a constant (HTSG's a(lambda)); pumpup's parameter ``diffuse`` is its
  hemispherical albedo, f = diffuse / pi.

Notation, in pumpup's frame (wi towards the light, wo towards the viewer, N = z):

* k = 2 pi / lambda; the paper's v = k_r - k_i with the incident wave vector k_i =
  -k wi, so v = k (wi + wo) = k s, s = wi + wo: v_xy = k |s_xy| and v_z = k s_z =
  k (cos theta_i + cos theta_r).
* g = sigma^2 v_z^2 = (2 pi sigma / lambda)^2 (cos theta_i + cos theta_r)^2 (HTSG's
  "g"), sigma the *effective* roughness (below), not sigma_0.
* Effective roughness (HTSG sec. 2.4, the paper's implicit equation for z_0):
  sqrt(pi / 2) z_0 = (sigma_0 / 4) (K_i + K_r) exp(-z_0^2 / (2 sigma_0^2)),
  K = tan(theta) erfc(tau cot(theta) / (2 sigma_0)), and sigma = sigma_0 (1 + z_0^2 /
  sigma_0^2)^(-1/2).  With t = z_0 / sigma_0 it reads sqrt(pi/2) t = a exp(-t^2/2),
  a = (K_i + K_r) / 4, whose left side minus right side increases strictly in t >= 0:
  one root in [0, a sqrt(2/pi)], found by safeguarded Newton iteration on
  ln(sqrt(pi/2) t) + t^2/2 - ln(a).
* Shadowing S = S(theta_i) S(theta_r) (HTSG sec. 2.4, after Smith 1967), with
  c = tau cot(theta) / (2 sigma_0): S(theta) = (1 - erfc(c) / 2) / (Lambda + 1),
  Lambda = (exp(-c^2) / (sqrt(pi) c) - erfc(c)) / 2.  The surface is Gaussian with
  autocorrelation exp(-r^2 / tau^2), whose RMS slope is m = 2 sigma_0 / tau (in the
  sense of Beckmann's exp(-tan^2 / m^2)); c = cot(theta) / m is then Smith's
  argument, and Lambda is the Beckmann Lambda of Walter et al. 2007.
* Fresnel: unpolarised reflectance of the index n + i k at the local angle, the angle
  between wi and the bisector s / |s|: cos = |s| / 2 (HTSG evaluate |F|^2 for the
  directional-diffuse part at this "bisector" angle and at theta_i for the specular
  part).  n omitted: F = 1 (000 sec. 4: "supposing that the Fresnel term is 1 (for
  silver this is practically true)", the assumption of 000 Fig. 5).
* Geometry factor: the paper's G is (v.v / v_z)^2 times a polarisation bracket
  [(s_r.k_i)^2 + (p_r.k_i)^2][(s_i.k_r)^2 + (p_i.k_r)^2] / |k_r x k_i|^4 in unit wave
  vectors.  With unpolarised F the bracket is 1 (s_r, p_r, k_r are orthonormal, so
  (s_r.k_i)^2 + (p_r.k_i)^2 = 1 - (k_r.k_i)^2 = |k_r x k_i|^2, and likewise for the
  other factor), and G = (|s|^2 / s_z)^2.  This is a derivation, not a quotation: the
  polarisation-resolved form of HTSG is not implemented.

Check of the constants (a test, ``tests/models/test_he_torrance.py``): for g >> 1 the series is
dominated by m ~ g, sum ~ exp(-v_xy^2 tau^2 / (4 g)) / g, and rho_dd becomes
F S exp(-tan^2 theta_h / m^2) / (4 pi m^2 cos^4 theta_h cos theta_i cos theta_r) with
m = 2 sigma / tau: Torrance-Sparrow with the Beckmann distribution and Smith shadowing,
the known geometric-optics limit of the Kirchhoff theory.

Where 000 and the original differ: 000 cites the model (ref. 7) and shows its albedo for
sigma_0 = 0.1, tau = 1.7 with F = 1 (Fig. 5) without a wavelength; HTSG give sigma_0 and
tau in micrometres.  000 Table 1 calls it physically plausible; measured here (docs/studies/he-torrance.md), it is
reciprocal to the last bit but its albedo with F = 1 exceeds 1 by up to 4 % near 80 degrees
(1e-4 at normal incidence), so it is not energy-conserving in this unpolarised form.  The
specular part makes it a BRDF with a delta, which 000 does not discuss.

Pumping (:func:`pumpup.pump`) divides ``eval`` by g built from the full albedo (delta
included), and the delta's weight by g at the mirror pair: the pumped model's albedo adds
w(mu) / g(mu, mu) (``Pumped.delta_albedo``).  Sampling is the cosine fallback; the delta is
not sampled (``mc_albedo`` adds its weight exactly).

Truncation of the series (provable bound).  With P_m = g^m e^(-g) / m! (Poisson) the
terms are T_m = P_m exp(-q / m) / m <= P_m / m, q = v_xy^2 tau^2 / 4.  For M + 2 > g,
P_{m+1} / P_m = g / (m + 1) <= g / (M + 2) < 1 for m > M, so the remainder is
R_M <= P_{M+1} / ((M + 1) (1 - g / (M + 2))).  The sum stops at the first M with
R_M <= ``SERIES_RTOL`` * (sum so far), or R_M below 1e-280 (absolute).  The truncated f
is therefore below the true f by a relative amount of at most SERIES_RTOL; the albedo
engine adds SERIES_RTOL * a to its error estimate (``HeTorrance.eval_rtol``).

References
----------
X. D. He, K. E. Torrance, F. X. Sillion, D. P. Greenberg, "A comprehensive physical
model for light reflection", Computer Graphics 25(4) (SIGGRAPH '91), 175-186 ("HTSG").
B. G. Smith, "Geometrical shadowing of a random rough surface", IEEE Trans. Antennas
Propag. 15 (1967) 668-671.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit, vectorize

from ..core import BRDF, MAX_INDEX, MIN_INDEX, Lobe, Param, SpecError, register
from .metal import _fresnel_real, fresnel

#: relative bound on the truncation remainder of the directional-diffuse series
SERIES_RTOL = 1e-13
#: largest g = (4 pi sigma_0 / lambda)^2 accepted (e^-g underflows near 745)
G_MAX = 700.0
_ABS_FLOOR = 1e-280
_SQRT_HALF_PI = math.sqrt(0.5 * math.pi)
_SQRT_PI = math.sqrt(math.pi)


# ----------------------------------------------------------------------------------------
# Compiled pieces
# ----------------------------------------------------------------------------------------


@njit(cache=True)
def _fresnel_c(c, n, k):  # pragma: no cover - compiled
    """Unpolarised Fresnel reflectance |F|^2 at cos = c of the index n + i k (n <= 0: 1)."""
    if n <= 0.0:
        return 1.0
    return _fresnel_real(min(max(c, 0.0), 1.0), n, k)  # (metal's, without cancellation near n + i k = 1)


@njit(cache=True)
def _shadow(mu, m0):  # pragma: no cover - compiled
    """Smith's shadowing S(theta) of a Gaussian surface with RMS slope m0 = 2 sigma_0 / tau."""
    s2 = 1.0 - mu * mu
    if s2 <= 0.0:
        return 1.0
    c = mu / (math.sqrt(s2) * m0)  # tau cot(theta) / (2 sigma_0)
    ec = math.erfc(c)
    lam = 0.5 * (math.exp(-c * c) / (_SQRT_PI * c) - ec)  # Lambda (HTSG sec. 2.4, Smith)
    return (1.0 - 0.5 * ec) / (lam + 1.0)


@njit(cache=True)
def _kfac(mu, m0):  # pragma: no cover - compiled
    """K = tan(theta) erfc(tau cot(theta) / (2 sigma_0)) (HTSG, effective roughness)."""
    s2 = 1.0 - mu * mu
    if s2 <= 0.0:
        return 0.0
    s = math.sqrt(s2)
    return s / mu * math.erfc(mu / (s * m0))


@njit(cache=True)
def _t_root(a):  # pragma: no cover - compiled
    """The root t >= 0 of sqrt(pi/2) t = a exp(-t^2 / 2) (t = z_0 / sigma_0)."""
    if a <= 0.0:
        return 0.0
    if a < 1e-8:  # t < 1e-8: exp(-t^2/2) = 1 - t^2/2 to rounding, one fixed-point step is exact
        t0 = a / _SQRT_HALF_PI
        return t0 * (1.0 - 0.5 * t0 * t0)
    lo = 0.0
    hi = a / _SQRT_HALF_PI
    la = math.log(a)
    t = min(hi, math.sqrt(2.0 * math.log1p(a)))
    for _ in range(100):
        phi = math.log(_SQRT_HALF_PI * t) + 0.5 * t * t - la  # increasing in t
        if phi > 0.0:
            hi = t
        else:
            lo = t
        step = phi / (1.0 / t + t)
        tn = t - step
        if not (lo < tn < hi):
            tn = 0.5 * (lo + hi)
        if abs(tn - t) <= 1e-15 * tn:
            return tn
        t = tn
    return t


@njit(cache=True)
def _sigma_eff(mu_i, mu_o, sigma0, m0):  # pragma: no cover - compiled
    a = 0.25 * (_kfac(mu_i, m0) + _kfac(mu_o, m0))
    t = _t_root(a)
    return sigma0 / math.sqrt(1.0 + t * t)  # sigma = sigma_0 (1 + z_0^2 / sigma_0^2)^(-1/2)


@njit(cache=True)
def _series(g, q, rtol):  # pragma: no cover - compiled
    """sum_{m>=1} g^m e^-g / (m! m) exp(-q / m), truncated with the bound of the module doc."""
    p = math.exp(-g)  # P_0
    total = 0.0
    m = 0
    while True:
        m += 1
        p *= g / m  # P_m
        total += p / m * math.exp(-q / m)
        if m + 2.0 > g:
            bound = p * g / (m + 1.0) / ((m + 1.0) * (1.0 - g / (m + 2.0)))  # R_m
            if bound <= rtol * total or bound < _ABS_FLOOR:
                return total


@vectorize(cache=True)
def _ht_kernel(lx, ly, lz, vx, vy, vz, sigma0, tau, lam, n, k, diffuse, rtol):  # pragma: no cover
    if lz <= 0.0 or vz <= 0.0:
        return 0.0
    sx = lx + vx
    sy = ly + vy
    sz = lz + vz
    sxy2 = sx * sx + sy * sy
    s2 = sxy2 + sz * sz  # |s|^2 = |wi + wo|^2
    m0 = 2.0 * sigma0 / tau
    kk = 2.0 * math.pi / lam
    sigma = _sigma_eff(lz, vz, sigma0, m0)
    g = (kk * sigma * sz) ** 2  # g = sigma^2 v_z^2 (HTSG)
    q = 0.25 * kk * kk * sxy2 * tau * tau  # v_xy^2 tau^2 / 4
    d = (math.pi * tau / lam) ** 2 / 4.0 * _series(g, q, rtol)  # D (HTSG)
    geo = (s2 / sz) ** 2  # G = (v.v / v_z)^2, unpolarised (module doc)
    shadow = _shadow(lz, m0) * _shadow(vz, m0)  # S = S(theta_i) S(theta_r)
    f = _fresnel_c(0.5 * math.sqrt(s2), n, k)  # |F|^2 at the bisector angle
    return f * geo * shadow * d / (math.pi * (lz * vz)) + diffuse / math.pi  # rho_dd + rho_ud


# ----------------------------------------------------------------------------------------
# Plain numpy reference (same equations, written on arrays)
# ----------------------------------------------------------------------------------------


def fresnel_unpolarised(c, n=None, k=0.0):
    """Unpolarised Fresnel reflectance |F|^2 of an interface with index n + i k.

    Parameters
    ----------
    c : array_like
        Cosine of the angle of incidence, in [0, 1].
    n, k : float
        Real and imaginary parts of the index (relative to the outside medium); n None
        gives 1.

    Returns
    -------
    ndarray
        (|r_s|^2 + |r_p|^2) / 2; ((n - 1)^2 + k^2) / ((n + 1)^2 + k^2) at c = 1.

    Examples
    --------
    >>> round(float(fresnel_unpolarised(1.0, 1.5)), 12)
    0.04
    """
    c = np.asarray(c, dtype=np.float64)
    if n is None or n <= 0:
        return np.ones_like(c)
    return fresnel(c, n, k)  # (metal's complex formula, without cancellation near n + i k = 1)


def shadowing(mu, m0):
    """Smith's shadowing S(theta) (HTSG sec. 2.4) for cos(theta) = mu, RMS slope m0 = 2 sigma_0 / tau."""
    from scipy.special import erfc

    mu = np.asarray(mu, dtype=np.float64)
    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
        c = mu / (np.sqrt(1.0 - mu * mu) * m0)
        ec = erfc(c)
        lam = 0.5 * (np.exp(-c * c) / (_SQRT_PI * c) - ec)
        s = (1.0 - 0.5 * ec) / (lam + 1.0)
    return np.where(mu >= 1.0, 1.0, s)


def effective_sigma(mu_i, mu_o, sigma0, tau):
    """Effective roughness sigma(theta_i, theta_r) [same unit as sigma0] (HTSG sec. 2.4).

    Solves sqrt(pi/2) z_0 = sigma_0 / 4 (K_i + K_r) exp(-z_0^2 / (2 sigma_0^2)) by
    bisection on arrays (60 halvings of [0, a sqrt(2/pi)], then Newton steps) and returns
    sigma_0 / sqrt(1 + z_0^2 / sigma_0^2).
    """
    from scipy.special import erfc

    m0 = 2.0 * sigma0 / tau
    mu_i = np.asarray(mu_i, dtype=np.float64)
    mu_o = np.asarray(mu_o, dtype=np.float64)

    def kfac(mu):
        s = np.sqrt(np.maximum(0.0, 1.0 - mu * mu))
        with np.errstate(divide="ignore", invalid="ignore"):
            return np.where(s > 0, s / mu * erfc(mu / (s * m0)), 0.0)

    a = 0.25 * (kfac(mu_i) + kfac(mu_o))
    lo = np.zeros_like(a)
    hi = a / _SQRT_HALF_PI
    for _ in range(200):  # bisection on h(t) = sqrt(pi/2) t - a exp(-t^2/2), increasing
        mid = 0.5 * (lo + hi)
        pos = _SQRT_HALF_PI * mid - a * np.exp(-0.5 * mid * mid) > 0
        hi = np.where(pos, mid, hi)
        lo = np.where(pos, lo, mid)
    t = 0.5 * (lo + hi)
    return sigma0 / np.sqrt(1.0 + t * t)


def series_reference(g, q, rtol=SERIES_RTOL):
    """The directional-diffuse series on arrays, same stopping rule as the kernel."""
    g = np.asarray(g, dtype=np.float64)
    q = np.asarray(q, dtype=np.float64)
    g, q = np.broadcast_arrays(g, q)
    p = np.exp(-g)
    total = np.zeros_like(g)
    active = np.ones(g.shape, bool)
    m = 0
    while active.any():
        m += 1
        p = np.where(active, p * g / m, p)
        total = np.where(active, total + p / m * np.exp(-q / m), total)
        bound = p * g / (m + 1.0) / ((m + 1.0) * (1.0 - g / (m + 2.0)))
        done = (m + 2.0 > g) & ((bound <= rtol * total) | (bound < _ABS_FLOOR))
        active &= ~done
    return total


def _ht_reference(wi, wo, sigma0, tau, lam, n, k, diffuse, rtol):
    lz, vz = wi[..., 2], wo[..., 2]
    up = (lz > 0) & (wo[..., 2] > 0)
    lzc, vzc = np.where(up, lz, 0.5), np.where(up, vz, 0.5)
    s = wi + wo
    sxy2 = s[..., 0] ** 2 + s[..., 1] ** 2
    sz = lzc + vzc
    s2 = sxy2 + sz * sz
    kk = 2.0 * np.pi / lam
    sigma = effective_sigma(lzc, vzc, sigma0, tau)
    g = (kk * sigma * sz) ** 2  # HTSG g
    q = 0.25 * kk * kk * sxy2 * tau * tau
    d = (np.pi * tau / lam) ** 2 / 4.0 * series_reference(g, q, rtol)  # D
    m0 = 2.0 * sigma0 / tau
    f = fresnel_unpolarised(0.5 * np.sqrt(s2), n if n > 0 else None, k)
    out = f * (s2 / sz) ** 2 * shadowing(lzc, m0) * shadowing(vzc, m0) * d / (np.pi * lzc * vzc) + diffuse / np.pi
    return np.where(up, out, 0.0)


# ----------------------------------------------------------------------------------------
# The model
# ----------------------------------------------------------------------------------------


@register("he_torrance")
class HeTorrance(BRDF):
    """He-Torrance-Sillion-Greenberg reflection (SIGGRAPH 1991) [1/sr], unpolarised.

    ``eval`` returns the directional-diffuse plus the uniform-diffuse parts; the specular
    part is a delta in the mirror direction whose weight :meth:`specular_weight` gives,
    and which :func:`pumpup.albedo` and :func:`pumpup.mc_albedo` add analytically
    (through :meth:`delta_albedo`).
    The equations, and which line implements which, are in the module docstring.

    Parameters
    ----------
    sigma_0 : float, in (0, inf), micrometres
        RMS height of the surface (HTSG's sigma_0).
    tau : float, in (0, inf), micrometres
        Autocorrelation length (HTSG's tau).  The RMS slope is 2 sigma_0 / tau.
    wavelength : float, in (0, inf), micrometres, default 0.55
        Wavelength lambda.  (4 pi sigma_0 / lambda)^2 must not exceed 700.
    n : float, in (0, inf), optional
        Real part of the index of refraction; omitted means |F|^2 = 1 (000 Fig. 5).
    k : float, in [0, inf), default 0
        Extinction coefficient (imaginary part of the index, conductors); needs ``n``.
    diffuse : float, in [0, 1], default 0
        Albedo of the uniform-diffuse part (f = diffuse / pi; HTSG's a(lambda) =
        diffuse / pi).

    Examples
    --------
    >>> import pumpup
    >>> f = pumpup.load({"type": "he_torrance", "sigma_0": 0.1, "tau": 1.7})
    >>> round(float(f.specular_weight(1.0)), 6)  # e^-g S at normal incidence, F = 1
    0.005406
    """

    params = {
        "sigma_0": Param(lo=0.0, lo_open=True, doc="RMS roughness [um]"),
        "tau": Param(lo=0.0, lo_open=True, doc="autocorrelation length [um]"),
        "wavelength": Param(0.55, lo=0.0, lo_open=True, doc="wavelength [um]"),
        "n": Param(None, lo=MIN_INDEX, hi=MAX_INDEX, doc="real index of refraction (None: |F|^2 = 1)"),
        "k": Param(0.0, lo=0.0, hi=MAX_INDEX, doc="extinction coefficient"),
        "diffuse": Param(0.0, lo=0.0, hi=1.0, doc="albedo of the uniform-diffuse part"),
    }
    constant = None
    examples = [
        {"sigma_0": 0.1, "tau": 1.7},
        {"sigma_0": 0.18, "tau": 1.0, "wavelength": 0.4, "n": 1.5, "diffuse": 0.2},
        {"sigma_0": 0.05, "tau": 3.0, "wavelength": 0.65, "n": 0.13, "k": 4.0},
    ]
    kernel = staticmethod(_ht_kernel)
    reference_fn = staticmethod(_ht_reference)
    #: relative truncation bound of eval (the series), added to the albedo error
    eval_rtol = SERIES_RTOL

    def _validate(self):
        p = self.p
        if p["n"] is None and p["k"] != 0.0:
            raise SpecError(f"he_torrance: parameter 'k' = {p['k']:g} needs the real index 'n' as well")
        ratio = p["sigma_0"] / p["wavelength"]  # (compared before squaring: a wavelength of 1e-181 overflowed g)
        lim = math.sqrt(G_MAX) / (4 * math.pi)
        if not ratio <= lim:
            raise SpecError(
                f"he_torrance: parameter 'sigma_0' / 'wavelength' = {p['sigma_0'] / p['wavelength']:g} is outside "
                f"its allowed range (0, {lim:.4g}] (g = (4 pi sigma_0 / lambda)^2 <= {G_MAX:g}; rougher surfaces "
                "are in the geometric-optics limit: use cook_torrance)"
            )

    def kernel_args(self):
        """(sigma_0, tau, wavelength, n, k, diffuse, series tolerance) for the compiled kernel, n 0 without a Fresnel
        factor.
        """
        p = self.p
        n = 0.0 if p["n"] is None else p["n"]
        return (p["sigma_0"], p["tau"], p["wavelength"], n, p["k"], p["diffuse"], SERIES_RTOL)

    # --- the specular (delta) part -------------------------------------------------------
    def specular_weight(self, mu):
        """Fraction of the flux from cos(theta_i) = mu reflected into the mirror direction.

        w(mu) = |F(theta_i)|^2 exp(-g) S(theta_i)^2, g = (4 pi sigma mu / lambda)^2 with the
        effective sigma at theta_r = theta_i (HTSG's rho_sp integrated over its cone).
        Dimensionless, in [0, 1].
        """
        p = self.p
        mu = np.asarray(mu, dtype=np.float64)
        m0 = 2.0 * p["sigma_0"] / p["tau"]
        sigma = effective_sigma(mu, mu, p["sigma_0"], p["tau"])
        g = (4.0 * np.pi * sigma * mu / p["wavelength"]) ** 2
        f = fresnel_unpolarised(mu, p["n"], p["k"])
        return f * np.exp(-g) * shadowing(mu, m0) ** 2

    def delta_albedo(self, mu):
        """The delta lobe's share of the albedo, :meth:`specular_weight`.

        :func:`pumpup.albedo` adds it to the cubature of ``eval`` (with a rounding error
        of 1e-15 of it) and :func:`pumpup.mc_albedo` to its estimate (exactly: the delta
        is not sampled); ``eval_rtol`` (= ``SERIES_RTOL``) of the cubature is added to the
        albedo error for the truncation of the series.
        """
        return self.specular_weight(mu)

    # --- hints ---------------------------------------------------------------------------
    def lobe(self, mu):
        """The Lobe hint: a GGX map about the half vector with the width of the dominant Gaussian, and the kinks of
        |F|^2 at wi.h.
        """
        # the Gaussian in v_xy with the dominant m ~ max(1, g) at the mirror direction is
        # exp(-tan^2(theta_h) / m_eff^2), m_eff = sqrt(max(1, g)) / (k tau mu) (module doc)
        p = self.p
        kk = 2.0 * math.pi / p["wavelength"]
        mu = max(float(mu), 1e-3)
        sigma = float(effective_sigma(mu, mu, p["sigma_0"], p["tau"]))
        g = (2.0 * kk * sigma * mu) ** 2
        den = kk * p["tau"] * mu  # (0 for a denormal tau: the lobe is then as wide as the map allows)
        m_eff = min(1.0, math.sqrt(max(1.0, g)) / den) if den > 0.0 else 1.0
        # the GGX map tan^2(theta_h) = r x / (1 - x), r = m_eff^2: its tail is heavier than
        # Gaussian, as the series' mixture of Gaussians of widths sqrt(m) is (the Beckmann
        # map's weight 1/x diverges at theta_h -> 90 deg where f does not vanish at grazing)
        # and the kink wi.h = x0 where |F|^2 at the bisector angle has total reflection (n < 1) or a near-kink: n = 0.6
        # took the nested engine 0.9 s for three values at rtol 1e-8 without it (n = 1.5: 0.1 s), the 2-D engine 95 s
        from .microfacet import wih_kinks

        return Lobe(axis="half", radial="ggx", sharpness=m_eff * m_eff, kinks=wih_kinks(self, p["n"], p["k"]))

    def albedo_breaks(self):
        """The kink of the delta lobe's F(mu) where the index is given, else none."""
        from .metal import fresnel_levels

        # (the delta's F(mu) turns there)
        return () if self.p["n"] is None else fresnel_levels(self.p["n"], self.p["k"])

    def sampling_lobe(self, mu):
        """The sampling hint: the cosine-weighted hemisphere (the delta lobe is not sampled)."""
        return Lobe(axis="normal", radial="cosine")  # cosine fallback (the delta is not sampled)
