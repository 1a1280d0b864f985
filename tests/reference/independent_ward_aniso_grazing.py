#!/usr/bin/env python
"""Independent long-double reference albedos of anisotropic Ward at grazing incidence.

Written from the BRDF's definition only, without reading or importing pumpup, for the case where the slope path
(pumpup.engine.slope) and the nested and 2-D engines disagree by 2e-12 at ax = 0.002, ay = 0.006, mu = 1e-8,
phi = pi/4 + 0.1.  Two methods in 80-bit long double, composite Gauss-Legendre with Newton-refined nodes:

1. the half vector's slopes m, rotated so t is along (cos phi, sin phi): wo_z = mu (t - t0)(t1 - t) / (1 + |m|^2) with
   the roots computed without cancellation, t = t0 + r^2 for the horizon's square root;
2. the outgoing direction in spherical coordinates about the mirror azimuth, h_x and h_y formed without cancellation,
   alpha = h_z beta and e = v^2.

They agree to < 1e-19 relative; grids 24x24 ... 48x48 panels and larger domains moved them by <= 1e-18.  Results (phi
exactly pi/4 + 0.1; with phi the double 0.8853981633974483 the values are 5e-17 relative lower):
mu = 1e-8: 1.20781491078982252; mu = 1e-4: 0.012506657640590035 (tests/engine/test_slope.py).

Run: ``python tests/reference/independent_ward_aniso_grazing.py`` (a few minutes).
"""
import numpy as np

L = np.longdouble
ax, ay = L(2)/1000, L(6)/1000
PI = L('3.14159265358979323846264338327950288')
phi = PI/4 + L(1)/10
c, sn = np.cos(phi), np.sin(phi)

def leggauss_ld(n):
    x0, _ = np.polynomial.legendre.leggauss(n)
    x = x0.astype(L)
    for it in range(5):
        p0 = np.ones_like(x)
        p1 = x.copy()
        for k in range(2, n+1):
            p0, p1 = p1, ((2*k-1)*x*p1 - (k-1)*p0)/k
        dp = n*(x*p1 - p0)/(x*x-1)
        x = x - p1/dp
    p0 = np.ones_like(x)
    p1 = x.copy()
    for k in range(2, n+1):
        p0, p1 = p1, ((2*k-1)*x*p1 - (k-1)*p0)/k
    dp = n*(x*p1 - p0)/(x*x-1)
    w = 2/((1-x*x)*dp*dp)
    return x, w

def glpanels(a, b, npan, n):
    x, w = leggauss_ld(n)
    a, b = L(a), L(b)
    X = []
    W = []
    for i in range(npan):
        lo = a + (b-a)*i/npan
        hi = a + (b-a)*(i+1)/npan
        X.append((hi-lo)/2*x + (hi+lo)/2)
        W.append((hi-lo)/2*w)
    return np.concatenate(X), np.concatenate(W)

def method1(mu, U=0.06, T=0.06, npu=32, npr=32, n=20):
    mu = L(mu)
    s = np.sqrt(1-mu*mu)
    u, wu = glpanels(-U, U, npu, n)
    S = np.sqrt(s*s + mu*mu*(1-u*u))
    t0 = -mu*(1-u*u)/(s+S)
    t1 = (s+S)/mu
    c0 = mu*(S + s*u*u)/(s+S)
    rr, wr = glpanels(0, 1, npr, n)
    U_, RR = np.meshgrid(u, rr, indexing='ij')
    R = np.sqrt(L(T) - t0)[:,None]
    r = RR*R
    w = wr[None,:]*R
    t = t0[:,None] + r*r
    mx = t*c - U_*sn
    my = t*sn + U_*c
    m2 = t*t + U_*U_
    Q = (mx/ax)**2 + (my/ay)**2
    g = r*r*np.sqrt(t1[:,None]-t)*(s*r*r + c0[:,None])*(1+m2)**L(-2.5)*np.exp(-Q)
    return 2/(PI*ax*ay)*np.sum(wu*np.sum(w*g, axis=1))

def method2(mu, E=0.2, B=0.1, npv=32, npb=32, n=20):
    mu = L(mu)
    s = np.sqrt(1-mu*mu)
    v, wv = glpanels(0, np.sqrt(E), npv, n)
    b, wb = glpanels(-B, B, npb, n)
    V, Bt = np.meshgrid(v, b, indexing='ij')
    e = V*V
    se, ce = np.sin(e), np.cos(e)
    hz = se + mu
    al = hz*Bt
    d = (se-mu)*(se+mu)/(s+ce)
    sa = np.sin(al/2)
    hx = d*c + ce*2*np.sin(phi+al/2)*sa
    hy = d*sn - ce*2*np.cos(phi+al/2)*sa
    Q = (hx/hz/ax)**2 + (hy/hz/ay)**2
    sq = V*np.sqrt(np.where(e>0, se/np.where(e>0,e,1), 1)/mu)
    g = np.exp(-Q)*sq*ce*hz*2*V
    return np.sum(wv*np.sum(wb[None,:]*g, axis=1))/(4*PI*ax*ay)

if __name__ == '__main__':
    for mu in ['1e-4','1e-8']:
        m = L(mu)
        for k in [(24,24,20),(32,32,24),(48,48,28)]:
            a1 = method1(m, npu=k[0], npr=k[1], n=k[2])
            a2 = method2(m, npv=k[0], npb=k[1], n=k[2])
            print(mu, k, np.format_float_scientific(a1, precision=19), np.format_float_scientific(a2, precision=19),
                  float((a1-a2)/a1))
        for E,B,U,T in [(0.3,0.15,0.08,0.08)]:
            a1 = method1(m,U=U,T=T,npu=48,npr=48,n=28)
            a2=method2(m,E=E,B=B,npv=48,npb=48,n=28)
            print(' trunc', np.format_float_scientific(a1, precision=19), np.format_float_scientific(a2, precision=19))
