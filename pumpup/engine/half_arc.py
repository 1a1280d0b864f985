"""Frame 4 of the 1-D routes (``half_arc``): the half vector's azimuth by a rule on its arc (the Smith models, the
V-cavity with a Fresnel factor, Schlick's and Ashikhmin-Shirley's lobes), and the parameter array ``mp`` of frames 4 and
5; :mod:`pumpup.engine.polar` describes the method.
"""

from __future__ import annotations

import math
import warnings

import numpy as np
from numba import njit

from ..core.hints import AzimuthHint
from ..physics.fresnel import conductor_scalar as _fresnel_real
from ..physics.fresnel import dielectric_scalar as _fresnel
from ..physics.fresnel import fresnel_branch, fresnel_brewster, fresnel_pole
from ..physics.microfacet import projected as _projected
from ..physics.quadrature import EPS, calibrated, rule_sums
from .half_frames import _half_arc
from .hint_view import kernel_view
from .lobe_frame import _tally

#: frame 4 declines a conductor's F(wi.h) whose branch point lies inside (0, 1) closer than this to the real axis (the
#: routing table leaves it to the nested engine, with the kink wi.h = x0 in the model's Lobe hint).  Measured against
#: the nested and 2-D engines at rtol 1e-13 (eta 0.551; GGX 0.3, 0.02, Beckmann 0.1; mu 0.05 ... 0.95): frame 4 was up
#: to 1.3e5 x its estimate for y0 = 0 (k = 0: total reflection below eta = 1) and y0 = 6.6e-13, 18 x for 6.6e-10, within
#: its estimate from 6.6e-8 up (``scripts/studies/fuzz_engines.py --registry``)
ARC_F_Y0_MIN = 1e-6

#: frame 4's models (``mp[0]``): the Smith microfacet models (Beckmann, GGX; ``SmithLobe``), the
#: V-cavity models with a Fresnel factor (Cook-Torrance, Torrance-Sparrow with ``ior``) and Schlick's model
#: (``SchlickLobe``), Ashikhmin and Shirley's lobe (``AshikhminShirleyLobe``, its rs in slot 4)
SMITH, VCAVITY_F, SCHLICK, LOBE_F, ASHIKHMIN = 0, 1, 2, 3, 4


def fresnel_scale(ior: float, eta: float, k: float) -> float:
    """c_F: the Fresnel factor F(c) has its singularities where c^2 = 1 - index^2, |c| = c_F = sqrt(|1 - index^2|)
    (a dielectric's real ior, or a conductor's eta + i k), which near an index of 1 come close to the arc's small c;
    :func:`_k_numeric` cuts the arc at c = c_F 3^k there.  inf without a Fresnel factor.
    """
    if eta > 0.0:
        return math.sqrt(abs(1.0 - complex(eta, k) ** 2))
    return math.sqrt((ior - 1.0) * (ior + 1.0)) if ior > 0.0 else math.inf


@njit(cache=True, nogil=True, inline="always")
def _fresnel_at(mp, c):  # pragma: no cover - compiled
    """The Fresnel factor at wi.h = c of frames 4 and 6: the conductor's (eta, k = mp[6], mp[7]; metal.py), Schlick's
    f0 + (1 - f0) (1 - c)^5 where mp[5] = -1 - f0 < 0 (Karis 2013), or the dielectric's (ior = mp[5], 1 when ior = 0;
    cook_torrance.py).
    """
    if mp[6] > 0.0:
        return _fresnel_real(c, mp[6], mp[7])
    if mp[5] < 0.0:
        q = 1.0 - c
        return (-1.0 - mp[5]) + (2.0 + mp[5]) * ((q * q) * (q * q) * q)  # Schlick, f0 = -1 - mp[5]
    return _fresnel(c, mp[5])


@njit(cache=True, nogil=True, inline="always")
def _phi_numeric(mp, mu, u, c0, d):  # pragma: no cover - compiled; see numeric_integrand_reference
    """Frame 4's integrand 4 c F(c) Gamma at d = c - c0 >= 0 (c = wi.h, N.wo = z = 2 u d): Gamma = G / mu for the
    Smith models (G = G1(mu) G1(z) = mu z / (P(mu) P(z)), Walter et al. 2007 eq. 20; or the height-correlated
    mu z / (z P(mu) + mu P(z) - mu z), Heitz 2014; P(w) = N.w / G1(w), pumpup.models.microfacet), Gamma = G =
    min(1, 2 u mu / c, 2 u z / c) for the V-cavity (001 eq. 10); F the dielectric (ior, 002 sec. 3.2) or conductor
    (eta, k) Fresnel factor at c, or 1.
    """
    c = c0 + d
    z = 2.0 * u * d
    f = _fresnel_at(mp, c)
    if mp[0] == VCAVITY_F:
        return 4.0 * f * min(c, 2.0 * u * mu, 2.0 * u * z)  # 4 c G, 001 eq. 10
    if mp[0] == SCHLICK:
        return 4.0 * c * z / (mp[4] + (1.0 - mp[4]) * z)  # 000 eq. 36's 1 / (r + (1 - r) N.V), times N.V
    if mp[0] == ASHIKHMIN:  # AS 2000 eq. 4: 4 c F(c) / (c max(mu, z)) times z, Schlick's F(c) (eq. 5)
        q = 1.0 - c
        return 4.0 * (mp[4] + (1.0 - mp[4]) * (q * q) * (q * q) * q) * min(z, mu) / mu
    if mp[1] == 1.0:  # GGX: P = (z + sqrt(z^2 + alpha^2 sin^2)) / 2, Walter eq. 34
        # (physics.microfacet.projected, one sqrt)
        pz = 0.5 * (z + math.sqrt(z * z + mp[4] * mp[4] * ((1.0 - z) * (1.0 + z))))
    else:
        pz = _projected(math.sqrt((1.0 - z) * (1.0 + z)), 0.0, z, 0, int(mp[2]), mp[4])
    if mp[3] == 0.0:
        return 4.0 * c * f * z / (mp[8] * pz)  # G1(mu) G1(z) / mu, Walter eq. 20
    return 4.0 * c * f * z / (z * mp[8] + mu * pz - mu * z)  # 1 / (mu (1 + Lambda_i + Lambda_o)), Heitz 2014


def _w_series(kmax: int = 6, terms: int = 24) -> np.ndarray:
    """Row k: the Taylor coefficients of (sin(y) / y)^(2k) in y^(2m), m < ``terms`` (exact, then each rounded once to
    a float), for :func:`_w_moments`' series.

    The series are multiplied in integers: with D = (2 terms - 1)!, D (sin(y) / y) has integer coefficients
    (-1)^m D / (2m + 1)!, so row k is an integer series over D^(2k); Python's int / int rounds correctly.
    """
    d = math.factorial(2 * terms - 1)
    sinc = [(-1) ** m * (d // math.factorial(2 * m + 1)) for m in range(terms)]  # D sin(y) / y in y^(2m)
    out = np.zeros((kmax + 1, terms))
    power, scale = [1] + [0] * (terms - 1), 1
    for k in range(kmax + 1):
        out[k] = [x / scale for x in power]
        for _ in range(2):  # times (sin(y) / y)^2
            power = [sum(power[i] * sinc[m - i] for i in range(m + 1)) for m in range(terms)]
            scale *= d
    return out


#: the series of W_6 (:func:`_w_moments`): the Taylor coefficients of (sin(y) / y)^12 in y^(2m), divided by 2m + 13;
#: where it turns to the Fourier form (both lose digits towards that point, the series to its alternating terms, the
#: Fourier form to its cancellation: x = 2 keeps every W_k within 6 eps of 150-digit values, measured on 200 x in
#: [0.05, pi]); the Fourier coefficients (-1)^j C(12, 6 - j)
W_TERMS = 40
W_SERIES = _w_series(6, W_TERMS)[6] / (2 * np.arange(W_TERMS) + 13)
W_SERIES_MAX = 2.0
W_FOURIER = np.array([924.0, -792.0, 495.0, -220.0, 66.0, -12.0, 1.0])



@njit(cache=True, nogil=True, inline="always")
def _w_moments(x, out):  # pragma: no cover - compiled; see as_arc_reference
    """out[k] = W_k(x) = integral_0^x sin^(2k)(t / 2) dt, k = 0 .. 6, 0 <= x <= pi (``out``: 13 slots, 7 .. 12 work).
    W_6 below x = W_SERIES_MAX by its series 2 sum_m coef_m y^(2m + 13) / (2m + 13), y = x / 2 (:data:`W_SERIES`),
    above it by sin^12(t / 2) = 4^-6 [C(12, 6) + 2 sum_(j=1..6) (-1)^j C(12, 6 - j) cos(j t)]; then W_(k-1) =
    (2k / (2k - 1)) (W_k + sin^(2k-1)(x / 2) cos(x / 2) / k) downwards, a sum of terms >= 0 which damps W_k's error
    (the upward recurrence loses a factor 1 / sin^2(x / 2) per step).  Every W_k within 6 eps (measured).
    """
    y = 0.5 * x
    sh, ch = math.sin(y), math.cos(y)
    if x < W_SERIES_MAX:
        y2 = y * y
        ym = 2.0 * y ** 13
        tot = 0.0
        for m in range(W_TERMS):
            term = W_SERIES[m] * ym
            tot += term
            if abs(term) < 1e-17 * tot:
                break
            ym *= y2
    else:
        tot = 924.0 * x  # C(12, 6) x
        ct, st = math.cos(x), math.sin(x)
        s_prev, s_cur = 0.0, st
        for j in range(1, 7):  # sin(j x) by the Chebyshev recurrence
            tot += 2.0 * W_FOURIER[j] * s_cur / j
            s_prev, s_cur = s_cur, 2.0 * ct * s_cur - s_prev
        tot *= 0.25**6
    out[6] = tot
    s2 = sh * sh
    p = sh * ch
    for k in range(1, 7):  # out[6 + k] = sin^(2k-1)(x / 2) cos(x / 2)
        out[6 + k] = p
        p *= s2
    for k in range(6, 1, -1):
        out[k - 1] = (2.0 * k / (2.0 * k - 1.0)) * (out[k] + out[6 + k] / k)
    out[0] = x


@njit(cache=True, nogil=True)
def _k_ashikhmin(mp, mu, s, psi, u, sa, ws):  # pragma: no cover - compiled; see as_arc_reference
    """(K(u), its rounding bound) of Ashikhmin and Shirley's lobe in frame 4, in closed form: the integral over h's
    azimuth beta, where N.wo > 0, of 4 F(c) min(N.wo, mu) / mu (AS 2000 eq. 4 times N.wo, with 4 (wi.h) from
    d omega_o; :func:`_phi_numeric`), F(c) = rs + (1 - rs) (1 - c)^5 (eq. 5), c = wi.h = a + b cos(beta).

    From the arc's top (beta = 0, the largest c) 1 - c = w = g + 2 b sin^2(beta / 2) with g = 1 - cos(theta_i - alpha)
    = 2 sin^2((theta_i - alpha) / 2) >= 0, a sum of terms >= 0, so M_k(beta_e) = integral_0^beta_e w^k d beta =
    sum_j C(k, j) g^(k-j) (2 b)^j W_j(beta_e) (:func:`_w_moments`) has no cancellation.  Where N.wo >= mu (|beta| <
    beta1, c >= c1 = 2 c0, as in :func:`pumpup.engine.half_frames._k_half`) the integrand is 4 F = 4 (rs + (1 - rs)
    w^5); below it (beta1 < |beta| < beta0) 4 F (c - c0) 2 u / mu with c - c0 = (1 - c0) - w, so with
    B(beta_e) = (1 - c0) (rs M_0 + (1 - rs) M_5) - rs M_1 - (1 - rs) M_6,

        K = 2 [4 (rs beta1 + (1 - rs) M_5(beta1)) + (8 u / mu) (B(beta0) - B(beta1))].

    B's two differences cancel where the band beta1 < |beta| < beta0 is thin (small mu): the bound returned is
    64 eps times the sum of the magnitudes of every term and of K's bound 8 beta0, and :func:`_k_numeric` takes its rule
    instead where that exceeds half its tolerance.  ``ws`` is a work array of 13 slots (:func:`_w_moments`).
    """
    live, b, c0, e0, sb0, beta0, low, _, _ = _half_arc(mu, s, psi, u, sa)
    if not live:
        return 0.0, 0.0
    rs = mp[4]
    th = 0.5 * math.pi - psi
    al = math.atan2(sa, u)
    hg = math.sin(0.5 * (th - al))
    g = 2.0 * hg * hg  # 1 - (a + b), exact
    tb = 2.0 * b
    # beta1: N.wo = mu (c = c1 = 2 c0), on the circle where u > mu and b > 0 (then cos(beta1) = mu sa / (u s) >= 0)
    beta1 = 0.0
    if u > mu and b > 0.0:
        beta1 = math.atan2(sa * math.sqrt((u - mu) * (u + mu)) / u, mu * sa * sa / u)
    f = 8.0 * u / mu
    tot = 0.0
    mag = 0.0
    for side in range(2):
        be = beta0 if side == 0 else beta1
        if be <= 0.0:
            continue
        _w_moments(be, ws)
        m0 = be
        m1 = g * be + tb * ws[1]
        # M_5, M_6: C(k, j) g^(k - j) (2 b)^j W_j summed over j (every term >= 0)
        g2 = g * g
        g3 = g2 * g
        g4 = g2 * g2
        g5 = g4 * g
        t2 = tb * tb
        t3 = t2 * tb
        t4 = t2 * t2
        t5 = t4 * tb
        m5 = (g5 * ws[0] + 5.0 * g4 * tb * ws[1] + 10.0 * g3 * t2 * ws[2] + 10.0 * g2 * t3 * ws[3]
              + 5.0 * g * t4 * ws[4] + t5 * ws[5])
        m6 = (g5 * g * ws[0] + 6.0 * g5 * tb * ws[1] + 15.0 * g4 * t2 * ws[2] + 20.0 * g3 * t3 * ws[3]
              + 15.0 * g2 * t4 * ws[4] + 6.0 * g * t5 * ws[5] + t3 * t3 * ws[6])
        pos = (1.0 - c0) * (rs * m0 + (1.0 - rs) * m5)
        neg = rs * m1 + (1.0 - rs) * m6
        sign = 1.0 if side == 0 else -1.0
        tot += sign * f * (pos - neg)
        mag += f * (pos + neg)
        if side == 1:
            arc1 = 4.0 * (rs * beta1 + (1.0 - rs) * m5)
            tot += arc1
            mag += arc1
    # (and K's own bound 8 beta0, the integrand being at most 4: the inputs g, b, c0 and the arcs' ends carry a few
    # ulps each, whose effect is not relative to the terms where w is small and rs is 0)
    mag += 4.0 * beta0
    return 2.0 * tot, 2.0 * 64.0 * EPS * mag


@njit(cache=True, nogil=True)
def _delta_rule(mp, mu, u, c0, low, sb0, q, lo, hi, nodes, wk, wg, mode, ibuf):  # pragma: no cover - compiled
    """(value, error) of the rule on delta in [lo, hi] for :func:`_phi_numeric` at d = low + sb0 sin(delta) +
    2 q sin^2(delta / 2) (:func:`_k_numeric`).
    """
    h = hi - lo
    for j in range(nodes.shape[0]):
        x = 0.5 * (lo + h * nodes[j])
        sh = math.sin(x)
        d = low + 2.0 * sh * (sb0 * math.cos(x) + q * sh)
        ibuf[j] = _phi_numeric(mp, mu, u, c0, max(d, 0.0))
    k, diff, asc, ab = rule_sums(ibuf, wk, wg)
    return k * h, calibrated(diff * h, asc * h, ab * h, mode)


@njit(cache=True, nogil=True, inline="always")
def _delta_at(c, a, b, beta0):  # pragma: no cover - compiled
    """The angle delta = beta0 - beta where wi.h = a + b cos(beta) = c (at most beta0)."""
    x = c - a
    return min(beta0 - math.atan2(math.sqrt(max(0.0, (b - x) * (b + x))), x), beta0)


@njit(cache=True, nogil=True)
def _k_numeric(mp, mu, s, psi, u, sa, itol, tol_abs,  # pragma: no cover - compiled; see numeric_integrand_reference
               nodes, wk, wg, mode, ibuf, iwork):
    """(K(u), its error) of frame 4: the integral over the azimuth beta of h about N, where N.wo > 0, of
    :func:`_phi_numeric` (4 c F(c) Gamma, which depends on beta through c = wi.h only, as in :func:`_k_half`), by a
    globally adaptive rule (``nodes``, ``wk``, ``wg``: the 7/15 rule) on the arc.

    The arc comes exact from :func:`_half_arc`, in delta = beta0 - beta measured from its end: d = c - c0 =
    2 e0 sin^2(delta / 2) + b sin(beta0) sin(delta) on a partial arc (N.wo = 0 at delta = 0), low + 2 b
    sin^2(delta / 2) on the full circle (beta0 = pi), no cancellation either way.  The arc is cut where the
    integrand has a kink or a jump: Walter's G1 switch (N.wo = ``mp[9]``), the crossings of the V-cavity's three
    lines (c = 2 u mu, mu / u, 2 u mu / (4 u^2 - 1), as :func:`_k_vcavity`); and graded towards the arc's small end
    where a factor has a singularity near it (N.wo = z_c 3^k, c = c_c 3^k, below).  The interval with the largest
    error is bisected until the summed error (QUADPACK's calibration: the integrand is analytic on every piece) is at
    most max(``itol`` |K|, ``tol_abs``) or INNER_MAX intervals are used; the error is returned either way.  Both signs
    of beta: 2 x.
    """
    if mp[0] == ASHIKHMIN and mp[20] > 0.0:  # the closed form, where its rounding bound is well within the tolerance
        k, e = _k_ashikhmin(mp, mu, s, psi, u, sa, ibuf)
        if e <= 0.5 * max(itol * abs(k), tol_abs):
            return k, e
    live, b, c0, e0, sb0, beta0, low, _, _ = _half_arc(mu, s, psi, u, sa)
    if not live:
        return 0.0, 0.0
    q = b if beta0 == math.pi else e0
    lo, hi, val, err = iwork[0], iwork[1], iwork[2], iwork[3]
    a = mu * u
    c_lo, c_hi = c0 + low, a + b  # the range of c on the arc (delta = 0 and beta0)
    # the cuts in c, as delta = beta0 - beta(c), sorted (at most three; scalars, not an array: this runs at every
    # node; those outside (0, beta0) stand at beta0, their pieces are empty)
    x1, x2, x3 = beta0, beta0, beta0
    if b > 0.0:
        for j in range(3):
            if mp[0] == VCAVITY_F:
                cb = 2.0 * u * mu if j == 0 else (mu / u if j == 1 else (
                    2.0 * u * mu / (4.0 * u * u - 1.0) if 4.0 * u * u > 1.0 else -1.0))
            elif mp[0] == ASHIKHMIN:
                cb = mu / u if j == 0 else -1.0  # N.wo = 2 c u - mu = mu: max(mu, N.wo)'s kink
            else:
                cb = 0.5 * (mu + mp[9]) / u if j == 0 and mp[9] > 0.0 else -1.0
            if c_lo < cb < c_hi:
                dl = _delta_at(cb, a, b, beta0)
                if 0.0 < dl < beta0:
                    if j == 0:
                        x1 = dl
                    elif j == 1:
                        x2 = dl
                    else:
                        x3 = dl
    x1, x2 = min(x1, x2), max(x1, x2)
    x2, x3 = min(x2, x3), max(x2, x3)
    x1, x2 = min(x1, x2), max(x1, x2)
    # graded cuts where a factor has a singularity near the arc's small end: P(N.wo) of the Smith models at
    # N.wo ~ +-i alpha (GGX's at +-i alpha / sqrt(1 - alpha^2); Beckmann's erf and exp turn on the scale
    # a = N.wo / (alpha sin) ~ 1), the Fresnel factor at c ~ +-i c_F (:func:`fresnel_scale`).  Where the arc runs from
    # below that scale to far above it, a rule on the whole arc does not see the feature at its end (GGX
    # alpha = 0.001 was 1.6e-10 off at rtol 1e-12 with an estimate of 6e-13), so it is cut at N.wo = z_c 3^k,
    # z_c = max(alpha, 3 N.wo_min), and at c = c_c 3^k, c_c = max(c_F, 3 c_min): each piece then lies at least its own
    # length from the singularity
    z_lo, z_hi = 2.0 * u * low, 2.0 * u * (c_hi - c0)
    zc = 3.0 * z_lo if z_lo >= mp[11] else mp[11]
    cc = 3.0 * c_lo if c_lo >= mp[10] else mp[10]
    da = _delta_at(c0 + 0.5 * zc / u, a, b, beta0) if zc < z_hi / 1.5 else beta0
    db = _delta_at(cc, a, b, beta0) if cc < c_hi / 1.5 else beta0
    m = 0
    start = 0.0
    f = 0
    while True:
        fx = x1 if f == 0 else (x2 if f == 1 else (x3 if f == 2 else beta0))
        end = min(da, db, fx)
        if end > start:
            lo[m], hi[m] = start, end
            val[m], err[m] = _delta_rule(mp, mu, u, c0, low, sb0, q, start, end, nodes, wk, wg, mode, ibuf)
            m += 1
            start = end
        if end >= beta0:
            break
        if m >= lo.shape[0] - 8:  # (keeps room to bisect)
            da, db, f = beta0, beta0, 3
            continue
        if da <= end:
            zc *= 3.0
            da = _delta_at(c0 + 0.5 * zc / u, a, b, beta0) if zc < z_hi / 1.5 else beta0
        if db <= end:
            cc *= 3.0
            db = _delta_at(cc, a, b, beta0) if cc < c_hi / 1.5 else beta0
        if fx <= end:
            f += 1
    while True:
        tot, e, worst = _tally(val, err, m, 0.0, 0.0)
        if 2.0 * e <= max(2.0 * itol * abs(tot), tol_abs) or m >= lo.shape[0]:
            return 2.0 * tot, 2.0 * e
        mid = 0.5 * (lo[worst] + hi[worst])
        lo[m], hi[m] = mid, hi[worst]
        hi[worst] = mid
        val[worst], err[worst] = _delta_rule(mp, mu, u, c0, low, sb0, q, lo[worst], mid, nodes, wk, wg, mode, ibuf)
        val[m], err[m] = _delta_rule(mp, mu, u, c0, low, sb0, q, mid, hi[m], nodes, wk, wg, mode, ibuf)
        m += 1

#: the most graded cuts per side of the branch point on an arc (:func:`_k_lobe_fresnel`) and in alpha (:func:`_pieces`)
LOBE_F_CUTS = 8
#: the slots of frame 4's and 5's parameter array ``mp`` (above)
MP_SIZE = 23 + 3 * LOBE_F_CUTS


def numeric_integrand_reference(brdf, mu: float, u) -> np.ndarray:
    """Plain twin of :func:`_k_numeric`: K(u) from the model's own numpy formula (``BRDF.reference`` at
    wo = 2 (wi.h) h - wi), integral over h's azimuth of 4 (wi.h) N.wo f_r where N.wo > 0 by scipy's QUADPACK (split at
    the arc's end, Walter's switch and the V-cavity's crossings), divided by the hint's scale and radial factor
    (w(t) / u^4 under the Beckmann and GGX weights, u^n under the power weight).
    """
    from scipy.integrate import quad

    hint = kernel_view(brdf.azimuth_hint())
    mp = numeric_params(hint)
    s = math.sqrt((1.0 - mu) * (1.0 + mu))
    wi = np.array([s, 0.0, mu])
    scale = float(np.asarray(hint.scale(np.array([mu])), dtype=float).ravel()[0])
    out = []
    for v in np.atleast_1d(np.asarray(u, dtype=float)):
        sa = math.sqrt((1.0 - v) * (1.0 + v))

        def g(beta, v=v, sa=sa):
            h = np.array([sa * math.cos(beta), sa * math.sin(beta), v])
            c = float(wi @ h)
            wo = 2.0 * c * h - wi
            return 4.0 * c * wo[2] * float(brdf.reference(wi, wo)) if wo[2] > 0.0 else 0.0

        b, a = s * sa, mu * v
        cuts = [0.5 * mu / v] + ([0.5 * (mu + mp[9]) / v] if mp[9] > 0.0 else [])
        if mp[0] == ASHIKHMIN:
            cuts += [mu / v]
        if mp[0] == VCAVITY_F:
            cuts += [2.0 * v * mu, mu / v] + ([2.0 * v * mu / (4.0 * v * v - 1.0)] if 4.0 * v * v > 1.0 else [])
        pts = [math.acos((cv - a) / b) for cv in cuts if b > 0.0 and abs((cv - a) / b) < 1.0] or None
        if hint.radial == "power":
            weight = v**hint.n
        else:
            t = sa * sa / (v * hint.n) ** 2
            weight = (math.exp(-t) if hint.radial == "beckmann" else 1.0 / (1.0 + t) ** 2) / v**4
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            k = 2.0 * quad(g, 0.0, math.pi, points=pts, epsabs=0.0, epsrel=1e-13, limit=400)[0]
        out.append(k / (scale * weight) if weight > 0.0 else math.nan)
    return np.array(out)


def as_arc_reference(rs: float, mu: float, u) -> np.ndarray:
    """Plain twin of :func:`_k_ashikhmin`: K(u) of Ashikhmin and Shirley's lobe from the same decomposition, the arc's
    ends from the plain geometry (cos(beta0) = (c0 - a) / b, cos(beta1) = (c1 - a) / b, clipped) and W_k(x) =
    integral_0^x sin^(2k)(t / 2) dt by a 48-point Gauss-Legendre rule (exact to rounding for these trigonometric
    polynomials of degree 6 on [0, pi]); none of the kernel's series, recurrences or exact angle forms.
    """
    xg, wg = np.polynomial.legendre.leggauss(48)
    s = math.sqrt((1.0 - mu) * (1.0 + mu))
    out = []
    for v in np.atleast_1d(np.asarray(u, dtype=float)):
        sa = math.sqrt((1.0 - v) * (1.0 + v))
        a, b, c0 = mu * v, s * sa, 0.5 * mu / v
        c1 = 2.0 * c0

        def end(level):  # the angle from the arc's top where c = a + b cos(beta) falls to the level
            if b == 0.0:
                return math.pi if a > level else 0.0
            return math.acos(min(1.0, max(-1.0, (level - a) / b)))

        def moments(x):  # M_k = integral_0^x (1 - c)^k d beta, k = 0, 1, 5, 6
            t = 0.5 * x * (xg + 1.0)
            w = 1.0 - (a + b * np.cos(t))
            return {k: 0.5 * x * float(np.sum(wg * w**k)) for k in (0, 1, 5, 6)}

        def band(x):  # integral_0^x F(c) (c - c0) d beta
            m = moments(x)
            return (1.0 - c0) * (rs * m[0] + (1.0 - rs) * m[5]) - rs * m[1] - (1.0 - rs) * m[6]

        beta0, beta1 = end(c0), end(c1)
        k = 8.0 * v / mu * (band(beta0) - band(beta1))
        if beta1 > 0.0:
            k += 4.0 * (rs * beta1 + (1.0 - rs) * moments(beta1)[5])
        out.append(2.0 * k)
    return np.array(out)


def numeric_params(hint, gauss: bool = True) -> np.ndarray:
    """Frame 4's parameter array ``mp`` (:data:`MP_SIZE` slots) of a :class:`KernelView` with ``smith`` or a V-cavity
    lobe with ``fresnel`` (zeros but the Walter level -1 otherwise); P(mu) is set per mu by :func:`_integrate`.
    ``gauss``: frame 5 takes its arcs by Gauss-Legendre pieces with an a-priori bound where they apply
    (:func:`_lobe_f_gauss`), and Ashikhmin-Shirley's lobe in closed form where its rounding bound meets the tolerance
    (:func:`_k_ashikhmin`), else both by the adaptive 7/15 rule alone (``mp[20]``).  An AzimuthHint is viewed first.
    """
    if isinstance(hint, AzimuthHint):
        hint = kernel_view(hint)
    mp = np.zeros(MP_SIZE)
    mp[9] = -1.0
    mp[5:8] = hint.fresnel
    mp[10] = fresnel_scale(*(float(x) for x in hint.fresnel))
    mp[11] = math.inf
    mp[12] = 1e-16  # (run sets the tolerance)
    if hint.smith is not None:
        mp[0], mp[1:5] = SMITH, hint.smith
        mp[11] = hint.smith[3]
        # a conductor's branch point, for :func:`_pieces`' cuts (frame 6 reuses 13, 14: n_params)
        if hint.fresnel[1] > 0.0:
            mp[13], mp[14] = fresnel_branch(float(hint.fresnel[1]), float(hint.fresnel[2]))
        if hint.smith[1] == 1:
            from ..physics.microfacet import walter_level

            mp[9] = walter_level(float(hint.smith[3]))
    elif hint.kind == "lobe" and any(hint.fresnel):  # frame 5: F(max(N.wi, N.wo)) of a conductor (eta, k)
        mp[0] = LOBE_F
        eta, k = float(hint.fresnel[1]), float(hint.fresnel[2])
        mp[13], mp[14] = fresnel_branch(eta, k)
        mp[15] = fresnel_pole(eta, k)
        cb, ok = fresnel_brewster(eta, k)
        mp[16], mp[17], mp[18] = cb.real, cb.imag, 1.0 if ok else 0.0
        mp[19] = abs(complex(eta * eta - k * k + 1.0, 2.0 * eta * k))  # |e^2 + 1|
        mp[20] = 1.0 if gauss else 0.0
    elif hint.schlick_fresnel is not None:
        mp[0], mp[4] = ASHIKHMIN, float(hint.schlick_fresnel)
        mp[20] = 1.0 if gauss else 0.0
    elif hint.schlick is not None:
        r = float(hint.schlick)
        mp[0], mp[4], mp[11] = SCHLICK, r, (r / (1.0 - r) if r < 1.0 else math.inf)
    else:
        mp[0] = VCAVITY_F
    return mp
