"""The outer integral of frames 0-5 over u (N.h or cos(alpha)): the breakpoints, the pieces and their substitutions, and
the globally adaptive rule (:func:`_integrate`); :mod:`pumpup.engine.polar` describes the method.
"""

from __future__ import annotations

import cmath
import math

import numpy as np
from numba import njit

from ..physics.microfacet import projected as _projected
from ..physics.quadrature import EPS, FLOOR, calibrated, rule_sums
from .cubature import NODES as _NODES
from .cubature import WG as _WG
from .cubature import WK as _WK
from .half_arc import LOBE_F_CUTS, SMITH, VCAVITY_F, _k_numeric
from .half_frames import _k_half, _k_vcavity, _k_ward
from .lobe_frame import INNER_MAX, INNER_RTOL_MIN, _k_closed, _k_of_u
from .lobe_fresnel import LOBE_F_WIDE, _k_lobe_fresnel, _lobe_f_prepare


@njit(cache=True, nogil=True)
def _smoothing(sm, tau):  # pragma: no cover - compiled
    """(x, 1 - x, dx/dtau) of the smoothing substitution on [0, 1]: sm = 0 none, 1 at the left
    end (x = tau^2), 2 at the right end (1 - x = (1 - tau)^2), 3 at both (x = tau^2 (3 - 2 tau)).
    """
    tc = 1.0 - tau
    if sm == 0:
        return tau, tc, 1.0
    if sm == 1:
        return tau * tau, tc * (1.0 + tau), 2.0 * tau
    if sm == 2:
        return tau * (1.0 + tc), tc * tc, 2.0 * tc
    return tau * tau * (3.0 - 2.0 * tau), tc * tc * (1.0 + 2.0 * tau), 6.0 * tau * tc


@njit(cache=True, nogil=True, inline="always")
def _u_at(kind, sm, n, v0, w, cv1, tau):  # pragma: no cover - compiled
    """(u, 1 - u, sin(alpha), factor) at tau in [0, 1] of a piece: the integrand per d tau is
    K(u) times the factor.

    kind 0: u = v0 + w X in [0, 1/2], factor u^n w dX;
    kind 1: z = -(n + 1) ln u in [v0, v0 + w] (y = u^(n+1)), 1 - y = cv1 + w (1 - X), factor
    e^-z w dX / (n + 1) (u^n du = e^-z dz / (n + 1));
    kind 2 (the half frame's Beckmann weight exp(-tan^2(alpha) / m^2), ``n`` = m): t = tan^2(alpha) / m^2 in
    [v0, v0 + w], u = 1 / sqrt(1 + m^2 t), factor e^-t (m^2 / 2) u^3 w dX (du = -(m^2 / 2) u^3 dt);
    kind 3 (the half frame's GGX weight 1 / (1 + t)^2, ``n`` = alpha): z = ln(1 + t) in [v0, v0 + w],
    t = e^z - 1, factor e^-z (m^2 / 2) u^3 w dX (dt / (1 + t)^2 = e^-z dz);
    X(tau) is the smoothing substitution ``sm`` (:func:`_smoothing`) at the ends where K has a
    square-root behaviour.
    """
    x, xc, dx = _smoothing(sm, tau)
    if kind == 0:
        u = v0 + w * x
        um = 1.0 - u
        un = u**n if n > 0.0 else 1.0
        return u, um, math.sqrt(um * (1.0 + u)), un * w * dx
    if kind == 2:
        t = v0 + w * x if x < 0.5 else cv1 - w * xc  # t = tan^2(alpha) / m^2, from the nearer end
        q = n * n * t  # tan^2(alpha)
        r = math.sqrt(1.0 + q)
        u = 1.0 / r
        return u, q / (r * (r + 1.0)), math.sqrt(q) / r, math.exp(-t) * 0.5 * n * n * u * u * u * w * dx
    if kind == 3:
        z = v0 + w * x if x < 0.5 else cv1 - w * xc  # z = ln(1 + tan^2(alpha) / alpha^2), from the nearer end
        q = n * n * math.expm1(z)  # tan^2(alpha)
        r = math.sqrt(1.0 + q)
        u = 1.0 / r
        return u, q / (r * (r + 1.0)), math.sqrt(q) / r, math.exp(-z) * 0.5 * n * n * u * u * u * w * dx
    z = v0 + w * x if x < 0.5 else cv1 - w * xc  # z = -(n + 1) ln u, from the nearer end
    lu = -z / (n + 1.0)
    um = -math.expm1(lu)
    u = 1.0 - um if um < 0.5 else math.exp(lu)  # exact to an ulp either way (one exp saved)
    return u, um, math.sqrt(um * (1.0 + u)), math.exp(-z) * w * dx / (n + 1.0)


# Gauss-Kronrod 10/21 on [-1, 1] (QUADPACK qk21): Kronrod nodes, their weights, and the weights of
# the embedded 10-point Gauss rule on the odd nodes
_XGK21 = np.array([
    0.995657163025808080735527280689003, 0.973906528517171720077964012084452,
    0.930157491355708226001207180059508, 0.865063366688984510732096688423493,
    0.780817726586416897063717578345042, 0.679409568299024406234327365114874,
    0.562757134668604683339000099272694, 0.433395394129247190799265943165784,
    0.294392862701460198131126603103866, 0.148874338981631210884826001129720, 0.0])
_WGK21 = np.array([
    0.011694638867371874278064396062192, 0.032558162307964727478818972459390,
    0.054755896574351996031381300244580, 0.075039674810919952767043140916190,
    0.093125454583697605535065465083366, 0.109387158802297641899210590325805,
    0.123491976262065851077482296703034, 0.134709217311473325928054001771707,
    0.142775938577060080797094273138717, 0.147739104901338491374841515972068,
    0.149445554002916905664936468389821])
_WG10 = np.array([0.066671344308688137593568809893332, 0.149451349150580593145776339657697,
                  0.219086362515982043995534934228163, 0.269266719309996355091226921569469,
                  0.295524224714752870173892994651338])
#: the 21-point rule on [0, 1]
NODES21 = 0.5 * (1.0 + np.concatenate([-_XGK21[:-1], _XGK21[::-1]]))
WK21 = 0.5 * np.concatenate([_WGK21[:-1], _WGK21[::-1]])
WG21 = np.zeros(21)
WG21[1:10:2] = 0.5 * _WG10
WG21[11::2] = 0.5 * _WG10[::-1]
#: the rule of the 1-D path (measured and tested with "gk21": 90-190 evaluations per mu for the
#: Phong family at rtol 1e-10)
RULE = "gk21"

#: the sharper estimate of the closed forms of frame 0 (``mode`` :data:`DECAY_MODE`, :func:`_decay_ratio`): the 21
#: values' coefficients of degree DECAY_LOW .. 20 in the polynomials orthonormal for the Kronrod weights, taken in pairs
#: of consecutive degrees, E_j = sqrt(c_(2j-1)^2 + c_(2j)^2) (so that an even or odd integrand's zeros do not read as
#: convergence).  Where their largest ratio r = max E_(j+1) / E_j is at most DECAY_RCRIT (geometric or faster decay),
#: the Kronrod rule's error, the coefficients from degree 32 on (it integrates degree 31 exactly), is estimated as
#: DECAY_SAFETY E_top r^DECAY_STEPS: the last pair's size carried the six pairs from degree 20 to 32 at the slowest
#: ratio seen, times a safety factor; else (slower decay: a singularity near the interval, a kink, rounding noise)
#: QUADPACK's estimate stands.  r is never taken below rho^-2, rho the Bernstein ellipse through the nearest point where
#: K or the weight is singular (:func:`_singular_ratio`): a small singular term's coefficients, hidden by
#: faster-decaying ones up to degree 20, decay no faster than that (retro n = 10 at mu = 0.864, the level's break 3 % of
#: the piece beyond its end: the coefficients' ratios 0.03, 0.09, 0.10 gave 1.6e-14 against a true 2.4e-14).  The
#: smaller of the two estimates is taken, never below QUADPACK's floor 50 eps resabs.
DECAY_LOW = 13  # (odd: :func:`_decay_ratio` pairs an odd degree with the next)
DECAY_RCRIT = 0.5
DECAY_STEPS = 6
DECAY_SAFETY = 10.0
#: QUADPACK's error of an interval at most DECAY_SHARE x rtol x (a lower bound of the integral) is kept as it is
DECAY_SHARE = 0.1
#: the ``mode`` that asks :func:`_integrate` for the sharper estimate (else QUADPACK's, :func:`calibrated`'s mode 1)
DECAY_MODE = 3


def _decay_rows(nodes: np.ndarray, wk: np.ndarray, low: int) -> np.ndarray:
    """Rows low .. len(nodes) - 1 of the matrix taking a rule's values to their coefficients in the polynomials
    orthonormal on [0, 1] for the discrete inner product sum_j wk_j f_j g_j (Legendre's, orthonormalised by a QR
    factorisation: up to degree 15 they are the Legendre polynomials themselves, which the Kronrod rule integrates
    exactly in pairs).
    """
    top = nodes.shape[0] - 1
    vander = np.polynomial.legendre.legvander(2.0 * nodes - 1.0, top)
    root = np.sqrt(wk)[:, None]
    q, r = np.linalg.qr(root * vander)
    q = q * np.sign(np.diag(r))
    rows = np.ascontiguousarray((q * root).T[low:])
    rows.flags.writeable = False
    return rows


#: :func:`_decay_rows` of the 21-point rule (8 x 21: degrees 13 .. 20)
DECAY_ROWS = _decay_rows(NODES21, WK21, DECAY_LOW)


@njit(cache=True, nogil=True, inline="always")
def _decay_ratio(f, rows, half):  # pragma: no cover - compiled; see decay_error_reference
    """(E_top, r) of the 21-point rule's values ``f`` (:data:`DECAY_ROWS`): the last pair's size and the largest ratio
    of consecutive pairs (inf where a pair follows one that is 0).  The rule is symmetric, so a polynomial of odd degree
    is odd about the middle and one of even degree even: the coefficients are sums over the 10 differences and the 11
    sums f_j -+ f_(20-j) (``half``, 2 x 11, work space).
    """
    for j in range(10):
        half[0, j] = f[j] - f[20 - j]
        half[1, j] = f[j] + f[20 - j]
    half[1, 10] = f[10]
    r = 0.0
    last = 0.0
    for pair in range(rows.shape[0] // 2):
        a = 0.0  # degree DECAY_LOW + 2 pair: odd
        b = rows[2 * pair + 1, 10] * half[1, 10]
        for j in range(10):
            a += rows[2 * pair, j] * half[0, j]
            b += rows[2 * pair + 1, j] * half[1, j]
        e = math.sqrt(a * a + b * b)
        if pair > 0:
            if last > 0.0:
                r = max(r, e / last)
            elif e > 0.0:
                r = math.inf
        last = e
    return last, r


@njit(cache=True, nogil=True, inline="always")
def _rho_ratio(xr, xi, sm, t0, t1, reach):  # pragma: no cover - compiled; see decay_error_reference
    """rho^-2 for the singular point x = xr + i xi (in the piece's variable before the smoothing ``sm``, the piece
    [0, 1]) seen from the interval [t0, t1] of tau: rho is the Bernstein ellipse's parameter through the nearest
    preimage of x under the smoothing (:func:`_smoothing`; 1.0 for sm = 3, whose preimages are not computed: no sharper
    estimate).  0.0 where every preimage lies farther than ``reach`` half-lengths from the interval's centre (outside
    the ellipse whose rho^-2 the caller already has), found without a square root.
    """
    if sm == 3:
        return 1.0
    c = 0.5 * (t0 + t1)
    hl = 0.5 * (t1 - t0)
    lim = reach * hl
    # |preimage - c| >= (the preimages' common distance from the smoothed end) - (c's distance from it)
    if sm == 0:
        far = (xr - c) * (xr - c) + xi * xi > lim * lim
    elif sm == 1:
        far = xr * xr + xi * xi > (lim + c) ** 4
    else:
        far = (1.0 - xr) * (1.0 - xr) + xi * xi > (lim + 1.0 - c) ** 4
    if far:
        return 0.0
    if xi == 0.0 and (sm == 0 or (sm == 1 and xr > 0.0) or (sm == 2 and xr < 1.0)):
        # real preimages: rho = |y| + sqrt(y^2 - 1) for the nearer one (|y| > 1: the point is outside the interval)
        if sm == 0:
            y = abs(xr - c) / hl
        elif sm == 1:
            y = min(abs(math.sqrt(xr) - c), math.sqrt(xr) + c) / hl
        else:
            y = min(abs(1.0 - math.sqrt(1.0 - xr) - c), abs(1.0 + math.sqrt(1.0 - xr) - c)) / hl
        if y <= 1.0:
            return 1.0
        rho = y + math.sqrt((y - 1.0) * (y + 1.0))
        return 1.0 / (rho * rho)
    x = complex(xr, xi)
    out = 0.0
    for branch in range(1 if sm == 0 else 2):
        if sm == 0:
            tau = x
        elif sm == 1:
            tau = cmath.sqrt(x) * (1.0 if branch == 0 else -1.0)
        else:
            tau = 1.0 - cmath.sqrt(1.0 - x) * (1.0 if branch == 0 else -1.0)
        y = (tau - c) / hl
        rho = abs(y + cmath.sqrt(y - 1.0) * cmath.sqrt(y + 1.0))
        out = max(out, 1.0 / (rho * rho) if rho > 1.0 else 1.0)
    return out


@njit(cache=True, nogil=True)
def _singular_points(n, p, mu, c2, sing):  # pragma: no cover - compiled; see decay_error_reference
    """Fill ``sing`` (4 x 6) with the points where frame 0's closed form K(u) (:func:`_k_closed`) or the weight is
    singular: u = +-s (the horizon), +-1, c2 = cos(2 theta_i) (p = 1: the level N.wo = mu) and 0 (u^n, n not an
    integer), row 0 (NaN where unused); rows 1-3 the same in z = -(n + 1) ln u: the real part, the imaginary step
    (pi (n + 1) for u < 0, the points -(n + 1) (ln|u| +- i pi); 2 pi (n + 1) for u > 0, the images of the real z) and
    1.0 where the real z itself is one (u > 0).
    """
    s = math.sqrt((1.0 - mu) * (1.0 + mu))
    ls = math.log(s) if s > 0.0 else -math.inf  # (one logarithm for +-s, none for +-1)
    for j in range(6):
        u = s if j == 0 else (-s if j == 1 else (1.0 if j == 2 else (-1.0 if j == 3 else (c2 if j == 4 else 0.0))))
        if (j == 4 and p != 1.0) or (j == 5 and n == math.floor(n)):
            u = math.nan
        sing[0, j] = u
        if u == 0.0 or u != u:
            sing[1, j], sing[2, j], sing[3, j] = math.nan, 0.0, 0.0
            continue
        lu = ls if j < 2 else (0.0 if j < 4 else math.log(abs(u)))
        sing[1, j] = -(n + 1.0) * lu
        sing[2, j] = (n + 1.0) * math.pi * (2.0 if u > 0.0 else 1.0)
        sing[3, j] = 1.0 if u > 0.0 else 0.0


@njit(cache=True, nogil=True)
def _singular_ratio(kind, sm, v0, w, t0, t1, r0, sing):  # pragma: no cover - compiled; see decay_error_reference
    """The largest rho^-2 (:func:`_rho_ratio`) above ``r0`` (else ``r0``) over the singular points ``sing``
    (:func:`_singular_points`) in the piece's variable: u (kind 0) or z (kind 1).  Points on the piece's closed range
    [0, 1] are its own ends: the singular side of a break there is the other piece's (or smoothed away).
    """
    worst = r0
    reach = -1.0
    for j in range(sing.shape[1]):
        if reach < 0.0:  # the ellipse of rho^-2 = worst (again after worst grew)
            big = 1.0 / math.sqrt(worst) if worst > 0.0 else math.inf
            reach = 0.5 * (big + 1.0 / big)
        last = worst
        if kind == 0:
            if sing[0, j] == sing[0, j]:
                x = (sing[0, j] - v0) / w
                if not 0.0 <= x <= 1.0:
                    worst = max(worst, _rho_ratio(x, 0.0, sm, t0, t1, reach))
            if worst > last:
                reach = -1.0
            continue
        if sing[1, j] != sing[1, j]:
            continue
        xr = (sing[1, j] - v0) / w
        step = sing[2, j] / w
        if sing[3, j] > 0.0 and not 0.0 <= xr <= 1.0:
            worst = max(worst, _rho_ratio(xr, 0.0, sm, t0, t1, reach))
        worst = max(worst, _rho_ratio(xr, step, sm, t0, t1, reach))
        worst = max(worst, _rho_ratio(xr, -step, sm, t0, t1, reach))
        if worst > last:
            reach = -1.0
    return worst


def singular_ratio_reference(kind: int, sm: int, n: float, p: float, mu: float, c2: float, v0: float, w: float,
                             t0: float, t1: float) -> float:
    """Plain Python twin of :func:`_singular_points` and :func:`_singular_ratio` (from r0 = 0): every point and every
    preimage in complex arithmetic, none skipped.
    """
    s = math.sqrt((1.0 - mu) * (1.0 + mu))
    us = [s, -s, 1.0, -1.0] + ([c2] if p == 1.0 else []) + ([0.0] if kind == 0 and n != math.floor(n) else [])
    points = []
    for u in us:
        if kind == 0:
            points.append(complex((u - v0) / w, 0.0))
        elif u != 0.0:
            z = -(n + 1.0) * math.log(abs(u))
            ims = [0.0, 2.0 * math.pi, -2.0 * math.pi] if u > 0.0 else [math.pi, -math.pi]
            points += [complex(z - v0, -(n + 1.0) * im) / w for im in ims]
    worst = 0.0
    for x in points:
        if x.imag == 0.0 and 0.0 <= x.real <= 1.0:
            continue
        if sm == 3:
            return 1.0
        root = cmath.sqrt(x) if sm == 1 else cmath.sqrt(1.0 - x)
        taus = {0: [x], 1: [root, -root], 2: [1.0 - root, 1.0 + root]}[sm]
        for tau in taus:
            y = (2.0 * tau - t0 - t1) / (t1 - t0)
            q = cmath.sqrt(y - 1.0) * cmath.sqrt(y + 1.0)
            rho = max(abs(y + q), abs(y - q))
            worst = max(worst, 1.0 / rho**2 if rho > 1.0 else 1.0)
    return worst


def decay_error_reference(f: np.ndarray, rho_ratio: float = 0.0) -> float:
    """Plain numpy twin of the sharper estimate (:func:`_decay_ratio`, per unit length) of the 21-point rule's values
    ``f``, with rho^-2 = ``rho_ratio`` from the singular points (:func:`_singular_ratio`): inf where it does not apply.
    """
    c = DECAY_ROWS @ np.asarray(f, dtype=np.float64)
    pairs = np.hypot(c[0::2], c[1::2])
    r = rho_ratio
    for lo, hi in zip(pairs[:-1], pairs[1:]):
        if lo == 0.0 and hi > 0.0:
            return math.inf
        r = max(r, hi / lo if lo > 0.0 else 0.0)
    return math.inf if r > DECAY_RCRIT else float(DECAY_SAFETY * pairs[-1] * r**DECAY_STEPS)


@njit(cache=True, nogil=True)
def _gk(frame, kind, sm, n, p, mu, c2, v0, w, cv1, t0, t1, nodes, wk, wg, mode, buf, itol, inodes,  # pragma: no cover
        iwk, iwg, ibuf, iwork, jac, mp, iacc):
    """(K, error) of the rule on [t0, t1]; the error is :func:`pumpup.physics.quadrature.calibrated` of
    |K - G| (``mode`` 1) or |K - G| itself (0), plus for p in (0, 1) and frame 4 the inner errors of the
    integrand's values (the inner rule ``inodes``, ``iwk``, ``iwg`` at relative tolerance
    ``itol``; frame 4 also at absolute tolerance ``iacc`` / the node's factor, :func:`_integrate`) summed with
    the Kronrod weights (frame 4: and |K - G| raised by what they can hide of it before its calibration); ``buf`` holds
    the values (one per node).  The closed forms p in {0, 1} have a loop of their own, with no call in it (a loop that
    may call :func:`_arc_power` ran 2.5 x slower for them; a pumped lobe has a loop of its own,
    :func:`_integrate_chain`: one integration loop that could call either rule ran 1.45 x slower for
    them).
    """
    h = t1 - t0
    ie = 0.0
    noise = 0.0
    if 0.0 < p < 1.0:
        for j in range(nodes.shape[0]):
            u, um, sa, fac = _u_at(kind, sm, n, v0, w, cv1, t0 + h * nodes[j])
            k, e = _k_of_u(p, mu, c2, u, um, sa, itol, inodes, iwk, iwg, mode, ibuf, iwork, jac)
            buf[j] = k * fac
            ie += wk[j] * e * fac
    elif frame == 0:
        for j in range(nodes.shape[0]):
            u, um, sa, fac = _u_at(kind, sm, n, v0, w, cv1, t0 + h * nodes[j])
            buf[j] = _k_closed(p, mu, c2, u, um, sa)[0] * fac
    elif frame == 4:  # the rule on h's arc (:func:`_k_numeric`); D's 1 / u^4 under the Beckmann and GGX weights
        s = math.sqrt((1.0 - mu) * (1.0 + mu))
        psi = math.atan2(mu, s)
        for j in range(nodes.shape[0]):
            u, um, sa, fac = _u_at(kind, sm, n, v0, w, cv1, t0 + h * nodes[j])
            if fac == 0.0:
                buf[j] = 0.0
                continue
            if kind >= 2:
                # (u^4 underflows below u ~ 1e-81, near grazing incidence, mu < 1e-80: GGX alpha = 1e-8 with an ior at
                # mu = 1e-100 divided by 0).  Where u^3 underflows too, below 1e-108, the weight's
                # value there is below 1e-96 K (GGX's e^-z (m^2 / 2) / u ~ m^4 u / 2, Beckmann's e^-t = 0): left out)
                u3 = u * u * u
                fac = fac / (u3 * u) if u3 * u > 0.0 else (fac / u3 / u if u3 > 0.0 else 0.0)
            # K's error may be itol |K| or iacc / fac: the second's share of the sum is at most itol times the
            # integral's lower bound so far (iacc, :func:`_integrate`).  Where that exceeds K's bound (0 <= K <= kmax:
            # 8 pi / P(mu) for the Smith models, 16 pi u mu for the V-cavity, 8 pi for Schlick's; F <= 1), K = 0 with
            # the error kmax (far in the weight's tail: a narrow GGX lobe's nodes beyond the horizon break); kmax holds
            # for every F(wi.h) <= 1 (the dielectric's, the conductor's, Schlick's)
            kmax = 8.0 * math.pi / mp[8] if mp[0] == SMITH else (16.0 * math.pi * u * mu if mp[0] == VCAVITY_F
                                                                 else 8.0 * math.pi)
            if iacc >= kmax * fac:
                k, e = 0.0, kmax
            else:
                k, e = _k_numeric(mp, mu, s, psi, u, sa, itol, iacc / fac, inodes, iwk, iwg, mode, ibuf, iwork)
            buf[j] = k * fac
            ie += wk[j] * e * fac
            noise += (wk[j] + wg[j]) * e * fac  # what the values' errors can hide of |K - G|
    elif frame == 5:  # the lobe frame with F(Theta_min) (:func:`_k_lobe_fresnel`), as frame 4 takes K's errors
        for j in range(nodes.shape[0]):
            u, um, sa, fac = _u_at(kind, sm, n, v0, w, cv1, t0 + h * nodes[j])
            if fac == 0.0:
                buf[j] = 0.0
                continue
            if iacc >= 2.0 * math.pi * fac:  # K <= 2 pi (N.wo F / max(mu, N.wo)^p <= 1)
                k, e = 0.0, 2.0 * math.pi
            else:
                k, e = _k_lobe_fresnel(mp, p, mu, c2, u, um, sa, itol, iacc / fac, inodes, iwk, iwg, mode, ibuf, iwork)
            buf[j] = k * fac
            ie += wk[j] * e * fac
            noise += (wk[j] + wg[j]) * e * fac
    else:  # the half-vector frame: the Blinn family and modified Ward, p in {0, 1} (frame 1); Ward (frame 2)
        s = math.sqrt((1.0 - mu) * (1.0 + mu))
        psi = math.atan2(mu, s)
        for j in range(nodes.shape[0]):
            u, um, sa, fac = _u_at(kind, sm, n, v0, w, cv1, t0 + h * nodes[j])
            if frame == 1:
                k = _k_half(p, mu, s, psi, u, sa)
            elif frame == 2:
                k = _k_ward(mu, s, psi, u, sa)
            else:  # 3: V-cavity G, F = 1; under the Beckmann and GGX weights D carries 1 / u^4 (001 eq. 9)
                k = _k_vcavity(mu, s, psi, u, sa) / (u * u * u * u if kind >= 2 else 1.0)
            buf[j] = k * fac
    k, diff, asc, ab = rule_sums(buf, wk, wg)
    # (frame 5: at most the raw |K - G| raised by the noise, QUADPACK's "min" mode: where the values' errors dominate
    # |K - G| on a small interval, the calibration's (200 |K - G| / resasc)^1.5 grows as resasc shrinks, and bisecting
    # raised the total: fresnel over stretched Phong n = 0, eta 0.999, k 0.001 at mu = 1e-3 and rtol 1e-6 went from
    # 4.1e-8 to 3.0e-7 in 1000 bisections)
    return k * h, calibrated((diff + noise) * h, asc * h, ab * h, 2 if frame == 5 and mode == 1 else mode) + ie * h


@njit(cache=True, nogil=True, inline="always")
def _gk_closed(kind, sm, n, p, mu, c2, v0, w, cv1, t0, t1, buf, sing, half, drel, low_sum):  # pragma: no cover
    """(K, error) of the 10/21 rule on [t0, t1] for frame 0's closed forms (p in {0, 1}, :func:`_k_closed`), the error
    the smaller of QUADPACK's calibrated one and the one from the decay of the rule's coefficients
    (:data:`DECAY_ROWS`, :func:`_decay_ratio`, :func:`_singular_ratio`; ``mode`` :data:`DECAY_MODE` of
    :func:`_integrate`).  Inlined, with the rule's arrays as constants: :func:`_gk`'s call passes a dozen arrays, whose
    reference counts cost about as much per interval as the sharper estimate saves.  Where QUADPACK's error is at most
    ``drel`` times a lower bound of the integral (``low_sum``, the intervals' so far, or this one's value less its
    error: the integrand is >= 0) the sharper one is not sought.
    """
    h = t1 - t0
    for j in range(21):
        u, um, sa, fac = _u_at(kind, sm, n, v0, w, cv1, t0 + h * NODES21[j])
        buf[j] = _k_closed(p, mu, c2, u, um, sa)[0] * fac
    k = 0.0
    g = 0.0
    ab = 0.0
    for j in range(21):
        k += WK21[j] * buf[j]
        g += WG21[j] * buf[j]
        ab += WK21[j] * abs(buf[j])
    asc = 0.0
    for j in range(21):
        asc += WK21[j] * abs(buf[j] - k)
    # QUADPACK's calibration (:func:`calibrated`, mode 1) written out with t^1.5 as t sqrt(t): calling it, with its
    # pow, made Phong n = 20's table 5-10 % slower (python scripts/bench/bench_polar.py, alternating)
    diff = abs(k - g) * h
    err = diff
    if asc != 0.0 and diff != 0.0:
        t = min(1.0, 200.0 * diff / (asc * h))
        err = asc * h * t * math.sqrt(t)
    low = FLOOR * EPS * ab * h
    err = max(low, err)
    if err > low and err > drel * max(low_sum, k * h - err):
        top, r = _decay_ratio(buf, DECAY_ROWS, half)
        if r <= DECAY_RCRIT and DECAY_SAFETY * top * r**DECAY_STEPS * h < err:
            # no faster than the nearest singular point lets the coefficients decay
            if sing[0, 0] != sing[0, 0]:  # (the points of this mu, once: row 0 starts as NaN)
                _singular_points(n, p, mu, c2, sing)
            r = _singular_ratio(kind, sm, v0, w, t0, t1, r, sing)
            if r <= DECAY_RCRIT:
                err = min(err, max(low, DECAY_SAFETY * top * r**DECAY_STEPS * h))
    return k * h, err


#: the peak variable z = -(n + 1) ln u runs at most to Z_MAX: below u = exp(-Z_MAX / (n + 1)) the
#: integral of u^n K(u) is at most 2 pi e^-Z_MAX / (n + 1) (K <= 2 pi), added to the error
Z_MAX = 40.0


#: the most breakpoints :func:`_pieces` takes (8, frame 4's graded cuts, 3 x 16, and its cuts about F's branch point,
#: 2 x (1 + 2 LOBE_F_CUTS))
MAX_BREAKS = 96

#: the most graded pieces :func:`_pieces` makes (:func:`_graded_cuts` stops there; 4 tail, the graded cuts above the
#: horizon break, 3 peak; frame 4's cuts)
MAX_PIECES = 128
#: the size of :func:`_pieces`'s arrays: MAX_PIECES graded ones and the pieces between every two breaks of the tail and
#: the peak, which come after them (with 128 slots in all, a narrow GGX lobe at grazing incidence, alpha = 1e-8 at mu =
#: 1e-100 and rtol 1e-13 on frame 4, wrote past the end: found by NUMBA_BOUNDSCHECK=1)
#: the most cuts :func:`_foreign_roots` adds to the tail's or the peak's breaks
FOREIGN_CUTS = 64
#: a piece is graded where a break's root lies beyond its end closer than this fraction of its length
#: (:func:`_foreign_roots`: farther, the 10-point Gauss rule's error is at least 1e-3 of the piece, and the calibrated
#: estimate is then the whole |K - G|)
FOREIGN_NEAR = 1.0 / 64.0
#: the split of tail (u) and peak (z) of :func:`_pieces`: the first of these without a break within SPLIT_CLEAR (else
#: the one farthest from them), so that no range's end lies next to a break it is not (the V-cavity's alpha = pi / 3 is
#: an ulp above 1/2; the level cos 2 theta_i passes 1/2 at mu = sqrt(3) / 2, where the horizon's s does)
SPLITS = (0.5, 0.45, 0.55, 0.4, 0.6)
SPLIT_CLEAR = 0.02
#: a lobe about R (frames 0 and 5) with 0 < n below this has its tail piece at u = 0 graded geometrically towards 0
#: (pieces [u / 4, u] down to :data:`LOG_GRADE_FLOOR`): u^n = exp(n ln u) then carries a term n ln u, singular at 0,
#: which a first rule on [0, 1/2] integrates with an error of order n that |K - G| under-reports (Phong n = 1e-9 was
#: 2.4 x its estimate against the 2-D cubature at rtol 1e-13, Lewis's Phong 5.4e-13 above its exact 1 with an estimate
#: of 9e-14); from n ~ 1e-6 up the rule's own estimate sees it
LOG_N_MAX = 1e-5
#: ... down to this u (the piece [0, LOG_GRADE_FLOOR] holds at most n LOG_GRADE_FLOOR |ln LOG_GRADE_FLOOR| of K's bound)
LOG_GRADE_FLOOR = 1e-20
PIECES_CAP = MAX_PIECES + 2 * (MAX_BREAKS + 4 + FOREIGN_CUTS) + 40


@njit(cache=True, nogil=True)
def _sorted_cuts(cv, cc, m):  # pragma: no cover - compiled
    """Insertion sort (stable) of the first m cut values ``cv`` with their codes ``cc``."""
    for a in range(1, m):
        v, c = cv[a], cc[a]
        b = a - 1
        while b >= 0 and cv[b] > v:
            cv[b + 1] = cv[b]
            cc[b + 1] = cc[b]
            b -= 1
        cv[b + 1] = v
        cc[b + 1] = c


@njit(cache=True, nogil=True)
def _foreign_roots(cv, cc, nc, rv, rc, nr, tail):  # pragma: no cover - compiled
    """Cuts (code 3) grading a piece between the cuts ``cv[:nc]`` towards its end where the square root of a break
    (``rv[:nr]``, codes ``rc``: every break, in the range or beyond it) lies beyond that end, closer than FOREIGN_NEAR
    of the piece's length: at that end -+ d 4^i (d the distance) over the piece's half next to it.  A break's root lies
    on one side of it (in u, ``tail``: code 0 below, 1 above, 2 both; in z = -(n + 1) ln u the other way round) and
    reaches across any cut next to it: near mu = sqrt(3) / 2 the level's (u = cos 2 theta_i) and the horizon's (u = s)
    nearly coincide, and the level's root lay 4.5e-6 beyond the end of the peak's piece [0, z_s], where no rule saw it
    (stretched Phong n = 10 at mu = 0.866025, rtol 1e-12: 3.2e-12 off with an estimate of 6.6e-13; 40-digit mpmath, the
    nested engine and the frame of N agree to 1e-15).  Appends to ``cv``, ``cc`` and sorts them; returns their number.
    """
    m = nc
    for j in range(nr):
        c = rc[j]
        low = (c == 0 or c == 2) if tail else (c == 1 or c == 2)  # its root reaches down (to the pieces below it)
        high = (c == 1 or c == 2) if tail else (c == 0 or c == 2)
        for i in range(nc - 1):
            lo, hi = cv[i], cv[i + 1]
            if low and rv[j] > hi:
                d = rv[j] - hi
                x, sign = hi, -1.0
            elif high and rv[j] < lo:
                d = lo - rv[j]
                x, sign = lo, 1.0
            else:
                continue
            if not d < FOREIGN_NEAR * (hi - lo):
                continue
            while d < 0.5 * (hi - lo) and m < min(cv.shape[0], nc + FOREIGN_CUTS):
                cv[m], cc[m] = x + sign * d, 3
                m += 1
                d *= 4.0
    if m > nc:
        _sorted_cuts(cv, cc, m)
    return m


@njit(cache=True, nogil=True, inline="always")
def _graded_cuts(kind, lo, hi, left, k, margin, kinds, sms, v0, w, v1):  # pragma: no cover - compiled
    """Pieces of ``kind`` from lo cut at lo (1 + 4^i) while they fit below hi (and the arrays keep ``margin``
    slots), written from slot k; the first keeps the left smoothing ``left``.  Returns (where the rest of
    [lo, hi] starts, the next slot, the rest's left smoothing).
    """
    a = lo
    step = lo  # the first cut at 2 lo
    while a + step < hi - step and k < MAX_PIECES - margin:
        kinds[k] = kind
        sms[k] = (1 if left else 0) if a == lo else 0
        v0[k] = a
        w[k] = step
        v1[k] = a + step
        k += 1
        a = a + step
        step = 3.0 * a - 3.0 * lo  # cuts at lo (1 + 4^i)
    return a, k, left and a == lo


@njit(cache=True, nogil=True)
def _vcavity_breaks(mu, s, psi):  # pragma: no cover - compiled
    """The angles alpha of h from N where :func:`_k_vcavity`'s pieces change (0 for none): where a crossing of
    its lines reaches the top of h's circle (c = 2 u mu at alpha = pi/2 - theta_i = psi; c = mu / u at
    alpha = theta_i) or the top or bottom (c = 2 u mu / (4 u^2 - 1): cos(theta_i -+ alpha) sin(3 alpha) =
    sin(2 alpha) mu, by bisection on (0, pi/3), where it changes sign), and where the crossings meet
    (alpha = pi/4) or one meets the arc's end mu / (2 u) (alpha = pi/3).
    """
    th = 0.5 * math.pi - psi
    out = np.zeros(6)
    out[0], out[1], out[2], out[3] = psi, th, 0.25 * math.pi, math.pi / 3.0
    for k in range(2):
        sg = 1.0 if k == 0 else -1.0
        lo, hi = 1e-9, math.pi / 3.0 - 1e-9
        flo = (mu * math.cos(lo) + sg * s * math.sin(lo)) * math.sin(3.0 * lo) - math.sin(2.0 * lo) * mu
        fhi = (mu * math.cos(hi) + sg * s * math.sin(hi)) * math.sin(3.0 * hi) - math.sin(2.0 * hi) * mu
        if flo * fhi >= 0.0:
            continue
        for _ in range(60):
            mid = 0.5 * (lo + hi)
            fm = (mu * math.cos(mid) + sg * s * math.sin(mid)) * math.sin(3.0 * mid) - math.sin(2.0 * mid) * mu
            if (fm < 0.0) == (flo < 0.0):
                lo, flo = mid, fm
            else:
                hi = mid
        out[4 + k] = 0.5 * (lo + hi)
    return out


@njit(cache=True, nogil=True, inline="always")
def _zr(radial, tb, n):  # pragma: no cover - compiled
    """The peak variable at tan(alpha) = tb under the half frame's Beckmann weight (radial 1: t = tan^2(alpha) / m^2)
    or GGX weight (radial 2: ln(1 + t)).
    """
    t = (tb / n) ** 2
    return t if radial == 1 else math.log1p(t)


@njit(cache=True, nogil=True, inline="always")
def _branch_cuts(ub, zb, kb, m, th_i, x0, y0, st0, radial, n, n1):  # pragma: no cover - compiled
    """:func:`_pieces`' cuts about F's branch point x0 - i y0 (st0 = sqrt(1 - x0^2)): where the arc's (frame 5) or h's
    circle's (frame 4) highest or lowest cosine, cos(theta_i -+ alpha), passes x0 (alpha = |theta_i - theta_0| or
    theta_i + theta_0), and at -+ (y0 / sin(theta_0) / 2) 4^j from there, j < LOBE_F_CUTS, not smoothed (code 3); u =
    cos(alpha), z by the radial weight (``radial`` 0: -(n + 1) ln u).  Returns the new number of breaks
    (at most MAX_BREAKS).
    """
    th_0 = math.atan2(st0, x0)
    for ax in (abs(th_i - th_0), th_i + th_0):
        if not 0.0 < ax < 0.5 * math.pi:
            continue
        for side in range(3):
            off = 0.5 * y0 / st0
            for _ in range(LOBE_F_CUTS if side else 1):
                ab = ax if side == 0 else (ax - off if side == 1 else ax + off)
                if not 0.0 < ab < 0.5 * math.pi or m >= MAX_BREAKS:
                    break
                ub[m], kb[m] = math.cos(ab), 3
                zb[m] = _zr(radial, math.tan(ab), n) if radial else -n1 * math.log1p(-2.0 * math.sin(0.5 * ab) ** 2)
                m += 1
                off *= 4.0
    return m


@njit(cache=True, nogil=True)
def _pieces(frame, radial, n, p, mu, s, kinds, sms, v0, w, v1, mp):  # pragma: no cover - compiled
    """The pieces between the breakpoints, written into ``kinds``, ``sms`` (the smoothing), ``v0``,
    ``w``, ``v1`` (arrays of :data:`PIECES_CAP`); returns (their number, c2 = cos 2 theta_i, a bound of
    the part left out).

    Breakpoints: u = 0, 1/2, 1 and, in the lobe frame (``frame`` 0), u = s (the horizon starts to cut
    the arc) and cos 2 theta_i (the level mu leaves it, p > 0); in the half-vector frame (1,
    :func:`_k_half`; 2, :func:`_k_ward`; 3, :func:`_k_vcavity`), u = cos(pi/4 - theta_i/2) (the horizon starts
    to cut h's circle), cos(theta_i) (the level mu leaves it, p > 0), u_lo = cos(pi/4 + theta_i/2), below which
    no h sends wo above the horizon (the range starts there), and for frame 3 :func:`_vcavity_breaks`.  kind 0: u in
    [v0, v1 = v0 + w] (u <= 1/2); kind 1: z = -(n + 1) ln u in [v0, v1].  Where exp(-Z_MAX / (n + 1)) > 1/2 the range of
    u below it is left out (its bound is returned).  With ``radial`` 1 (the half frame's Beckmann weight, ``n`` = m) the
    whole range is kind 2, t = tan^2(alpha) / m^2 in [0, Z_MAX] (:func:`_u_at`), cut at the same breaks; with
    ``radial`` 2 (the GGX weight, ``n`` = alpha) kind 3, z = ln(1 + t) up to u_lo (the weight e^-z dz leaves no
    tail to cut).  Frame 4 (:func:`_k_numeric`, parameters ``mp``) has the V-cavity's breaks for its V-cavity model,
    and for Walter's G1 the angles |arccos(z_w) -+ theta_i| / 2 where its switch level N.wo = z_w leaves h's
    circle (at its top and bottom, N.wo = cos(2 alpha -+ theta_i)).
    """
    c2 = (mu - s) * (mu + s)
    n1 = n + 1.0
    uz = math.exp(-Z_MAX / n1)
    skip = uz > 0.5
    z_split = Z_MAX if skip else n1 * math.log(2.0)
    # breakpoints in u, and their z = -(n + 1) ln u (or t) to full precision; codes 0: horizon (sqrt
    # below), 1: level mu (sqrt above), 2: a kink smoothed on both sides, 3: a cut (frame 4's grading), not smoothed
    ub = np.empty(MAX_BREAKS)
    zb = np.empty(MAX_BREAKS)
    kb = np.empty(MAX_BREAKS, np.int64)
    m = 0
    u_min, z_end, k_end = 0.0, z_split, -1  # the range: u >= u_min, z <= z_end (code of that end)
    peak = 1  # the kind of the peak's pieces
    if radial == 1:  # t = tan^2(alpha) / m^2 everywhere (half frame only)
        skip, z_end, peak = True, Z_MAX, 2
    elif radial == 2:  # ln(1 + t) everywhere, up to u_lo (half frame only)
        skip, z_end, peak = True, math.inf, 3
    if frame == 0 or frame == 5:
        if 0.0 < s < 1.0:
            ub[m], zb[m], kb[m] = s, -0.5 * n1 * math.log1p(-mu * mu), 0
            m += 1
        if (p > 0.0 or frame == 5) and 0.0 < c2 < 1.0:  # (frame 5: F(max(mu, N.wo)) has the level for any p)
            ub[m], zb[m], kb[m] = c2, -n1 * math.log1p(-2.0 * s * s), 1
            m += 1
        for pt in range(2 if frame == 5 else 0):
            x0, y0 = (mp[13], mp[14]) if pt == 0 else (0.0, mp[15])  # F's branch point; its pole near 0
            st0 = math.sqrt((1.0 - x0) * (1.0 + x0)) if x0 < 1.0 else 0.0
            if not (x0 < 1.0 and x0 + 2.0 * y0 > mu and y0 < LOBE_F_WIDE * st0):
                continue
            # K(u) turns where the arc's highest or lowest N.wo, cos(theta_i -+ alpha), passes F's branch point's x0
            # (alpha = |theta_i - theta_0| or theta_i + theta_0), on the scale y0 / sin(theta_0) in alpha: cuts there
            # and at -+ (that scale / 2) 4^j, not smoothed (code 3), as frame 4's (a first rule on a wide piece may not
            # see it; one on the scale LOBE_F_WIDE or wider does)
            m = _branch_cuts(ub, zb, kb, m, math.atan2(s, mu), x0, y0, st0, 0, n, n1)
    else:
        psi = math.atan2(mu, s)  # pi / 2 - theta_i, exact near grazing incidence
        hf = 0.25 * psi  # u_f = cos(pi/4 - theta_i/2) = cos(2 hf) = 1 - 2 sin^2(hf)
        tf = math.tan(2.0 * hf)  # tan(alpha_f); alpha_lo = pi/2 - alpha_f
        ub[m], kb[m] = math.cos(2.0 * hf), 0
        zb[m] = _zr(radial, tf, n) if radial else -n1 * math.log1p(-2.0 * math.sin(hf) ** 2)
        m += 1
        if p > 0.0 and 0.0 < mu < 1.0:
            ub[m], kb[m] = mu, 1
            zb[m] = _zr(radial, s / mu, n) if radial else -n1 * math.log(mu)  # tan(theta_i) = s / mu
            m += 1
        u_min = math.sin(0.5 * psi)  # cos(pi/4 + theta_i/2)
        if u_min > 0.0:
            if radial == 1:
                z_lo = 1.0 / (tf * n) ** 2
            elif radial == 2:
                z_lo = math.log1p((tf * n) ** 2) - 2.0 * math.log(tf * n)  # ln(1 + 1 / (tf n)^2), no overflow
            else:
                z_lo = -n1 * math.log(u_min)
            if z_lo < z_end:
                z_end, k_end = z_lo, 1
        if frame == 3 or (frame == 4 and mp[0] == VCAVITY_F):  # the V-cavity G's kinks (:func:`_vcavity_breaks`),
            for ab in _vcavity_breaks(mu, s, psi):  # smoothed on both sides (code 2)
                if ab > 0.0:
                    ub[m], kb[m] = math.cos(ab), 2
                    zb[m] = _zr(radial, math.tan(ab), n) if radial else -n1 * math.log1p(-2.0 * math.sin(0.5 * ab) ** 2)
                    m += 1
        if frame == 4 and mp[9] > 0.0:  # Walter's G1 switch N.wo = z_w leaves h's circle: a jump of G, a kink of K
            th = 0.5 * math.pi - psi
            aw = math.atan2(math.sqrt((1.0 - mp[9]) * (1.0 + mp[9])), mp[9])
            for ab in (0.5 * (aw + th), 0.5 * abs(aw - th)):
                if 0.0 < ab < 0.5 * math.pi:
                    ub[m], kb[m] = math.cos(ab), 2
                    zb[m] = _zr(radial, math.tan(ab), n) if radial else -n1 * math.log1p(-2.0 * math.sin(0.5 * ab) ** 2)
                    m += 1
        if frame == 4 and mp[0] == SMITH:
            # a conductor's F(c) whose branch point w = x0 - i y0 lies near the real axis inside (0, 1) (eta < 1, small
            # k: a near-kink at c = x0): h's circle at alpha has c = wi.h in [cos(alpha + theta_i),
            # cos(alpha - theta_i)], so K(u) turns where an end of that range passes x0, at alpha =
            # |theta_i -+ theta_0|, on the scale y0 / sin(theta_0) in alpha; near normal incidence c hardly varies on
            # the circle and the whole near-kink is K's.  Cuts there and at -+ (that scale / 2) 4^j, not smoothed
            # (code 3), as frame 5's in the lobe frame.  Without them GGX alpha = 0.003 with eta 0.271, k 0.0605 at mu =
            # 1 was 2.4e-11 off with an estimate of 3.5e-12 (rtol 1e-10; scripts/studies/fuzz_engines.py)
            x0, y0 = mp[13], mp[14]
            st0 = math.sqrt((1.0 - x0) * (1.0 + x0)) if 0.0 < x0 < 1.0 else 0.0
            if st0 > 0.0 and y0 < x0 and y0 < LOBE_F_WIDE * st0:
                m = _branch_cuts(ub, zb, kb, m, 0.5 * math.pi - psi, x0, y0, st0, radial, n, n1)
        # (the weight's mass beyond alpha_f / 2, 1 / (1 + t) for GGX's and e^-t for Beckmann's, times K's bound over
        # P(mu) ~ mu, below 1e-3 rtol: the cuts cannot matter, a narrow lobe far from grazing incidence)
        tail = 0.0
        if frame == 4 and mp[11] < 1.0 and radial > 0:
            t_half = (math.tan(0.25 * psi) / n) ** 2
            tail = (1.0 / (1.0 + t_half) if radial == 2 else math.exp(-t_half)) / mu
        if tail > 1e-3 * mp[12]:
            # K(u) turns on the scale alpha (P's, :func:`_k_numeric`; Schlick's r / (1 - r)) where the lowest N.wo on
            # h's circle, sin(psi - 2 alpha_h) / (2 u) ~ alpha_f - alpha_h, nears 0 (the horizon break alpha_f = psi /
            # 2, from both sides) and where the arc's highest N.wo does (alpha_lo = pi / 2 - psi / 2): a first rule on a
            # piece hundreds of times wider did not see it (GGX alpha = 0.001, mu = 0.59: 1.6e-10 off at rtol 1e-12, the
            # estimate 6e-13), so these get cuts at alpha_f -+ (alpha / 2) 4^k and alpha_lo - (alpha / 2) 4^k,
            # without smoothing (code 3), up to the middle of [alpha_f, alpha_lo]
            a_f, a_lo = 0.5 * psi, 0.5 * math.pi - 0.5 * psi
            a_mid = 0.5 * (a_f + a_lo)
            for side in range(3):
                off = 0.5 * mp[11]
                for _ in range(16):
                    ab = a_f - off if side == 0 else (a_f + off if side == 1 else a_lo - off)
                    if ((side == 0 and ab <= 0.0) or (side == 1 and ab >= a_mid) or (side == 2 and ab <= a_mid)
                            or m >= MAX_BREAKS):
                        break
                    ub[m], kb[m] = math.cos(ab), 3
                    zb[m] = _zr(radial, math.tan(ab), n)
                    m += 1
                    off *= 4.0
    u_sp = 0.5
    if not skip:  # the split of tail and peak away from the breaks (SPLITS)
        far = -1.0
        for cand in SPLITS:
            gap = 1.0
            for j in range(m):
                if kb[j] != 3:
                    gap = min(gap, abs(ub[j] - cand))
            if gap > far:
                far, u_sp = gap, cand
            if gap >= SPLIT_CLEAR:
                break
        if u_sp != 0.5:
            if u_min < u_sp:  # the peak ends at the split
                z_end, k_end = -n1 * math.log(u_sp), -1
            elif k_end == -1:  # (u_min in [u_sp, 1/2): the range ends at u_min, before the split)
                z_end, k_end = -n1 * math.log(u_min), 1
    cv = np.empty(MAX_BREAKS + 4 + FOREIGN_CUTS)
    cc = np.empty(MAX_BREAKS + 4 + FOREIGN_CUTS, np.int64)
    k = 0
    # tail pieces (increasing u)
    if not skip and u_min < u_sp:
        nc = 0
        cv[nc], cc[nc] = u_min, (1 if u_min > 0.0 else -1)
        nc += 1
        for j in range(m):
            if u_min < ub[j] < u_sp:
                cv[nc], cc[nc] = ub[j], kb[j]
                nc += 1
        cv[nc], cc[nc] = u_sp, -1
        nc += 1
        _sorted_cuts(cv, cc, nc)
        nc = _foreign_roots(cv, cc, nc, ub, kb, m, True)
        for j in range(nc - 1):
            lo, hi = cv[j], cv[j + 1]
            if hi > lo:
                left = cc[j] == 1 or cc[j] == 2  # (code 1 only where p > 0, or the half frame's u_lo)
                right = cc[j + 1] == 0 or cc[j + 1] == 2
                a = lo
                if lo == 0.0 and (frame == 0 or frame == 5) and 0.0 < n < LOG_N_MAX:
                    # n ln u at u = 0: pieces [e / 4, e] from the floor up (:data:`LOG_N_MAX`)
                    e = hi
                    while e > LOG_GRADE_FLOOR:
                        e *= 0.25
                    while 4.0 * e < hi:
                        kinds[k], sms[k], v0[k], w[k], v1[k] = 0, 0, a, e - a, e
                        k += 1
                        a, e = e, 4.0 * e
                    left = False
                if frame != 0 and frame != 5 and lo > 0.0:
                    # the half frame near grazing incidence: above u_lo ~ mu / 2 and the level u = mu the
                    # arc's end c0 = mu / (2 u) changes on the scale of u itself, so the piece is cut at
                    # lo (1 + 4^i) (as above z_s below): one first interval on [mu / 2, 1/2] hid it
                    a, k, left = _graded_cuts(0, lo, hi, left, k, 8, kinds, sms, v0, w, v1)
                kinds[k] = 0
                sms[k] = (1 if left else 0) + (2 if right else 0)
                v0[k] = a
                w[k] = hi - a
                v1[k] = hi
                k += 1
    # peak pieces (increasing z = decreasing u)
    nc = 0
    cv[nc], cc[nc] = 0.0, -2  # z = 0: u = 1, a square-root end for p = 1
    nc += 1
    for j in range(m):
        if zb[j] < z_end:
            cv[nc], cc[nc] = zb[j], kb[j]
            nc += 1
    top = p > 0.0 or frame == 5  # u = 1 (z = 0) is a square-root end: the level mu passes through R (through h = N)
    cv[nc], cc[nc] = z_end, k_end
    nc += 1
    _sorted_cuts(cv, cc, nc)
    nc = _foreign_roots(cv, cc, nc, zb, kb, m, False)
    for j in range(nc - 1):
        lo, hi = cv[j], cv[j + 1]
        if hi > lo:
            # in z the horizon's square root lies above z_s, the level's below z_c
            left = cc[j] == 0 or cc[j] == 2 or (top and cc[j] == -2)
            right = cc[j + 1] == 1 or cc[j + 1] == 2
            # above the horizon break z_s the arc shrinks from the full circle to half of it on
            # the scale of z_s itself (sin(alpha) ~ mu): near grazing z_s is tiny, and the piece
            # is cut at z_s (1 + 4^i) so that no first interval hides that feature
            a = lo
            if cc[j] == 0 or cc[j] == 2:
                a, k, left = _graded_cuts(peak, lo, hi, left, k, 4, kinds, sms, v0, w, v1)
            kinds[k] = peak
            sms[k] = (1 if left else 0) + (2 if right else 0)
            v0[k] = a
            w[k] = hi - a
            v1[k] = hi
            k += 1
    # beyond Z_MAX: K <= 2 pi in the lobe frame, <= 8 pi in the half-vector frame (4 (wi.h) N.wo / max^p <= 4);
    # with the Beckmann weight, integral_Z^inf e^-t 8 pi (m^2 / 2) u^3 dt, u^3 <= (1 + m^2 Z)^(-3/2) there
    # the V-cavity's K <= 16 pi u mu (c G <= 2 u mu): under the Beckmann weight e^-t (m^2 / 2) u^3 K / u^4 <= 8 pi m^2
    # mu e^-t; under u^n, integral_0^uz u^(n+1) 16 pi mu du
    if radial == 2:
        left_out = 0.0  # the range ends at u_lo
    elif radial == 1 and frame == 4 and mp[0] == SMITH:
        # K <= 8 pi / P(mu) (4 c F Gamma <= 4 G / mu <= 4 / P(mu)), and (m^2 / 2) u^3 K / u^4 with
        # 1 / u = sqrt(1 + m^2 t) <= A + B (t - Z), A = sqrt(1 + m^2 Z), B = m^2 / (2 A) (concave)
        big_a = math.sqrt(1.0 + n * n * Z_MAX)
        left_out = (4.0 * math.pi * n * n * math.exp(-Z_MAX) * (big_a + 0.5 * n * n / big_a) / mp[8] if k_end == -1
                    else 0.0)
    elif frame == 5:  # K <= 2 pi, as in the lobe frame
        left_out = 2.0 * math.pi * math.exp(-Z_MAX) / n1 if skip and k_end == -1 else 0.0
    elif radial == 1 and frame >= 3:
        left_out = 8.0 * math.pi * n * n * mu * math.exp(-Z_MAX) if k_end == -1 else 0.0
    elif frame >= 3:  # (frame 4 here: the V-cavity with F <= 1)
        left_out = 16.0 * math.pi * mu * math.exp(-Z_MAX * (n + 2.0) / n1) / (n + 2.0) if skip and k_end == -1 else 0.0
    elif radial == 1:
        left_out = 4.0 * math.pi * n * n * math.exp(-Z_MAX) / (1.0 + n * n * Z_MAX) ** 1.5 if k_end == -1 else 0.0
    else:
        left_out = (2.0 if frame == 0 else 8.0) * math.pi * math.exp(-Z_MAX) / n1 if skip and k_end == -1 else 0.0
    return k, c2, left_out


@njit(cache=True, nogil=True, inline="always")
def _buffers(max_intervals, nodes, inodes, rtol):  # pragma: no cover - compiled
    """The work arrays of the adaptive loop (intervals: piece, ends, value, error; rule values; the
    inner rule's) and the inner rule's relative tolerance, a small part of the total (rtol / 8).
    """
    cap = max_intervals + 64
    return (cap, np.empty(cap, np.int64), np.empty(cap), np.empty(cap), np.empty(cap), np.empty(cap),
            np.empty(nodes.shape[0]), np.empty(inodes.shape[0]), np.empty((4, INNER_MAX)),
            max(0.125 * rtol, INNER_RTOL_MIN))


@njit(cache=True, nogil=True, inline="always")
def _status(kv, ke, m, left_out, rounding, rtol, atol):  # pragma: no cover - compiled
    """(value, error, rounding error, the interval with the largest error, done) of the first m
    intervals: done when the error meets the tolerance or is below the rounding error of the
    integrand (refining cannot help there).
    """
    tot = 0.0
    e = left_out
    ab = 0.0
    worst = 0
    for j in range(m):
        tot += kv[j]
        e += ke[j]
        ab += abs(kv[j])
        if ke[j] > ke[worst]:
            worst = j
    r = rounding * ab
    return tot, e, r, worst, e <= max(rtol * abs(tot), atol) or e <= r


@njit(cache=True, nogil=True, inline="always")
def _bisect(pk, t0, t1, worst, m):  # pragma: no cover - compiled
    """Bisect interval ``worst``: it keeps the lower half, interval m (new) takes the upper; returns
    (piece, lower end, midpoint, upper end).
    """
    i = pk[worst]
    a_, b_ = t0[worst], t1[worst]
    mid = 0.5 * (a_ + b_)
    t1[worst] = mid
    pk[m], t0[m], t1[m] = i, mid, b_
    return i, a_, mid, b_


@njit(cache=True, nogil=True)
def _integrate(frame, radial, n, p, mu_arr, rtol, atol_arr, max_intervals, rounding, nodes, wk, wg,  # pragma: no cover
               mode, n_init, inodes, iwk, iwg, jac, mp, val, err, conv, evals):
    """Adaptive Gauss-Kronrod (the rule ``nodes``, ``wk``, ``wg``) of integral u^n K(u) du for
    every mu (without the scale); ``frame`` 0 the lobe frame (:func:`_k_closed`, :func:`_k_of_u`), 1-3 the
    half vector's (:func:`_k_half`, :func:`_k_ward`, :func:`_k_vcavity`; 4 :func:`_k_numeric` with the parameters
    ``mp``, its P(mu) set here per mu), ``radial`` 1 the Beckmann weight, 2 the GGX weight, in place of u^n
    (:func:`_pieces`).
    """
    # (room for every piece's first intervals besides max_intervals bisections: up to PIECES_CAP pieces)
    cap, pk, t0, t1, kv, ke, buf, ibuf, iwork, itol = _buffers(max_intervals + PIECES_CAP * n_init, nodes, inodes, rtol)
    kinds = np.empty(PIECES_CAP, np.int64)
    sms = np.empty(PIECES_CAP, np.int64)
    v0 = np.empty(PIECES_CAP)
    w = np.empty(PIECES_CAP)
    cv1 = np.empty(PIECES_CAP)
    sing = np.empty((4, 6))
    half = np.empty((2, 11))
    for q in range(mu_arr.shape[0]):
        mu = mu_arr[q]
        s = math.sqrt((1.0 - mu) * (1.0 + mu))
        if frame == 4 and mp[0] == SMITH:  # P(mu) = mu / G1(mu)
            mp[8] = _projected(s, 0.0, mu, int(mp[1]), int(mp[2]), mp[4])
        elif frame == 5:  # F(mu) and the arcs' cuts
            _lobe_f_prepare(mp, mu)
        npieces, c2, left_out = _pieces(frame, radial, n, p, mu, s, kinds, sms, v0, w, cv1, mp)
        sing[0, 0] = math.nan  # (:func:`_gk_closed` fills it where it needs it)
        # frame 4's inner rule may leave an absolute error iacc / (the node's factor) in K, iacc = itol times a lower
        # bound of the integral so far over the pieces' total length in tau: its share of the sum is then at most
        # itol times that bound (the integrand is >= 0; the errors are added to the estimate either way)
        live = 0
        for i in range(npieces):
            live += n_init if w[i] > 0.0 else 0
        acc = 0.0
        m = 0
        ev = 0
        for ii in range(2 * npieces if mode == DECAY_MODE else npieces):
            # (the closed forms' sharper estimate: the peak's pieces (kind 1) first, from u = 1 down, then the tail's,
            # so that the pieces of a small share of the integral see the lower bound that decides whether they need
            # it)
            i = ii % npieces
            if w[i] <= 0.0 or (mode == DECAY_MODE and (kinds[i] == 0) != (ii >= npieces)):
                continue
            for j in range(n_init):
                iacc = itol * acc / live
                pk[m] = i
                t0[m] = j / n_init
                t1[m] = (j + 1.0) / n_init
                if mode == DECAY_MODE:
                    ev += 21
                    kv[m], ke[m] = _gk_closed(kinds[i], sms[i], n, p, mu, c2, v0[i], w[i], cv1[i], t0[m], t1[m], buf,
                                              sing, half, DECAY_SHARE * rtol, acc)
                else:
                    ev += nodes.shape[0]
                    kv[m], ke[m] = _gk(frame, kinds[i], sms[i], n, p, mu, c2, v0[i], w[i], cv1[i], t0[m], t1[m], nodes,
                                       wk, wg, mode, buf, itol, inodes, iwk, iwg, ibuf, iwork, jac, mp, iacc)
                acc += max(kv[m] - ke[m], 0.0)
                m += 1
        start = m
        while True:
            tot, e, r, worst, ok = _status(kv, ke, m, left_out, rounding, rtol, atol_arr[q])
            if ok or m - start >= max_intervals or m >= cap:
                break
            i, a_, mid, b_ = _bisect(pk, t0, t1, worst, m)
            ev += 2 * nodes.shape[0]
            iacc = itol * max(tot - e, 0.0) / live
            if mode == DECAY_MODE:
                low_sum = max(tot - e, 0.0)
                kv[worst], ke[worst] = _gk_closed(kinds[i], sms[i], n, p, mu, c2, v0[i], w[i], cv1[i], a_, mid, buf,
                                                  sing, half, DECAY_SHARE * rtol, low_sum)
                kv[m], ke[m] = _gk_closed(kinds[i], sms[i], n, p, mu, c2, v0[i], w[i], cv1[i], mid, b_, buf, sing, half,
                                          DECAY_SHARE * rtol, low_sum)
            else:
                kv[worst], ke[worst] = _gk(frame, kinds[i], sms[i], n, p, mu, c2, v0[i], w[i], cv1[i], a_, mid, nodes,
                                           wk, wg, mode, buf, itol, inodes, iwk, iwg, ibuf, iwork, jac, mp, iacc)
                kv[m], ke[m] = _gk(frame, kinds[i], sms[i], n, p, mu, c2, v0[i], w[i], cv1[i], mid, b_, nodes, wk, wg,
                                   mode, buf, itol, inodes, iwk, iwg, ibuf, iwork, jac, mp, iacc)
            m += 1
        val[q] = tot
        err[q] = e + r
        conv[q] = ok
        evals[q] = ev  # (every split evaluates two halves)

_RULES = {"gk15": (_NODES, _WK, _WG), "gk21": (NODES21, WK21, WG21)}

#: the radial weights of a hint (``_integrate``'s codes)
_RADIAL = {"power": 0, "beckmann": 1, "ggx": 2}
