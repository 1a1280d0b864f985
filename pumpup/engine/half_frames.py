"""Frames 1-3 of the 1-D routes (``half``, ``ward``, ``vcavity``): the half vector's azimuth about N in closed form for
the Blinn family, Ward's model (complete elliptic integrals) and the V-cavity G; :mod:`pumpup.engine.polar` describes
the method.
"""

from __future__ import annotations

import math
import warnings

import numpy as np
from numba import njit

from ..physics.quadrature import EPS


@njit(cache=True, nogil=True)
def _trig_tail(x, which):  # pragma: no cover - compiled; see half_moments_reference
    """Integrals of trigonometric polynomials that cancel to high order at small x, by their series
    below x = 1 and in closed form above (where at most a digit cancels).

    ``which`` 0: x - sin(x);  1: F1 = integral_0^x (cos(t) - cos(x)) dt = sin(x) - x cos(x);
    2: F2 = integral_0^x (cos(t) - cos(x))^2 dt;  3: R2 = integral_0^x (1 - cos(t))^2 dt.
    """
    if x >= 1.0:
        if which == 0:
            return x - math.sin(x)
        if which == 1:
            return math.sin(x) - x * math.cos(x)
        if which == 2:
            c = math.cos(x)
            return x * (0.5 + c * c) - 1.5 * math.sin(x) * c
        return 1.5 * x - 2.0 * math.sin(x) + 0.25 * math.sin(2.0 * x)
    # the series sum_k coef(k) y^(2k+1) / (2k+1)!, y = 2x for F2 (then / 4), x otherwise
    y = 2.0 * x if which == 2 else x
    y2 = y * y
    term = y  # y^(2k+1) / (2k+1)! at k = 0
    total = 0.0
    for k in range(1, 30):
        term *= y2 / ((2.0 * k) * (2.0 * k + 1.0))
        sign = 1.0 if k % 2 == 0 else -1.0
        if which == 0:
            coef = -sign  # (-1)^(k+1)
        elif which == 1:
            coef = -sign * 2.0 * k  # (-1)^(k+1) 2k
        elif which == 2:
            coef = sign * (2.0 * k - 2.0)  # (-1)^k (2k - 2)
        else:
            coef = sign * (2.0 ** (2 * k - 1) - 2.0)  # (-1)^k (2^(2k-1) - 2)
        total += coef * term
        if term < 1e-18 * abs(total):
            break
    return 0.25 * total if which == 2 else total


@njit(cache=True, nogil=True, inline="always")
def _arc_moments(e, sb, b, beta):  # pragma: no cover - compiled; see half_moments_reference
    """(J1, J2) = integral_0^beta (d, d^2) d beta' for d = c - c_e = e + b cos(beta') >= 0 on the arc, where
    cos(beta) = -e / b, sb = b sin(beta) (sb = 0 and beta = pi for a full circle): J1 = sb + beta e,
    J2 = beta (e^2 + b^2 / 2) + 3/2 e sb, by their series b F1(beta), b^2 F2(beta) below beta = 1 (where
    e is near -b and the closed forms cancel).
    """
    if beta < 1.0:
        return b * _trig_tail(beta, 1), b * b * _trig_tail(beta, 2)
    return sb + beta * e, beta * (e * e + 0.5 * b * b) + 1.5 * e * sb


@njit(cache=True, nogil=True, inline="always")
def _half_arc(mu, s, psi, u, sa):  # pragma: no cover - compiled; see the kernels' twins
    """The arc of h's azimuth where N.wo > 0, for h at u = N.h, sa = sin(alpha) (s = sin(theta_i),
    psi = pi/2 - theta_i): (live, b, c0, e0, sb0, beta0, low, f1, f2).  live is False where no h on the circle
    sends wo above the horizon; b = s sa, c0 = mu / (2 u) (wi.h there), e0 = a - c0 = mu cos(2 alpha) / (2 u);
    on the full circle (2 alpha <= psi, or b = 0) sb0 = 0, beta0 = pi and low = d(pi) = a - b - c0, else
    sb0 = b sin(beta0) = sqrt(sin(2 alpha + psi) sin(2 alpha - psi)) / (2 u), each sine with its angle written
    as a difference of small exact angles near its zero (alpha' = pi/2 - alpha), and low = 0; and those two
    sines, f1 = 2 u T with T = d(0) = a + b - c0 and f2 = 2 u (b - e0) (0 on the full circle): nine values.
    """
    al = math.atan2(sa, u)
    alc = math.atan2(u, sa)  # pi/2 - alpha, exact where u is small
    if u <= 0.0 or 2.0 * alc <= psi:  # 2 alpha + psi >= pi: the whole circle of h sends wo below the horizon
        return False, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0
    b = s * sa
    c0 = 0.5 * mu / u
    e0 = 0.5 * mu * (u - sa) * (u + sa) / u
    if 2.0 * al <= psi or b == 0.0:  # the whole circle sends wo above it (b = 0: mu = 1, or h = N)
        low = 0.5 * math.sin(psi - 2.0 * al) / u
        return low + 2.0 * b > 0.0, b, c0, e0, 0.0, math.pi, low, 0.0, 0.0
    f1 = math.sin(2.0 * alc - psi) if 2.0 * al + psi > 0.5 * math.pi else math.sin(2.0 * al + psi)
    f2 = math.sin(2.0 * alc + psi) if 2.0 * al - psi > 0.5 * math.pi else math.sin(2.0 * al - psi)
    sb0 = 0.5 * math.sqrt(max(0.0, f1 * f2)) / u
    return True, b, c0, e0, sb0, math.atan2(sb0, -e0), 0.0, f1, f2


@njit(cache=True, nogil=True)
def _k_half(p, mu, s, psi, u, sa):  # pragma: no cover - compiled; see half_integrand_reference
    """K(u) of the half-vector frame, p in {0, 1}: the integral over the azimuth beta of h about N of
    4 (wi.h) N.wo / max(mu, N.wo)^p where N.wo > 0, for h at u = N.h = cos(alpha), sa = sin(alpha);
    s = sin(theta_i), psi = pi / 2 - theta_i = atan2(mu, s) (exact near grazing incidence, where the
    arc's ends depend on 2 alpha - psi).

    d omega_o = 4 (wo.h) d omega_h and wo.h = wi.h = c = a + b cos(beta), a = mu u, b = s sa (the
    form of N.wo about R, pumpup.engine.polar's lobe frame); N.wo = 2 c u - mu, so N.wo > 0 where
    c > c0 = mu / (2 u), and N.wo >= mu where c >= c1 = 2 c0.  On the arc |beta| < beta0 (c > c0),
    with d = c - c0 >= 0: p = 0 integrates 4 c 2 u d = 8 u (c0 d + d^2); p = 1 that on the part
    |beta| > beta1 (c < c1), divided by mu = 2 u c0, and 4 c on |beta| < beta1.  The arc's end beta0 comes
    exact from :func:`_half_arc`, beta1 from b^2 - (a - c1)^2 = sa^2 (u - mu)(u + mu) / u^2; the part between
    beta1 and beta0 is integrated in delta = beta0 - beta (no cancellation when it is thin, near grazing
    incidence).
    """
    live, b, c0, e0, sb0, beta0, dpi, _, _ = _half_arc(mu, s, psi, u, sa)
    if not live:
        return 0.0
    j1, j2 = _arc_moments(e0, sb0, b, beta0)
    if p == 0.0:
        return 16.0 * u * (c0 * j1 + j2)  # 2 (both signs of beta) 8 u (c0 J1 + J2)
    # p = 1 (000 eq. 32's max(N.L, N.V)): |beta| < beta1 where N.wo >= mu, non-empty for alpha < theta_i
    if u <= mu or b == 0.0:
        return 8.0 * (j1 + j2 / c0)  # (8 u / mu) (c0 J1 + J2) on the whole arc
    e1 = -mu * sa * sa / u  # a - c1
    sb1 = sa * math.sqrt((u - mu) * (u + mu)) / u  # b sin(beta1)
    beta1 = math.atan2(sb1, -e1)
    k1, _ = _arc_moments(e1, sb1, b, beta1)
    # beta1 < beta < beta0: d = D + X, X = P sin(delta) + Q (cos(delta) - 1) >= 0, with D = d(beta0) (0 on
    # a partial arc), P = b sin(beta0), Q = b cos(beta0) (-e0 on a partial arc, -b on the full circle)
    dl = beta0 - beta1
    hs = math.sin(0.5 * dl)
    P = sb0
    Q = -b if beta0 == math.pi else -e0
    ix = 2.0 * P * hs * hs - Q * _trig_tail(dl, 0)
    ix2 = P * P * 0.25 * _trig_tail(2.0 * dl, 0) - 4.0 * P * Q * hs ** 4 + Q * Q * _trig_tail(dl, 3)
    i1 = dpi * dl + ix
    i2 = dpi * dpi * dl + 2.0 * dpi * ix + ix2
    return 8.0 * (2.0 * c0 * beta1 + k1 + i1 + i2 / c0)  # 2 [4 (c1 beta1 + J1(c1)) + (4 / c0)(c0 I1 + I2)]


@njit(cache=True, nogil=True)
def _complete_kd(y):  # pragma: no cover - compiled; tested against scipy.special.elliprf, elliprd, ellipk, ellipe
    """(K, D) = (R_F(0, y, 1), R_D(0, y, 1) / 3) for 0 < y <= 1: with m = 1 - y the complete elliptic integrals
    K(m) = integral_0^(pi/2) d phi / Delta and D(m) = (K - E) / m = integral_0^(pi/2) sin^2 phi d phi / Delta,
    Delta = sqrt(1 - m sin^2 phi), by the arithmetic-geometric mean (DLMF 19.8.1, 19.8.6): a_0 = 1, g_0 = sqrt(y),
    c_(n+1) = (a_n - g_n) / 2 = c_n^2 / (4 a_(n+1)) (c_1 = m / (2 (1 + sqrt(y))): no cancellation), K = pi / (2 AGM),
    K - E = K sum_(n>=0) 2^(n-1) c_n^2 with c_0^2 = m, so D = K (1/2 + sum_(n>=1) 2^(n-1) c_n^2 / m), a sum of
    positive terms.  Quadratic convergence: at most about 10 steps of one square root each for y down to 1e-300
    (Carlson's duplication, 170 ns per pair, would take most of Ward's K(u)).
    """
    m = 1.0 - y
    kc = math.sqrt(y)
    a = 0.5 * (1.0 + kc)
    g = math.sqrt(kc)
    c = 0.5 * m / (1.0 + kc)
    tot = c * c
    w = 1.0
    for _ in range(64):
        if c <= EPS * a:
            break
        an = 0.5 * (a + g)
        c = c * c / (4.0 * an)
        g = math.sqrt(a * g)
        a = an
        w *= 2.0
        tot += w * c * c
    k = 0.5 * math.pi / a
    return k, k * (0.5 + (tot / m if m > 0.0 else 0.0))


@njit(cache=True, nogil=True)
def _k_ward(mu, s, psi, u, sa):  # pragma: no cover - compiled; see ward_integrand_reference
    """K(u) of Ward's model (000 eq. 34) in the half-vector frame: the integral over the azimuth beta of h
    about N of 4 (wi.h) sqrt(N.wo) where N.wo > 0 (its 1 / sqrt(N.L) goes into the scale), for h at
    u = N.h, sa = sin(alpha); s = sin(theta_i), psi = pi/2 - theta_i.

    As in :func:`_k_half`, c = wi.h = c0 + d, N.wo = 2 u d, d = e0 + b cos(beta) >= 0 on the arc |beta| <
    beta0: K = 8 sqrt(2 u) (c0 I_1/2 + I_3/2), I_q = integral_0^beta0 d^q d beta, complete elliptic integrals
    (Carlson's R_F, R_D; :func:`_complete_kd`): with x = sin(beta / 2), d = T - 2 b x^2, T = d(0), on a partial arc (T <
    2 b, M = T / (2 b)) I_1/2 = 2 T / sqrt(2 b) (R_F - R_D / 3), I_-1/2 = 2 R_F / sqrt(2 b), the R at (0, 1 - M, 1);
    on the full circle (k^2 = 2 b / T <= 1) I_1/2 = 2 sqrt(T) E(k^2) = 2 sqrt(T) (R_F - k^2 R_D / 3),
    I_-1/2 = 2 R_F / sqrt(T) at (0, 1 - k^2, 1); and 3 I_3/2 = 4 e0 I_1/2 + (b^2 - e0^2) I_-1/2 (the
    recurrence (q + 1) I_(q+1) = (2q + 1) e0 I_q + q (b^2 - e0^2) I_(q-1), from d/d beta (d^q sin(beta)),
    whose boundary terms vanish).  T, 1 - M and 1 - k^2 come from :func:`_half_arc`'s exact angle forms.
    """
    live, b, c0, e0, _, beta0, low, f1, f2 = _half_arc(mu, s, psi, u, sa)
    if not live:
        return 0.0
    if beta0 == math.pi:  # the full circle: d(pi) = low >= 0, d(0) = T = low + 2 b
        top = low + 2.0 * b
        if b == 0.0:
            ih, imh = math.pi * math.sqrt(top), math.pi / math.sqrt(top)
        else:
            k2 = 2.0 * b / top
            rf, rd3 = _complete_kd(low / top)
            ih = 2.0 * math.sqrt(top) * (rf - k2 * rd3)
            imh = 2.0 * rf / math.sqrt(top)
        bb = -low * top  # b^2 - e0^2 = (b - e0)(b + e0)
    else:
        top = 0.5 * f1 / u  # T = a + b - c0
        gap = 0.5 * f2 / u  # 2 b - T = b - e0
        rf, rd3 = _complete_kd(gap / (2.0 * b))
        sb2 = math.sqrt(2.0 * b)
        ih = 2.0 * top / sb2 * (rf - rd3)
        imh = 2.0 * rf / sb2
        bb = gap * top
    i3h = (4.0 * e0 * ih + bb * imh) / 3.0
    return 8.0 * math.sqrt(2.0 * u) * (c0 * ih + i3h)


@njit(cache=True, nogil=True)
def _k_vcavity(mu, s, psi, u, sa):  # pragma: no cover - compiled; see vcavity_integrand_reference
    """K(u) of the V-cavity microfacet models with F = 1 (Cook-Torrance, 001 eq. 9-10; Torrance-Sparrow, 002
    eq. 10) in the half-vector frame, without their D(u): the integral over the azimuth beta of h about N of
    4 (wi.h) G N.wo / N.wo = 4 c G where N.wo > 0, G = min(1, 2 u min(mu, N.wo) / c) (001 eq. 10; the
    1 / (N.L) goes into the scale), i.e. 4 min(c, 2 u mu, 4 u^2 c - 2 u mu) with c = wi.h = a + b cos(beta)
    (N.wo = 2 u c - mu, as in :func:`_k_half`).  A minimum of three lines in c: on each range of c between
    their crossings (c = 2 u mu, mu / u, 2 u mu / (4 u^2 - 1)) and the arc's end c0 = mu / (2 u) the integral is
    p J0 + q J1, J0 = integral d beta and J1 = integral c d beta over {beta: c(beta) in the range}.  The arc's
    end (c0, b sin(beta0)) comes from the exact forms of _k_half; at the interior crossings X = c - a and
    S = b sin(beta) = sqrt((b - X)(b + X)) are consistent, so their rounding moves a kink of the (continuous)
    minimum and changes the integral only to second order.
    """
    live, b, c0, e0, sb0, _, _, _, _ = _half_arc(mu, s, psi, u, sa)
    if not live:
        return 0.0
    a = mu * u
    lo = max(c0, a - b)  # the range of c on the arc
    hi = a + b
    if b == 0.0:  # c = a on the whole circle (mu = 1 or h = N)
        g = min(a, 2.0 * u * mu, 4.0 * u * u * a - 2.0 * u * mu)
        return 8.0 * math.pi * g if a > c0 else 0.0
    # the lines' crossings inside (lo, hi), sorted (those outside stand at hi: their pieces are empty); scalars,
    # not an array: this runs at every node
    x1, x2 = 2.0 * u * mu, mu / u
    x3 = 2.0 * u * mu / (4.0 * u * u - 1.0) if 4.0 * u * u > 1.0 else hi
    x1, x2, x3 = (x1 if lo < x1 < hi else hi), (x2 if lo < x2 < hi else hi), (x3 if lo < x3 < hi else hi)
    x1, x2 = min(x1, x2), max(x1, x2)
    x2, x3 = min(x2, x3), max(x2, x3)
    x1, x2 = min(x1, x2), max(x1, x2)
    total = 0.0
    for j in range(4):
        c_lo = lo if j == 0 else (x1 if j == 1 else (x2 if j == 2 else x3))
        c_hi = x1 if j == 0 else (x2 if j == 1 else (x3 if j == 2 else hi))
        if not c_hi > c_lo:
            continue
        # X = c - a = b cos(beta) and S = b sin(beta) at both ends (c decreases with beta): the arc's end exactly
        # (X = -e0, S = b sin(beta0)), the circle's bottom and top (X = -+b, S = 0), the rest S = sqrt((b - X)(b + X))
        if j == 0 and c_lo == c0:
            x_lo, s_lo = -e0, sb0
        elif j == 0:
            x_lo, s_lo = -b, 0.0
        else:
            x_lo = c_lo - a
            s_lo = math.sqrt(max(0.0, (b - x_lo) * (b + x_lo)))
        if c_hi == hi:
            x_hi, s_hi = b, 0.0
        else:
            x_hi = c_hi - a
            s_hi = math.sqrt(max(0.0, (b - x_hi) * (b + x_hi)))
        # J0 = beta_lo - beta_hi and J1 = a J0 + S_lo - S_hi without cancellation: b^2 sin(J0) and S_lo - S_hi
        # from X_hi^2 - X_lo^2 = (c_hi - c_lo)(X_hi + X_lo) (thin pieces near grazing incidence, where the
        # integrand lives on arcs of width ~mu: the plain differences lost 8 digits at mu = 1e-8)
        dc, xs = c_hi - c_lo, x_hi + x_lo
        if x_lo * x_hi > 0.0:
            sin_b2 = b * b * dc * xs / (s_lo * x_hi + x_lo * s_hi)
        else:
            sin_b2 = s_lo * x_hi - x_lo * s_hi
        j0 = math.atan2(sin_b2, x_lo * x_hi + s_lo * s_hi)
        j1 = a * j0 + (dc * xs / (s_lo + s_hi) if s_lo + s_hi > 0.0 else 0.0)
        cm = 0.5 * (c_lo + c_hi)
        l1, l2, l3 = cm, 2.0 * u * mu, 4.0 * u * u * cm - 2.0 * u * mu
        if l1 <= l2 and l1 <= l3:
            total += j1  # G = 1: c
        elif l2 <= l3:
            total += 2.0 * u * mu * j0  # G = 2 u mu / c
        else:
            total += 4.0 * u * u * j1 - 2.0 * u * mu * j0  # G = 2 u N.wo / c
    return 8.0 * total  # 2 (both signs of beta) 4 c G


def vcavity_integrand_reference(mu: float, u) -> np.ndarray:
    """Plain twin of :func:`_k_vcavity` by scipy's QUADPACK over beta of 4 min(c, 2 u mu, 4 u^2 c - 2 u mu)
    where c > mu / (2 u) (split at the lines' crossings).
    """
    from scipy.integrate import quad

    s = math.sqrt((1.0 - mu) * (1.0 + mu))

    def one(uu):
        if uu <= 0:
            return 0.0
        b, a = s * math.sqrt((1.0 - uu) * (1.0 + uu)), mu * uu

        def g(t):
            c = a + b * math.cos(t)
            return 4.0 * min(c, 2 * uu * mu, 4 * uu * uu * c - 2 * uu * mu) if c > 0.5 * mu / uu else 0.0

        pts = [math.acos((cv - a) / b) for cv in (0.5 * mu / uu, 2 * uu * mu, mu / uu,
                                                  2 * uu * mu / (4 * uu * uu - 1) if 4 * uu * uu != 1 else -9.0)
               if b > 0 and abs((cv - a) / b) < 1]
        return 2.0 * quad(g, 0.0, math.pi, points=pts or None, epsabs=0, epsrel=1e-13, limit=200)[0]

    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return np.array([one(uu) for uu in np.atleast_1d(np.asarray(u, dtype=np.float64))])


def ward_integrand_reference(mu: float, u: np.ndarray) -> np.ndarray:
    """Plain numpy K(u) of :func:`_k_ward`: the arc integrals I_q = integral_0^beta0 (e0 + b cos(beta))^q
    d beta by scipy's QUADPACK (beta0 from arccos), K = 8 sqrt(2 u) (c0 I_1/2 + I_3/2).
    """
    from scipy.integrate import quad

    s = math.sqrt((1.0 - mu) * (1.0 + mu))

    def one(uu):
        if uu <= 0:
            return 0.0
        b, c0 = s * math.sqrt((1.0 - uu) * (1.0 + uu)), 0.5 * mu / uu
        e0 = mu * uu - c0
        beta0 = math.pi if e0 - b >= 0 else (0.0 if e0 + b <= 0 else math.acos(-e0 / b))
        if beta0 == 0.0:
            return 0.0
        ih, i3 = (quad(lambda t, q=q: max(e0 + b * math.cos(t), 0.0) ** q, 0.0, beta0, epsabs=0, epsrel=1e-13,
                       limit=200)[0]
                  for q in (0.5, 1.5))
        return 8.0 * math.sqrt(2.0 * uu) * (c0 * ih + i3)

    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # (QUADPACK's roundoff notes at 1e-13 on these smooth arcs)
        return np.array([one(uu) for uu in np.atleast_1d(np.asarray(u, dtype=np.float64))])


def half_moments_reference(x):
    """Plain numpy twins of :func:`_trig_tail`'s four functions, in closed form (exact in exact arithmetic;
    the tests compare them with the series at x >= 1e-2, where these lose at most ~10 digits of 16).
    """
    x = np.asarray(x, dtype=np.float64)
    return (x - np.sin(x), np.sin(x) - x * np.cos(x), x * (0.5 + np.cos(x) ** 2) - 1.5 * np.sin(x) * np.cos(x),
            1.5 * x - 2.0 * np.sin(x) + 0.25 * np.sin(2.0 * x))


def half_integrand_reference(p: float, mu: float, u: np.ndarray) -> np.ndarray:
    """Plain numpy K(u) of the half-vector frame (the readable twin of :func:`_k_half`), from the
    antiderivatives in beta of c and c^2 with beta from arccos:
    integral_0^beta (a + b cos t)^k dt = a beta + b sin(beta) (k = 1),
    a^2 beta + 2 a b sin(beta) + b^2 (beta / 2 + sin(2 beta) / 4) (k = 2).
    """
    u = np.asarray(u, dtype=np.float64)
    s = math.sqrt((1.0 - mu) * (1.0 + mu))
    a = mu * u
    b = s * np.sqrt((1.0 - u) * (1.0 + u))

    def ends(cv):  # beta where c = cv (0: none of the arc, pi: all of it)
        with np.errstate(divide="ignore", invalid="ignore"):
            return np.where(a - b >= cv, np.pi, np.where(a + b <= cv, 0.0, np.arccos(np.clip((cv - a) / b, -1, 1))))

    def i1(t):
        return a * t + b * np.sin(t)

    def i2(t):
        return a * a * t + 2 * a * b * np.sin(t) + b * b * (t / 2 + np.sin(2 * t) / 4)

    with np.errstate(divide="ignore", invalid="ignore"):
        c0 = np.where(u > 0, mu / (2 * u), np.inf)
        t0 = ends(c0)
        # 2 integral_0^beta0 4 c (2 c u - mu)
        k0 = 8 * (2 * u * i2(t0) - mu * i1(t0))
        if p == 0:
            return np.where(u > 0, k0, 0.0)
        t1 = ends(2 * c0)
        # N.wo / max(mu, N.wo): 4 c where N.wo >= mu, 4 c N.wo / mu elsewhere
        k1 = 8 * i1(t1) + 8 * ((2 * u * (i2(t0) - i2(t1)) - mu * (i1(t0) - i1(t1))) / mu)
        return np.where(u > 0, k1, 0.0)
