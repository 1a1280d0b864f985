"""Non-Lambertian diffuse models: Minnaert, the Neumann-Neumann lacquer model, Oren-Nayar.

All three are reciprocal and isotropic, and their lobes are centred on the normal.
"""

from __future__ import annotations

import math

import numpy as np
from numba import vectorize

from ..core import BRDF, MAX_EXPONENT, Lobe, Param, register


def _up(wi, wo):
    return (wi[..., 2] > 0) & (wo[..., 2] > 0)


# --- Minnaert -----------------------------------------------------------------------------


@vectorize(cache=True)
def _minnaert_kernel(lx, ly, lz, vx, vy, vz, k, b):  # pragma: no cover - compiled
    if lz <= 0.0 or vz <= 0.0:
        return 0.0
    return b * lz ** (k - 1.0) * vz ** (k - 1.0)  # 002 sec. 3.4: b ((N.S)(N.V))^(k-1)


def _minnaert_reference(wi, wo, k, b):
    up = _up(wi, wo)
    prod = np.where(up, wi[..., 2], 1.0) ** (k - 1.0) * np.where(up, wo[..., 2], 1.0) ** (k - 1.0)
    return np.where(up, b * prod, 0.0)  # 002 sec. 3.4


def _minnaert_b(q):
    return (q["k"] + 1.0) / (2.0 * math.pi)  # 002 sec. 4.3: k_rho = 1 at normal incidence


@register("minnaert")
class Minnaert(BRDF):
    """Minnaert's lunar model as a BRDF, f_r = b ((N.S)(N.V))^(k-1) [1/sr].

    002 sec. 3.4 (after Minnaert 1941).  Its directional albedo is closed form,
    a(mu) = b 2 pi / (k + 1) mu^(k-1) (002 sec. 4.3, with 002 eq. 16), so the default
    b = (k + 1) / (2 pi) gives a(mu) = mu^(k-1): albedo 1 at normal incidence, and
    energy conservation at every angle for k >= 1.  For k < 1 the BRDF and its albedo
    diverge at grazing incidence.

    Parameters
    ----------
    k : float, > 0
        Minnaert exponent (dimensionless); k = 1 is Lambert with albedo pi b.
        Lewis relates it to a half-width beta by k = 1 - ln 2 / ln cos(beta).
    b : float, >= 0, default (k + 1) / (2 pi)
        Scale b_M [1/sr]; the value at wi = wo = N.

    Examples
    --------
    >>> import pumpup
    >>> f = pumpup.load({"type": "minnaert", "k": 2})
    >>> round(float(f.eval([0, 0, 1], [0, 0, 1])) * 2 * 3.141592653589793 / 3, 12)
    1.0
    """

    params = {
        "k": Param(lo=0.0, hi=MAX_EXPONENT, lo_open=True, doc="Minnaert exponent"),
        "b": Param(_minnaert_b, lo=0.0, doc="scale [1/sr]"),
    }
    constant = "b"
    examples = [{"k": 1.0}, {"k": 2.0}, {"k": 1.37, "b": 0.1}, {"k": 0.8}]
    kernel = staticmethod(_minnaert_kernel)
    reference_fn = staticmethod(_minnaert_reference)

    def lobe(self, mu):
        """The Lobe hint: the cosine map about the normal, even in the azimuth."""
        return Lobe(axis="normal", radial="cosine", symmetric=True)

    def azimuth_hint(self):
        """The azimuth hint: a closed form, a(mu) = 2 pi b mu^(k-1) / (k + 1)."""
        from ..core.hints import AzimuthHint, ClosedForm

        k, b = self.p["k"], self.p["b"]
        return AzimuthHint(ClosedForm(),
                           scale=lambda mu: b * 2.0 * math.pi / (k + 1.0) * np.asarray(mu, float) ** (k - 1.0))


# --- Neumann-Neumann lacquer -----------------------------------------------------------------


@vectorize(cache=True)
def _lacquer_kernel(lx, ly, lz, vx, vy, vz, c, s):  # pragma: no cover - compiled
    if lz <= 0.0 or vz <= 0.0:
        return 0.0
    # s / mu overflows to inf (and exp to 0) at tiny mu, which is the right limit; written
    # as s/lz + s/vz so that s = 0 never meets 1/mu = inf
    return c * math.exp(-(s / lz + s / vz))  # 002 sec. 3.3


def _lacquer_reference(wi, wo, c, s):
    up = _up(wi, wo)
    mi = np.where(up, wi[..., 2], 1.0)
    mo = np.where(up, wo[..., 2], 1.0)
    with np.errstate(over="ignore"):
        f = c * np.exp(-s * (1.0 / mi + 1.0 / mo)) if s > 0 else np.full(mi.shape, float(c))  # 002 sec. 3.3
    return np.where(up, f, 0.0)


@register("lacquer")
class Lacquer(BRDF):
    """Neumann-Neumann lacquer model, f_r = c exp(-s (1/(N.S) + 1/(N.V))) [1/sr].

    A diffuse base under an absorbing, non-scattering lacquer layer (002 sec. 3.3,
    after Neumann and Neumann 1989).  Separable and reciprocal; the value at
    wi = wo = N is c exp(-2 s) (Lewis's b_N).

    Parameters
    ----------
    c : float, >= 0, default 1/pi
        Scale [1/sr]; with s = 0 the model is Lambert with albedo pi c.
    s : float, >= 0, default 0.1
        Absorption of the lacquer (optical thickness, dimensionless).

    Examples
    --------
    >>> import math, pumpup
    >>> f = pumpup.load({"type": "lacquer", "s": 0.25})
    >>> round(float(f.eval([0, 0, 1], [0, 0, 1])) * math.pi / math.exp(-0.5), 12)
    1.0
    """

    params = {
        "c": Param(1.0 / math.pi, lo=0.0, doc="scale [1/sr]"),
        "s": Param(0.1, lo=0.0, doc="lacquer absorption (dimensionless)"),
    }
    constant = "c"
    examples = [{}, {"s": 0.0}, {"c": 0.5, "s": 0.02}, {"s": 1.5}]
    kernel = staticmethod(_lacquer_kernel)
    reference_fn = staticmethod(_lacquer_reference)

    def lobe(self, mu):
        """The Lobe hint: the cosine map about the normal, even in the azimuth."""
        return Lobe(axis="normal", radial="cosine", symmetric=True)

    def azimuth_hint(self):
        """The azimuth hint: a closed form, a(mu) = 2 pi c e^(-s/mu) E_3(s) (pi c for s = 0), with its rounding error in
        ulps.
        """
        from scipy.special import expn

        from ..core.hints import AzimuthHint, ClosedForm

        c, s = self.p["c"], self.p["s"]
        e3 = float(expn(3, s))  # integral_0^1 t e^(-s/t) dt = E_3(s) (t = 1/x); E_3(0) = 1/2: Lambert's pi c
        # a(mu) = 2 pi c e^(-s/mu) E_3(s).  Error: scipy's E_3 within 3.9 eps of mpmath (s in [0, 700]), a few ulps of
        # products, and e^(-s/mu) inherits the rounding of s / mu, eps s / mu (as the kernel does): 8 + 2 s / mu eps
        return AzimuthHint(ClosedForm(ulps=lambda mu: 8.0 + 2.0 * s / mu),
                           scale=lambda mu: 2.0 * math.pi * c * np.exp(-s / np.asarray(mu, float)) * e3 if s > 0
                           else np.full(np.shape(mu), math.pi * c))


# --- Oren-Nayar ------------------------------------------------------------------------------


def _on_ab(sigma):
    s2 = sigma * sigma
    return 1.0 - 0.5 * s2 / (s2 + 0.33), 0.45 * s2 / (s2 + 0.09)  # Oren-Nayar 1994, qualitative model


@vectorize(cache=True)
def _on_kernel(lx, ly, lz, vx, vy, vz, albedo, sigma):  # pragma: no cover - compiled
    if lz <= 0.0 or vz <= 0.0:
        return 0.0
    s2 = sigma * sigma
    a = 1.0 - 0.5 * s2 / (s2 + 0.33)
    b = 0.45 * s2 / (s2 + 0.09)
    # max(0, cos(phi_i - phi_o)) sin(alpha) tan(beta) = max(0, Lx Vx + Ly Vy) / max(N.L, N.V),
    # since sin(alpha) sin(beta) = sin(theta_i) sin(theta_o) and cos(beta) = max(N.L, N.V)
    t = lx * vx + ly * vy
    if t < 0.0:
        t = 0.0
    return albedo / math.pi * (a + b * t / max(lz, vz))  # Oren & Nayar 1994, qualitative model


def _on_reference(wi, wo, albedo, sigma):
    a, b = _on_ab(sigma)
    up = _up(wi, wo)
    sin_i = np.hypot(wi[..., 0], wi[..., 1])
    sin_o = np.hypot(wo[..., 0], wo[..., 1])
    den = sin_i * sin_o
    dot = wi[..., 0] * wo[..., 0] + wi[..., 1] * wo[..., 1]
    with np.errstate(divide="ignore", invalid="ignore"):
        cos_dphi = np.where(den > 0, dot / den, 0.0)  # cos(phi_i - phi_o); 0 if a projection vanishes
        max_mu = np.maximum(wi[..., 2], wo[..., 2])  # cos(beta), beta = min(theta_i, theta_o)
        sin_alpha = np.where(wi[..., 2] <= wo[..., 2], sin_i, sin_o)  # alpha = max(theta_i, theta_o)
        sin_beta = np.where(wi[..., 2] <= wo[..., 2], sin_o, sin_i)
        f = albedo / np.pi * (a + b * np.maximum(0.0, cos_dphi) * sin_alpha * sin_beta / max_mu)  # Oren-Nayar
    return np.where(up, f, 0.0)


@register("oren_nayar")
class OrenNayar(BRDF):
    """Oren-Nayar rough diffuse reflection (qualitative model) [1/sr].

    f_r = albedo / pi (A + B max(0, cos(phi_i - phi_o)) sin(alpha) tan(beta)),
    A = 1 - 0.5 sigma^2 / (sigma^2 + 0.33), B = 0.45 sigma^2 / (sigma^2 + 0.09),
    alpha = max(theta_i, theta_o), beta = min(theta_i, theta_o)
    (M. Oren and S. K. Nayar, "Generalization of Lambert's reflectance model",
    SIGGRAPH 1994, eq. 30 without the interreflection term).  The kernel uses the
    identity max(0, cos(phi_i - phi_o)) sin(alpha) tan(beta) =
    max(0, Lx Vx + Ly Vy) / max(N.L, N.V), which needs no azimuths.  The qualitative
    model does not conserve energy exactly: with albedo = 1 and sigma = 0.3 its
    directional albedo rises from about 0.893 at normal incidence to about 1.005 at
    grazing incidence.

    Parameters
    ----------
    albedo : float, in [0, 1], default 1
        Albedo rho of the facets.
    sigma : float, >= 0, default 0.3
        Standard deviation of the facet slope angle [rad]; sigma = 0 is Lambert.

    Examples
    --------
    >>> import pumpup
    >>> f = pumpup.load({"type": "oren_nayar", "albedo": 0.5, "sigma": 0.0})
    >>> g = pumpup.load({"type": "lambert", "albedo": 0.5})
    >>> wi, wo = [0.6, 0, 0.8], [-0.8, 0, 0.6]
    >>> bool(f.eval(wi, wo) == g.eval(wi, wo))
    True
    """

    params = {
        "albedo": Param(1.0, lo=0.0, hi=1.0, doc="facet albedo"),
        "sigma": Param(0.3, lo=0.0, doc="slope angle standard deviation [rad]"),
    }
    constant = "albedo"
    examples = [{}, {"sigma": 0.0}, {"albedo": 0.7, "sigma": 0.5}, {"sigma": 1.2}]
    kernel = staticmethod(_on_kernel)
    reference_fn = staticmethod(_on_reference)

    def lobe(self, mu):
        """The Lobe hint: the cosine map about the normal, with the kink at N.wo = mu where alpha and beta swap."""
        # alpha and beta swap where N.wo = mu: a kink at wo_z = mu
        return Lobe(axis="normal", radial="cosine", levels=(mu,), symmetric=True)

    def azimuth_hint(self):
        """The azimuth hint: the closed form of :func:`oren_nayar_albedo`."""
        from ..core.hints import AzimuthHint, ClosedForm

        rho, sigma = self.p["albedo"], self.p["sigma"]
        return AzimuthHint(ClosedForm(), scale=lambda mu: oren_nayar_albedo(mu, rho, sigma))


def oren_nayar_albedo(mu, albedo=1.0, sigma=0.3):
    """The directional albedo of the qualitative Oren-Nayar model in closed form.

    The azimuth gives integral max(0, cos(phi)) d phi = 2, so with t = N.wo and s = sin(theta_i)
    a(mu) = albedo (A + (2 B s / pi) (integral_0^1 t sqrt(1 - t^2) / max(mu, t) dt))
          = albedo (A + (2 B s / pi) ((1 - s^3) / (3 mu) + (theta_i - mu s) / 2)),
    written without cancellation: (1 - s^3) / (3 mu) = mu (1 + s + s^2) / (3 (1 + s)) and
    theta_i - mu s = (2 theta_i - sin(2 theta_i)) / 2 (its series below 2 theta_i = 1).  A(1) = A; a(0) = A + B / 2.
    """
    mu = np.asarray(mu, dtype=np.float64)
    a, b = _on_ab(sigma)
    s = np.sqrt((1.0 - mu) * (1.0 + mu))
    th2 = 2.0 * np.arctan2(s, mu)
    with np.errstate(divide="ignore", invalid="ignore"):
        below = mu * (1.0 + s + s * s) / (3.0 * (1.0 + s))
    # x - sin(x) at x = 2 theta_i, by its series where it cancels (x < 1)
    series = np.zeros_like(th2)
    term = th2.copy()
    for k in range(1, 12):
        term = term * th2 * th2 / ((2.0 * k) * (2.0 * k + 1.0))
        series = series + (-1.0) ** (k + 1) * term
    x_sin = np.where(th2 < 1.0, series, th2 - np.sin(th2))
    return albedo * (a + (2.0 * b * s / math.pi) * (below + 0.25 * x_sin))
