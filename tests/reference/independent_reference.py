#!/usr/bin/env python
"""Independent high-accuracy reference values for BRDF directional / mean albedos.

Written from scratch with numpy / scipy / numba / mpmath only; it does NOT import
or read the ``pumpup`` package (the code these numbers are meant to check).

Conventions
-----------
N = (0, 0, 1);  L = (sqrt(1 - mu^2), 0, mu);  V over the upper hemisphere.
a(mu) = int_{H^2} f_r(L, V) cos(theta_V) d omega_V,  mean albedo = 2 int_0^1 a(mu) mu dmu.
R = 2 (N.L) N - L,  H = (L + V) / |L + V|.

Coordinates (spherical about N, NOT about the lobe)
---------------------------------------------------
V = (-s cos(psi), s sin(psi), t),   t = cos(theta_V), s = sin(theta_V), psi = pi - phi_V.
The mirror direction R sits at psi = 0, t = mu.  Everything is symmetric in psi -> -psi,
so a(mu) = 2 int_0^1 dt int_0^pi dpsi  f(L, V) t      (cos(theta) d omega = dt dphi).

Three independent evaluations of every directional albedo (nested QUADPACK,
scipy.integrate.quad, integrand compiled with numba and passed as LowLevelCallable):

  A  outer t = cos(theta_V), inner psi; break points at the analytic kinks and at
     geometric multiples of the lobe width around the mirror direction.
  B  outer theta_V (not t), inner psi; break points at different multiples.
  C  swapped order: outer psi, inner t; kinks in t located analytically or by
     root bracketing + brentq.

The reported value is A, abs_err_estimate = max(|A-B|, |A-C|, quad error estimates
of A, 1e-15*max(1,|A|)).  For the Phong family an extra, fully different check is
done: the azimuthal integral about the reflection direction R has a closed form
(J below) so a(mu) becomes a 1-D integral, evaluated with mpmath tanh-sinh at 30 digits.

Care is taken near grazing incidence: the horizontal components of L + V are formed
without cancellation: (L+V)_x = (t^2 - mu^2)/(sin(theta_i) + s) + 2 s sin^2(psi/2).
"""
import json
import math
import multiprocessing as mp
import os
import sys
import time

import mpmath
import numba as nb
import numpy as np
from numba import cfunc, types
from scipy import LowLevelCallable
from scipy.integrate import quad
from scipy.optimize import brentq

PHONG, SPHONG, BLINN, SBLINN, WARD, MWARD, CT = range(7)
MODEL_ID = {"phong": PHONG, "stretched_phong": SPHONG, "blinn": BLINN,
            "stretched_blinn": SBLINN, "ward": WARD, "modified_ward": MWARD,
            "cook_torrance": CT}
HALFVEC = (BLINN, SBLINN, WARD, MWARD, CT)


# --------------------------------------------------------------------------- integrand
@nb.njit(cache=False, fastmath=False)
def f_cos(model, p, mu, sti, t, psi):
    """f_r(L, V) * cos(theta_V) for V = (-s cos psi, s sin psi, t)."""
    if t <= 0.0:
        return 0.0
    s = math.sqrt((1.0 - t) * (1.0 + t))
    if model <= 1:  # Phong family: R = (-sti, 0, mu)
        rv = sti * s * math.cos(psi) + mu * t
        if rv <= 0.0:
            return 0.0
        val = (p + 2.0) / (2.0 * math.pi) * rv ** p * t
        if model == 1:
            val /= max(mu, t)
        return val
    den = sti + s
    hx = 2.0 * s * math.sin(0.5 * psi) ** 2
    if den > 0.0:
        hx += (t - mu) * (t + mu) / den
    hy = s * math.sin(psi)
    hz = mu + t
    h2 = hx * hx + hy * hy
    if model <= 3:  # Blinn family
        nh = hz / math.sqrt(h2 + hz * hz)
        val = nh ** p * t
        if model == 3:
            val /= max(mu, t)
        return val
    m2 = p * p
    tan2 = h2 / (hz * hz)
    if tan2 > 740.0 * m2:
        return 0.0
    D = math.exp(-tan2 / m2) / (4.0 * math.pi * m2)
    if model == 4:
        return D * math.sqrt(t / mu)
    if model == 5:
        return D * t / max(mu, t)
    # Cook-Torrance, Fresnel = 1.  N.H = hz/|L+V|, V.H = L.H = |L+V|/2
    ll2 = h2 + hz * hz
    G = min(1.0, 4.0 * hz * t / ll2, 4.0 * hz * mu / ll2)
    return D * (1.0 + tan2) ** 2 * G / mu


sig = types.double(types.intc, types.CPointer(types.double))


@cfunc(sig)
def _c_inner_psi(n, xx):  # xx = psi, model, p, mu, sti, t
    return f_cos(int(xx[1]), xx[2], xx[3], xx[4], xx[5], xx[0])


@cfunc(sig)
def _c_inner_t(n, xx):  # xx = t, model, p, mu, sti, psi
    return f_cos(int(xx[1]), xx[2], xx[3], xx[4], xx[0], xx[5])


@cfunc(sig)
def _c_inner_psi_theta(n, xx):  # xx = psi, model, p, mu, sti, theta  (t = cos theta)
    return f_cos(int(xx[1]), xx[2], xx[3], xx[4], math.cos(xx[5]), xx[0])


LLC_PSI = LowLevelCallable(_c_inner_psi.ctypes)
LLC_T = LowLevelCallable(_c_inner_t.ctypes)
LLC_PSI_TH = LowLevelCallable(_c_inner_psi_theta.ctypes)


# --------------------------------------------------------------------------- helpers
def sin_theta_i(mu):
    return math.sqrt((1.0 - mu) * (1.0 + mu))


def lobe_m(model, p):
    """Effective Beckmann-like width of the half-vector lobe."""
    if model in (BLINN, SBLINN):
        return math.sqrt(2.0 / p)
    return p


def uniq_in(pts, a, b, rel=1e-13):
    out = []
    for x in sorted(pts):
        if a + rel * (b - a) < x < b - rel * (b - a):
            if not out or x - out[-1] > rel * (b - a):
                out.append(x)
    return out


def quad_pieces(func, a, b, pts, args, epsabs, epsrel, limit=400):
    """Integrate over [a,b] split at pts (each piece by QAGS); returns (val, err)."""
    edges = [a] + uniq_in(pts, a, b) + [b]
    tot = 0.0
    err = 0.0
    for lo, hi in zip(edges[:-1], edges[1:]):
        v, e = quad(func, lo, hi, args=args, epsabs=epsabs, epsrel=epsrel, limit=limit)
        tot += v
        err += e
    return tot, err


def roots_on(fun, a, b, n=400, extra=()):
    """All sign changes of fun on [a,b] (grid + brentq)."""
    xs = np.unique(np.concatenate([np.linspace(a, b, n), np.asarray(extra, float)]))
    xs = xs[(xs >= a) & (xs <= b)]
    ys = np.array([fun(x) for x in xs])
    r = []
    for i in range(len(xs) - 1):
        if ys[i] == 0.0:
            r.append(xs[i])
        elif ys[i] * ys[i + 1] < 0.0:
            r.append(brentq(fun, xs[i], xs[i + 1], xtol=1e-16, rtol=1e-15))
    return r


def geom_near(c, w, scales, lo, hi):
    pts = [c]
    for k in scales:
        pts += [c - k * w, c + k * w]
    return [x for x in pts if lo < x < hi]


# --------------------------------------------------------------------------- kinks
def ct_kink_cos(mu, t, which):
    """cos(psi) on the Cook-Torrance G kink curves at given t (see docstring of CT)."""
    # 2 (N.H)(N.V) = V.H  <=>  L.V = 2 t (mu + t) - 1 ;  L.V = mu t - sti s cos psi
    sti = sin_theta_i(mu)
    s = math.sqrt((1 - t) * (1 + t))
    if sti * s == 0:
        return None
    if which == 1:
        return (1.0 - mu * t - 2.0 * t * t) / (sti * s)
    return (1.0 - 2.0 * mu * mu - mu * t) / (sti * s)


def psi_points(model, p, mu, t, scales):
    """Break points for the inner psi integral at fixed t; returns (psi_max, points)."""
    sti = sin_theta_i(mu)
    s = math.sqrt((1 - t) * (1 + t))
    psimax = math.pi
    pts = []
    if model in (PHONG, SPHONG):
        if sti * s > 0:
            x = -mu * t / (sti * s)
            if x > -1.0:
                psimax = math.acos(min(1.0, x))
            w = 1.0 / math.sqrt(p * sti * s)
            pts += [k * w for k in scales]
    else:
        m = lobe_m(model, p)
        if s > 0:
            w = m * (mu + t) / s
            pts += [k * w for k in scales]
        if model == CT:
            for which in (1, 2):
                c = ct_kink_cos(mu, t, which)
                if c is not None and -1.0 < c < 1.0:
                    pts.append(math.acos(c))
    return psimax, uniq_in(pts, 0.0, psimax)


def t_points(model, p, mu, scales):
    """Break points for an outer integral over t = cos(theta_V)."""
    sti = sin_theta_i(mu)
    pts = [mu]
    if model in (PHONG, SPHONG):
        pts.append(sti)  # psi_max(t) starts to move here (R.V = 0 curve leaves psi = pi)
        w = 1.0 / math.sqrt(p)
    else:
        w = lobe_m(model, p) * (sti + math.sqrt((1 - mu) * (1 + mu))) / 2 + 1e-300
        w = max(w, 1e-300)
    pts += geom_near(mu, w, scales, 0.0, 1.0)
    # grazing incidence: structure on the scale of mu near t = 0
    if mu < 0.2:
        pts += [mu * k for k in (0.25, 0.5, 2, 4, 10, 30, 100, 300, 1e3, 1e4, 1e5) if mu * k < 1]
        if model in HALFVEC:
            m = lobe_m(model, p)
            pts += [m * k for k in (0.5, 1, 2, 3, 4) if m * k < 1]
    if model == CT and 0 < mu < 1:
        # the G kink curves appear / disappear where |cos psi_kink(t)| = 1
        for which in (1, 2):
            for sgn in (1.0, -1.0):
                def g(t, which=which, sgn=sgn):
                    s = math.sqrt((1 - t) * (1 + t))
                    num = (1.0 - mu * t - 2.0 * t * t) if which == 1 else (1.0 - 2 * mu * mu - mu * t)
                    return num - sgn * sti * s
                pts += roots_on(g, 0.0, 1.0, n=800, extra=[mu])
    return uniq_in(pts, 0.0, 1.0)


# --------------------------------------------------------------------------- methods
IN_TOL = dict(epsabs=1e-17, epsrel=1e-14)
OUT_TOL = dict(epsabs=1e-16, epsrel=1e-13)

SC_A = (0.5, 1, 2, 4, 8, 16)
SC_B = (0.37, 0.8, 1.7, 3.3, 6.5, 13)


def inner_psi(t, model, p, mu, sti, scales, errs):
    psimax, pts = psi_points(model, p, mu, t, scales)
    v, e = quad_pieces(LLC_PSI, 0.0, psimax, pts, (float(model), p, mu, sti, t), **IN_TOL)
    errs[0] += e
    return v


def albedo_A(model, p, mu):
    sti = sin_theta_i(mu)
    errs = [0.0]
    pts = t_points(model, p, mu, SC_A)
    v, e = quad_pieces(lambda t: inner_psi(t, model, p, mu, sti, SC_A, errs), 0.0, 1.0, pts,
                       (), **OUT_TOL)
    return 2.0 * v, 2.0 * e


def albedo_B(model, p, mu):
    """outer over theta_V with different split points"""
    sti = sin_theta_i(mu)
    tp = t_points(model, p, mu, SC_B)
    thp = [math.acos(x) for x in tp]

    def outer(th):
        t = math.cos(th)
        psimax, pts = psi_points(model, p, mu, t, SC_B)
        v, e = quad_pieces(LLC_PSI, 0.0, psimax, pts, (float(model), p, mu, sti, t), **IN_TOL)
        return v * math.sin(th)

    v, e = quad_pieces(outer, 0.0, math.pi / 2, thp, (), **OUT_TOL)
    return 2.0 * v, 2.0 * e


def t_inner_points(model, p, mu, psi):
    sti = sin_theta_i(mu)
    pts = [mu]
    lo = 0.0
    c = math.cos(psi)
    if model in (PHONG, SPHONG):
        if c < 0 and sti > 0:
            k = sti * (-c) / mu
            lo = k / math.sqrt(1 + k * k)  # R.V > 0 only for t > lo
        w = 1.0 / math.sqrt(p)
    else:
        w = lobe_m(model, p)
    pts += geom_near(mu, w, (0.5, 1, 2, 4, 8), 0.0, 1.0)
    if mu < 0.2:
        pts += [mu * k for k in (0.5, 2, 5, 20, 100, 1e3, 1e4) if mu * k < 1]
    if model in HALFVEC and mu < 1:
        # t where the psi-lobe edge passes: s sin psi ~ m (mu + t)
        m = lobe_m(model, p)
        pts += [x for x in (math.sin(psi) / m - mu, 0.5 * math.sin(psi) / m - mu) if 0 < x < 1]
    if model == CT and sti > 0:
        def g1(t):
            s = math.sqrt((1 - t) * (1 + t))
            return (1.0 - mu * t - 2.0 * t * t) - sti * s * c

        def g2(t):
            s = math.sqrt((1 - t) * (1 + t))
            return (1.0 - 2 * mu * mu - mu * t) - sti * s * c
        ex = [mu] + [mu * k for k in (0.5, 2, 10)]
        pts += roots_on(g1, 0.0, 1.0, n=300, extra=ex) + roots_on(g2, 0.0, 1.0, n=300, extra=ex)
    return lo, uniq_in(pts, lo, 1.0)


def albedo_C(model, p, mu):
    """swapped order: outer psi, inner t"""
    sti = sin_theta_i(mu)

    def outer(psi):
        lo, pts = t_inner_points(model, p, mu, psi)
        v, e = quad_pieces(LLC_T, lo, 1.0, pts, (float(model), p, mu, sti, psi), **IN_TOL)
        return v

    if model in (PHONG, SPHONG):
        pts = [k / math.sqrt(p) for k in (0.5, 1, 2, 4, 8)] + [math.pi / 2]
        # beyond pi/2 the lower limit t_lo(psi) sweeps 0 -> 1 on the scale of mu
        pts += [math.pi / 2 + mu * k for k in (0.3, 1, 3, 10, 30, 100, 300, 1e3, 1e4, 1e5)]
    else:
        m = lobe_m(model, p)
        pts = [m * k for k in (0.25, 0.5, 1, 2, 4, 8)] + [math.pi / 2]
        if mu < 0.2:
            pts += [m * mu * k for k in (0.3, 1, 3, 10, 30, 100, 300, 1e3, 1e4, 1e5)]
        if model == CT and sti > 0:
            # extreme psi of the G kink curves -> kinks of the outer integrand
            for which in (1, 2):
                def negpsi(t, which=which):
                    c = ct_kink_cos(mu, t, which)
                    return c
                ts = np.linspace(1e-9, 1 - 1e-9, 4001)
                cs = np.array([negpsi(x) for x in ts])
                ok = np.abs(cs) <= 1
                if ok.any():
                    pts += [math.acos(cs[ok].min()), math.acos(cs[ok].max())]
    v, e = quad_pieces(outer, 0.0, math.pi, pts, (), **OUT_TOL)
    return 2.0 * v, 2.0 * e


# ------------------------------------------- Phong family: 1-D lobe-frame cross-check
def _J(a, b):
    """int_0^{2 pi} (a + b cos alpha)_+ d alpha, b >= 0 (mpmath)."""
    if a >= b:
        return 2 * mpmath.pi * a
    if a <= -b:
        return mpmath.mpf(0)
    al = mpmath.acos(-a / b)
    return 2 * (a * al + b * mpmath.sin(al))


def phong_1d(model, n, mu, dps=30):
    """a(mu) = c int_0^1 x^n K(x) dx, x = cos(angle(R, V)); K = closed-form azimuthal
    integral about R of V_z (Phong) or of V_z / max(mu, V_z) (stretched Phong)."""
    with mpmath.workdps(dps):
        mu = mpmath.mpf(mu)
        sti = mpmath.sqrt((1 - mu) * (1 + mu))
        c = (n + 2) / (2 * mpmath.pi)

        def K(x):
            a = x * mu
            b = mpmath.sqrt((1 - x) * (1 + x)) * sti
            if model == PHONG:
                return _J(a, b)
            return (_J(a, b) - _J(a - mu, b)) / mu

        pts = [mpmath.mpf(0)]
        for x in (sti, 2 * mu * mu - 1):
            if 0 < x < 1:
                pts.append(x)
        pts.append(mpmath.mpf(1))
        pts = sorted(set(pts))
        v, e = mpmath.quad(lambda x: x ** n * K(x), pts, error=True)
        return float(c * v), float(abs(c * e))


def phong_1d_float(model, n, mu):
    """double-precision version of phong_1d for the mean-albedo outer integral."""
    sti = sin_theta_i(mu)
    c = (n + 2) / (2 * math.pi)

    def J(a, b):
        if a >= b:
            return 2 * math.pi * a
        if a <= -b:
            return 0.0
        al = math.acos(-a / b)
        return 2 * (a * al + b * math.sin(al))

    def K(x):
        a = x * mu
        b = math.sqrt((1 - x) * (1 + x)) * sti
        if model == PHONG:
            return J(a, b)
        return (J(a, b) - J(a - mu, b)) / mu

    pts = [x for x in (sti, 2 * mu * mu - 1) if 0 < x < 1]
    v, e = quad_pieces(lambda x: x ** n * K(x), 0.0, 1.0, pts, (), epsabs=1e-15, epsrel=1e-13)
    return c * v


# --------------------------------------------------- integrand self-test (mpmath, vectors)
def f_cos_direct(model, p, mu, t, psi, dps=40):
    """f_r * cos(theta_V) straight from the vector definitions, in mpmath."""
    with mpmath.workdps(dps):
        mu, t, psi = mpmath.mpf(mu), mpmath.mpf(t), mpmath.mpf(psi)
        s = mpmath.sqrt(1 - t * t)
        sti = mpmath.sqrt(1 - mu * mu)
        L = mpmath.matrix([sti, 0, mu])
        V = mpmath.matrix([-s * mpmath.cos(psi), s * mpmath.sin(psi), t])
        NL, NV = L[2], V[2]

        def dot(a, b):
            return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]

        if model in (PHONG, SPHONG):
            R = mpmath.matrix([-L[0], -L[1], 2 * NL - L[2]])
            RV = dot(R, V)
            f = (p + 2) / (2 * mpmath.pi) * (RV ** p if RV > 0 else 0)
            if model == SPHONG:
                f /= max(NL, NV)
            return f * NV
        Hs = L + V
        H = Hs / mpmath.sqrt(dot(Hs, Hs))
        NH, VH = H[2], dot(V, H)
        if model in (BLINN, SBLINN):
            f = NH ** p
            if model == SBLINN:
                f /= max(NL, NV)
            return f * NV
        d = mpmath.acos(NH)
        D = mpmath.exp(-mpmath.tan(d) ** 2 / p ** 2)
        if model == WARD:
            f = D / (4 * mpmath.pi * p ** 2 * mpmath.sqrt(NL * NV))
        elif model == MWARD:
            f = D / (4 * mpmath.pi * p ** 2 * max(NL, NV))
        else:
            G = min(1, 2 * NH * NV / VH, 2 * NH * NL / VH)
            f = D / (4 * mpmath.pi * p ** 2 * mpmath.cos(d) ** 4) * G / (NL * NV)
        return f * NV


def integrand_selftest(npts=300, seed=12345):
    rng = np.random.default_rng(seed)
    cases = [(PHONG, 1), (PHONG, 100), (SPHONG, 8), (BLINN, 128), (SBLINN, 8), (WARD, 0.1),
             (MWARD, 0.4), (CT, 0.1), (CT, 0.4)]
    mus = [1.0, 0.9, 0.5, 0.1, 1e-3, 8.726646259902554e-06, 1e-6]
    worst = {}
    for model, p in cases:
        w = 0.0
        for _ in range(npts):
            mu = mus[rng.integers(len(mus))]
            r = rng.random()
            if r < 0.4:   # near the mirror direction
                t = min(1.0, max(1e-12, mu * (1 + 10 ** rng.uniform(-6, 0) * rng.choice([-1, 1]))))
                psi = 10 ** rng.uniform(-8, 0)
            elif r < 0.6:  # near grazing
                t = 10 ** rng.uniform(-9, -1)
                psi = math.pi * rng.random()
            else:
                t = rng.random()
                psi = math.pi * rng.random()
            ref = f_cos_direct(model, p, mu, t, psi)
            val = f_cos(model, float(p), mu, sin_theta_i(mu), t, psi)
            if ref > mpmath.mpf("1e-250"):
                w = max(w, float(abs((val - ref) / ref)))
            else:
                w = max(w, abs(val) / 1e-250 * 1e-300)
        worst[f"{[k for k, v in MODEL_ID.items() if v == model][0]}(p={p})"] = w
    return worst


# ----------------------------------------------------------- mu = 1: 1-D / closed forms
def normal_incidence_1d(model, p, dps=30):
    """a(1) from the azimuthally symmetric 1-D integral (t = cos theta_V, L = N)."""
    with mpmath.workdps(dps):
        p = mpmath.mpf(p)
        if model in (PHONG, SPHONG):
            return mpmath.mpf(1)
        if model in (BLINN, SBLINN):  # closed form (the max is 1 at mu = 1)
            def F(u):
                return 2 * u ** (p + 4) / (p + 4) - u ** (p + 2) / (p + 2)
            return 8 * mpmath.pi * (F(mpmath.mpf(1)) - F(1 / mpmath.sqrt(2)))
        m2 = p * p

        def E(t):
            return mpmath.exp(-(1 - t) / ((1 + t) * m2)) / (4 * mpmath.pi * m2)
        if model == WARD:
            def g(t):
                return E(t) * mpmath.sqrt(t)
        elif model == MWARD:
            def g(t):
                return E(t) * t
        else:  # cos^4(d) = ((1+t)/2)^2, G = min(1, 2t)
            def g(t):
                return E(t) * (2 / (1 + t)) ** 2 * min(1, 2 * t)
        return 2 * mpmath.pi * mpmath.quad(g, [0, mpmath.mpf(1) / 2, 1])


def blinn_closed_form_normal(n, dps=30):
    with mpmath.workdps(dps):
        def F(u):
            return 2 * u ** (n + 4) / (n + 4) - u ** (n + 2) / (n + 2)
        return float(8 * mpmath.pi * (F(mpmath.mpf(1)) - F(1 / mpmath.sqrt(2))))


# ------------------------------------------------------------------------- task runners
def directional_task(task):
    name, p, mu = task["model"], task["p"], task["mu"]
    model = MODEL_ID[name]
    t0 = time.time()
    A, eA = albedo_A(model, p, mu)
    B, eB = albedo_B(model, p, mu)
    C, eC = albedo_C(model, p, mu)
    checks = {"A_outer_t_inner_psi": A, "A_quad_err": eA,
              "B_outer_theta_inner_psi_other_splits": B, "B_quad_err": eB,
              "C_outer_psi_inner_t": C, "C_quad_err": eC}
    diffs = [abs(A - B), abs(A - C)]
    if model in (PHONG, SPHONG):
        v1, e1 = phong_1d(model, p, mu)
        checks["phong_1d_lobe_azimuth_closed_form_mpmath30"] = v1
        diffs.append(abs(A - v1))
    if mu == 1.0:
        ex = float(normal_incidence_1d(model, p))
        checks["normal_incidence_1d_mpmath30"] = ex
        diffs.append(abs(A - ex))
    err = max(max(diffs), eA, 1e-15 * abs(A))
    out = dict(task)
    out.update(value=A, abs_err_estimate=float("%.2g" % (err * 1.0000001)), cross_checks=checks,
               seconds=round(time.time() - t0, 3))
    return out


def mean_albedo_task(task):
    name, n = task["model"], task["p"]
    model = MODEL_ID[name]
    t0 = time.time()
    pts = [1e-4, 1e-3, 1e-2, 0.1, 0.5, 1 / math.sqrt(2)]
    # M1: outer quad in mu, inner a(mu) by method A (spherical coords about N)
    MA, eMA = quad_pieces(lambda mu: 2 * mu * albedo_A(model, n, mu)[0], 0.0, 1.0, pts, (),
                          epsabs=1e-14, epsrel=1e-12, limit=200)
    # M2: outer quad in mu, inner 1-D lobe-azimuth formula in double precision
    MB, eMB = quad_pieces(lambda mu: 2 * mu * phong_1d_float(model, n, mu), 0.0, 1.0, pts, (),
                          epsabs=1e-15, epsrel=1e-13, limit=200)
    # M3: mpmath tanh-sinh outer, mpmath inner (20 digits)
    with mpmath.workdps(20):
        MC = float(mpmath.quad(lambda mu: 2 * mu * mpmath.mpf(phong_1d(model, n, float(mu), dps=20)[0]),
                               [0] + pts + [1]))
    err = max(abs(MA - MB), abs(MA - MC), eMA, 1e-15)
    out = dict(task)
    out.update(value=MA, abs_err_estimate=float("%.2g" % (err * 1.0000001)),
               cross_checks={"M1_quad_mu_of_method_A": MA, "M1_quad_err": eMA,
                             "M2_quad_mu_of_phong_1d_double": MB, "M2_quad_err": eMB,
                             "M3_mpmath_mu_of_phong_1d_mpmath": MC},
               seconds=round(time.time() - t0, 3))
    return out


def run_task(task):
    import warnings
    warnings.simplefilter("ignore")
    if task["quantity"] == "mean_albedo":
        return mean_albedo_task(task)
    return directional_task(task)


def param_dict(model, p):
    if model in ("ward", "modified_ward", "cook_torrance"):
        return {"m": p}
    d = {"n": p}
    if model in ("phong", "stretched_phong"):
        d["c"] = (p + 2) / (2 * math.pi)
    else:
        d["c"] = 1.0
    return d


def build_tasks():
    tasks = []

    def add(item, model, p, mu, method, **extra):
        t = dict(item=item, quantity="directional_albedo", model=model, p=p,
                 params=param_dict(model, p), mu=mu, method=method)
        t.update(extra)
        tasks.append(t)

    M2D = ("2-D nested scipy.integrate.quad in spherical coords about N (outer t=cos theta_V, "
           "inner psi=pi-phi_V), eps 1e-14 inner / 1e-13 outer, splits at analytic kinks and "
           "around the mirror direction; err from methods B (outer theta, other splits) and "
           "C (swapped order) and QUADPACK estimates")
    MPH = M2D + "; plus 1-D mpmath check with closed-form azimuth about R"
    for model in ("phong", "stretched_phong"):
        for n in (1, 8, 100):
            for mu in (1.0, 0.9, 0.5, 0.2, 0.05, 1e-3):
                add(1, model, n, mu, MPH)
    for model in ("blinn", "stretched_blinn"):
        for n in (1, 8, 128):
            for mu in (1.0, 0.5, 0.05):
                add(2, model, n, mu, M2D + (" ; mu=1 also vs closed form" if mu == 1 else ""))
        add(2, model, 128, 1e-6, M2D)
        add(2, model, 128, 0.0, M2D + " (mu = 0 exactly: grazing limit)")
    for model in ("ward", "modified_ward", "cook_torrance"):
        for m in (0.1, 0.4):
            for mu in (1.0, 0.5, 0.1):
                add(3, model, m, mu, M2D + (" ; mu=1 also vs 1-D mpmath" if mu == 1 else ""))
    for th in (89.995, 89.999, 89.9995):
        mu = math.sin(math.radians(90.0 - th))
        add(3, "ward", 0.1, mu, M2D, theta_i_deg=th)
    for model in ("phong", "stretched_phong"):
        for n in (1, 8):
            tasks.append(dict(item=4, quantity="mean_albedo", model=model, p=n,
                              params=param_dict(model, n), mu=None,
                              method="2*int_0^1 a(mu) mu dmu: scipy quad over mu of method A; "
                                     "checked by quad over mu of the 1-D lobe-azimuth formula "
                                     "(double) and by mpmath tanh-sinh over mu of the mpmath 1-D "
                                     "formula"))
    for n in (1, 2, 8):
        add(5, "stretched_phong", n, 1e-6, MPH, limit_eq26=(n + 2) / (2 * (n + 1)))
    return tasks


def main():
    import warnings
    # QUADPACK warns "roundoff error detected" when asked for 1e-14; the achieved accuracy is
    # judged by the cross-checks instead.
    warnings.simplefilter("ignore")
    t0 = time.time()
    here = os.path.dirname(os.path.abspath(__file__))
    out_path = os.path.join(here, "..", "data", "independent_reference.json")
    tasks = build_tasks()
    # longest first
    order = sorted(range(len(tasks)), key=lambda i: tasks[i]["quantity"] != "mean_albedo")
    with mp.get_context("fork").Pool(2) as pool:
        res = pool.map(run_task, [tasks[i] for i in order], chunksize=1)
        selftest = pool.apply_async(integrand_selftest).get()
    results = [None] * len(tasks)
    for i, r in zip(order, res):
        results[i] = r
    for r in results:
        r.pop("p", None)

    def find(model, mu=None, quantity="directional_albedo", **par):
        for r in results:
            if r["model"] == model and r["quantity"] == quantity and \
                    (mu is None or r["mu"] == mu) and all(r["params"].get(k) == v for k, v in par.items()):
                return r
        raise KeyError((model, mu, par))

    checks = []
    # --- Blinn closed form at normal incidence
    for n in (1, 8, 128):
        cf = blinn_closed_form_normal(n)
        for model in ("blinn", "stretched_blinn"):
            r = find(model, 1.0, n=n)
            checks.append(dict(check=f"{model} n={n} a(1) vs closed form 8pi[2u^(n+4)/(n+4)-u^(n+2)/(n+2)]_(1/sqrt2)^1",
                               closed_form=cf, numeric=r["value"], diff=r["value"] - cf,
                               verdict="confirmed" if abs(r["value"] - cf) < 1e-12 else "MISMATCH"))
    # --- Phong at normal incidence is exactly 1
    for model in ("phong", "stretched_phong"):
        for n in (1, 8, 100):
            r = find(model, 1.0, n=n)
            checks.append(dict(check=f"{model} n={n} a(1) == 1 exactly", numeric=r["value"],
                               diff=r["value"] - 1.0,
                               verdict="confirmed" if abs(r["value"] - 1) < 1e-12 else "MISMATCH"))
    # --- 000 sec 6.1.1, Blinn n=128 at 90 degrees
    K = 5.34
    for model, quoted in (("blinn", 7.8e-3), ("stretched_blinn", 3.7e-2)):
        r6, r0 = find(model, 1e-6, n=128), find(model, 0.0, n=128)
        checks.append(dict(
            check=f"000 sec. 6.1.1: {model} n=128 at 90 deg quoted {quoted}",
            a_mu_1em6=r6["value"], a_mu_0=r0["value"], a_times_5_34=r6["value"] * K,
            a_divided_by_5_34=r6["value"] / K, ratio_quoted_over_a=quoted / r6["value"],
            raw_reading=f"does not match (a is {r6['value']:.3g})",
            scaled_reading=f"a*5.34 = {r6['value'] * K:.4g} vs quoted {quoted:.2g}",
            verdict=("scaled reading (a*5.34) matches to the quoted 2 digits" if round(r6["value"] * K, 4) == quoted
                     else f"scaled reading gives {r6['value'] * K:.3g}, i.e. {r6['value'] * K:.2g} at 2 digits, "
                          f"not the quoted {quoted:.2g} (quoted/a = {quoted / r6['value']:.3f} instead of 5.34); "
                          "raw reading far off")))
        if round(r6["value"] * K, 4) != quoted:
            # smallest mu at which a*5.34 would round to the quoted value
            target = (quoted - 0.05 * 10 ** math.floor(math.log10(quoted))) / K
            mdl = MODEL_ID[model]
            mu_eq = brentq(lambda mu: albedo_A(mdl, 128, mu)[0] - target, 1e-7, 0.05, xtol=1e-12)
            checks[-1]["mu_where_a_times_5_34_first_rounds_to_quoted"] = mu_eq
            checks[-1]["theta_deg_where_a_times_5_34_first_rounds_to_quoted"] = math.degrees(math.acos(mu_eq))
    # --- 000 sec 6.2, Ward m=0.1 near grazing
    for th, quoted in ((89.995, 1.2), (89.999, 2.6), (89.9995, 3.8)):
        r = [x for x in results if x.get("theta_i_deg") == th][0]
        ok = round(r["value"], 1) == quoted
        checks.append(dict(check=f"000 sec. 6.2: ward m=0.1 a at theta_i={th} deg quoted {quoted}",
                           mu=r["mu"], numeric=r["value"],
                           a_times_sqrt_mu=r["value"] * math.sqrt(r["mu"]),
                           verdict=("confirmed to the quoted 2 digits" if ok else
                                    f"CONTRADICTED: {r['value']:.4f} rounds to {r['value']:.1f}, not {quoted:.1f}")))
    # --- 000 Table 3 mean albedos
    for model, n, quoted in (("phong", 1, 0.737), ("phong", 8, 0.676),
                             ("stretched_phong", 1, 0.934), ("stretched_phong", 8, 0.888)):
        r = find(model, None, quantity="mean_albedo", n=n)
        ok = round(r["value"], 3) == quoted
        checks.append(dict(check=f"000 Table 3: mean albedo {model} n={n} quoted {quoted}",
                           numeric=r["value"],
                           verdict=("confirmed to the quoted 3 digits" if ok else
                                    f"CONTRADICTED: {r['value']:.6f} rounds to {r['value']:.3f}")))
    # --- 000 eq. 26 limit
    for n in (1, 2, 8):
        r = find("stretched_phong", 1e-6, n=n)
        lim = (n + 2) / (2 * (n + 1))
        checks.append(dict(check=f"000 eq. 26: stretched phong n={n} a(mu->0) = (n+2)/(2(n+1)) = {lim}",
                           a_mu_1em6=r["value"], diff=r["value"] - lim,
                           slope_estimate=(r["value"] - lim) / 1e-6,
                           verdict="confirmed (difference is O(mu))" if abs(r["value"] - lim) < 1e-5
                           else "CONTRADICTED"))

    doc = dict(
        description="Independent reference values for BRDF directional and mean albedos "
                    "(computed without using the pumpup package).",
        conventions="N=(0,0,1); L=(sqrt(1-mu^2),0,mu); a(mu)=int_H f_r(L,V) cos(theta_V) dw_V; "
                    "mean=2 int_0^1 a(mu) mu dmu; R=2(N.L)N-L; H=(L+V)/|L+V|. "
                    "phong c=(n+2)/(2pi); blinn c=1; ward/modified_ward/cook_torrance as in the "
                    "script docstring (Fresnel=1). For grazing Ward entries mu=sin(radians(90-theta_i_deg)).",
        generated_by="tests/reference/independent_reference.py",
        software=dict(python=sys.version.split()[0], numpy=np.__version__,
                      scipy=__import__("scipy").__version__, numba=nb.__version__,
                      mpmath=mpmath.__version__),
        abs_err_estimate_definition="max(|A-B|, |A-C|, |A-other check| where present, QUADPACK "
                                    "error estimate of A, 1e-15*|A|), rounded to 2 digits; A, B, C "
                                    "and the other checks are listed under cross_checks",
        entries=results,
        checks=checks,
        integrand_selftest_max_rel_diff_vs_mpmath_vector_formulas=selftest,
        integrand_selftest_note="f_r*cos(theta_V) as coded (cancellation-free half-vector form) vs "
                                "40-digit mpmath evaluation straight from the vector definitions "
                                "at random points (many near the mirror direction and near "
                                "grazing). The largest relative differences (~1e-13) for Ward/"
                                "Cook-Torrance occur where tan^2(d)/m^2 is in the hundreds "
                                "(value < e^-50), i.e. the usual X*eps amplification in exp(-X) "
                                "on negligible contributions.",
        notes=["Methods A, B, C are all spherical coordinates about N (theta_V, phi_V), nested "
               "QUADPACK (scipy.integrate.quad), not a lobe frame.",
               "The Phong-family cross-check phong_1d does use the reflection direction R as pole, "
               "but with the azimuthal integral done in closed form and mpmath tanh-sinh at 30 "
               "digits; it is an independent derivation, reported only as a check.",
               "abs_err_estimate is dominated by the (conservative) QUADPACK error estimate; the "
               "actual spread between A, B, C and the 1-D/closed-form checks is typically 1e-16..1e-15."],
        runtime_seconds=None,
    )
    doc["runtime_seconds"] = round(time.time() - t0, 1)
    os.makedirs(os.path.dirname(out_path), exist_ok=True)
    with open(out_path, "w") as fh:
        json.dump(doc, fh, indent=1)
    # console summary
    print(f"{'model':<16} {'params':<18} {'mu':<13} {'value':<22} {'abs_err':<8}")
    for r in results:
        par = ",".join(f"{k}={v}" for k, v in r["params"].items() if k != "c")
        mu = "mean" if r["mu"] is None else f"{r['mu']:.6g}"
        print(f"{r['model']:<16} {par:<18} {mu:<13} {r['value']!r:<22} {r['abs_err_estimate']:<8.1e}")
    for c in checks:
        print("*", c["check"], "->", c["verdict"])
    print("integrand self-test:", selftest)
    print("wrote", os.path.normpath(out_path), f"in {doc['runtime_seconds']:.1f} s")


if __name__ == "__main__":
    main()
