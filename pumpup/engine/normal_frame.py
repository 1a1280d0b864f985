"""Frame 6 of the 1-D routes (``normal``): GGX, Beckmann and Schlick's model about N, the weight's azimuth on each ring
in closed form (Kummer's function for Beckmann), a Fresnel factor per ring, pumping's g, 1/E's factor or F(max) per
node; :mod:`pumpup.engine.polar` describes the method.
"""

from __future__ import annotations

import math
import os

import numpy as np
from numba import njit

from ..core.hints import AzimuthHint
from ..physics.fresnel import conductor_scalar as _fresnel_real
from ..physics.fresnel import fresnel_pole
from ..physics.lookups import g_levels, g_product
from ..physics.lookups import scale_bound as _scale_bound
from ..physics.microfacet import projected as _projected
from ..physics.quadrature import calibrated, rule_sums
from .chain_frame import CHAIN_SAFETY
from .half_arc import SCHLICK, SMITH, _fresnel_at, numeric_params
from .hint_view import kernel_view
from .lobe_frame import INNER_RTOL_MIN
from .outer_rule import _bisect, _buffers, _status


@njit(cache=True, nogil=True, inline="always")
def _ggx_ring(a2, xmu, xs, d):  # pragma: no cover - compiled; see ring_reference
    """The integral over phi in [0, 2 pi) of the GGX weight D = a2 / (pi (1 - (1 - a2) (N.h)^2)^2) (Walter et al. 2007
    eq. 33; 000 eq. 36 with a2 = r) on the circle of wo at elevation x = x_mu + d (N.wo = sin x) for wi at elevation
    x_mu (x_s = pi / 2 - x_mu).

    With X = |wi + wo|^2 = P0 + Q cos(phi) and (N.h)^2 = m^2 / X, m = N.wi + N.wo, D = (a2 / pi) X^2 / (X - k)^2, k =
    (1 - a2) m^2, and the integral of (1 + k / Y)^2 over phi, Y = X - k = a' + Q cos(phi), is 2 pi (1 + 2 k / R + k^2 a'
    / R^3), R^2 = (a' - Q)(a' + Q).  Both factors are sums of squares: a' - Q = m^2 (a2 + tan^2(d / 2)), a' + Q = 4
    cos^2(d / 2) (a2 S^2 + C^2), S, C = sin, cos((x + x_mu) / 2), m = 2 S cos(d / 2); so, with A = a2 + tan^2(d / 2) and
    B = a2 S^2 + C^2, the integral is 2 a2 (1 + 2 (1 - a2) S / sqrt(A B) + (1 - a2)^2 S (S^2 A + B) / (2 (A B)^(3/2))):
    every term >= 0 for a2 <= 1 (no cancellation), no division by m (which vanishes at grazing incidence), and d, the
    offset from the peak, exact where the peak is narrow (a rule in x itself lost ulp(x) / alpha there: GGX alpha = 1e-5
    at mu = 0.9986 was 3e-13 off with an estimate of 9e-14), and cosines near pi / 2 as sines of x_s - ... (cos(x) of a
    rounded x near pi / 2 lost ulp(pi / 2) / alpha: alpha = 1e-8 at mu = 1 did not converge).
    """
    tau = math.tan(0.5 * d)
    sy, cy = math.sin(xmu + 0.5 * d), math.sin(xs - 0.5 * d)  # (cos(y) as sin(pi / 2 - y): exact near the normal)
    a = a2 + tau * tau  # (a' - Q) / m^2
    b = a2 * sy * sy + cy * cy  # (a' + Q) / (4 cos^2(d / 2))
    r = math.sqrt(a * b)
    k = 1.0 - a2
    return 2.0 * a2 * (1.0 + 2.0 * k * sy / r + k * k * sy * (sy * sy * a + b) / (2.0 * r * r * r))


#: frame 6 with a Fresnel factor (GGX, :func:`_ggx_ring_f`): the ring's product rule doubles its F samples from
#: RING_F_N0 + 1 to at most RING_F_NMAX + 1 on [0, pi]
RING_F_N0 = 16
RING_F_NMAX = 128
#: ... and takes |W_N - W_N/2| times the larger ratio of the last three such steps as W_N's error where both ratios are
#: at most this (geometric decay of F's coefficients; with the last ratio alone, from N = 16 on, it was 1100 x below the
#: true error of a strong absorber, eta 1.1, k 6, at itol 1e-6: measured by
#: scripts/calibration/ring_fresnel_calibration.py)
RING_F_RATIO = 0.5
#: :func:`_ring_f_sums` sums term by term where nn |1 - z| is below this (at most the sample n = 0, where 1 - rho < 2 /
#: nn: n >= 1 has |1 - z| >= rho sin(pi / nn)); summing term by term wherever |1 - z| < 0.25, up to ~nn / 12 samples
#: of nn + 1 terms each, took a quarter of GGX alpha 0.02 with ior 1.5's table time
RING_F_DIRECT = 2.0
#: sin^2(psi / 2) at psi = j pi / RING_F_NMAX (the finest level's samples; a coarser level takes every stride-th)
_RING_F_SIN2 = np.sin(0.5 * np.pi * np.arange(RING_F_NMAX + 1) / RING_F_NMAX) ** 2
#: cos(psi), sin(psi) there
_RING_F_COS = np.cos(np.pi * np.arange(RING_F_NMAX + 1) / RING_F_NMAX)
_RING_F_SIN = np.sin(np.pi * np.arange(RING_F_NMAX + 1) / RING_F_NMAX)


@njit(cache=True, nogil=True, inline="always")
def _ring_f_sums(rho, rn, n, nn, j):  # pragma: no cover - compiled; see ring_f_sums_reference
    """(C0, C1) = the sums over k = 0 .. nn, the first and last halved, of rho^k cos(k theta) and k rho^k cos(k theta)
    at theta = n pi / nn = j pi / RING_F_NMAX (``rn`` = rho^nn): geometric sums in z = rho e^(i theta), z^nn = (-1)^n
    rho^nn real, 1 - z = w = (1 - rho) + 2 rho sin^2(theta / 2) - i rho sin(theta) without cancellation.  sum k z^k = z
    N / w^2 with N = 1 - (nn + 1) z^nn + nn z^(nn + 1) = (1 - z^nn) - nn z^nn w: of size nn^2 |w|^2 where nn |w| is
    small, from terms of size nn |w| (the first form's terms are of size nn: it lost 2e-11 at nn = 128, n = 1).  Its
    error is then about eps (1 + nn |w|) / |w|^2, within a few eps of the sum's scale nn^2 where nn |w| >= 1; below
    RING_F_DIRECT, term by term.
    """
    zn = -rn if n % 2 else rn  # z^nn
    zr, zi = rho * _RING_F_COS[j], rho * _RING_F_SIN[j]
    p, r = (1.0 - rho) + 2.0 * rho * _RING_F_SIN2[j], zi  # 1 - z = p - i r
    dd = p * p + r * r
    if nn * nn * dd < RING_F_DIRECT * RING_F_DIRECT:  # (term by term)
        c0 = c1 = 0.0
        zk = complex(1.0, 0.0)
        z = complex(zr, zi)
        for k in range(nn + 1):
            h = 0.5 if k == 0 or k == nn else 1.0
            c0 += h * zk.real
            c1 += h * k * zk.real
            zk *= z
        return c0, c1
    # in real arithmetic, 1 / (1 - z) = (p + i r) / dd: sum z^k = (1 - zn z) / (1 - z), sum k z^k = z (1 - (nn + 1) zn +
    # nn zn z) / (1 - z)^2
    g0 = (((1.0 - zn) + zn * p) * p + zn * zi * r) / dd  # (1 - zn z = (1 - zn) + zn w)
    a = (1.0 - zn) - nn * zn * p  # N = a + i b
    b = nn * zn * r
    g1 = ((zr * a - zi * b) * (p * p - r * r) - (zr * b + zi * a) * (2.0 * p * r)) / (dd * dd)
    return g0 - 0.5 - 0.5 * zn, g1 - 0.5 * nn * zn


def ring_f_sums_reference(rho: float, n: int, nn: int) -> tuple:
    """:func:`_ring_f_sums` term by term in 40-digit mpmath (for the tests)."""
    import mpmath

    with mpmath.workdps(40):
        th = mpmath.pi * n / nn
        r = mpmath.mpf(rho)
        terms = [(mpmath.mpf(0.5) if k in (0, nn) else 1) * r ** k * mpmath.cos(k * th) for k in range(nn + 1)]
        return float(mpmath.fsum(terms)), float(mpmath.fsum(k * t for k, t in enumerate(terms)))


@njit(cache=True, nogil=True)
def _ggx_ring_f(mp, a2, xmu, xs, d, itol, tol_abs, fv):  # pragma: no cover - compiled; see ring_reference
    """(W, its error, F's samples): the integral over phi of the GGX weight D times the Fresnel factor F(wi.h) on the
    circle of wo at x = x_mu + d (:func:`_ggx_ring` with F; ``fv`` a work array of RING_F_NMAX + 1 values).

    On the circle, measured from the mirror side (psi = phi - pi), D = (a2 / pi)(1 + k / Y)^2 with Y = a' - Q cos(psi)
    (:func:`_ggx_ring`), whose Fourier cosine coefficients are closed forms: with rho = (sqrt(B) - S sqrt(A)) /
    (sqrt(B) + S sqrt(A)) (= (a' - R) / Q, no cancellation), the integral of D cos(k psi) is M_k = 2 a2 (delta_k0 +
    rho^k (2 k1 + t2 + k k1^2)), k1 = k / R = (1 - a2) S / sqrt(A B), t2 = k^2 a' / R^3 (M_0 is :func:`_ggx_ring`).  F
    depends on psi through c = wi.h = sqrt(S^2 + s cos(x) sin^2(psi / 2)) only, smooth and periodic: its cosine
    interpolant at psi = n pi / N (Chebyshev-Lobatto in cos psi) integrates against D exactly from the M_k, sum'' a_k
    M_k = (4 a2 / N) sum''_n F_n (1/2 + (2 k1 + t2) C0_n + k1^2 C1_n) (:func:`_ring_f_sums`).  N doubles from RING_F_N0
    until W_N's error is at most max(itol W_N, ``tol_abs``) or N = RING_F_NMAX: |W_N - W_N/2|, times the larger ratio of
    the last three such steps where both are at most RING_F_RATIO (from N = 32: the coefficients then decay
    geometrically, or faster, so W_N's error is below |W_N - W_N/2| times that ratio).  F's singularities limit the
    decay: c = 0, at psi = +- 2 i asinh(S / sqrt(s cos x)) (so S must not be small: :data:`N_FRESNEL_S_MIN`), and the
    index's (:func:`n_fresnel_ok`).
    """
    tau = math.tan(0.5 * d)
    sy, cy = math.sin(xmu + 0.5 * d), math.sin(xs - 0.5 * d)
    a = a2 + tau * tau
    b = a2 * sy * sy + cy * cy
    r = math.sqrt(a * b)
    k = 1.0 - a2
    k1 = k * sy / r
    al = 2.0 * k1 + k * k * sy * (sy * sy * a + b) / (2.0 * r * r * r)
    be = k1 * k1
    sa, sb = sy * math.sqrt(a), math.sqrt(b)
    rho = (sb - sa) / (sb + sa)
    q = math.sin(xs) * math.sin(xs - d)  # s cos(x)
    s2 = sy * sy
    stride = RING_F_NMAX // RING_F_N0
    for j in range(0, RING_F_NMAX + 1, stride):
        fv[j] = _fresnel_at(mp, math.sqrt(s2 + q * _RING_F_SIN2[j]))
    prev = _ring_f_level(fv, rho, al, be, RING_F_N0 // 2, 2 * stride)
    step, step2 = abs(prev - _ring_f_level(fv, rho, al, be, RING_F_N0 // 4, 4 * stride)), -1.0
    nn = RING_F_N0
    while True:
        w = _ring_f_level(fv, rho, al, be, nn, stride)
        e = abs(w - prev)
        # where the last three steps shrink, each by RING_F_RATIO at least (from N = 32 on: W_8 - W_4, W_16 - W_8,
        # W_32 - W_16), |W_N - W_N/2| times the larger of their two ratios; else |W_N - W_N/2|
        ratio = max(e / step, step / step2) if step > 0.0 and step2 > 0.0 else 1.0
        est = e * ratio if ratio <= RING_F_RATIO else e
        if est <= max(itol * w, tol_abs / (4.0 * a2)) or nn >= RING_F_NMAX:
            return 4.0 * a2 * w, 4.0 * a2 * (est + RING_F_ROUNDING * nn * w), nn + 1
        step, step2 = abs(w - prev), step
        prev = w
        stride //= 2
        for j in range(stride, RING_F_NMAX + 1, 2 * stride):  # the next level's new samples
            fv[j] = _fresnel_at(mp, math.sqrt(s2 + q * _RING_F_SIN2[j]))
        nn *= 2


@njit(cache=True, nogil=True, inline="always")
def _ring_f_level(fv, rho, al, be, nn, stride):  # pragma: no cover - compiled
    """The product rule of :func:`_ggx_ring_f` with nn + 1 samples (every ``stride``-th of ``fv``), over 4 a2."""
    tot = 0.0
    rn = rho ** nn
    for n in range(nn + 1):
        c0, c1 = _ring_f_sums(rho, rn, n, nn, n * stride)
        tot += (0.5 if n == 0 or n == nn else 1.0) * fv[n * stride] * (0.5 + al * c0 + be * c1)
    return tot / nn


#: the rounding of :func:`_ggx_ring_f`'s sums per unit of W and per sample: twice the 8 eps of their scale within which
#: tests/engine/test_route_normal_fresnel.py finds :func:`_ring_f_sums` against a summation term by term in 40-digit
#: mpmath
RING_F_ROUNDING = 16.0 * np.finfo(float).eps


def ring_reference(distribution: int, a2: float, mu: float, x: float, fresnel=None) -> float:
    """:func:`_ggx_ring` (``distribution`` 1) or :func:`_beckmann_ring` (0) at elevation ``x`` by scipy's adaptive
    quadrature of Walter's D over phi (their numpy/scipy twin, for the tests); with ``fresnel`` = (ior, eta, k), D times
    the Fresnel factor F(wi.h) (:func:`_ggx_ring_f`; pumpup.models.cook_torrance.fresnel, pumpup.models.metal.fresnel),
    graded towards the mirror side at the scale of S = sin((x + x_mu) / 2) too (F's branch point at c = 0; without it,
    at S ~ 0.05, scipy missed the feature by 3e-7, measured against mpmath).
    """
    from scipy.integrate import quad

    from ..physics.fresnel import fresnel_conductor as conductor
    from ..physics.fresnel import fresnel_dielectric as dielectric

    s = math.sqrt((1.0 - mu) * (1.0 + mu))
    wi = np.array([s, 0.0, mu])

    def d(phi):
        wo = np.array([math.cos(x) * math.cos(phi), math.cos(x) * math.sin(phi), math.sin(x)])
        h = wi + wo
        c2, s2 = h[2] * h[2] / (h @ h), (h[0] * h[0] + h[1] * h[1]) / (h @ h)  # cos^2, sin^2 of h's angle from N
        if distribution == 1:
            d = a2 / (math.pi * (a2 * c2 + s2) ** 2)  # Walter eq. 33: a2 / (pi (a2 cos^2 + sin^2)^2)
        else:
            t2 = s2 / c2
            d = math.exp(-t2 / a2) * (1.0 + t2) ** 2 / (math.pi * a2)  # Walter eq. 25
        if fresnel is None:
            return d
        c = float(wi @ h) / math.sqrt(h @ h)
        return d * float(conductor(c, fresnel[1], fresnel[2]) if fresnel[1] > 0.0 else dielectric(c, fresnel[0]))

    points = _peak_points(math.sqrt(a2))
    if fresnel is not None:  # (and towards F's branch point c = 0, at the scale of the ring's smallest c, S)
        points = sorted(points + _peak_points(math.sin(0.5 * (x + math.asin(mu)))))
    return 2.0 * quad(d, 0.0, math.pi, epsabs=0.0, epsrel=1e-13, limit=1000, points=points)[0]


def _peak_points(alpha: float) -> list:
    """Breakpoints in the azimuth phi in (0, pi) graded towards the mirror direction phi = pi, where a lobe alpha wide
    peaks (for scipy's quadrature in the references).
    """
    w = alpha * 3.0 ** np.arange(-4, 30)
    return list(math.pi - w[w < math.pi])


#: above this z, :func:`_kummer_half` sums the asymptotic series (its smallest term ~ sqrt(2 pi z) e^-z < 1e-20)
KUMMER_ASYMPTOTIC = 50.0


@njit(cache=True, nogil=True)
def _kummer_half(z):  # pragma: no cover - compiled; tested against mpmath.hyp1f1
    """(H0, H1, H2), H_j = z^j e^-z 1F1(1/2; j + 1; z) for z >= 0 (inf included): below KUMMER_ASYMPTOTIC the power
    series (positive terms, DLMF 13.2.2), above it the asymptotic one, z^(j - 1/2) (j! / sqrt(pi)) sum_n (j + 1/2)_n
    (1/2)_n / (n! z^n) (DLMF 13.7.1; positive terms too, the rest of the function e^-z smaller).
    """
    if z >= KUMMER_ASYMPTOTIC:
        r = 1.0 / math.sqrt(math.pi * z) if z < math.inf else 0.0
        h0 = h1 = h2 = 0.0
        for j in range(3):
            term, sm = 1.0, 1.0
            for n in range(200):
                term *= (j + 0.5 + n) * (0.5 + n) / ((n + 1.0) * z)
                sm += term
                if term <= 1e-17 * sm:
                    break
            if j == 0:
                h0 = r * sm
            elif j == 1:
                h1 = r * sm
            else:
                h2 = 2.0 * r * sm
        return h0, h1, h2
    t0 = t1 = t2 = 1.0
    s0 = s1 = s2 = 1.0
    n = 0
    while True:
        c = (0.5 + n) * z / (n + 1.0)
        t0 *= c / (1.0 + n)
        t1 *= c / (2.0 + n)
        t2 *= c / (3.0 + n)
        s0 += t0
        s1 += t1
        s2 += t2
        n += 1
        if n > z and t0 <= 1e-17 * s0:
            break
    e = math.exp(-z)
    return e * s0, z * e * s1, z * z * e * s2


#: :func:`_kummer_fast`'s Chebyshev pieces of H_j on [0, 200), interpolating :func:`_kummer_half` at KUMMER_DEGREE + 1
#: Chebyshev points each (built at import: at most 27 ulps of max H_j on the piece against 30-digit mpmath, the series
#: itself 10; the series took 120-670 ns a value there, the asymptotic one 130 ns up to 200, the pieces 70)
KUMMER_EDGES = np.array([0.0, 3.0, 8.0, 16.0, 28.0, 50.0, 80.0, 130.0, 200.0])
KUMMER_DEGREE = 18


def _kummer_table() -> np.ndarray:
    """The Chebyshev coefficients (piece, j, degree) of :data:`KUMMER_EDGES`' pieces (for :func:`_kummer_fast`)."""
    n = KUMMER_DEGREE + 1
    k = np.arange(n)
    ang = np.pi * (k + 0.5) / n
    cos = np.cos(np.outer(k, ang))  # [m, k]
    out = np.empty((len(KUMMER_EDGES) - 1, 3, n))
    for i, (a, b) in enumerate(zip(KUMMER_EDGES[:-1], KUMMER_EDGES[1:])):
        h = np.array([_kummer_half(0.5 * (a + b) + 0.5 * (b - a) * math.cos(t)) for t in ang])  # (k, j)
        c = (2.0 / n) * (cos @ h)
        c[0] *= 0.5
        out[i] = c.T
    return out


#: :func:`_kummer_table`, read from the package's data (computing it means running the compiled series at import);
#: ``tests/project/test_startup.py`` checks the file against :func:`_kummer_table`
KUMMER_COEF = np.load(os.path.join(os.path.dirname(__file__), "data", "kummer_chebyshev.npy"))


@njit(cache=True, nogil=True)
def _kummer_fast(z):  # pragma: no cover - compiled; tested against _kummer_half and mpmath
    """:func:`_kummer_half` by its Chebyshev pieces below 200 (Clenshaw's recurrence), the asymptotic series above."""
    if z >= KUMMER_EDGES[-1]:
        return _kummer_half(z)
    i = 0
    while z >= KUMMER_EDGES[i + 1]:
        i += 1
    a, b = KUMMER_EDGES[i], KUMMER_EDGES[i + 1]
    x = (2.0 * z - a - b) / (b - a)
    h0 = h1 = h2 = 0.0
    for j in range(3):
        b1 = b2 = 0.0
        for m in range(KUMMER_DEGREE, 0, -1):
            b1, b2 = 2.0 * x * b1 - b2 + KUMMER_COEF[i, j, m], b1
        v = x * b1 - b2 + KUMMER_COEF[i, j, 0]
        if j == 0:
            h0 = v
        elif j == 1:
            h1 = v
        else:
            h2 = v
    return h0, h1, h2


@njit(cache=True, nogil=True, inline="always")
def _beckmann_ring(a2, xmu, xs, d):  # pragma: no cover - compiled; see ring_reference
    """The integral over phi in [0, 2 pi) of the Beckmann weight D = exp(-tan^2(h) / a2) / (pi a2 cos^4(h)) (Walter et
    al. 2007 eq. 25) on the circle of wo at elevation x = x_mu + d, for wi at elevation x_mu (x_s = pi / 2 - x_mu).

    With X = |wi + wo|^2 = X_min + Q v, v = 1 - cos(psi) (psi = phi - pi, from the plane of incidence's mirror side),
    X_min = m^2 (1 + tan^2(d / 2)), Q = 2 sin(theta_i) cos(x), m = N.wi + N.wo: tan^2(h) = X / m^2 - 1 = tau^2 +
    (Q / m^2) v (tau = tan(d / 2)) and 1 / cos^4 = X^2 / m^4 = (1 + tau^2 + a2 kappa v)^2, kappa = Q / (m^2 a2), so the
    integral is e^-(tau^2 / a2) / (pi a2) times (1 + tau^2)^2 M0 + 2 (1 + tau^2) a2 kappa M1 + a2^2 kappa^2 M2, M_j =
    integral of v^j e^-(kappa v) over psi = c_j e^-z 1F1(1/2; j + 1; z), z = 2 kappa, c = (2 pi, 2 pi, 3 pi) (v = 2
    sin^2(psi / 2)): in :func:`_kummer_half`'s H_j, (e^-(tau^2 / a2) / a2) (2 (1 + tau^2)^2 H0 + 2 a2 (1 + tau^2) H1 +
    (3 / 4) a2^2 H2), every term >= 0.
    """
    tau = math.tan(0.5 * d)
    g = math.exp(-tau * tau / a2)
    if g == 0.0:  # (far in the Gaussian's tail: the rest is finite)
        return 0.0
    sy, cd = math.sin(xmu + 0.5 * d), math.cos(0.5 * d)
    m2 = 4.0 * sy * sy * cd * cd  # (N.wi + N.wo)^2, m = 2 sin((x + x_mu) / 2) cos(d / 2)
    q = 2.0 * math.sin(xs) * math.sin(xs - d)  # 2 sin(theta_i) cos(x)
    z = 2.0 * q / (m2 * a2) if m2 * a2 > 0.0 else math.inf
    h0, h1, h2 = _kummer_fast(z)
    w = 1.0 + tau * tau
    return g / a2 * (2.0 * w * w * h0 + 2.0 * a2 * w * h1 + 0.75 * a2 * a2 * h2)


@njit(cache=True, nogil=True, inline="always")
def _n_value(mp, mu, xmu, xs, d):  # pragma: no cover - compiled; see n_integrand_reference
    """Frame 6's integrand at x = x_mu + d: pi a2 cos(x) sin(x) W(x) Gamma(sin x), W the weight's integral over the
    azimuth (:func:`_ggx_ring`, :func:`_beckmann_ring`), Gamma = 1 / (P(mu) P(t)) for the separable Smith G (Walter et
    al. 2007 eq. 20), 1 / (t P(mu) + mu P(t) - mu t) for the height-correlated one (Heitz 2014), 1 / (r + (1 - r) t) for
    Schlick's model (000 eq. 36); P(t) = N.wo / G1(wo) (physics.microfacet.projected, Walter eq. 27, 34), P(mu) in
    mp[8].
    """
    a2 = mp[4] if mp[0] == SCHLICK else mp[4] * mp[4]
    w = _beckmann_ring(a2, xmu, xs, d) if mp[0] == SMITH and mp[1] == 0.0 else _ggx_ring(a2, xmu, xs, d)
    if w == 0.0:  # (far in the Beckmann weight's tail)
        return 0.0
    return _n_times(mp, mu, xmu, xs, d, a2, w)


@njit(cache=True, nogil=True, inline="always")
def _n_times(mp, mu, xmu, xs, d, a2, w):  # pragma: no cover - compiled; see n_integrand_reference
    """:func:`_n_value` of the ring's integral ``w``: pi a2 cos(x) sin(x) w Gamma(sin x) (1 for ``w`` the factor)."""
    t = math.sin(xmu + d)
    ct = math.sin(xs - d)  # cos(x)
    v = math.pi * a2 * ct * t * w
    if mp[0] == SCHLICK:
        return v / (mp[4] + (1.0 - mp[4]) * t)  # 000 eq. 36's 1 / (r + (1 - r) N.V)
    pt = _projected(ct, 0.0, t, int(mp[1]), int(mp[2]), mp[4])  # P(t) = N.wo / G1(wo), Walter eq. 27, 34
    return v / (mp[8] * pt if mp[3] == 0.0 else t * mp[8] + mu * pt - mu * t)  # Walter eq. 20; Heitz 2014


@njit(cache=True, nogil=True)
def _n_incidence(mp, mu):  # pragma: no cover - compiled
    """(x_mu, x_s = pi / 2 - x_mu) of incidence mu, both from atan2 (each exact near its own 0), and P(mu) = mu / G1(mu)
    into mp[8] for the Smith models (Walter eq. 27, 34).
    """
    s = math.sqrt((1.0 - mu) * (1.0 + mu))
    if mp[0] == SMITH:
        mp[8] = _projected(s, 0.0, mu, int(mp[1]), int(mp[2]), mp[4])
    return math.atan2(mu, s), math.atan2(s, mu)


@njit(cache=True, nogil=True, inline="always")
def _n_chain_g(chain, mu, t):  # pragma: no cover - compiled
    """g_1 ... g_k(mu, t) of a pumped chain at N.wo = t, as the chain kernel computes it
    (``pumpup.physics.lookups.g_product``, ``g_levels``; 001 eq. 16).
    """
    if min(mu, t) > chain.product_mlo:
        return g_product(max(mu, t), chain.product_cbase, chain.product_cell, chain.product_lo, chain.product_rows)
    return g_levels(max(mu, t), min(mu, t), chain.offsets, chain.logx, chain.coef, chain.v0, chain.slope0,
                    chain.margin_lo, chain.cap, chain.controlled, chain.increasing, chain.mu0, chain.index,
                    chain.index_lo, chain.index_h_inv)


@njit(cache=True, nogil=True)
def _n_rule(mp, mu, xmu, xs, lo, hi, nodes, wk, wg, buf, mode, chain, factor, itol, iacc,  # pragma: no cover - compiled
            fv, kind):
    """(value, error) of the rule on d = x - x_mu in [lo, hi] of :func:`_n_value`; with a pumped chain (``chain`` not
    None, :meth:`pumpup.operators.pumping.Pumped._chain_args`) divided by g_1 ... g_k(mu, N.wo) exactly as the chain
    kernel divides by it (001 eq. 16; written out as in :func:`_x_rule`; first times F(max(mu, N.wo)) where mp[15] = 1,
    ``FresnelAtMax``, analytic between the cuts), or with a 1/E-scaled model's ``factor`` (not None: F0 and
    :attr:`pumpup.operators.compensate._Bound.args`) times 1 + F0 (1 / U(N.wo) - 1) as its kernel multiplies (Turquin
    eq. 6, :func:`pumpup.operators.compensate._scale_kernel`); its error then the larger of QUADPACK's calibration (for
    the weight's peak, as without g) and CHAIN_SAFETY |K - G| (for the splines of g or U, which are not analytic:
    :data:`CHAIN_SAFETY`).  With a Fresnel factor (mp[13] = 1, GGX) the ring is :func:`_ggx_ring_f` at relative
    tolerance ``itol`` or absolute ``iacc`` / the node's factor (``fv`` its work array), and its errors are taken as
    frame 4 takes K's (:func:`_gk`): summed with the Kronrod weights, and into |K - G| before its calibration as far as
    they can hide it.  ``kind`` 0: the variable is d itself; 1 and 2 (a piece off the peak, GGX and Schlick): u = ln
    |d|, d = e^u or -e^u, the integrand times |d| (:data:`N_LOG_GRADE`); 3 (a piece near x = 0, GGX and Schlick): u = ln
    x, d = e^u - x_mu, the integrand times x (:data:`N_LOG_GRADE`).
    """
    h = hi - lo
    ie = 0.0
    noise = 0.0
    ns = 0
    for j in range(nodes.shape[0]):
        d = lo + h * nodes[j]
        jac = 1.0
        if kind != 0:
            jac = math.exp(d)
            d = jac if kind == 1 else (-jac if kind == 2 else jac - xmu)
        we, rf = 0.0, 0.0  # the ring's error and its factor to the node's units (:func:`_ggx_ring_f`)
        g = 1.0
        if mp[13] > 0.0:
            if chain is not None:  # (g first: the ring's absolute tolerance is in the units of the node divided by it)
                g = _n_chain_g(chain, mu, math.sin(xmu + d))
            a2 = mp[4] * mp[4]
            fac = _n_times(mp, mu, xmu, xs, d, a2, 1.0) * jac
            w, we, nf = _ggx_ring_f(mp, a2, xmu, xs, d, itol, iacc * g / fac if fac > 0.0 else math.inf, fv)
            ns += nf
            v = w * fac
            rf = fac
        else:
            v = _n_value(mp, mu, xmu, xs, d) * jac
        if mp[15] > 0.0 and v != 0.0:  # the fresnel wrapper's F(max(N.wi, N.wo)), 000 eq. 28 (``FresnelAtMax``)
            v *= _fresnel_real(max(mu, math.sin(xmu + d)), mp[16], mp[17])
        if chain is not None and v != 0.0:
            if mp[13] <= 0.0:
                g = _n_chain_g(chain, mu, math.sin(xmu + d))
            v /= g  # 001 eq. 16
            rf /= g
        ie += wk[j] * we * rf
        noise += (wk[j] + wg[j]) * we * rf
        if factor is not None and v != 0.0:
            u = _scale_bound(math.sin(xmu + d), factor[1], factor[2], factor[3], factor[4], factor[5], factor[6],
                             factor[7], factor[8], factor[9], factor[10], factor[11], factor[12])
            if factor[0] == 1.0:
                v /= u  # Turquin eq. 6 with F0 = 1: f / E(mu_o)
            else:
                v *= 1.0 + factor[0] * (1.0 / u - 1.0)  # Turquin eq. 6
        buf[j] = v
    k, diff, asc, ab = rule_sums(buf, wk, wg)
    e = calibrated((diff + noise) * h, asc * h, ab * h, mode) + ie * h
    return k * h, (max(e, CHAIN_SAFETY * diff * h + ie * h) if chain is not None or factor is not None else e), ns


@njit(cache=True, nogil=True)
def _n_values(mp, mu, x, chain, factor):  # pragma: no cover - compiled
    """:func:`_n_value` (divided by the chain's g, or times the scaled model's factor, where ``chain`` or ``factor`` is
    not None) at the elevations ``x`` (for the tests: the rule's own arithmetic, one node per call).
    """
    xmu, xs = _n_incidence(mp, mu)
    out = np.empty(x.shape[0])
    buf = np.empty(1)
    one = np.ones(1)
    for i in range(x.shape[0]):
        d = x[i] - xmu
        out[i] = _n_rule(mp, mu, xmu, xs, d, d + 1.0, np.zeros(1), one, one, buf, 1, chain, factor, INNER_RTOL_MIN, 0.0,
                         np.empty(RING_F_NMAX + 1), 0)[0]
    return out


def n_params(hint) -> np.ndarray:
    """Frame 6's parameter array: :func:`numeric_params`, and for GGX with a Fresnel factor mp[13] = 1
    (:func:`_ggx_ring_f`) and mp[14] the scale of F's pole near c = 0 (:func:`fresnel_pole`, a conductor's; 0 for a
    dielectric) for :func:`_n_cuts`; with F(max) = (eta, k) (``KernelView.fmax``) mp[15:18] = 1, eta, k
    (:func:`_n_rule`).
    """
    if isinstance(hint, AzimuthHint):
        hint = kernel_view(hint)
    mp = numeric_params(hint)
    if any(hint.fresnel):
        mp[13] = 1.0
        mp[14] = fresnel_pole(float(hint.fresnel[1]), float(hint.fresnel[2])) if hint.fresnel[1] > 0.0 else 0.0
    if hint.fmax is not None:  # 000 eq. 28's F(max(N.wi, N.wo)) of a conductor (eta, k): a factor per node (_n_rule)
        mp[15], mp[16], mp[17] = 1.0, *hint.fmax
    return mp


def n_integrand(brdf, mu: float, x) -> np.ndarray:
    """Frame 6's integrand (:func:`_n_value`, divided by g for a pumped model, times the factor of a 1/E-scaled one) for
    ``brdf``'s hint at N.wi = ``mu`` and elevations ``x`` of wo, as the engine computes it (for the tests).
    """
    hint = kernel_view(brdf.azimuth_hint())
    return _n_values(n_params(hint), float(mu), np.atleast_1d(np.asarray(x, dtype=float)), hint.chain, hint.factor)


def n_integrand_reference(brdf, mu: float, x) -> np.ndarray:
    """Frame 6's integrand (:func:`_n_value`) at elevations ``x`` from the model itself: its BRDF times N.wo integrated
    over the azimuth of wo by scipy's adaptive quadrature, times cos(x) and divided by the hint's scale (for the tests).
    """
    from scipy.integrate import quad

    s = math.sqrt((1.0 - mu) * (1.0 + mu))
    wi = np.array([[s, 0.0, mu]])
    hint = kernel_view(brdf.azimuth_hint())
    scale = float(hint.scale(np.array([mu]))[0])
    alpha = math.sqrt(hint.schlick) if hint.schlick is not None else hint.smith[3]
    out = []
    for xv in np.atleast_1d(np.asarray(x, dtype=float)):
        def f(phi):
            wo = np.array([[math.cos(xv) * math.cos(phi), math.cos(xv) * math.sin(phi), math.sin(xv)]])
            return float(brdf.eval(wi, wo)[0]) * math.sin(xv)

        out.append(2.0 * quad(f, 0.0, math.pi, epsabs=0.0, epsrel=1e-13, limit=1000, points=_peak_points(alpha))[0]
                   * math.cos(xv) / scale)
    return np.array(out)


#: frame 6 grades GGX's and Schlick's peak by this factor per cut, and integrates every piece off the peak in u = ln |d|
#: (:func:`_n_rule`): there the singularities at d = +- 2 i atanh(alpha) lie pi / 2 from the real axis whatever |d|, so
#: a piece [a, 27 a] (length ln 27 = 3.3 in u) is as far from them, relative to its length, as [a, 3 a] is in d (0.52 of
#: it instead of 0.5); GGX alpha = 1e-8 at mu = 1/2 took 34 graded pieces in d, now 14
N_LOG_GRADE = 27.0
#: ... on the side short of the peak only for |d| <= this times x_mu: towards x = 0, P(t)'s singularity (or Schlick's
#: pole) lies near d = -x_mu, ln 8 = 2.1 from u = ln(x_mu / 8) (at 1/2 a piece came within 0.23 of its length in u of
#: it, on the cuts at mu = 1; tests/engine/test_route_normal.py checks every piece in the variable it is integrated in)
#: ... and from x = 0 up to this times x_mu, by N_LOG_GRADE in u = ln x (:func:`_n_kind` 3):
#: P(t)'s singularities at x = +- i atanh(alpha) lie pi / 2 from the real u axis whatever x (Schlick's pole at
#: x ~ -r / (1 - r), pi), the peak's ln 8 beyond the last piece (GGX alpha = 1e-8 had 17 pieces graded by 3 in x there,
#: now 6)
N_LOG_SIDE = 0.125
#: ... and beyond it up to this times the range's end pi / 2 - x_mu (the weight's singularity at x = pi - x_mu + - 2 i
#: atanh(alpha), where B = 0, lies ln 2 beyond that end in u), then by 3 in u
N_LOG_END = 0.25


@njit(cache=True, nogil=True, inline="always")
def _n_kind(mp, a, b, xmu):  # pragma: no cover - compiled
    """The variable of frame 6's piece [a, b] of d (:func:`_n_rule`): for GGX and Schlick (not Beckmann's Gaussian) 1
    (u = ln d) beyond the peak, 2 (u = ln -d) short of it within N_LOG_SIDE x_mu, 3 (u = ln x, x = x_mu + d) near x = 0
    within N_LOG_SIDE x_mu but off x = 0 itself (:data:`N_LOG_GRADE`); else 0 (d).
    """
    if mp[0] == SMITH and mp[1] == 0.0:
        return 0
    if a > 0.0:
        return 1
    if b < 0.0 and a >= -N_LOG_SIDE * xmu:
        return 2
    if a > -xmu and b + xmu <= N_LOG_SIDE * xmu * (1.0 + 1e-12):
        return 3
    return 0


def n_pieces_reference(brdf, mu: float) -> list:
    """Frame 6's pieces for ``brdf``'s hint at N.wi = ``mu``: (lo, hi, kind) in d = x - x_mu, kind as :func:`_n_kind`
    (for the tests).
    """
    hint = kernel_view(brdf.azimuth_hint())
    mp = n_params(hint)
    cut = np.empty(N_CUTS)
    xmu = _n_incidence(mp, mu)[0]
    c = cut[:_n_cuts(mp, xmu, cut)]
    return [(a, b, _n_kind(mp, a, b, xmu)) for a, b in zip(c[:-1], c[1:]) if b > a]


#: frame 6's breakpoints per mu: 0, pi / 2, x_mu, Walter's switch and the graded ones (the peak's two sides, 2 x 17 at
#: alpha = 1e-8; from 0, up to 26 at Schlick's r = 1e-12; the x_mu grading takes what is left)
N_CUTS = 96


@njit(cache=True, nogil=True)
def _n_cuts(mp, xmu, cut):  # pragma: no cover - compiled; see n_cuts_reference
    """The breakpoints of frame 6's d = x - x_mu at incidence x_mu, sorted, into ``cut``; returns their number.  The
    integrand's singularities near x in [0, pi / 2] (:func:`_ggx_ring`, :func:`_n_value`): the weight's at x = x_mu +- 2
    i atanh(alpha) (A = 0) and at pi - x_mu +- 2 i atanh(alpha) (B = 0, as far beyond pi / 2 as x_mu is short of it);
    P(t)'s branch point at x = +- i atanh(alpha) (sin^2 x + alpha^2 cos^2 x = 0); Schlick's pole at sin x = -r /
    (1 - r); the height-correlated G's pole at x = -x_mu (t P(mu) + mu P(t) - mu t = 0 at t = -mu).  The Beckmann weight
    (:func:`_beckmann_ring`) is a Gaussian 2 alpha wide in d, its kappa has a pole where N.wi + N.wo = 0 (x = -x_mu),
    and its P(t) turns on the scale alpha near x = 0 (erf(tan(x) / alpha)); Walter's rational G1 jumps at N.wo = mp[9].
    So d is cut at 0 and +- 2 atanh(alpha) 3^j (Beckmann: +- 2 alpha 3^j; GGX and Schlick 27^j, in u = ln |d|, up to
    x_mu / 8 short of the peak and a quarter of the range's end beyond it, :data:`N_LOG_GRADE`), and x at z 3^j from 0
    (z = atanh(alpha), alpha or r / (1 - r), and x_mu for the correlated G and for Beckmann) and at Walter's switch:
    every piece then lies at least about its own length from the nearest singularity, in the variable it is integrated
    in.  With a Fresnel factor (mp[13], :func:`_ggx_ring_f`) x is also cut where the rings' smallest wi.h,
    sin((x + x_mu) / 2), is 3^j times the scales of F's pole (mp[14]) and branch point (mp[10]).
    """
    half = 0.5 * math.pi
    alpha = math.sqrt(mp[4]) if mp[0] == SCHLICK else mp[4]
    beckmann = mp[0] == SMITH and mp[1] == 0.0
    cut[0], cut[1], cut[2] = -xmu, half - xmu, 0.0
    m = 3
    if 0.0 < mp[9] < 1.0:  # Walter's G1 switch
        cut[m] = math.asin(mp[9]) - xmu
        m += 1
    d0 = 2.0 * alpha if beckmann else (2.0 * math.atanh(alpha) if alpha < 1.0 else math.inf)
    # beyond the peak (d > 0), then short of it; GGX and Schlick in u = ln |d| (:data:`N_LOG_GRADE`)
    for side in range(2):
        end = half - xmu if side == 0 else xmu
        top = end * (N_LOG_END if side == 0 else N_LOG_SIDE)  # (where the log grading stops)
        d = d0
        while d < end and m < cut.shape[0] - 2:
            cut[m] = d if side == 0 else -d
            m += 1
            d = 3.0 * d if beckmann or d >= top else min(N_LOG_GRADE * d, top)
    # (GGX, Schlick: by N_LOG_GRADE in u = ln x up to there, :func:`_n_kind`)
    top = 0.0 if beckmann else N_LOG_SIDE * xmu
    for which in range(2):
        if which == 0:
            if mp[0] == SCHLICK:
                d = mp[4] / (1.0 - mp[4]) if mp[4] < 1.0 else math.inf
            else:
                d = alpha if beckmann else (math.atanh(alpha) if alpha < 1.0 else math.inf)
        else:
            d = 3.0 * xmu if mp[0] == SMITH and (mp[3] != 0.0 or beckmann) else math.inf
        while d < half and m < cut.shape[0]:
            cut[m] = d - xmu
            m += 1
            d = min(N_LOG_GRADE * d, top) if which == 0 and d < top else 3.0 * d
    # GGX with F (:func:`_ggx_ring_f`): the rings' smallest wi.h, S = sin((x + x_mu) / 2), at F's scales
    if mp[13] > 0.0:
        for which in range(2):  # (the parallel reflectance's pole, the refracted cosine's branch point: mp[14], mp[10])
            z = mp[14] if which == 0 else mp[10]
            if not 0.0 < z < 1.0:
                continue
            while z > N_FRESNEL_S_MIN:
                z /= 3.0
            z *= 3.0
            while z < 1.0 and m < cut.shape[0]:
                d = 2.0 * math.asin(z) - 2.0 * xmu
                if -xmu < d < half - xmu:
                    cut[m] = d
                    m += 1
                z *= 3.0
    cut[:m].sort()
    return m


def n_cuts_reference(brdf, mu: float) -> np.ndarray:
    """:func:`_n_cuts` for ``brdf``'s hint at N.wi = ``mu``, as elevations x (for the tests)."""
    mp = n_params(kernel_view(brdf.azimuth_hint()))
    cut = np.empty(N_CUTS)
    xmu = _n_incidence(mp, mu)[0]
    m = _n_cuts(mp, xmu, cut)
    return cut[:m] + xmu


@njit(cache=True, nogil=True)
def _integrate_n(mp, mu_arr, rtol, atol_arr, max_intervals, rounding, nodes, wk, wg, mode, chain, factor, ecut, necut,
                 val, err, conv, evals):  # pragma: no cover
    """Frame 6: adaptive 10/21 quadrature over the elevation x = x_mu + d of wo (:func:`_n_rule`) for every mu, from the
    pieces between :func:`_n_cuts` and, for a pumped or a 1/E-scaled model (``chain`` or ``factor`` not None), the
    elevations ``ecut[q, :necut[q]]`` (:func:`chain_cuts` of the kinks of g or U).
    """
    cap, pk, t0, t1, kv, ke, buf, _, _, itol = _buffers(max_intervals + N_CUTS + ecut.shape[1], nodes, nodes, rtol)
    cut = np.empty(N_CUTS + ecut.shape[1])
    fv = np.empty(RING_F_NMAX + 1)
    kd = np.empty(cap, np.int64)
    for q in range(mu_arr.shape[0]):
        mu = mu_arr[q]
        xmu, xs = _n_incidence(mp, mu)
        nc = _n_cuts(mp, xmu, cut[:N_CUTS])
        for i in range(necut[q]):
            cut[nc] = ecut[q, i] - xmu
            nc += 1
        cut[:nc].sort()
        # a ring's absolute tolerance iacc / (the node's factor), iacc = itol times a lower bound of the integral so far
        # over the pieces' total length in their variables (d or ln |d|): its share of the sum is then at most itol
        # times that bound (as :func:`_integrate`)
        m = 0
        length = 0.0  # (of the pieces in their variables)
        for i in range(nc - 1):
            if cut[i + 1] > cut[i]:
                pk[m], t0[m], t1[m], kd[m] = i, cut[i], cut[i + 1], _n_kind(mp, cut[i], cut[i + 1], xmu)
                if kd[m] == 1:  # off the peak: u = ln |d| (:data:`N_LOG_GRADE`)
                    t0[m], t1[m] = math.log(cut[i]), math.log(cut[i + 1])
                elif kd[m] == 2:
                    t0[m], t1[m] = math.log(-cut[i + 1]), math.log(-cut[i])
                elif kd[m] == 3:  # near x = 0: u = ln x (:data:`N_LOG_GRADE`)
                    t0[m], t1[m] = math.log(cut[i] + xmu), math.log(cut[i + 1] + xmu)
                length += t1[m] - t0[m]
                m += 1
        acc = 0.0
        ns = 0
        for i in range(m):
            kv[i], ke[i], nf = _n_rule(mp, mu, xmu, xs, t0[i], t1[i], nodes, wk, wg, buf, mode, chain, factor, itol,
                                       itol * acc / length, fv, kd[i])
            acc += max(kv[i] - ke[i], 0.0)
            ns += nf
        start = m
        while True:
            tot, e, r, worst, ok = _status(kv, ke, m, 0.0, rounding, rtol, atol_arr[q])
            # (as :func:`_integrate_chain`: the reported error within the tolerance)
            if chain is not None or factor is not None:
                ok = ok and (e <= r or e + r <= max(rtol * abs(tot), atol_arr[q]))
            if ok or m - start >= max_intervals or m >= cap:
                break
            i, a_, mid, b_ = _bisect(pk, t0, t1, worst, m)
            kd[m] = kd[worst]
            iacc = itol * max(tot - e, 0.0) / length
            kv[worst], ke[worst], nf = _n_rule(mp, mu, xmu, xs, a_, mid, nodes, wk, wg, buf, mode, chain, factor, itol,
                                               iacc, fv, kd[worst])
            ns += nf
            kv[m], ke[m], nf = _n_rule(mp, mu, xmu, xs, mid, b_, nodes, wk, wg, buf, mode, chain, factor, itol, iacc,
                                       fv, kd[m])
            ns += nf
            m += 1
        val[q] = tot
        err[q] = e + r
        conv[q] = ok
        evals[q] = nodes.shape[0] * (m + (m - start)) + ns  # (and F's samples on the rings, :func:`_ggx_ring_f`)


#: frame 6 takes GGX with a Fresnel factor (:func:`_ggx_ring_f`) at the incidences where every ring's smallest wi.h, S =
#: sin((x + x_mu) / 2), is at least this (mu >= :data:`N_FRESNEL_MU_MIN`): F(c) has a square-root branch point at c = 0,
#: which for S below ~0.1 lies too close for the ring's RING_F_NMAX + 1 samples (measured: S = 0.05 was 1e-7 off at N =
#: 64); frame 4 takes the incidences below it
N_FRESNEL_S_MIN = 0.125
N_FRESNEL_MU_MIN = math.sin(2.0 * math.asin(N_FRESNEL_S_MIN))
#: ... and an index whose F(c) has no other singularity within this of [N_FRESNEL_S_MIN, 1] (:func:`n_fresnel_ok`)
N_FRESNEL_SING_MIN = 0.1


def n_fresnel_ok(ior: float, eta: float, k: float) -> bool:
    """Whether frame 6 takes the Fresnel factor of a dielectric ``ior`` or a conductor (``eta``, ``k``): F(c)'s
    singularities but c = 0 (the refracted cosine's branch points +- w, w = sqrt(1 - index^2); the parallel
    reflectance's poles, on the physical sheet in the left half-plane, :func:`fresnel_pole`) at least
    :data:`N_FRESNEL_SING_MIN` from the rings' range of c, [:data:`N_FRESNEL_S_MIN`, 1].  A dielectric with ior > 1 has
    w on the imaginary axis; ior <= 1 (a total reflection's kink at c = w real) and a near-kink conductor
    (w near the real segment) stay with frame 4.  Schlick's factor (ior = -1 - f0 < 0, :func:`_fresnel_at`) is a
    polynomial in c: c = 0 is its only singularity.
    """
    if ior < 0.0:
        return True
    if eta > 0.0:
        w = complex(1.0 - (eta * eta - k * k), -2.0 * eta * k) ** 0.5
        x = min(max(abs(w.real), N_FRESNEL_S_MIN), 1.0)
        return abs(complex(abs(w.real) - x, w.imag)) >= N_FRESNEL_SING_MIN
    return ior > 1.0
