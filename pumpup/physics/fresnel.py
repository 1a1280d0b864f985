"""Fresnel reflectance, shared by the models, the albedo engine, the spectral kernels and the renderer plugins.

Each compiled kernel has its plain numpy twin beside it, and they are tested against each other:

* conductors (complex index eta + i k; a dielectric is k = 0): :func:`fresnel_conductor` (numpy, complex arithmetic,
  pbrt-v4's FrComplex), :func:`conductor_scalar` and :func:`conductor_select` (numba, real arithmetic);
  000 eq. 27-28;
* dielectrics with a real index of refraction (Cook and Torrance's form, 002 sec. 3.2): :func:`fresnel_dielectric` and
  :func:`dielectric_reference` (numpy), :func:`dielectric_scalar` (numba);
* where the conductor factor F(c) has its singularities (branch point, pole, Brewster's zero), for the quadrature
  rules that integrate it: :func:`fresnel_branch`, :func:`fresnel_pole`, :func:`fresnel_brewster`, and the level of
  its (near-)kink that a model adds to its quadrature hint, :func:`fresnel_levels`.
"""

from __future__ import annotations

import cmath
import math

import numpy as np
from numba import njit

__all__ = ["fresnel_conductor", "fresnel_dielectric", "conductor_scalar", "conductor_select", "dielectric_scalar",
           "dielectric_reference", "fresnel_levels", "fresnel_branch", "fresnel_pole", "fresnel_brewster",
           "FRESNEL_LEVEL_Y0"]


@njit(cache=True, inline="always")
def conductor_select(cc, s2, e21, ek2, ek):  # pragma: no cover - compiled
    """F(eta + i k, theta) with cos(theta) = cc, sin^2 = s2, from the hoisted constants.

    The same formula as ``_fresnel_real`` (a + i b = sqrt((eta + i k)^2 - sin^2), a >= 0):
    R_s = ((a - c)^2 + b^2) / ((a + c)^2 + b^2) = |1 - (eta + i k)^2|^2 / ((a + c)^2 + b^2)^2,
    R_p = R_s ((a c - s^2)^2 + b^2 c^2) / ((a c + s^2)^2 + b^2 c^2), F = (R_s + R_p) / 2
    (000 eq. 27; pbrt-v3 FrConductor), with the larger of a, b from the cancellation-free root
    sqrt((|z| + |t0|) / 2) and the smaller as eta k / that root, and one division.  ``e21`` is
    eta^2 - k^2 - 1 (:func:`fresnel_constants`), so t0 = e21 + c^2 and R_s lose nothing near eta + i k = 1.
    """
    t0 = e21 + cc * cc
    big = math.sqrt(t0 * t0 + ek2)  # |(eta + i k)^2 - sin^2| = a^2 + b^2 (eta, k <= 1e3: no overflow)
    q = math.sqrt(0.5 * (big + abs(t0)))  # the larger of a, b
    r = ek / max(q, 1e-300)  # the smaller (q = 0 only where eta k = 0: then r = 0)
    a = q if t0 >= 0.0 else r
    b = r if t0 >= 0.0 else q
    b2 = b * b
    ap = a + cc
    ds = ap * ap + b2
    if ds == 0.0:  # (eta + i k = 1 at c = 0: F's limit 0; before the division, which would raise)
        return 0.0
    ns = (e21 * e21 + ek2) / ds  # R_s = ns / ds (|c - A|^2 = |1 - e^2|^2 / |c + A|^2)
    x = a * cc - s2
    y = a * cc + s2
    bc2 = b2 * cc * cc
    npar = x * x + bc2  # R_p / R_s = npar / dp
    dp = y * y + bc2
    return 0.5 * ns * (dp + npar) / (ds * dp)  # (R_s + R_p) / 2


def fresnel_conductor(cos_i, eta, k=0.0):
    """Unpolarised Fresnel reflectance of a smooth interface with complex index eta + i k.

    The exact formula with complex arithmetic, as pbrt-v4's ``FrComplex``:
    cos_t = sqrt(1 - sin^2(theta_i) / eta^2),
    r_par = (eta cos_i - cos_t) / (eta cos_i + cos_t),
    r_perp = (cos_i - eta cos_t) / (cos_i + eta cos_t),
    F = (|r_par|^2 + |r_perp|^2) / 2.

    Parameters
    ----------
    cos_i : array_like
        Cosine of the incidence angle, clipped to [0, 1].
    eta : float or array_like, > 0
        Real part of the relative refractive index (dimensionless).
    k : float or array_like, >= 0
        Extinction coefficient (imaginary part of the index); 0 for a dielectric.

    Returns
    -------
    ndarray
        F in [0, 1].

    Examples
    --------
    >>> round(float(fresnel_conductor(1.0, 1.5)), 12)  # ((eta - 1) / (eta + 1))^2
    0.04
    """
    c = np.clip(np.asarray(cos_i, dtype=np.float64), 0.0, 1.0)
    e = np.asarray(eta, dtype=np.float64) + 1j * np.asarray(k, dtype=np.float64)
    # Snell's law, complex angle of refraction: cos_t^2 = 1 - sin^2 / e^2 = ((e - 1)(e + 1) + c^2) / e^2, without the
    # cancellation of e^2 - sin^2 near e = 1 at grazing incidence (eta 1, c = 1e-8 gave F = 0.039 for 0)
    e21 = (e - 1.0) * (e + 1.0)  # e^2 - 1
    cos_t = np.sqrt((e21 + c * c) / (e * e))
    # the Fresnel equations (pbrt-v4 FrComplex) r_par = (e c - cos_t) / (e c + cos_t), r_perp = (c - e cos_t) /
    # (c + e cos_t); near e = 1, where both are small, over their denominators squared: (e^2 c)^2 - (e cos_t)^2 =
    # (e^2 - 1)((e^2 + 1) c^2 - 1), c^2 - (e cos_t)^2 = 1 - e^2 (no cancellation; r_par's form loses digits near a
    # dielectric's total reflection, so only where |e^2 - 1| < 1/2)
    near = np.abs(e21) < 0.5
    with np.errstate(divide="ignore", invalid="ignore"):
        r_par = np.where(e21 == 0.0, 0.0, np.where(near,
                                                   e21 * ((e21 + 2.0) * c * c - 1.0) / (e * e * c + e * cos_t) ** 2,
                                                   (e * c - cos_t) / (e * c + cos_t)))
        r_perp = np.where(e21 == 0.0, 0.0, -e21 / (c + e * cos_t) ** 2)  # (e = 1: no reflection, c = 0 its limit)
    return 0.5 * (np.abs(r_par) ** 2 + np.abs(r_perp) ** 2)


@njit(cache=True)
def conductor_scalar(c, eta, k):  # pragma: no cover - compiled
    """``fresnel`` in real arithmetic, free of cancellation (for the numba kernels).

    With a + i b = sqrt((eta + i k)^2 - sin^2) (a >= 0), the classic real form
    (e.g. pbrt-v3 FrConductor) becomes a ratio of sums of squares:
    R_s = ((a - c)^2 + b^2) / ((a + c)^2 + b^2), computed as |1 - (eta + i k)^2|^2 / ((a + c)^2 + b^2)^2,
    R_p = R_s ((a c - s^2)^2 + b^2 c^2) / ((a c + s^2)^2 + b^2 c^2), F = (R_s + R_p) / 2: the spectral kernels'
    :func:`conductor_select` with its constants from (eta, k) (one square root for a^2 + b^2
    instead of math.hypot, which took more than half of the time: 40-46 ns a value before, 12.6-12.8 after, measured
    in a compiled loop; eta, k <= MAX_INDEX, so the squares do not overflow).
    """
    ek = eta * k
    return conductor_select(c, (1.0 - c) * (1.0 + c), (eta - 1.0) * (eta + 1.0) - k * k, 4.0 * ek * ek, ek)


#: a Fresnel factor whose branch point lies closer than this to the real axis inside (0, 1) adds its real part as a
#: level of the quadrature hint (:func:`fresnel_levels`)
FRESNEL_LEVEL_Y0 = 0.05


def fresnel_levels(eta: float, k: float, y0_max: float | None = None) -> tuple:
    """The level N.wo = x0 where F(eta + i k, max(N.wi, N.wo)) has a kink or a near-kink, for a model's ``Lobe`` hint:
    () or (x0,): the branch point's real part inside (0, 1), its imaginary part below ``y0_max`` (default
    :data:`FRESNEL_LEVEL_Y0`; ``pumpup.models.microfacet`` asks with its own threshold whether frame 4 declines).  Below
    eta = 1 with k = 0 (a dielectric seen from the denser side) F = 1 up to cos = x0 = sqrt(1 - eta^2), total
    reflection, with a square-root kink there; a small k makes it a near-kink, the branch point sqrt(1 -
    (eta + i k)^2) = x0 - i y0 (:func:`fresnel_branch`) y0 off the axis.  The 1-D path declines such a factor
    (``pumpup.engine.lobe_fresnel.lobe_fresnel_ok``) and the nested engine, blind to the kink, bisected towards it:
    fresnel over Blinn n = 5, eta = 0.551, k = 0 took 0.25-0.41 s per value at rtol 1e-10
    (``scripts/studies/fuzz_engines.py --registry``).
    """
    x0, y0 = fresnel_branch(float(eta), float(k))
    return (x0,) if 0.0 < x0 < 1.0 and y0 < (FRESNEL_LEVEL_Y0 if y0_max is None else y0_max) else ()


@njit(cache=True)
def dielectric_scalar(c, n):  # pragma: no cover - compiled
    """Compiled unpolarised Fresnel reflectance of a dielectric of relative index ``n`` at the cosine ``c`` (002 sec.
    3.2), without cancellation for an index near 1; 1 where no index is given (n <= 0).
    """
    if n <= 0.0:
        return 1.0  # no index of refraction given: F = 1
    n21 = (n - 1.0) * (n + 1.0)
    g = math.sqrt(n21 + c * c)
    a = n21 / ((g + c) * (g + c))  # (g - c) / (g + c) without cancellation (an ior near 1: g ~ c)
    q = (c * (g + c) - 1.0) / (c * n21 / (g + c) + 1.0)
    return 0.5 * a * a * (1.0 + q * q)  # 002 sec. 3.2


def dielectric_reference(c, n):
    """Dielectric Fresnel factor (002 sec. 3.2); 1 when n <= 0 (no index given)."""
    if n <= 0.0:
        return np.ones_like(c)
    n21 = (n - 1.0) * (n + 1.0)
    g = np.sqrt(n21 + c * c)
    a = n21 / ((g + c) * (g + c))  # (g - c) / (g + c), g - c = (n^2 - 1) / (g + c): no cancellation near n = 1
    q = (c * (g + c) - 1.0) / (c * n21 / (g + c) + 1.0)
    return 0.5 * a * a * (1.0 + q * q)  # 002 sec. 3.2


def fresnel_dielectric(cos_theta, ior):
    """Fresnel reflectance of a dielectric for unpolarised light (002 sec. 3.2).

    Parameters
    ----------
    cos_theta : array_like
        Cosine of the angle of incidence on the facet, c = V.H, in [0, 1].
    ior : float or None
        Real index of refraction n > 1; None gives F = 1.

    Returns
    -------
    ndarray
        F = (g - c)^2 / (2 (g + c)^2) [1 + (c (g + c) - 1)^2 / (c (g - c) + 1)^2],
        g = sqrt(n^2 + c^2 - 1); ((n - 1) / (n + 1))^2 at normal incidence.

    Examples
    --------
    >>> round(float(fresnel_dielectric(1.0, 1.5)), 12)
    0.04
    """
    return dielectric_reference(np.asarray(cos_theta, dtype=np.float64), 0.0 if ior is None else float(ior))


def fresnel_branch(eta: float, k: float) -> tuple:
    """(x0, y0): the branch point w = sqrt(1 - (eta + i k)^2) = x0 - i y0 of the conductor Fresnel factor F(c)
    (:func:`pumpup.models.metal._fresnel_real`, where the refracted cosine sqrt((eta + i k)^2 - 1 + c^2) vanishes; F is
    analytic in c elsewhere near [0, 1], its other singularities -w and the conjugates as far), x0 = |Re w|,
    y0 = |Im w|.
    """
    w = complex(1.0 - (eta * eta - k * k), -2.0 * eta * k) ** 0.5
    return abs(w.real), abs(w.imag)


def fresnel_pole(eta: float, k: float) -> float:
    """The scale rho = 1 / |sqrt((eta + i k)^2 + 1)|: F(c)'s parallel reflectance has poles where A c + sin^2 = 0 (A the
    refracted cosine times the index), c^2 = 1 / ((eta + i k)^2 + 1), in the left half-plane on the physical sheet; for
    a strong absorber (|eta + i k| >> 1) near c = 0, at distance ~rho from the arc's small end (eta = 1.1, k = 30:
    -0.0012 + 0.033 i; a rule blind to it was 1.9e-11 off with an estimate of 4.1e-12 at mu = 1e-3, rtol 1e-10, measured
    against the nested and 2-D engines): frame 5 grades its arcs towards c = 0 on this scale.
    """
    return 1.0 / abs(complex(eta * eta - k * k + 1.0, 2.0 * eta * k) ** 0.5)


def fresnel_brewster(eta: float, k: float) -> tuple:
    """(c_b, ok): Brewster's zero c_b of the parallel reflectance's numerator N = A c - (1 - c^2), A =
    sqrt((eta + i k)^2 - 1
    + c^2) continued from the real axis, c_b^2 = 1 / ((eta + i k)^2 + 1) (:func:`_lobe_f_bound`), and whether it was
    found.  On the real axis A is the principal root (Im A^2 = 2 eta k >= 0); from c = Re c_b up to c_b it is the
    principal root, negated where c^2 - w^2 (w^2 = 1 - (eta + i k)^2) crosses the negative real axis on the way
    (Im (c^2 - w^2) = 2 Re(c) Im(c) - Im w^2 = 0).
    """
    e2 = complex(eta * eta - k * k, 2.0 * eta * k)
    cp = 1.0 / cmath.sqrt(e2 + 1.0)
    w2 = 1.0 - e2
    for z in (cp, -cp):
        r, ci = z.real, z.imag
        y = w2.imag / (2.0 * r) if r != 0.0 else math.inf
        flip = (0.0 < y < ci or ci < y < 0.0) and r * r - y * y - w2.real < 0.0
        a = (-1.0 if flip else 1.0) * cmath.sqrt(z * z - w2)
        if abs(a * z - (1.0 - z * z)) <= 1e-9 * (abs(a * z) + abs(1.0 - z * z)):
            return z, True
    return cp, False
