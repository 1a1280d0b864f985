"""Frame 5 of the 1-D routes (``lobe_fresnel``): the lobe frame with 000 eq. 28's Fresnel factor F(max(N.wi, N.wo))
(metal, plastic, the fresnel wrapper), its arcs cut about F's branch point and pole; :mod:`pumpup.engine.polar`
describes the method.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from ..physics.fresnel import conductor_scalar as _fresnel_real
from ..physics.fresnel import fresnel_branch
from ..physics.microfacet import projected as _projected
from ..physics.quadrature import EPS, calibrated, mode_code, rule_sums
from .cubature import NODES as _NODES
from .cubature import WG as _WG
from .cubature import WK as _WK
from .half_arc import LOBE_F, LOBE_F_CUTS, SMITH, _k_numeric, numeric_params
from .hint_view import kernel_view
from .lobe_frame import GL_MAX, GL_W, GL_X, INNER_MAX, _k_closed, _tally

#: frame 5 refuses (the nested engine takes the model) where the Fresnel factor's branch point w = sqrt(1 -
#: (eta + i k)^2) lies closer than this to the real axis but off it (a near-kink: graded cuts would need log(1 / Im w)
#: pieces per arc), or on it inside (0, 1) (a dielectric's total reflection below eta = 1: F = 1 up to a square-root
#: kink)
LOBE_F_Y0_MIN = 1e-3
#: the pumped lobe's frame of N takes F(Theta_min) only where its branch point lies at least this far from the real axis
#: (or beyond 1): a pumped metal's g then has the near-kink too, on a spline whose nodes no cut marks (eta 0.3, k 0.01,
#: n 20, g1: Im w = 0.0031, 1.7 x the estimate at mu = 0.96, rtol 1e-10, against the nested and 2-D engines)
CHAIN_F_Y0_MIN = 1e-2

#: no cuts in alpha (:func:`_pieces`) where the feature's scale there is at least this (rad): the outer rule's first
#: 21 nodes on a piece of at most pi / 2 see it (metal eta 0.2, k 3: its pole's scale 0.35 had doubled the pieces)
LOBE_F_WIDE = 0.25


def lobe_fresnel_ok(eta: float, k: float, chain: bool = False) -> bool:
    """Whether frame 5 (``chain``: the pumped lobe's frame of N) takes the Fresnel factor of (eta, k)
    (:data:`LOBE_F_Y0_MIN`, :data:`CHAIN_F_Y0_MIN`).
    """
    x0, y0 = fresnel_branch(eta, k)
    if y0 == 0.0:
        return x0 == 0.0 or x0 >= 1.0  # on the real axis: only outside (0, 1) (eta = 1, k = 0: F = 0)
    return y0 >= (CHAIN_F_Y0_MIN if chain and x0 < 1.0 else LOBE_F_Y0_MIN)


@njit(cache=True, nogil=True)
def _lobe_rule(mp, q, a, b, lo, hi, nodes, wk, wg, mode, ibuf):  # pragma: no cover - compiled
    """(value, error) of the rule on beta in [lo, hi] for F(t) t^q, t = N.wo = a + b cos(beta)
    (:func:`_k_lobe_fresnel`).
    """
    h = hi - lo
    for j in range(nodes.shape[0]):
        t = a + b * math.cos(lo + h * nodes[j])
        ibuf[j] = _fresnel_real(t, mp[6], mp[7]) * (t if q == 1.0 else 1.0)
    k, diff, asc, ab = rule_sums(ibuf, wk, wg)
    return k * h, calibrated(diff * h, asc * h, ab * h, mode)


@njit(cache=True, nogil=True, inline="always")
def _beta_at(t, top, b):  # pragma: no cover - compiled
    """The angle beta where a + b cos(beta) = t, from top - t = 2 b sin^2(beta / 2) (no cancellation near beta = 0)."""
    return 2.0 * math.asin(min(1.0, math.sqrt(max(0.0, (top - t) / (2.0 * b)))))


#: frame 5's Gauss-Legendre pieces (:func:`_lobe_f_bound`): the candidate ellipses, log(R) = f log(R_max) for f in these
LOBE_F_FRACTIONS = (0.8, 0.5, 0.25)
#: and log(R) at most this (R_max overflows where a piece is short beside far singular points)
LOBE_F_LOG_R_CAP = math.log(1e4)
#: frame 5 drops the arc's first cut where it lies closer to the arc's top T than this times the next piece's length
#: (that piece, a rule in t, would otherwise see the (T - t)^-1/2 of d beta = dt / sqrt((T - t)(t - L)) next to its end)
LOBE_F_MERGE = 0.25


@njit(cache=True, nogil=True, inline="always")
def _sqrt_re(x, y):  # pragma: no cover - compiled
    """Re sqrt(x + i y), the principal root, without cancellation: sqrt((r + x) / 2), or |y| / sqrt(2 (r - x)) for x < 0
    (r = |x + i y|; 0 for a negative real x).
    """
    r = math.sqrt(x * x + y * y)
    return math.sqrt(0.5 * (r + x)) if x >= 0.0 else abs(y) / math.sqrt(2.0 * (r - x))


@njit(cache=True, nogil=True, inline="always")
def _focal_sum(zr, zi, lo, hi):  # pragma: no cover - compiled
    """(|z - lo| + |z - hi|) / 2 for z = zr + i zi: the semi-major axis of the Bernstein ellipse of [lo, hi] through z
    (its parameter R = A + sqrt(A^2 - 1) for A = that over h = (hi - lo) / 2).  For t in the ellipse whose semi-major
    axis is h A_R, gap(z) = this - h A_R is a lower bound of |t - z| (not positive: z may lie inside): in elliptic
    coordinates t = m + h cosh(xi + i theta), |dt| >= h sinh(xi) d xi = h d(cosh xi), and a path from t to z crosses the
    confocal ellipses from t's to z's.
    """
    return 0.5 * (math.sqrt((zr - lo) * (zr - lo) + zi * zi) + math.sqrt((zr - hi) * (zr - hi) + zi * zi))


@njit(cache=True, nogil=True)
def _lobe_f_bound(mp, q, lo, d, top, low, first, tol):  # pragma: no cover - compiled; see the tests' mpmath check
    """(n, bound, values): the Gauss-Legendre rule (n <= GL_MAX points; GL_MAX + 1 if none suffices) of the fewest
    values whose error on a piece [lo, lo + d] of frame 5's arc (:func:`_lobe_f_gauss`) is at most ``tol``, and its
    bound.

    The piece is integral G(t) dt, G = F(t) t^q / sqrt((T - t)(t - L)), F the conductor Fresnel factor of
    e = eta + i k (``mp[6]``, ``mp[7]``; 000 eq. 28), T = ``top``, L = ``low``.  ``first``: lo + d = T, by s with
    t = T - d s^2, s in [-1, 1]: sqrt(d) integral F t^q / sqrt(t - L) ds, even in s, whose Bernstein ellipse of
    parameter r maps onto t's of [lo, T] with R = r^2; else in t itself.  The n-point rule errs by at most 64 M / (15
    (1 - r^-2) r^(2 n)) times the length factor (Trefethen, ATAP Thm 19.3), M a bound of the integrand on the ellipse,
    which must avoid F's branch points +-w, +-conj(w) (w^2 = 1 - e^2; x0, y0 = ``mp[13]``, ``mp[14]``:
    :func:`fresnel_branch`), L and (in t) T.

    M on the t-ellipse E_R of [lo, hi] (semi-axes h A_R, h B_R about m).  Every bound holds for either sign of the
    refracted cosine A = sqrt(e^2 - 1 + t^2), so for F's continuation, whatever its branch:
    - |t| <= tau = m + h A_R; |A|^2 = |t - w| |t + w| <= tau^2 + |w|^2 and >= gap(w) gap(-w) (:func:`_focal_sum`);
    - F = r_s(e) r_s(conj e) (1 + N_e N_conj(e) / (D_e D_conj(e))) / 2 continues |r_s|^2 (1 + |N|^2 / |D|^2) / 2 of
      the real axis (R_p = R_s |N|^2 / |D|^2, pbrt-v3's FrConductor), r_s = (t - A) / (t + A), N = A t - (1 - t^2),
      D = A t + 1 - t^2; the bounds for e hold for conj(e) (E_R is symmetric about the real axis);
    - |r_s| <= (tau + |A|)^2 / |w|^2, as (t - A)(t + A) = w^2; or (tau + |A|) / |t + A|, where on [lo, hi] (A's real
      part rising, its imaginary part >= 0 falling with t) |t + A| >= max(lo + Re A(lo), Im A(hi)), and E_R lies within
      h B_R of the segment, where |d(t + A)/dt| <= 1 + tau / min |A|;
    - |N| <= |A| tau + 1 + tau^2; D N = (e^2 + 1)(t - c_b)(t + c_b), c_b^2 = 1 / (e^2 + 1), so |D| >= |e^2 + 1|
      gap(c_b) gap(-c_b) / max |N|; and where N(c_b) = 0 (Brewster's zero, ``mp[16:19]``: :func:`fresnel_brewster`,
      A continued along the real axis to Re c_b, then straight to c_b), |N(t)| <= max |N'| |t - c_b| on the Bernstein
      ellipse through c_b (or E_R, the larger: convex and symmetric, it holds that path and the straight one from t,
      and A is analytic on it where it avoids +-w), N' = A + t^2 / A + 2 t, so
      |D| >= |e^2 + 1| gap(-c_b) / max |N'|: no loss at Brewster's angle;
    - |t - L|, |T - t| >= gap(L), gap(T).
    log(R) is the first of LOBE_F_FRACTIONS of log(R_max) that gives a rule; ``values`` is (n + 1) // 2 for ``first``,
    n else.
    """
    eta, k, x0, y0 = mp[6], mp[7], mp[13], mp[14]
    h = 0.5 * d  # (d = hi - lo; for ``first`` T - lo without cancellation)
    m = lo + h
    hi = lo + d
    if not (tol > 0.0 and h > 0.0):
        return GL_MAX + 1, 0.0, GL_MAX + 1
    # the semi-major axes of the ellipses through w, -w, L, T, c_b, -c_b: gap(z) = s_z - h A_R (:func:`_focal_sum`)
    cbr, cbi = mp[16], abs(mp[17])
    s_w = _focal_sum(x0, y0, lo, hi)
    s_mw = _focal_sum(-x0, y0, lo, hi)
    s_l = m - low
    s_t = top - m
    s_b = _focal_sum(cbr, cbi, lo, hi)
    s_mb = _focal_sum(-cbr, cbi, lo, hi)
    amx = min(s_w, s_mw, s_l) / h
    if not first:
        amx = min(amx, s_t / h)
    lrmax = min(math.log(amx + math.sqrt(max(0.0, (amx - 1.0) * (amx + 1.0)))), LOBE_F_LOG_R_CAP)
    if not lrmax > 1e-3:
        return GL_MAX + 1, 0.0, GL_MAX + 1
    w2 = x0 * x0 + y0 * y0  # |w|^2 = |1 - e^2|
    e2r, e2i = (eta - k) * (eta + k), 2.0 * eta * k
    re_lo = _sqrt_re(e2r - 1.0 + lo * lo, e2i)  # Re A(lo)
    im_hi = e2i / (2.0 * _sqrt_re(e2r - 1.0 + hi * hi, e2i)) if e2i > 0.0 else 0.0  # Im A(hi) >= 0
    s_seg = max(lo + re_lo, im_hi)  # |t + A| on [lo, hi]
    ep1 = mp[19]
    brewster = mp[18] > 0.0
    for f in LOBE_F_FRACTIONS:
        lr = f * lrmax
        big_r = math.exp(lr)
        big_a = 0.5 * (big_r + 1.0 / big_r)
        big_b = 0.5 * (big_r - 1.0 / big_r)
        ha = h * big_a
        tau = m + ha
        dw, dmw, dl = s_w - ha, s_mw - ha, s_l - ha
        dt = 1.0 if first else s_t - ha
        if not (dw > 0.0 and dmw > 0.0 and dl > 0.0 and dt > 0.0):
            continue
        amin = math.sqrt(dw * dmw)
        amax = math.sqrt(tau * tau + w2)
        rs = (tau + amax) * (tau + amax) / w2 if w2 > 0.0 else math.inf
        s_low = s_seg - (1.0 + tau / amin) * h * big_b
        if s_low > 0.0:
            rs = min(rs, (tau + amax) / s_low)
        nmax = amax * tau + 1.0 + tau * tau
        d_low = -1.0
        dm = s_mb - ha  # |t + c_b|
        if dm > 0.0:
            if s_b - ha > 0.0:
                d_low = ep1 * (s_b - ha) * dm / nmax
            if brewster:
                ha2 = max(ha, s_b)  # the ellipse through c_b, or E_R
                tau2 = m + ha2
                dw2, dmw2 = s_w - ha2, s_mw - ha2
                if dw2 > 0.0 and dmw2 > 0.0:
                    d_low = max(d_low, ep1 * dm / (math.sqrt(tau2 * tau2 + w2) + tau2 * tau2 / math.sqrt(dw2 * dmw2)
                                                   + 2.0 * tau2))
        if not (d_low > 0.0 and rs < math.inf):
            continue
        big_m = 0.5 * rs * rs * (1.0 + (nmax / d_low) ** 2) * (tau if q == 1.0 else 1.0) / math.sqrt(dl * dt)
        if first:  # sqrt(T - lo) 64 M / (15 (1 - 1 / R) R^n), n points, (n + 1) // 2 values
            c = math.sqrt(d) * 64.0 * big_m / (15.0 * (1.0 - 1.0 / big_r))
            n = max(1.0, math.ceil(math.log(c / tol) / lr))
            v = (n + 1.0) // 2.0
            bound = c * math.exp(-n * lr)
        else:  # h 64 M / (15 (1 - R^-2) R^(2 n)), n points and values
            c = h * 64.0 * big_m / (15.0 * (1.0 - 1.0 / (big_r * big_r)))
            n = max(1.0, math.ceil(math.log(c / tol) / (2.0 * lr)))
            v = n
            bound = c * math.exp(-2.0 * n * lr)
        if n <= GL_MAX:
            return int(n), bound, int(v)
    return GL_MAX + 1, 0.0, GL_MAX + 1


@njit(cache=True, nogil=True)
def _lobe_f_piece(eta, k, q, lo, d, top, low, first, n):  # pragma: no cover - compiled; see lobe_f_piece_reference
    """integral_lo^(lo + d) F(t) t^q / sqrt((T - t)(t - L)) dt by the n-point Gauss-Legendre rule
    (:func:`_lobe_f_bound`): ``first`` (lo + d = T) in s, t = T - d s^2, else in t.
    """
    tot = 0.0
    if first:
        for j in range((n + 1) // 2):
            s2 = d * GL_X[n, j] * GL_X[n, j]
            t = top - s2
            tot += GL_W[n, j] * _fresnel_real(t, eta, k) * t**q / math.sqrt((top - low) - s2)
        return math.sqrt(d) * tot
    h = 0.5 * d
    m = lo + h
    for j in range((n + 1) // 2):
        x = h * GL_X[n, j]
        t = m - x
        g = _fresnel_real(t, eta, k) * t**q / math.sqrt(((top - m) + x) * ((m - low) - x))
        if x == 0.0:  # (the middle node of an odd rule, its weight once)
            tot += GL_W[n, j] * g
            continue
        t = m + x
        g += _fresnel_real(t, eta, k) * t**q / math.sqrt(((top - m) - x) * ((m - low) + x))
        tot += 0.5 * GL_W[n, j] * g
    return h * tot


def lobe_f_piece_reference(eta: float, k: float, q: float, lo: float, d: float, top: float, low: float,
                           first: bool) -> float:
    """Plain twin of :func:`_lobe_f_piece`: integral_lo^(lo + d) F(t) t^q / sqrt((T - t)(t - L)) dt by numpy's 200-point
    Gauss-Legendre rule in the same variable (s for ``first``, else t), F the complex-arithmetic
    :func:`pumpup.models.metal.fresnel`.
    """
    from ..physics.fresnel import fresnel_conductor as fresnel

    x, w = np.polynomial.legendre.leggauss(200)
    if first:
        t = top - d * x * x
        return float(math.sqrt(d) * np.sum(w * fresnel(t, eta, k) * t**q / np.sqrt((top - low) - d * x * x)))
    t = lo + 0.5 * d * (1.0 + x)
    return float(0.5 * d * np.sum(w * fresnel(t, eta, k) * t**q / np.sqrt((top - t) * (t - low))))


@njit(cache=True, nogil=True)
def _lobe_f_gauss(mp, q, mu, a, b, d, beta1, tol, cut):  # pragma: no cover - compiled
    """(H, error) of H = integral_0^beta1 F(t) t^q d beta, t = N.wo = a + b cos(beta) >= mu (frame 5's arc,
    :func:`_k_lobe_fresnel`), d = T - mu, by Gauss-Legendre rules with an a-priori bound (:func:`_lobe_f_bound`) on the
    pieces between frame 5's cuts (``cut``: falling t in (mu, T)), each at the tolerance ``tol`` times its share of
    [mu, T]; the error is the bounds plus (n + 64) eps of rounding per piece.  (0, -1) where a piece would want more
    than GL_MAX points: the caller then takes the adaptive rule.
    """
    eta, k = mp[6], mp[7]
    top = a + b
    low = a - b
    nc = cut.shape[0]
    # the first piece, in s, reaches down to the first cut; drop cuts that lie too close to T (LOBE_F_MERGE)
    i = 0
    while i < nc:
        nxt = cut[i + 1] if i + 1 < nc else mu
        if top - cut[i] >= LOBE_F_MERGE * (cut[i] - nxt):
            break
        i += 1
    tot = 0.0
    err = 0.0
    scale = tol / d
    lo = cut[i] if i < nc else mu
    d0 = top - lo if i < nc else d
    n, bound, _ = _lobe_f_bound(mp, q, lo, d0, top, low, True, scale * d0)
    if n > GL_MAX:
        return 0.0, -1.0
    p = _lobe_f_piece(eta, k, q, lo, d0, top, low, True, n)
    tot += p
    err += bound + (n + 64) * EPS * abs(p)
    while i < nc:
        hi = cut[i]
        lo = cut[i + 1] if i + 1 < nc else mu
        i += 1
        n, bound, _ = _lobe_f_bound(mp, q, lo, hi - lo, top, low, False, scale * (hi - lo))
        if n > GL_MAX:
            return 0.0, -1.0
        p = _lobe_f_piece(eta, k, q, lo, hi - lo, top, low, False, n)
        tot += p
        err += bound + (n + 64) * EPS * abs(p)
    return tot, err


#: 3^j, j < LOBE_F_CUTS (:func:`_lobe_f_cuts`)
_POW3 = 3.0 ** np.arange(LOBE_F_CUTS)


@njit(cache=True, nogil=True)
def _lobe_f_cuts(mp, mu, out):  # pragma: no cover - compiled
    """Frame 5's cuts of the arcs t = N.wo in (mu, 1] (:func:`_k_lobe_fresnel`) into ``out``, falling, and their number:
    t = x0 + y0 3^j (j falling), x0 - y0 3^j (j rising), j < LOBE_F_CUTS, about F's branch point (``mp[13]``,
    ``mp[14]``), and rho 3^j (j falling) from max(rho, 3 mu), rho the distance of its pole near 0 (``mp[15]``).
    """
    x0, y0 = mp[13], mp[14]
    rho = mp[15]
    r0 = rho if 3.0 * mu <= rho else 3.0 * mu
    m = 0
    ia, ib = 0, 0
    while True:
        ta = -1.0
        if ia < 2 * LOBE_F_CUTS:
            ta = x0 + y0 * _POW3[LOBE_F_CUTS - 1 - ia] if ia < LOBE_F_CUTS else x0 - y0 * _POW3[ia - LOBE_F_CUTS]
        tb = r0 * _POW3[LOBE_F_CUTS - 1 - ib] if ib < LOBE_F_CUTS else -1.0
        if ta < 0.0 and tb < 0.0:
            return m
        if ta >= tb:
            t = ta
            ia += 1
        else:
            t = tb
            ib += 1
        if t <= mu:  # (the rest fall below it too)
            return m
        if t <= 1.0 and (m == 0 or t < out[m - 1]):
            out[m] = t
            m += 1


@njit(cache=True, nogil=True)
def _lobe_f_prepare(mp, mu):  # pragma: no cover - compiled
    """Frame 5's per-mu quantities in ``mp``: F(mu) (``mp[21]``), the arc's cuts in (mu, 1] (:func:`_lobe_f_cuts`, at
    most 3 LOBE_F_CUTS, falling: ``mp[23:]``) and their number (``mp[22]``); every node's arc takes those below its top.
    """
    mp[21] = _fresnel_real(mu, mp[6], mp[7])
    mp[22] = _lobe_f_cuts(mp, mu, mp[23:])


@njit(cache=True, nogil=True)
def _k_lobe_fresnel(mp, p, mu, c2, u, um, sa, itol,  # pragma: no cover - compiled; see lobe_fresnel_integrand_reference
                    tol_abs, nodes, wk, wg, mode, ibuf, iwork):
    """(K(u), its error) of frame 5: the integral over the visible arc of N.wo F(max(mu, N.wo)) / max(mu, N.wo)^p,
    p in {0, 1}, for u = cos(alpha) about R (or wi), um = 1 - u, sa = sin(alpha), c2 = cos(2 theta_i); F the conductor
    Fresnel factor of (eta, k) = (``mp[6]``, ``mp[7]``), 000 eq. 28.

    Where N.wo < mu the factor is F(mu) / mu^p, a constant: that part is :func:`_k_closed`'s ``below`` times it.  Where
    N.wo = t = a + b cos(beta) >= mu (|beta| <= beta1 <= pi / 2) the integrand F(t) t^(1 - p) is analytic but near F's
    branch point w = x0 - i y0 (``mp[13]``, ``mp[14]``, :func:`fresnel_branch`) and its pole near 0 (at distance rho,
    ``mp[15]``, :func:`fresnel_pole`): that arc is cut at t = x0 -+ y0 3^j and at t = rho 3^j from max(rho, 3 mu) (each
    piece then lies about its own length from them; computed once per mu, :func:`_lobe_f_prepare`) and its pieces taken
    by Gauss-Legendre rules with an a-priori bound (:func:`_lobe_f_gauss`) at max(``itol``
    times a guess of K's lower bound, ``tol_abs`` / 2).  Where a piece would want more than GL_MAX points (or with
    ``using(lobe_fresnel_gauss=False)``) the arc is the globally adaptive 7/15 rule in beta, from the same cuts, the
    interval with the largest error bisected until the summed error (QUADPACK's calibration) is at most max(``itol``
    |K|, ``tol_abs``) or INNER_MAX intervals are used; the error is returned either way.  Both signs of beta: 2 x.
    """
    _, beta1, below = _k_closed(1.0, mu, c2, u, um, sa)
    fm = mp[21]  # F(mu) (:func:`_lobe_f_prepare`)
    closed = below * fm / (mu if p == 1.0 else 1.0)
    if beta1 <= 0.0:
        return 2.0 * closed, 0.0
    a = mu * u
    b = math.sqrt((1.0 - mu) * (1.0 + mu)) * sa
    top = a + b  # t at beta = 0; t = mu at beta1
    q = 1.0 - p
    lo, hi, val, err = iwork[0], iwork[1], iwork[2], iwork[3]
    nall = int(mp[22])  # the cuts in (mu, 1], falling (:func:`_lobe_f_prepare`): those below T
    i0 = 0
    while i0 < nall and mp[23 + i0] >= top:
        i0 += 1
    cut = mp[23 + i0:23 + nall]
    nc = nall - i0
    if mp[20] > 0.0:
        # the Gauss-Legendre pieces with an a-priori bound, at the tolerance's target for
        # H >= beta1 min(F) mu^q, min(F) guessed as half the smaller of F(mu), F(T)
        d = um * (u - c2) / (b + mu * um)  # T - mu = d1 / (b + mu - a), without cancellation
        h_low = 0.5 * beta1 * min(fm, _fresnel_real(top, mp[6], mp[7])) * (mu if q == 1.0 else 1.0)
        tol = max(itol * (closed + h_low), 0.5 * tol_abs)
        h, e = _lobe_f_gauss(mp, q, mu, a, b, d, beta1, tol, cut)
        if e >= 0.0:
            return 2.0 * (closed + h), 2.0 * e
    # else the globally adaptive 7/15 rule in beta from the same cuts
    m = 0
    start = 0.0
    for i in range(nc + 1):
        end = min(_beta_at(cut[i], top, b), beta1) if i < nc else beta1
        if end > start:
            lo[m], hi[m] = start, end
            val[m], err[m] = _lobe_rule(mp, q, a, b, start, end, nodes, wk, wg, mode, ibuf)
            m += 1
            start = end
        if end >= beta1:
            break
    while True:
        tot, e, worst = _tally(val, err, m, 0.0, 0.0)
        if 2.0 * e <= max(2.0 * itol * abs(tot + closed), tol_abs) or m >= lo.shape[0]:
            return 2.0 * (tot + closed), 2.0 * e
        mid = 0.5 * (lo[worst] + hi[worst])
        lo[m], hi[m] = mid, hi[worst]
        hi[worst] = mid
        val[worst], err[worst] = _lobe_rule(mp, q, a, b, lo[worst], mid, nodes, wk, wg, mode, ibuf)
        val[m], err[m] = _lobe_rule(mp, q, a, b, mid, hi[m], nodes, wk, wg, mode, ibuf)
        m += 1


def lobe_fresnel_integrand_reference(brdf, mu: float, u) -> np.ndarray:
    """Frame 5's K(u) (:func:`_k_lobe_fresnel`) for ``brdf``'s hint, independently: scipy's ``quad`` over the azimuth
    beta in [0, pi] of N.wo F(max(mu, N.wo)) / max(mu, N.wo)^p where N.wo = mu u + s sin(alpha) cos(beta) > 0, with F
    the complex-arithmetic :func:`pumpup.models.metal.fresnel`, the arcs' ends as the rule's points; times 2.
    """
    from scipy.integrate import quad

    from ..physics.fresnel import fresnel_conductor as fresnel

    hint = kernel_view(brdf.azimuth_hint())
    _, eta, k = hint.fresnel
    s = math.sqrt((1.0 - mu) * (1.0 + mu))
    out = []
    for v in np.atleast_1d(np.asarray(u, dtype=float)):
        a, b = mu * v, s * math.sqrt((1.0 - v) * (1.0 + v))

        def g(beta):
            t = a + b * math.cos(beta)
            if t <= 0.0:
                return 0.0
            mx = max(mu, t)
            return t * float(fresnel(mx, eta, k)) / mx**hint.p

        pts = [math.acos(min(1.0, max(-1.0, x))) for x in ((mu - a) / b, -a / b)] if b > 0 else []
        out.append(2.0 * quad(g, 0.0, math.pi, points=pts or None, epsabs=0.0, epsrel=1e-13, limit=400)[0])
    return np.array(out)


def numeric_integrand(brdf, mu: float, u, rtol: float = 1e-13):
    """(K(u), error) of frame 4 (:func:`_k_numeric`, ``u`` the values of N.h) or, for a lobe hint with a Fresnel factor,
    frame 5 (:func:`_k_lobe_fresnel`, ``u`` the values of cos(alpha) about R) for ``brdf``'s hint at N.wi = ``mu``, at
    relative tolerance ``rtol`` (the kernels as the engine calls them; for the tests).
    """
    hint = kernel_view(brdf.azimuth_hint())
    mp = numeric_params(hint)
    s = math.sqrt((1.0 - mu) * (1.0 + mu))
    if mp[0] == SMITH:
        mp[8] = _projected(s, 0.0, mu, int(mp[1]), int(mp[2]), mp[4])
    u = np.atleast_1d(np.asarray(u, dtype=float))
    ibuf, iwork = np.empty(_NODES.shape[0]), np.empty((4, INNER_MAX))
    val, err = np.empty(u.shape), np.empty(u.shape)
    if mp[0] == LOBE_F:
        _lobe_f_prepare(mp, mu)
    for i, v in enumerate(u):
        sa = math.sqrt((1.0 - v) * (1.0 + v))
        if mp[0] == LOBE_F:
            val[i], err[i] = _k_lobe_fresnel(mp, float(hint.p), mu, (mu - s) * (mu + s), float(v), 1.0 - float(v), sa,
                                             rtol, 0.0, _NODES, _WK, _WG, mode_code(), ibuf, iwork)
        else:
            val[i], err[i] = _k_numeric(mp, mu, s, math.atan2(mu, s), float(v), sa, rtol, 0.0, _NODES, _WK, _WG,
                                        mode_code(), ibuf, iwork)
    return val, err
