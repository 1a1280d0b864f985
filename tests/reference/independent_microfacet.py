#!/usr/bin/env python
"""Independent directional albedo of Beckmann and GGX microfacet BRDFs with Smith shadowing.

Written from the textbook formulas with math / scipy only; it does NOT import pumpup
(the code these numbers check).  Fresnel factor 1.

f_r = D(h) G(L, V) / (4 (N.L)(N.V))                       Walter et al. 2007, eq. 20
Beckmann D = exp(-tan^2 t_h / a^2) / (pi a^2 cos^4 t_h),  GGX D = a^2 / (pi cos^4 t_h (a^2 + tan^2 t_h)^2)
Smith Lambda(w), with c = 1 / (a tan t_w):
  Beckmann  (erf(c) - 1) / 2 + exp(-c^2) / (2 c sqrt(pi))     (exact)
            1 / G1 - 1 with G1 = (3.535 c + 2.181 c^2) / (1 + 2.276 c + 2.577 c^2), c < 1.6
                                                               (Walter's fit, "walter")
  GGX       (-1 + sqrt(1 + 1 / c^2)) / 2
G = 1 / ((1 + Lambda(L)) (1 + Lambda(V)))  ("separable") or 1 / (1 + Lambda(L) + Lambda(V)) ("correlated").

Coordinates: spherical about N, azimuth measured from the mirror direction.
L = (sin t_i, 0, mu), V = (-sin t cos psi, sin t sin psi, cos t);
a(mu) = 2 int_0^{pi/2} dt int_0^pi dpsi f(L, V) cos t sin t     (even in psi),
nested QUADPACK (scipy.integrate.quad) with break points at geometric multiples of
alpha around the mirror direction.  (L + V)_x is formed without cancellation as
(cos^2 t - mu^2) / (sin t_i + sin t) + 2 sin t sin^2(psi / 2).
"""

from __future__ import annotations

import math

from scipy.integrate import quad

SQRT_PI = math.sqrt(math.pi)


def smith_lambda(dist: str, g1: str, alpha: float, cos_t: float, sin_t: float) -> float:
    """Lambda of a direction with polar cosine cos_t and sine sin_t (both >= 0)."""
    if sin_t == 0.0:
        return 0.0
    c = cos_t / (alpha * sin_t)  # 1 / (alpha tan theta)
    if dist == "ggx":
        return (-1.0 + math.sqrt(1.0 + 1.0 / (c * c))) / 2.0
    if g1 == "walter":
        if c >= 1.6:
            return 0.0
        return (1.0 + 2.276 * c + 2.577 * c * c) / (3.535 * c + 2.181 * c * c) - 1.0
    return (math.erf(c) - 1.0) / 2.0 + math.exp(-c * c) / (2.0 * c * SQRT_PI)


def ndf(dist: str, alpha: float, hz: float, hxy2: float) -> float:
    """D of the half vector with components h_z and h_x^2 + h_y^2 (not normalised)."""
    tan2 = hxy2 / (hz * hz)
    cos2 = hz * hz / (hz * hz + hxy2)
    a2 = alpha * alpha
    if dist == "beckmann":
        return math.exp(-tan2 / a2) / (math.pi * a2 * cos2 * cos2)
    return a2 / (math.pi * cos2 * cos2 * (a2 + tan2) ** 2)


def integrand(dist, g1, shadowing, alpha, mu, sti, theta, psi):
    """f_r(L, V) cos(theta) sin(theta) at V = (theta, psi)."""
    ct, st = math.cos(theta), math.sin(theta)
    if ct <= 0.0:
        return 0.0
    hx = (ct - mu) * (ct + mu) / (sti + st) + 2.0 * st * math.sin(0.5 * psi) ** 2
    hy = st * math.sin(psi)
    hz = mu + ct
    d = ndf(dist, alpha, hz, hx * hx + hy * hy)
    if d == 0.0:
        return 0.0
    lam_l = smith_lambda(dist, g1, alpha, mu, sti)
    lam_v = smith_lambda(dist, g1, alpha, ct, st)
    if shadowing == "separable":
        g = 1.0 / ((1.0 + lam_l) * (1.0 + lam_v))
    else:
        g = 1.0 / (1.0 + lam_l + lam_v)
    return d * g / (4.0 * mu * ct) * ct * st


def albedo(dist: str, alpha: float, mu: float, shadowing: str = "separable", g1: str = "exact",
           rtol: float = 1e-11) -> tuple[float, float]:
    """Directional albedo a(mu) and an error estimate (sum of the quad estimates and rounding).

    Parameters
    ----------
    dist : {"beckmann", "ggx"}
    alpha : float
        Roughness, > 0.
    mu : float
        cos(theta_i), in (0, 1].
    shadowing : {"separable", "correlated"}
    g1 : {"exact", "walter"}
        Beckmann's G1: exact or Walter et al.'s rational fit.
    rtol : float
        Relative tolerance of both nested quadratures.
    """
    sti = math.sqrt((1.0 - mu) * (1.0 + mu))
    theta_m = math.acos(mu) if mu < 0.5 else math.asin(sti)  # the mirror direction's polar angle
    w = min(alpha, 1.0)
    tpts = sorted({min(max(theta_m + s * w * 2.0**j, 0.0), math.pi / 2)
                   for j in range(-4, 4) for s in (-1, 1)} | {theta_m})
    tpts = [p for p in tpts if 0.0 < p < math.pi / 2]
    if g1 == "walter" and dist == "beckmann":  # G1 of V jumps where 1 / (alpha tan t) = 1.6
        tpts = sorted(set(tpts) | {math.atan(1.0 / (1.6 * alpha))})
    errs = []

    def inner(theta):
        st = math.sin(theta)
        ppts = [min(w * 2.0**j / max(st, 1e-300), math.pi) for j in range(-4, 4)]
        ppts = sorted({p for p in ppts if 0.0 < p < math.pi})
        v, e = quad(lambda psi: integrand(dist, g1, shadowing, alpha, mu, sti, theta, psi), 0.0, math.pi,
                    points=ppts, epsabs=0.0, epsrel=rtol, limit=400)
        errs.append(e)
        return v

    v, e = quad(inner, 0.0, math.pi / 2, points=tpts, epsabs=0.0, epsrel=rtol, limit=400)
    return 2.0 * v, 2.0 * (e + max(errs) * math.pi / 2) + 1e-14 * abs(v)


if __name__ == "__main__":
    import time

    for dist in ("beckmann", "ggx"):
        for alpha in (0.05, 0.5):
            for mu in (1.0, 0.3, 1e-4):
                t = time.perf_counter()
                a, e = albedo(dist, alpha, mu)
                dt = time.perf_counter() - t
                print(f"{dist:8s} alpha={alpha:<5g} mu={mu:<6g} a={a:.14f} +- {e:.1e} ({dt:.2f} s)")
