"""Frame 0 of the 1-D routes (``lobe``): a power lobe's azimuth about R in closed form, and the inner rules on arcs
(Gauss-Legendre with an a-priori bound, Gauss-Jacobi at an arc's end) that frames 0-5 share; :mod:`pumpup.engine.polar`
describes the method.
"""

from __future__ import annotations

import functools
import math

import numpy as np
from numba import njit

from ..physics.quadrature import EPS, calibrated, mode_code

#: relative rounding error of the 1-D quadrature (per unit of sum |K|): the integrand is a few
#: elementary functions of u, accurate to a few ulp, summed over a few hundred nodes
ROUNDING = 64.0 * np.finfo(float).eps

#: initial subintervals of every piece (1 since the calibrated estimate: every piece is smooth
#: after its substitution, and 2 only doubled the evaluations; measured in scripts/calibration/error_calibration.py)
N_INIT = 1

#: the inner rule on the arc where N.wo >= mu (p in (0, 1)), should the Gauss-Legendre bound (:func:`_arc_bound`) want
#: more than GL_MAX points, is the engine's 7/15 Gauss-Kronrod pair, globally adaptive on at most INNER_MAX intervals
INNER_MAX = 64
#: the inner rule's relative tolerance is rtol / 8, but not below this (its rounding floor is
#: QUADPACK's 50 eps of the integral)
INNER_RTOL_MIN = 1e-14
#: the orders of the Gauss-Jacobi rules on the arc's end near grazing incidence (:func:`_arc_power`,
#: :func:`_jacobi_bound`)
JACOBI_ORDERS = (10, 14)


@njit(cache=True, nogil=True)
def _arc_rule(q, a, b, lo, hi, nodes, wk, wg, mode, ibuf):  # pragma: no cover - compiled
    """(value, error) of the rule on beta in [lo, hi] for the integrand (a + b cos beta)^q."""
    h = hi - lo
    k = 0.0
    g = 0.0
    ab = 0.0
    for j in range(nodes.shape[0]):
        f = (a + b * math.cos(lo + h * nodes[j])) ** q
        ibuf[j] = f
        k += wk[j] * f
        g += wg[j] * f
        ab += wk[j] * abs(f)
    asc = 0.0
    if mode != 0:
        for j in range(nodes.shape[0]):
            asc += wk[j] * abs(ibuf[j] - k)
    return k * h, calibrated(abs(k - g) * h, asc * h, ab * h, mode)


@njit(cache=True, nogil=True)
def _jacobi_sum(q, top, low, c, jt, jw):  # pragma: no cover - compiled
    """integral_0^c t^q / sqrt((top - t)(t - low)) dt by the Gauss-Jacobi rule (nodes ``jt`` on
    [0, 1], weights ``jw`` for the weight t^q).
    """
    s = 0.0
    for j in range(jt.shape[0]):
        t = c * jt[j]
        s += jw[j] / math.sqrt((top - t) * (t - low))
    return c ** (q + 1.0) * s


#: the Bernstein ellipse of :func:`_jacobi_bound`: log(rho) = JACOBI_RHO log(rho_max), at most JACOBI_LOG_RHO_CAP
#: (rho_max overflows where c = mu is subnormal: a hypothesis test found mu = 5e-324 giving a NaN error)
JACOBI_RHO = 0.95
JACOBI_LOG_RHO_CAP = math.log(1e4)


@njit(cache=True, nogil=True)
def _jacobi_bound(q, top, low, c, n):  # pragma: no cover - compiled; see the tests' mpmath check
    """A bound of the n-point Gauss-Jacobi rule's error in :func:`_jacobi_sum` (low < 0 < c < top).  With t = c (1 + x)
    / 2, g(t) = ((top - t)(t - low))^-1/2 is analytic but at x_T = 2 top / c - 1 > 1 and x_L = 2 low / c - 1 < -1 (the
    square root's cuts lie on the real axis beyond them), so inside the Bernstein ellipse E_rho, |x| <= A =
    (rho + 1/rho) / 2 < min(x_T, -x_L), |g| <= M = 2 / (c sqrt((x_T - A)(-x_L - A))) (computed in t's units, finite as
    c -> 0).  A Gauss rule with a positive weight errs by at most 2 W E_(2n-1)(g), W = c^(q+1) / (q + 1) the weight's
    integral, and E_m(g) <= 2 M rho^-m / (rho - 1) (Trefethen, ATAP Thm 8.2): the bound is 4 W M rho^(1 - 2n) /
    (rho - 1).
    """
    xt = 2.0 * top / c - 1.0  # (inf where c is tiny: rho is then capped)
    xl = 1.0 - 2.0 * low / c
    r = min(xt, xl)
    rho = math.exp(min(JACOBI_RHO * math.log(r + math.sqrt((r - 1.0) * (r + 1.0))), JACOBI_LOG_RHO_CAP))
    big_a = 0.5 * (rho + 1.0 / rho)
    # M in t's units: the ellipse's ends lie at t = c (1 -+ A) / 2, so |T - t| >= T - c (1 + A) / 2 and |t - L| >= -L -
    # c (A - 1) / 2
    m = 1.0 / math.sqrt((top - 0.5 * c * (1.0 + big_a)) * (-low - 0.5 * c * (big_a - 1.0)))
    return 4.0 * c ** (q + 1.0) / (q + 1.0) * m * rho ** (1.0 - 2.0 * n) / (rho - 1.0)


@njit(cache=True, nogil=True, inline="always")
def _tally(val, err, m, tot, e):  # pragma: no cover - compiled
    """(value, error, the interval with the largest error) of an adaptive rule's first m intervals, the
    sums starting from ``tot`` and ``e``.
    """
    worst = 0
    for i in range(m):
        tot += val[i]
        e += err[i]
        if err[i] > err[worst]:
            worst = i
    return tot, e, worst


#: the Gauss-Legendre rules of the arc's piece in s (:func:`_arc_bound`), n = 1 .. GL_MAX points: row n holds the
#: nodes x >= 0 (``GL_X``) and their weights, doubled for x > 0 (``GL_W``): the piece's integrand is even in s
GL_MAX = 64


def _gl_tables():
    xs, ws = np.zeros((GL_MAX + 1, (GL_MAX + 1) // 2)), np.zeros((GL_MAX + 1, (GL_MAX + 1) // 2))
    for n in range(1, GL_MAX + 1):
        x, w = np.polynomial.legendre.leggauss(n)  # (ascending; an odd rule's middle node is 0)
        k = (n + 1) // 2
        xs[n, :k], ws[n, :k] = x[::-1][:k], 2.0 * w[::-1][:k]  # the nonnegative half, largest first
        if n % 2:
            ws[n, k - 1] = w[n // 2]  # the middle node, once
    xs.flags.writeable = False
    ws.flags.writeable = False
    return xs, ws


GL_X, GL_W = _gl_tables()
#: the Bernstein ellipse of the piece's bound (:func:`_arc_bound`): log(rho) at most ARC_RHO_BRANCH times that of the
#: ellipse through t^q's branch point (the integrand stays bounded up to it) and ARC_RHO_POLE times that through the
#: pole of (t - L)^-1/2.  Measured over a 257-point table's nodes (q 0.1, 0.5, 0.9; itol 1.25e-7 .. 1.25e-13): 0.03 %
#: more values than the best of eight ellipses from 0.5 to 0.999 per call
ARC_RHO_BRANCH = 0.999
ARC_RHO_POLE = 0.99


@njit(cache=True, nogil=True)
def _arc_bound(q, big_t, d, b, c, tol):  # pragma: no cover - compiled; see arc_piece_reference
    """(n, bound): the fewest Gauss-Legendre points (at most GL_MAX; GL_MAX + 1 if none suffices) whose error on
    P = sqrt(D) c integral_-1^1 F(c x) dx, F(s) = t^q (t - L)^-1/2, t = T - D s^2, is at most ``tol``, and that error
    bound.  F is analytic but where t = 0 (s^2 = s0^2 = T / D, t^q's branch point) or t = L (s^2 = s1^2 = 2 b / D,
    a pole of order 1/2): inside the Bernstein ellipse E_rho of x, |x| <= A = (rho + 1 / rho) / 2, so where c A <
    min(s0, s1) |t| <= T + D c^2 A^2 < 2 T and |t - L| = D |s1^2 - s^2| >= D (s1^2 - c^2 A^2): |F| <= M = (2 T)^q /
    sqrt(D (s1^2 - c^2 A^2)).  The n-point Gauss rule's error is then at most 64 M / (15 (1 - rho^-2) rho^(2 n))
    (Trefethen, Approximation Theory and Approximation Practice, Thm 19.3) times sqrt(D) c.  log(rho) is the smaller of
    ARC_RHO_BRANCH log(rho_0) and ARC_RHO_POLE log(rho_1), rho_i the ellipse through s_i / c.
    """
    s0sq = big_t / d
    s1sq = 2.0 * b / d
    best_n = GL_MAX + 1
    best = 0.0
    if not tol > 0.0:
        return best_n, best
    r0, r1 = math.sqrt(s0sq) / c, math.sqrt(s1sq) / c  # (both > 1: s0^2 >= 4/3, s1^2 >= 2, c^2 = s0^2 / 2 beyond 4 mu)
    lrho = min(ARC_RHO_BRANCH * math.log(r0 + math.sqrt((r0 - 1.0) * (r0 + 1.0))),
               ARC_RHO_POLE * math.log(r1 + math.sqrt((r1 - 1.0) * (r1 + 1.0))))
    rho = math.exp(lrho)
    big_a = 0.5 * (rho + 1.0 / rho)
    gap = s1sq - c * c * big_a * big_a
    if gap > 0.0:
        # log of sqrt(D) c 64 M / (15 (1 - rho^-2) tol)
        lb = math.log(c * 64.0 / 15.0 * (2.0 * big_t) ** q / (math.sqrt(gap) * (1.0 - 1.0 / (rho * rho)) * tol))
        n = max(1.0, math.ceil(lb / (2.0 * lrho)))
        if n <= GL_MAX:
            best_n = int(n)
            best = math.exp(lb - 2.0 * n * lrho) * tol
    return best_n, best


@njit(cache=True, nogil=True)
def _arc_piece(q, big_t, d, b, c, n):  # pragma: no cover - compiled; see arc_piece_reference
    """P = sqrt(D) c integral_-1^1 F(c x) dx by the n-point Gauss-Legendre rule, F even (:func:`_arc_bound`):
    integral_(T - D c^2)^T t^q / sqrt((T - t)(t - L)) dt with t = T - D s^2, 2 b = T - L.
    """
    tot = 0.0
    for j in range((n + 1) // 2):
        s2 = c * c * GL_X[n, j] * GL_X[n, j]
        t = big_t - d * s2
        tot += GL_W[n, j] * t**q / math.sqrt(2.0 * b - d * s2)
    return math.sqrt(d) * c * tot


@njit(cache=True, nogil=True)
def _arc_power(q, mu, a, b, d1, beta1, rtol, rest, nodes, wk, wg, mode, ibuf, iwork,  # pragma: no cover - compiled
               jac):
    """(H, error) of H = integral_0^beta1 (a + b cos beta)^q d beta, q = 1 - p in (0, 1): the arc
    where N.wo = a + b cos beta >= mu (000 eq. 12's max(N.L, N.V) = N.wo there); d1 = b^2 - (mu - a)^2.

    With t = N.wo, d beta = dt / sqrt((T - t)(t - L)), T = a + b (beta = 0), L = a - b: H is
    integral_mu^T t^q / sqrt((T - t)(t - L)) dt.  Where T > 4 mu (near grazing incidence: (N.wo)^q
    then nears its branch point t = 0 at the arc's end), the range t in [mu, T / 2] is
    integral_0^(T/2) - integral_0^mu by the Gauss-Jacobi rule for the weight t^q (``jac``: nodes and
    weights of two orders): the rest of the integrand has its singularities at T and at L <= mu - (T - 2 mu) < -T / 2,
    at least T / 2 away, so the rules converge geometrically, and the shorter one is taken where its a-priori bound
    (:func:`_jacobi_bound`) meets half the tolerance, the longer one else, the bound its error.  The rest,
    t from T - D c^2 (mu, or T / 2 beyond 4 mu) to T, is t = T - D s^2, s in [0, c] (D = T - mu = d1 / (b + mu - a),
    without cancellation): an even, analytic integrand in s (:func:`_arc_piece`), by the fewest Gauss-Legendre
    points whose a-priori error bound (:func:`_arc_bound`) meets ``rtol`` times a lower bound of K = ``rest`` + H
    (``rest`` >= 0, H >= beta1 mu^q), its rounding added; about 5 values of t^q per call where the 7/15 rule in beta
    takes 15 to 45.  Should the bound want more than GL_MAX points, the piece is
    the 7/15 rule in beta, globally adaptive on at most INNER_MAX intervals (``iwork``, 4 x INNER_MAX), until
    the summed calibrated error meets the same tolerance; the error is returned either way.
    """
    if beta1 <= 0.0:
        return 0.0, 0.0
    top = a + b
    d = d1 / (b + (mu - a))  # T - mu
    fixed = 0.0  # the Gauss-Jacobi part and its error
    fixed_err = 0.0
    end = beta1
    c = 1.0
    low_h = beta1 * mu**q  # H's lower bound: t >= mu on the arc (and t >= T / 2 on the piece beyond the Jacobi part)
    if top > 4.0 * mu:
        low = a - b
        half = 0.5 * top
        # the shorter rule where its bound (:func:`_jacobi_bound`) is at most half the tolerance's lower bound, else the
        # longer one, its bound the error either way (plus the sums' rounding)
        n1, n2 = JACOBI_ORDERS
        tol0 = rtol * (rest + low_h)
        e1 = _jacobi_bound(q, top, low, half, n1) + _jacobi_bound(q, top, low, mu, n1)
        if e1 <= 0.5 * tol0:
            fixed = (_jacobi_sum(q, top, low, half, jac[0, :n1], jac[1, :n1])
                     - _jacobi_sum(q, top, low, mu, jac[0, :n1], jac[1, :n1]))
        else:
            fixed = _jacobi_sum(q, top, low, half, jac[2], jac[3]) - _jacobi_sum(q, top, low, mu, jac[2], jac[3])
            e1 = _jacobi_bound(q, top, low, half, n2) + _jacobi_bound(q, top, low, mu, n2)
        fixed_err = e1 + 64.0 * EPS * abs(fixed)
        end = math.acos((half - a) / b)
        c = math.sqrt(half / d)  # T - D c^2 = T / 2
    if fixed > 0.0:
        low_h = max(low_h, fixed - fixed_err + end * (0.5 * top) ** q)
    tol = rtol * (rest + low_h)
    n, bound = _arc_bound(q, top, d, b, c, max(tol - fixed_err, 0.5 * tol))
    if n <= GL_MAX:
        h = _arc_piece(q, top, d, b, c, n)
        return fixed + h, fixed_err + bound + (n + 16) * EPS * h  # n / 2 terms of a few roundings each, and T, D's
    lo, hi, val, err = iwork[0], iwork[1], iwork[2], iwork[3]
    lo[0], hi[0] = 0.0, end
    val[0], err[0] = _arc_rule(q, a, b, 0.0, end, nodes, wk, wg, mode, ibuf)
    m = 1
    while True:
        tot, e, worst = _tally(val, err, m, fixed, fixed_err)
        if e <= rtol * (rest + max(tot - e, beta1 * mu**q)) or m >= lo.shape[0]:
            return tot, e
        mid = 0.5 * (lo[worst] + hi[worst])
        lo[m], hi[m] = mid, hi[worst]
        hi[worst] = mid
        val[worst], err[worst] = _arc_rule(q, a, b, lo[worst], mid, nodes, wk, wg, mode, ibuf)
        val[m], err[m] = _arc_rule(q, a, b, mid, hi[m], nodes, wk, wg, mode, ibuf)
        m += 1


def arc_piece_reference(q: float, mu: float, a: float, b: float, d1: float, c: float = 1.0) -> float:
    """The arc's piece in s (:func:`_arc_piece`) in plain numpy, for N.wo = a + b cos(beta), d1 = b^2 - (mu - a)^2:
    P by numpy's 200-point Gauss-Legendre rule in s on [0, c] (c = 1: t from mu to T; the compiled kernel's twin).
    """
    d = d1 / (b + (mu - a))  # (mu - a first: b + mu would round b away near mu = 1)
    x, w = np.polynomial.legendre.leggauss(200)
    sx = c * x
    t = a + b - d * sx * sx
    return float(math.sqrt(d) * c * np.sum(w * t**q / np.sqrt(2.0 * b - d * sx * sx)))


#: the unused Gauss-Jacobi argument of the closed forms p in {0, 1} (read-only, as jacobi_rules' arrays:
#: one compiled signature)
_NO_JACOBI = np.zeros((4, 1))
_NO_JACOBI.flags.writeable = False


@functools.lru_cache(maxsize=256)
def jacobi_rules(q: float) -> np.ndarray:
    """Nodes on [0, 1] and weights of the Gauss-Jacobi rules for integral_0^1 t^q g(t) dt, of
    :data:`JACOBI_ORDERS` (the shorter, the longer: :func:`_arc_power`): rows t, w of the first, t, w of the second
    (read-only, cached per q: scipy computes them in about 0.1 ms).
    """
    from scipy.special import roots_jacobi

    lo_n, hi_n = JACOBI_ORDERS
    out = np.zeros((4, hi_n))
    for row, n in ((0, lo_n), (2, hi_n)):
        x, w = roots_jacobi(n, 0.0, q)  # weight (1 + x)^q on [-1, 1]
        out[row, :n] = 0.5 * (x + 1.0)
        out[row + 1, :n] = w / 2.0 ** (q + 1.0)  # (the shorter rule is padded: _arc_power reads its first n)
    out.flags.writeable = False
    return out


@njit(cache=True, nogil=True)
def _k_closed(p, mu, c2, u, um, sa):  # pragma: no cover - compiled; see integrand_reference
    """(K, beta1, below) for u = cos(alpha), um = 1 - u, sa = sin(alpha); c2 = cos(2 theta_i): K is
    the integral over the visible arc of N.wo / max(mu, N.wo)^p in closed form for p in {0, 1} (for
    other p, the p = 1 value); beta1 is the half-arc where N.wo >= mu (p > 0) and ``below`` the
    integral of N.wo over the half-arc where 0 < N.wo < mu.
    """
    a = mu * u
    d0 = (sa - mu) * (sa + mu)  # b^2 - a^2 = sin^2(alpha) - mu^2
    if d0 > 0.0:
        bs0 = math.sqrt(d0)  # b sin(beta0)
        beta0 = math.atan2(bs0, -a)  # cos(beta0) = -a / b
    else:
        bs0 = 0.0
        beta0 = math.pi
    if p == 0.0:
        return 2.0 * (a * beta0 + bs0), 0.0, 0.0  # 2 (a beta0 + b sin beta0)
    d1 = um * (u - c2)  # b^2 - (mu - a)^2
    if d1 > 0.0:
        bs1 = math.sqrt(d1)
        beta1 = math.atan2(bs1, mu * um)  # cos(beta1) = (mu - a) / b
    else:
        bs1 = 0.0
        beta1 = 0.0
    if bs0 > 0.0 and bs1 > 0.0:
        diff = mu * mu * (1.0 - 2.0 * u) / (bs0 + bs1)  # b sin(beta0) - b sin(beta1), no cancellation
    else:
        diff = bs0 - bs1
    below = a * (beta0 - beta1) + diff
    return 2.0 * (beta1 + below / mu), beta1, below  # 000 eq. 7: N.wo / max(mu, N.wo)


@njit(cache=True, nogil=True, inline="always")  # (a call passes 6 arrays, with reference counts, per node)
def _k_of_u(p, mu, c2, u, um, sa, itol, nodes, wk, wg, mode,  # pragma: no cover - compiled; see integrand_reference
            ibuf, iwork, jac):
    """(K(u), its error): K is the integral over the visible arc of N.wo / max(mu, N.wo)^p, for
    u = cos(alpha), um = 1 - u, sa = sin(alpha); c2 = cos(2 theta_i).  Closed form for p in
    {0, 1} (:func:`_k_closed`); for p in (0, 1) the arc where N.wo >= mu by :func:`_arc_power`
    (relative error ``itol``), the rest in closed form.  The error is 0 for the closed forms.
    """
    k, beta1, below = _k_closed(p, mu, c2, u, um, sa)
    if p == 0.0 or p == 1.0:
        return k, 0.0
    # 000 eq. 12: N.wo / max(mu, N.wo)^p, (N.wo)^(1 - p) on the arc N.wo >= mu
    below = below / mu**p
    b = math.sqrt((1.0 - mu) * (1.0 + mu)) * sa  # s sin(alpha)
    h, e = _arc_power(1.0 - p, mu, mu * u, b, um * (u - c2), beta1, itol, below, nodes, wk, wg, mode, ibuf, iwork, jac)
    return 2.0 * (h + below), 2.0 * e


def integrand_reference(n: float, p: float, mu: float, u: np.ndarray) -> np.ndarray:
    """Plain numpy u^n K(u), straight from the arccos form (the readable twin of the kernel).

    K(u) = J(a, b) for p = 0 and (J(a, b) - J(a - mu, b)) / mu for p = 1, with
    J(a, b) = integral over beta of (a + b cos beta)_+ = 2 (a acos(-a/b) + b sin(acos(-a/b))),
    a = mu u, b = s sqrt(1 - u^2).  For p in (0, 1): (J(a, b) - J(a - mu, b)) / mu^p for the arc
    where N.wo < mu, plus 2 integral_0^beta1 (a + b cos beta)^(1 - p) d beta by scipy's QUADPACK.
    """
    u = np.asarray(u, dtype=np.float64)
    s = math.sqrt((1.0 - mu) * (1.0 + mu))
    b = s * np.sqrt((1.0 - u) * (1.0 + u))

    def J(a):
        with np.errstate(divide="ignore", invalid="ignore"):
            al = np.arccos(np.clip(-a / b, -1.0, 1.0))
        out = 2.0 * (a * al + b * np.sin(al))
        return np.where(a >= b, 2.0 * np.pi * a, np.where(a <= -b, 0.0, out))

    a = mu * u
    if p in (0, 1):
        k = J(a) if p == 0 else (J(a) - J(a - mu)) / mu
        return u**n * k
    from scipy.integrate import quad

    with np.errstate(divide="ignore", invalid="ignore"):
        beta1 = np.arccos(np.clip((mu - a) / b, -1.0, 1.0))
    beta1 = np.where(b > mu - a, beta1, 0.0)
    h = np.array([quad(lambda t, ai=ai, bi=bi: (ai + bi * math.cos(t)) ** (1.0 - p), 0.0, b1, epsabs=0, epsrel=1e-12,
                       limit=200)[0] if b1 > 0 else 0.0 for ai, bi, b1 in zip(a.ravel(), b.ravel(), beta1.ravel())])
    # the arc where 0 < N.wo < mu: all of it (J(a)) less its part above mu, J(a) - J(a - mu) - mu 2 beta1
    below = J(a) - J(a - mu) - 2.0 * mu * beta1
    k = below / mu**p + 2.0 * h.reshape(a.shape)
    return u**n * k


def integrand(n: float, p: float, mu: float, u, rtol: float = 1e-13):
    """(u^n K(u), its error) by the compiled kernel at every u in [0, 1] (for tests and checks;
    ``rtol`` is the inner rule's relative tolerance for p in (0, 1)).
    """
    from .cubature import NODES, WG, WK

    u = np.atleast_1d(np.asarray(u, dtype=np.float64))
    s = math.sqrt((1.0 - mu) * (1.0 + mu))
    c2 = (mu - s) * (mu + s)
    ibuf, iwork = np.empty(NODES.shape[0]), np.empty((4, INNER_MAX))
    jac = jacobi_rules(1.0 - p) if 0.0 < p < 1.0 else _NO_JACOBI
    val, err = np.empty(u.shape), np.empty(u.shape)
    for i, v in enumerate(u):
        k, e = _k_of_u(float(p), mu, c2, v, 1.0 - v, math.sqrt((1.0 - v) * (1.0 + v)), rtol, NODES, WK, WG, mode_code(),
                       ibuf, iwork, jac)
        un = v**n if n else 1.0
        val[i], err[i] = un * k, un * e
    return val, err
