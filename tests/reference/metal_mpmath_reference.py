#!/usr/bin/env python3
"""Independent mpmath reference for the directional albedo of the Neumann et al. (1999)
"metal" BRDF:

  f(L,V) = c * max(R.V,0)^n / max(N.L,N.V) * F(max(N.L,N.V)),  c = (n+2)/(2 pi)
  a(mu)  = int_{H+} f(L,V) (N.V) dw_V,   L = (sqrt(1-mu^2), 0, mu),  N = (0,0,1)

F = exact unpolarised conductor Fresnel reflectance, complex index e = eta + i k.

Method A (lobe frame about R):  V = u R + w (e1 cos b + e2 sin b), w = sqrt(1-u^2),
  e1 = (mu, 0, s) (in the N-R plane), s = sqrt(1-mu^2);  N.V = mu u + s w cos b;  dw = du db.
  For fixed u, N.V decreases in b on [0,pi]:
    b in [0, b1]  : N.V >= mu  -> integrand c u^n F(N.V)                      (inner quad)
    b in [b1, b0] : 0<N.V<mu   -> integrand c u^n N.V F(mu)/mu                 (closed form)
    b in [b0, pi] : N.V <= 0   -> 0
  cos b1 = mu(1-u)/(s w)  (exists iff u >= 2 mu^2 - 1),  cos b0 = -mu u/(s w)  (exists iff u <= s).
  u integrated over [0,1] split at s and 2mu^2-1.

Method B (spherical coordinates about N): t = cos(theta_o), phi_o.
  R.V = mu t - s sqrt(1-t^2) cos(phi).  F depends only on t, so
  a = 2 c int_0^1 t F(max(mu,t))/max(mu,t) G(t) dt,   G(t) = int_{phi0}^{pi} (R.V)^n dphi,
  cos(phi0) = mu t /(s sqrt(1-t^2)) (phi0 = 0 for t >= s).  t split at mu and s.

Usage: python tests/reference/metal_mpmath_reference.py [dps]    (76 s at dps 30, 141 s at 40; both methods agree to
1e-41 at 40)

Written without pumpup: tests/engine/test_route_lobe_fresnel.py holds the 1-D path to
these values.
"""
import sys
import time

from mpmath import acos, cos, mp, mpc, mpf, nstr, pi, quad, sin, sqrt

DPS = int(sys.argv[1]) if len(sys.argv) > 1 else 30
mp.dps = DPS

CASES = [
    # n,      eta,   k,     mu
    ("20", "0.2", "3.0", "0.5"),
    ("20", "0.2", "3.0", "0.05"),
    ("7.5", "0.6", "0.3", "0.3"),
    ("1", "1.1", "30.0", "0.001"),
    ("1", "1.5", "0.0", "0.2"),
]


def fresnel(cosi, e):
    """Exact unpolarised Fresnel reflectance, complex index e, principal sqrt."""
    cosi = mpf(cosi)
    cost = sqrt(1 - (1 - cosi * cosi) / (e * e))
    rpar = (e * cosi - cost) / (e * cosi + cost)
    rperp = (cosi - e * cost) / (cosi + e * cost)
    return (abs(rpar) ** 2 + abs(rperp) ** 2) / 2


def clamp1(x):
    return mpf(1) if x > 1 else (mpf(-1) if x < -1 else x)


def albedo_lobe(n, e, mu):
    """Method A."""
    c = (n + 2) / (2 * pi)
    s = sqrt(1 - mu * mu)
    Fmu = fresnel(mu, e)
    if s == 0:  # mu = 1: N.V = u <= mu everywhere -> 2 pi c F(1) int u^(n+1) du = F(1)
        return 2 * pi * c * Fmu * quad(lambda u: u ** (n + 1), [0, 1])

    def inner(u):
        if u <= 0:
            return mpf(0)
        w = sqrt(1 - u * u)
        if w == 0:  # u = 1: V = R, N.V = mu
            return 2 * pi * Fmu * u ** n
        # b1: N.V = mu ; b0: N.V = 0
        cb1 = mu * (1 - u) / (s * w)
        cb0 = -mu * u / (s * w)
        b1 = acos(cb1) if cb1 <= 1 else mpf(0)
        b0 = acos(cb0) if cb0 >= -1 else pi
        # region N.V >= mu
        if b1 > 0:
            I1 = quad(lambda b: fresnel(mu * u + s * w * cos(b), e), [0, b1])
        else:
            I1 = mpf(0)
        # region 0 < N.V < mu : int (mu u + s w cos b) db * F(mu)/mu
        I2 = (mu * u * (b0 - b1) + s * w * (sin(b0) - sin(b1))) * Fmu / mu
        return 2 * u ** n * (I1 + I2)

    pts = {mpf(0), mpf(1), s}
    u1 = 2 * mu * mu - 1
    if u1 > 0:
        pts.add(u1)
    pts = sorted(p for p in pts if 0 <= p <= 1)
    return c * quad(inner, pts)


def albedo_sph(n, e, mu):
    """Method B."""
    c = (n + 2) / (2 * pi)
    s = sqrt(1 - mu * mu)
    Fmu = fresnel(mu, e)

    def G(t):
        r = sqrt(1 - t * t)
        if s * r == 0:
            return pi * (mu * t) ** n
        x = mu * t / (s * r)
        phi0 = acos(x) if x < 1 else mpf(0)

        def g(phi):
            v = mu * t - s * r * cos(phi)
            return v ** n if v > 0 else mpf(0)
        return quad(g, [phi0, pi])

    def outer(t):
        if t <= 0:
            return mpf(0)
        if t < mu:
            w = t * Fmu / mu
        else:
            w = fresnel(t, e)
        return w * G(t)

    pts = sorted({mpf(0), mpf(1), mu, s})
    return 2 * c * quad(outer, pts)


def main():
    print("mp.dps =", mp.dps)
    # sanity check at mu = 1 with case-1 material
    e = mpc(mpf("0.2"), mpf("3.0"))
    for n in (mpf(20), mpf("7.5"), mpf(1)):
        a1 = albedo_lobe(n, e, mpf(1))
        print(f"mu=1, n={nstr(n, 4)}: a(1)={nstr(a1, 25)}  F(1)={nstr(fresnel(1, e), 25)}  "
              f"diff={nstr(a1 - fresnel(1, e), 3)}")
    # also method B near mu=1
    a1b = albedo_sph(mpf(20), e, mpf(1))
    print(f"mu=1 method B n=20: {nstr(a1b, 25)}  diff={nstr(a1b - fresnel(1, e), 3)}")

    rows = []
    for i, (ns, es, ks, mus) in enumerate(CASES, 1):
        n, eta, k, mu = mpf(ns), mpf(es), mpf(ks), mpf(mus)
        e = mpc(eta, k)
        t0 = time.time()
        aA = albedo_lobe(n, e, mu)
        tA = time.time() - t0
        t0 = time.time()
        aB = albedo_sph(n, e, mu)
        tB = time.time() - t0
        d = aA - aB
        rows.append((i, ns, es, ks, mus, aA, aB, d, tA, tB))
        print(f"case {i:d} n={ns} eta={es} k={ks} mu={mus}")
        print(f"   A (lobe) = {nstr(aA, DPS - 2)}   [{tA:.1f}s]")
        print(f"   B (sph)  = {nstr(aB, DPS - 2)}   [{tB:.1f}s]")
        print(f"   A - B    = {nstr(d, 3)}")
        sys.stdout.flush()


if __name__ == "__main__":
    main()
