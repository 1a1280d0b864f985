"""The frame of N for power lobes (``pumped_lobe``, ``lobe_normal``): a pumped lobe divided by g_1 ... g_k (001 eq. 16),
or a lobe with F(max(N.wi, N.wo)) (000 eq. 28), the lobe's azimuth on each ring from a Chebyshev table;
:mod:`pumpup.engine.polar` describes the method.
"""

from __future__ import annotations

import functools
import math

import numpy as np
from numba import njit

from ..physics.fresnel import conductor_scalar as _fresnel_real
from ..physics.fresnel import fresnel_branch, fresnel_pole
from ..physics.lookups import g_levels, g_product
from ..physics.quadrature import EPS, calibrated, rule_sums
from .half_arc import LOBE_F_CUTS
from .lobe_frame import INNER_MAX, _tally
from .lobe_fresnel import LOBE_F_WIDE
from .outer_rule import _RULES, _bisect, _buffers, _status

#: a lobe with 000 eq. 28's F(Theta_min) (metal, the fresnel wrapper of a lobe) is integrated about N (the pumped lobe's
#: frame with g = 1, :func:`_integrate_chain`) for n at least this, and in the lobe frame (frame 5) below it, where the
#: ring table leaves the pieces next to kappa = 1 to quadrature and the elevation is graded towards x_s (measured: n = 1
#: took 4 x frame 5's time, n = 7.5 0.8 x, n = 20 0.17 x)
LOBE_N_MIN = 8.0  # (RING_SMOOTH_N)


@njit(cache=True, nogil=True, inline="always")
def _ring_f(n, kappa, phi):  # pragma: no cover - compiled
    """(1 - kappa sin^2(phi / 2))_+^n as exp(n log1p(-kappa sin^2(phi / 2))): accurate for any n (a power
    of A + B cos(phi) lost n ulp, 2.2e-13 for n = 2000, measured).
    """
    sp = math.sin(0.5 * phi)
    omu = kappa * sp * sp
    return math.exp(n * math.log1p(-omu)) if omu < 1.0 else 0.0


@njit(cache=True, nogil=True)
def _ring_rule(n, kappa, lo, hi, nodes, wk, wg, ibuf):  # pragma: no cover - compiled
    """(value, |K - G|) of the rule on phi in [lo, hi] for :func:`_ring_f`."""
    h = hi - lo
    for j in range(nodes.shape[0]):
        ibuf[j] = _ring_f(n, kappa, lo + h * nodes[j])
    k, diff, asc, ab = rule_sums(ibuf, wk, wg)
    return k * h, diff * h


#: for n below RING_END_N and kappa above 1 - RING_END_DELTA, V's end phi0 (pi, or where 1 - kappa sin^2(phi / 2)
#: = 0) is integrated in s = cos(phi / 2) = s0 + e^u (:func:`_ring_end`): there the integrand's derivative is
#: unbounded at phi0 ((phi0 - phi)^n, or (pi - phi)^(2n) at kappa = 1) or varies within about sqrt(1 - kappa) of it,
#: which bisection in phi meets only in many steps (n = 0.127 at kappa = 1: 64 intervals, 5.8e-11 off, estimate
#: 3.1e-13; in u 11 us, 2e-15).  For larger n bisection in phi is faster (n = 2, 3.5, 5.5: 3-4 us against 8-10 us).
RING_END_N = 1.0
RING_END_DELTA = 1e-3


@njit(cache=True, nogil=True, inline="always")
def _ring_end_f(n, kappa, s0, u):  # pragma: no cover - compiled
    """(the integrand of :func:`_ring_end` at u, d log of it / du)."""
    e = math.exp(u)
    s = s0 + e
    # 1 - kappa sin^2(phi / 2) = 1 - kappa + kappa s^2; for kappa > 1 kappa (s - s0)(s + s0), s0^2 = (kappa - 1) / kappa
    w = kappa * e * (2.0 * s0 + e) if s0 > 0.0 else (1.0 - kappa) + kappa * s * s
    f = e * w ** n * 2.0 / math.sqrt((1.0 - s) * (1.0 + s))
    return f, 1.0 + 2.0 * n * kappa * s * e / w


@njit(cache=True, nogil=True)
def _ring_end_rule(n, kappa, s0, lo, hi, nodes, wk, wg, ibuf):  # pragma: no cover - compiled
    """(value, |K - G|) of the rule on u in [lo, hi] for :func:`_ring_end_f`."""
    h = hi - lo
    for j in range(nodes.shape[0]):
        ibuf[j] = _ring_end_f(n, kappa, s0, lo + h * nodes[j])[0]
    k, diff, asc, ab = rule_sums(ibuf, wk, wg)
    return k * h, diff * h


@njit(cache=True, nogil=True)
def _ring_end(n, kappa, phic, atol, nodes, wk, wg, ibuf, iwork):  # pragma: no cover - compiled
    """(value, error) of the integral over phi in [phic, phi0] of (1 - kappa sin^2(phi / 2))_+^n, by the 10/21
    rule, globally adaptive, to the error ``atol``, in u: s = cos(phi / 2) = s0 + e^u (s0 = cos(phi0 / 2),
    0 for kappa <= 1), d phi = 2 ds / sqrt(1 - s^2).  The integrand e^u (1 - kappa + kappa s^2)^n 2 / sqrt(1 - s^2)
    is analytic in u and falls at least like e^u as u decreases (the lobe's power law (phi0 - phi)^n, or
    (pi - phi)^(2n) at kappa = 1, and the bend of width sqrt(1 - kappa) next to pi become exponentials), so pieces of
    a few times 1 / (its log-derivative) fit it.  It over e^u increases with u, so the part below the lowest piece's
    end u0 is at most its value there: added to the error, its value left out.
    """
    s0 = math.sqrt((kappa - 1.0) / kappa) if kappa > 1.0 else 0.0
    lo, hi, val, err = iwork[0], iwork[1], iwork[2], iwork[3]
    b = math.log(math.cos(0.5 * phic) - s0)
    fb, rate = _ring_end_f(n, kappa, s0, b)
    nint = 0
    while True:
        a = b - min(4.0, 4.0 / rate)
        lo[nint], hi[nint] = a, b
        val[nint], err[nint] = _ring_end_rule(n, kappa, s0, a, b, nodes, wk, wg, ibuf)
        nint += 1
        fb, rate = _ring_end_f(n, kappa, s0, a)
        if fb <= 1e-3 * atol or nint >= lo.shape[0] // 2:
            break
        b = a
    while True:
        tot, e, worst = _tally(val, err, nint, 0.0, fb)
        if e <= atol or nint >= lo.shape[0]:
            return tot, e
        mid = 0.5 * (lo[worst] + hi[worst])
        lo[nint], hi[nint] = mid, hi[worst]
        hi[worst] = mid
        val[worst], err[worst] = _ring_end_rule(n, kappa, s0, lo[worst], mid, nodes, wk, wg, ibuf)
        val[nint], err[nint] = _ring_end_rule(n, kappa, s0, mid, hi[nint], nodes, wk, wg, ibuf)
        nint += 1


@njit(cache=True, nogil=True)
def _ring_quad(n, kappa, itol, nodes, wk, wg, ibuf, iwork):  # pragma: no cover - compiled
    """(V, its error): V(kappa) = integral over phi in (-pi, pi] of (1 - kappa sin^2(phi / 2))_+^n,
    kappa in [0, 2], by the 10/21 rule, globally adaptive, to the relative error ``itol``.

    The integrand f decreases on the half-arc [0, phi0] (phi0 = pi, or where 1 - kappa sin^2(phi / 2)
    = 0) from its peak f(0) = 1, of width sigma = sqrt(2 / (n kappa)) (f ~ exp(-(phi / sigma)^2 / 2)).
    The half-arc is cut at sigma (1, 2, 3, 4, 6, 8, 11, 15, ...) until the rest is at most
    (phi0 - c) f(c) <= 1e-18 sigma f(sigma) (f decreases: a bound, added to the error, its value left
    out): a rule on a piece that starts several widths out sees zeros at its nodes (n = 1e6,
    kappa = 0.95, with one piece beyond 4 sigma: 6.3e-5 off, estimate 2.6e-15).  For n below :data:`RING_END_N`
    and kappa above 1 - :data:`RING_END_DELTA` the cuts stop at phic = phi0 - min(pi / 2, phi0 / 2), and the
    rest, should the cuts reach it, is :func:`_ring_end`'s, to half the tolerance times the cuts' sum.
    """
    phi0 = math.pi if kappa <= 1.0 else 2.0 * math.asin(1.0 / math.sqrt(kappa))
    if n == 0.0:
        return 2.0 * phi0, 8.0 * EPS * phi0
    phic = phi0 - min(0.5 * math.pi, 0.5 * phi0) if n < RING_END_N and kappa > 1.0 - RING_END_DELTA else phi0
    lo, hi, val, err = iwork[0], iwork[1], iwork[2], iwork[3]
    sig = math.sqrt(2.0 / (n * kappa)) if kappa > 0.0 else math.inf
    floor = 1e-18 * min(sig, phi0) * _ring_f(n, kappa, min(sig, phi0))
    nint = 0
    a = 0.0
    k = 1.0
    tail = 0.0
    while True:
        b = min(phic, k * sig)
        lo[nint], hi[nint] = a, b
        val[nint], err[nint] = _ring_rule(n, kappa, a, b, nodes, wk, wg, ibuf)
        nint += 1
        if b >= phic:
            break
        fb = _ring_f(n, kappa, b)
        if (phi0 - b) * fb <= floor or nint >= lo.shape[0] // 2:
            tail = (phi0 - b) * fb  # f decreases beyond b
            break
        a = b
        k = k + 1.0 if k < 4.0 else math.floor(1.35 * k)
    end = 0.0  # (the part beyond phic)
    if b >= phic and phic < phi0:  # (its error in place of the bound; its work arrays the columns the cuts left free)
        end, tail = _ring_end(n, kappa, phic, 0.5 * itol * np.sum(val[:nint]), nodes, wk, wg, ibuf, iwork[:, nint:])
    while True:
        tot, e, worst = _tally(val, err, nint, end, tail)
        if e <= itol * tot or nint >= lo.shape[0]:
            return 2.0 * tot, 2.0 * e + 16.0 * EPS * tot
        mid = 0.5 * (lo[worst] + hi[worst])
        lo[nint], hi[nint] = mid, hi[worst]
        hi[worst] = mid
        val[worst], err[worst] = _ring_rule(n, kappa, lo[worst], mid, nodes, wk, wg, ibuf)
        val[nint], err[nint] = _ring_rule(n, kappa, mid, hi[nint], nodes, wk, wg, ibuf)
        nint += 1


@njit(cache=True)
def _ring_values(n, kappa, itol, nodes, wk, wg):  # pragma: no cover - compiled
    """:func:`_ring_quad` at every kappa: (values, errors)."""
    ibuf = np.empty(nodes.shape[0])
    iwork = np.empty((4, 4 * INNER_MAX))
    val = np.empty(kappa.shape[0])
    err = np.empty(kappa.shape[0])
    for i in range(kappa.shape[0]):
        val[i], err[i] = _ring_quad(n, kappa[i], itol, nodes, wk, wg, ibuf, iwork)
    return val, err


@njit(cache=True, nogil=True, inline="always")
def _ring_at(kappa, kb, kc, keps):  # pragma: no cover - compiled
    """(V(kappa), its error) from the table of :func:`ring_table`: the piece by bisection of the
    breaks ``kb``, its Chebyshev series ``kc[piece]`` by Clenshaw's recurrence.  Inlined where it is
    called.
    """
    a = 0
    b = kb.shape[0] - 1
    while b - a > 1:
        c = (a + b) >> 1
        if kappa >= kb[c]:
            a = c
        else:
            b = c
    x = (2.0 * kappa - kb[a] - kb[a + 1]) / (kb[a + 1] - kb[a])
    b1 = 0.0
    b2 = 0.0
    for k in range(kc.shape[1] - 1, 0, -1):
        b1, b2 = 2.0 * x * b1 - b2 + kc[a, k], b1
    v = x * b1 - b2 + kc[a, 0]
    return v, keps[a] * v


#: the ring table's Chebyshev degree per piece and relative tolerance (pieces bisected until met)
RING_DEGREE = 16
RING_TOL = 1e-14
#: a piece of the ring table narrower than this that misses RING_TOL is computed by quadrature
#: wherever it is needed (near kappa = 1 for small n)
RING_MIN_WIDTH = 1e-6
#: the relative tolerance of V by quadrature (:func:`_ring_quad`): the table's values, and the pieces left to it
RING_QUAD_RTOL = 1e-15


@functools.lru_cache(maxsize=64)
def ring_table(n: float) -> tuple:
    """(breaks, Chebyshev coefficients per piece, relative error per piece) of V(kappa) on [0, 2]
    (:func:`_ring_quad`) for the lobe exponent ``n``: the lobe u^n integrated over a circle N.wo = t
    is (A + B)^n V(2 B / (A + B)), u = A + B cos(phi) = (A + B)(1 - kappa sin^2(phi / 2)).

    Pieces: the octaves of kappa from 2 down to about 1 / (8 n), and [0, that]; on each a Chebyshev
    interpolant of degree :data:`RING_DEGREE` at the Chebyshev points, bisected until it matches V
    to :data:`RING_TOL` (relative) at 2 (degree + 1) + 1 test points.  The relative error of a piece:
    twice its largest miss, plus the values' own quadrature error (:data:`RING_QUAD_RTOL`), plus 4 ulp.  Near
    kappa = 1, where the arc stops being the whole circle, V has a term |kappa - 1|^(n + 1/2): a
    piece narrower than :data:`RING_MIN_WIDTH` that still misses gets the error -1, which tells the
    kernel to compute V there by quadrature.  Cached per n.
    """
    n = float(n)
    deg = RING_DEGREE
    if n == 0.0:  # (V = 2 phi0 in closed form, :func:`_x_rule`: no table)
        return np.array([0.0, 2.0]), np.zeros((1, deg + 1)), np.zeros(1)
    br = [2.0]
    k = 1.0
    while k > 1.0 / (8.0 * max(n, 1e-300)) and k > 1e-300:
        br.append(k)
        k *= 0.5
    br.append(0.0)
    br = sorted(br)
    xk = np.cos(np.pi * (np.arange(deg + 1) + 0.5) / (deg + 1))
    tt = np.linspace(-1.0, 1.0, 2 * (deg + 1) + 1)
    nodes, wk, wg = _RULES["gk21"]
    todo = list(zip(br[:-1], br[1:]))
    done = []
    while todo:
        lo = np.array([a for a, _ in todo])
        hi = np.array([b for _, b in todo])
        center, half = 0.5 * (lo + hi), 0.5 * (hi - lo)
        x = np.concatenate([xk, tt])
        v, e = _ring_values(n, (center[:, None] + half[:, None] * x[None, :]).ravel(), RING_QUAD_RTOL, nodes, wk, wg)
        v, e = v.reshape(len(lo), -1), e.reshape(len(lo), -1)
        todo = []
        for i in range(len(lo)):
            coef = np.polynomial.chebyshev.chebfit(xk, v[i, :deg + 1], deg)
            miss = np.max(np.abs(np.polynomial.chebyshev.chebval(tt, coef) / v[i, deg + 1:] - 1.0))
            if miss <= RING_TOL or hi[i] - lo[i] <= RING_MIN_WIDTH:
                eps = 2.0 * miss + np.max(e[i] / v[i]) + 4.0 * np.finfo(float).eps if miss <= RING_TOL else -1.0
                done.append((lo[i], hi[i], coef, eps))
            else:
                todo += [(lo[i], center[i]), (center[i], hi[i])]
    done.sort(key=lambda r: r[0])
    return (np.array([r[0] for r in done] + [done[-1][1]]), np.ascontiguousarray([r[2] for r in done]),
            np.array([r[3] for r in done]))


@njit(cache=True, nogil=True)
def _x_rule(n, p, mu, s, lo, hi, chain, kb, kc, keps, nodes, wk, wg, buf, ibuf, iwork, fr, mode):  # pragma: no cover
    """(value, error) of the rule on the elevation x of wo in [lo, hi] for
    t / (max(mu, t)^p g(mu, t)) W(t) cos(x), t = N.wo = sin(x) (001 eq. 16 with 000 eq. 7, 12;
    d omega = dt d phi), g the product of the chain's levels exactly as the BRDF divides by it, and
    W(t) the lobe u^n integrated over the circle N.wo = t: u = A + B cos(phi), A = mu t, B = s cos(x),
    W = (A + B)^n V(kappa), kappa = 2 B / (A + B), A + B = cos(x - x_mu) (x_mu the elevation of the
    lobe's axis; (A + B)^n = exp(n log1p(-2 sin^2((x - x_mu) / 2))), accurate for any n), V from
    the ring table (:func:`ring_table`, its errors summed with the Kronrod weights); with ``fr`` = (1, eta, k) times
    000 eq. 28's F(max(mu, t)) (a pumped metal, or the fresnel wrapper of a pumped lobe).  Without a chain (None: g = 1,
    a metal's lobe, :func:`chain_cut_matrix`) the error is QUADPACK's calibration of |K - G| (``mode``) instead of
    CHAIN_SAFETY |K - G| (which is for g's splines).
    """
    h = hi - lo
    ie = 0.0
    xmu = math.atan2(mu, s)
    for j in range(nodes.shape[0]):
        x = lo + h * nodes[j]
        t = math.sin(x)
        ct = math.cos(x)
        # g_1 ... g_k as the chain kernel divides by it (pumpup.operators.pumping._chain_kernel): the product
        # table where it applies, else level by level (written out: an inlined function that calls
        # the inlined look-ups ran 20 x slower, measured)
        g = 1.0  # (no chain: a metal's lobe)
        if chain is not None:
            if min(mu, t) > chain.product_mlo:
                g = g_product(max(mu, t), chain.product_cbase, chain.product_cell, chain.product_lo,
                              chain.product_rows)
            else:
                g = g_levels(max(mu, t), min(mu, t), chain.offsets, chain.logx, chain.coef, chain.v0, chain.slope0,
                             chain.margin_lo, chain.cap, chain.controlled, chain.increasing, chain.mu0, chain.index,
                             chain.index_lo, chain.index_h_inv)
        if p == 0.0:
            f = t * ct / g
        elif p == 1.0:
            f = t * ct / (max(mu, t) * g)
        else:
            f = t * ct / (max(mu, t) ** p * g)
        if fr[0] != 0.0:
            f *= _fresnel_real(max(mu, t), fr[1], fr[2])  # 000 eq. 28, as the kernels compute it
        sx = math.sin(0.5 * (x - xmu))
        d1 = 2.0 * sx * sx
        kappa = min(2.0 * s * ct / (1.0 - d1), 2.0)
        if n == 0.0:
            v = 2.0 * (math.pi if kappa <= 1.0 else 2.0 * math.asin(1.0 / math.sqrt(kappa)))
            ve = 8.0 * EPS * v
        else:
            v, ve = _ring_at(kappa, kb, kc, keps)
            if ve < 0.0:  # (a piece the table leaves to quadrature)
                v, ve = _ring_quad(n, kappa, RING_QUAD_RTOL, nodes, wk, wg, ibuf, iwork)
            an = math.exp(n * math.log1p(-d1))
            v *= an
            ve *= an
        buf[j] = f * v
        ie += wk[j] * f * ve
    k, diff, asc, ab = rule_sums(buf, wk, wg)
    if chain is None:
        return k * h, calibrated(diff * h, asc * h, ab * h, mode) + ie * h
    return k * h, CHAIN_SAFETY * diff * h + ie * h


@njit(cache=True, nogil=True)
def _integrate_chain(n, p, mu_arr, rtol, atol_arr, max_intervals, rounding, nodes, wk, wg, n_init, cuts, ncut, chain,
                      kb, kc, keps, fr, mode, val, err, conv, evals):  # pragma: no cover
    """Adaptive 10/21 quadrature over the elevation of wo of a pumped lobe (:func:`_x_rule`) for every
    mu, from the pieces between ``cuts[q, :ncut[q]]`` (:func:`chain_cuts`), each ``n_init`` intervals to
    start; ``kb``, ``kc``, ``keps`` the ring table of the lobe's exponent (:func:`ring_table`); ``fr`` the Fresnel
    factor's (on, eta, k) (:func:`_x_rule`).
    """
    # (room for every piece's first intervals besides max_intervals bisections: a pumped metal near grazing incidence
    # has ~100 pieces, more than the 64 spare slots)
    cap, pk, t0, t1, kv, ke, buf, ibuf, iwork, itol = _buffers(max_intervals + cuts.shape[1] * n_init, nodes, nodes,
                                                               rtol)
    for q in range(mu_arr.shape[0]):
        mu = mu_arr[q]
        s = math.sqrt((1.0 - mu) * (1.0 + mu))
        npc = ncut[q] - 1
        m = 0
        for i in range(npc):
            a_, b_ = cuts[q, i], cuts[q, i + 1]
            if b_ <= a_:
                continue
            for j in range(n_init):
                pk[m] = i
                t0[m] = a_ + (b_ - a_) * j / n_init
                t1[m] = a_ + (b_ - a_) * (j + 1.0) / n_init if j + 1 < n_init else b_
                kv[m], ke[m] = _x_rule(n, p, mu, s, t0[m], t1[m], chain, kb, kc, keps, nodes, wk, wg, buf, ibuf, iwork,
                                       fr, mode)
                m += 1
        start = m
        while True:
            tot, e, r, worst, ok = _status(kv, ke, m, 0.0, rounding, rtol, atol_arr[q])
            # (the reported error e + r within the tolerance, unless e is down to the rounding)
            ok = ok and (e <= r or e + r <= max(rtol * abs(tot), atol_arr[q]))
            if ok or m - start >= max_intervals or m >= cap:
                break
            i, a_, mid, b_ = _bisect(pk, t0, t1, worst, m)
            kv[worst], ke[worst] = _x_rule(n, p, mu, s, a_, mid, chain, kb, kc, keps, nodes, wk, wg, buf, ibuf, iwork,
                                           fr, mode)
            kv[m], ke[m] = _x_rule(n, p, mu, s, mid, b_, chain, kb, kc, keps, nodes, wk, wg, buf, ibuf, iwork, fr, mode)
            m += 1
        val[q] = tot
        err[q] = e + r
        conv[q] = ok
        evals[q] = nodes.shape[0] * (m + (m - start))


def chain_cuts(levels, n: float, mu: float, fresnel=None, chain: bool = True) -> np.ndarray:
    """The breakpoints in the elevation x of wo (N.wo = sin x) of a pumped lobe at incidence mu:
    0, pi/2, the levels of g (``levels``), N.wo = mu (max(mu, N.wo)), N.wo = s (u > 0 on the whole
    circle above it), the lobe's peak theta_o = theta_i +- k / sqrt(n), k = 3, 8, 13 (u^n ~
    exp(-n alpha^2 / 2)), N.wo = 2^-(1 + 2k) (:data:`GRADE`), every pi / 16 (:data:`X_PIECES`), and for
    n < :data:`RING_SMOOTH_N` a grading towards x_s; with ``fresnel`` = (eta, k), N.wo = x0 -+ y0 3^j about F's branch
    point and rho 3^j towards its pole near 0 (as frame 5's arcs, :func:`_k_lobe_fresnel`; the pole's only where rho <
    :data:`LOBE_F_WIDE`); x = atan2(L, sqrt(1 - L^2)) keeps levels near 1 to full precision.  ``chain`` False (a metal's
    lobe about N, g = 1): without g's grading in N.wo and the pi / 16 cuts.  The engine computes them compiled, for
    every mu at once (:func:`chain_cut_matrix`); this is their reference.
    """
    s = math.sqrt((1.0 - mu) * (1.0 + mu))
    L = np.asarray(levels, dtype=np.float64).reshape(-1)
    L = L[(L > 0.0) & (L < 1.0)]
    x_mu, x_s = math.atan2(mu, s), math.atan2(s, mu)
    x = [0.0, 0.5 * math.pi, x_mu, x_s]
    x.extend(np.arctan2(L, np.sqrt((1.0 - L) * (1.0 + L))))
    if n > 0.0:
        # (beyond 13 / sqrt(n), (A + B)^n = cos^n(x - x_mu) <= exp(-84.5): no rule there sees zeros where
        # the lobe is not negligible)
        for k in (3.0, 8.0, 13.0):
            x.extend([x_mu - k / math.sqrt(n), x_mu + k / math.sqrt(n)])
    if 0.0 < n < RING_SMOOTH_N:
        # W has a term |x - x_s|^(n + 1/2) at x_s (the ring table's kappa = 1): for small n the pieces
        # near it are graded towards it, so that none lies within a fraction of its width of it (stretched
        # Phong n = 0.5 at mu = 0.5, rtol 1e-8: a piece ending 0.002 short of it was 1.8e-8 off, estimate 3.4e-9)
        d = 0.5
        while d > 1e-9:
            x.extend([x_s - d, x_s + d])
            d *= 0.25
    if chain:
        # g's tables are splines in ln(N.wo): N.wo = 2^-(1 + 2 k) down to a quarter of mu or of the lowest level
        floor = max(0.25 * min(mu, L.min(initial=1.0)), GRADE_FLOOR)
        t = 0.5
        while t > floor:
            x.append(math.asin(t))
            t *= GRADE
        x.extend(np.arange(1, X_PIECES) * (0.5 * math.pi / X_PIECES))
    if fresnel is not None:
        x0, y0 = fresnel_branch(*fresnel)
        rho = fresnel_pole(*fresnel)
        js = 3.0 ** np.arange(LOBE_F_CUTS)
        t = np.concatenate([x0 + y0 * js, x0 - y0 * js, rho * js if rho < LOBE_F_WIDE else []])
        t = t[(t > 0.0) & (t < 1.0)]
        x.extend(np.arctan2(t, np.sqrt((1.0 - t) * (1.0 + t))))
    x = np.unique(np.asarray(x))
    return x[(x >= 0.0) & (x <= 0.5 * math.pi)]


#: room in :func:`_chain_cut_matrix` per mu besides the levels: 4 fixed cuts, 6 about the peak, 2 x 15 towards x_s, 20
#: graded in N.wo (GRADE down to GRADE_FLOOR), X_PIECES - 1, 3 x LOBE_F_CUTS about F's branch point and pole
CHAIN_CUTS_ROOM = 96


@njit(cache=True, nogil=True)
def _chain_cut_matrix(n, mu_arr, lev, nlev, chain, fres, x0, y0, rho):  # pragma: no cover - compiled; see chain_cuts
    """(cut, ncut): :func:`chain_cuts` for every mu, compiled (it was a quarter to a half of a pumped or 1/E-scaled
    table's time in Python): the levels ``lev[q, :nlev[q]]``, ``chain`` (g's grading in N.wo and the pi / 16 cuts), with
    ``fres`` F's branch point x0 - i y0 and pole scale rho (:func:`fresnel_branch`, :func:`fresnel_pole`); sorted,
    duplicates dropped, as chain_cuts (np.unique) has them.
    """
    half = 0.5 * math.pi
    cap = CHAIN_CUTS_ROOM + lev.shape[1]
    cut = np.zeros((mu_arr.shape[0], cap))
    ncut = np.zeros(mu_arr.shape[0], np.int64)
    x = np.empty(cap)
    for q in range(mu_arr.shape[0]):
        mu = mu_arr[q]
        s = math.sqrt((1.0 - mu) * (1.0 + mu))
        x_mu, x_s = math.atan2(mu, s), math.atan2(s, mu)
        x[0], x[1], x[2], x[3] = 0.0, half, x_mu, x_s
        m = 4
        lmin = 1.0
        for i in range(nlev[q]):
            L = lev[q, i]
            if 0.0 < L < 1.0:
                x[m] = math.atan2(L, math.sqrt((1.0 - L) * (1.0 + L)))
                m += 1
                lmin = min(lmin, L)
        if n > 0.0:
            for k in (3.0, 8.0, 13.0):
                x[m], x[m + 1] = x_mu - k / math.sqrt(n), x_mu + k / math.sqrt(n)
                m += 2
        if 0.0 < n < RING_SMOOTH_N:
            d = 0.5
            while d > 1e-9:
                x[m], x[m + 1] = x_s - d, x_s + d
                m += 2
                d *= 0.25
        if chain:
            floor = max(0.25 * min(mu, lmin), GRADE_FLOOR)
            t = 0.5
            while t > floor:
                x[m] = math.asin(t)
                m += 1
                t *= GRADE
            for i in range(1, X_PIECES):
                x[m] = i * (0.5 * math.pi / X_PIECES)
                m += 1
        if fres:
            for side in range(3):
                if side == 2 and not rho < LOBE_F_WIDE:
                    break
                for j in range(LOBE_F_CUTS):
                    sc = 3.0 ** j
                    t = x0 + y0 * sc if side == 0 else (x0 - y0 * sc if side == 1 else rho * sc)
                    if 0.0 < t < 1.0:
                        x[m] = math.atan2(t, math.sqrt((1.0 - t) * (1.0 + t)))
                        m += 1
        x[:m].sort()
        c = 0
        for i in range(m):
            if 0.0 <= x[i] <= half and (c == 0 or x[i] > cut[q, c - 1]):
                cut[q, c] = x[i]
                c += 1
        ncut[q] = c
    return cut, ncut


def chain_cut_matrix(levels, n: float, mu: np.ndarray, fresnel=None, chain: bool = True) -> tuple:
    """(cut, ncut): :func:`chain_cuts` (``levels(mu)`` or, with None, no levels) at every mu, by the compiled
    :func:`_chain_cut_matrix`.
    """
    mu = np.ascontiguousarray(mu, dtype=np.float64)
    if levels is None:
        lev, nlev = np.zeros((mu.size, 0)), np.zeros(mu.size, np.int64)
    else:
        lev, nlev = _cut_matrix([np.asarray(levels(float(m)), dtype=np.float64).reshape(-1) for m in mu])
    x0, y0, rho = (*fresnel_branch(*fresnel), fresnel_pole(*fresnel)) if fresnel is not None else (0.0, 0.0, math.inf)
    return _chain_cut_matrix(float(n), mu, lev, nlev, bool(chain), fresnel is not None, x0, y0, rho)

#: a pumped lobe's error estimate per interval: CHAIN_SAFETY |K - G| of the 10/21 rule.  g's tables are
#: splines whose 5th derivatives jump at every node: no cut marks them, and across many of them |K - G|
#: can fall well below the true error (2-level g1 Phong n = 20 at mu = 0.7133, rtol 1e-9: a piece over
#: the lobe's flank, 0.67 rad wide, was 3.5e-11 off with a raw |K - G| of 1e-12; its eighths were each
#: right to 1e-17).  So the elevation is also cut every pi / 16 (X_PIECES), where such errors (~ width^6)
#: are far below the rounding term, and the estimate is 3 |K - G|.  Measured over 15 chains (g1 and g2,
#: 1-4 levels, n from 0.5 to 5000, p in {0, 0.5, 1}, retro), 351 mu from 1e-10 to 1 and rtol 1e-6 ...
#: 1e-12, against the lobe frame's engine at 1e-13 on the same BRDFs: the worst true error was 0.49 of
#: the estimate (one case excepted, where the lobe frame was the one off: retro n = 10 at mu = 0.3705,
#: 9e-13, by the nested engine and this one at 1e-13); with the raw |K - G| it was 1.41, without the
#: pi / 16 cuts 4.19.  `python scripts/calibration/pumped_calibration.py` repeats it against the nested engine at
#: 1e-13 (in the tree): worst 0.50 over 149 mu.
CHAIN_SAFETY = 3.0
#: the rule of a pumped lobe's quadrature over the elevation (and of the ring table's)
CHAIN_RULE = "gk21"
#: graded cuts of a pumped lobe's elevation: N.wo = 1/2, 1/2 GRADE, 1/2 GRADE^2, ... down to a quarter of
#: mu or of the lowest level of g, but not below GRADE_FLOOR (g's tables are splines in ln(N.wo))
GRADE = 0.25
GRADE_FLOOR = 1e-12
#: below this lobe exponent the elevation is also graded towards x_s (:func:`chain_cuts`)
RING_SMOOTH_N = 8.0
#: the elevation of a pumped lobe is cut every pi / (2 X_PIECES) (see CHAIN_SAFETY)
X_PIECES = 8
#: first intervals per piece of a pumped lobe's elevation
N_INIT_CHAIN = 1


def _cut_matrix(cuts: list) -> tuple:
    """(cut, ncut): the per-mu arrays of cuts as one zero-padded matrix and their lengths."""
    ncut = np.array([len(c) for c in cuts], np.int64)
    cut = np.zeros((len(cuts), int(ncut.max(initial=2))))
    for q, c in enumerate(cuts):
        cut[q, :len(c)] = c
    return cut, ncut
