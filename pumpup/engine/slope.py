"""Anisotropic Ward's albedo in slope space: a ray integral per direction, one adaptive rule over the directions
(issue 14; before it, ``ward_aniso`` took the nested engine at about 55 000 evaluations per mu).

Method
------
Ward's anisotropic model (Ward 1992; its isotropic case is 000 eq. 34) depends on wo only through the slopes of the half
vector, m = (h_x / h_z, h_y / h_z):  f = c exp(-(m_x / a_x)^2 - (m_y / a_y)^2) / (4 pi a_x a_y sqrt(mu N.wo)).  With
wo = 2 (wi.h) h - wi, d omega_o = 4 (wo.h) d omega_h and d omega_h = h_z^3 d^2 m, where h_z = (1 + |m|^2)^(-1/2):

    wi.h = mu (1 + m.c) h_z,            c = (wi_x, wi_y) / mu,
    N.wo = 2 (wi.h) h_z - mu = mu (1/mu^2 - |m - c|^2) h_z^2,

so wo is above the horizon exactly on the disc |m - c| < 1/mu (the origin, h = N, lies inside it), and

    a(wi) = c mu / (pi a_x a_y) integral over the disc of exp(-(m_x / a_x)^2 - (m_y / a_y)^2) (1 + m.c)
            sqrt(1/mu^2 - |m - c|^2) h_z^5 d^2 m.

In stretched polar coordinates m = r (a_x cos(theta), a_y sin(theta)) = r e the weight is the isotropic Gaussian
r e^(-r^2) dr d theta, m.c = r b with b = e.c, and 1/mu^2 - |m - c|^2 = 1 + 2 r b - r^2 |e|^2 = |e|^2 (R - r)(r - r_-),
R > 0 > r_- the roots (1 / (|e|^2 r^2 - 2 b r - 1) = 0, computed without cancellation).  So

    a(wi) = (c mu / pi) integral_0^(2 pi) |e| J(theta) d theta,
    J = integral_0^R r e^(-r^2) (1 + r b) sqrt((R - r)(r - r_-)) (1 + r^2 |e|^2)^(-5/2) dr    (:func:`_ray`).

The ray ends at the horizon with a square root: the piece next to R is integrated in tau, r = R - (R - lo) tau^2, which
makes it analytic.  Beyond r = a = :data:`R_MAX` (when R is larger) the Gaussian leaves at most
sqrt(R (1 + |r_-| / a)) (I(1.5) + |b| I(2.5)), I(k) = integral_a^inf r^k e^(-r^2) dr <= a^(k - 1) e^(-a^2) / (2 (1 -
(k - 1) / (2 a^2))) (bound 1 + r b by 1 + r |b|, (R - r)(r - r_-) by R r (1 + |r_-| / a) and h_z by 1), which is added
to the ray's error.  (A first bound, (R - r_-) / 2 for the square root, was e^-40 sqrt(R) of J: near grazing incidence,
where R reaches 1e100, it never let the rays converge.)  The ray's first pieces are graded by 4 from twice the scale of
the singularities next to r = 0 (r_-, and h_z's pole at r = i / |e| of a wide lobe) up to :data:`RAY_CUTS`, the
Gaussian's scale; each piece is adaptive 10/21 Gauss-Kronrod (the worst bisected) to a relative tolerance or an absolute
share of the albedo's lower bound so far.

J(theta) is analytic and periodic; the rule over theta is globally adaptive 7/15 Gauss-Kronrod over the turn, the rays'
errors added through the Kronrod weights as frame 4 does (:func:`pumpup.engine.half_arc._k_numeric`).  Near grazing
incidence the disc's edge nearest to h = N, m* = -(cos phi, sin phi)(1 - s) / mu, comes within the Gaussian: in the
stretched plane it is a line at the distance ``edge`` = mu / ((1 + s) a_x a_y |T|), T = (-sin phi / a_x, cos phi / a_y)
its direction.  A ray at an angle delta from it meets it at R ~ edge / sin(delta), so J changes from its value near the
edge to the full Gaussian within a few times ``edge`` of the edge's parallels tpar and tpar + pi (which are th0 +- pi /
2, th0 the direction of m*, only where a_x = a_y); beyond a parallel r_- sweeps through the Gaussian in the same way,
r_- R = -1 / |e|^2.  So the first cuts are th0 + pi, the parallels, and from each parallel cuts graded by 4 from
``edge`` / 8 on both sides (:data:`EDGE_GRADE`), where ``edge`` < :data:`EDGE_MAX`.  Found by the calibration: cuts at
th0 +- pi / 2 left a_x / a_y = 1000 at mu = 1e-4 4e-7 off, and cuts on the near side only (0.05, 0.5) at mu = 0.003
8.4e-13 off with an estimate of 5e-13.  Where wi lies in the plane of a tangent axis (phi = 0 or pi / 2, and isotropic
models, which take phi = 0) J is even about th0 and half the turn is integrated.  The estimate per interval, of the rays
and of theta, is QUADPACK's calibration of |K - G| (:func:`pumpup.physics.quadrature.calibrated`), plus the rounding
term :data:`pumpup.engine.lobe_frame.ROUNDING` times the sum of |K|.

Checked in ``tests/engine/test_slope.py`` against ``tests/data/independent_ward_aniso.json`` (two nested-quad methods
written without pumpup, ``tests/reference/independent_ward_aniso.py``), against the nested engine at rtol 1e-13 (the
half vector's polar angle and azimuth), against Ward's isotropic 1-D path (complete elliptic integrals) at a_x = a_y,
and the ray integral against scipy's quadrature (:func:`ray_reference`); ``scripts/calibration/slope_calibration.py``
over 9 pairs of slopes x 14 mu x 4 azimuths x 4 rtol.  At a_x / a_y = 1000 the nested engine is off by up to 1.3e-8 with
estimates of 5e-14, where the slope path agrees with both independent methods.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from ..physics.quadrature import calibrated, mode_code, rule_sums
from .lobe_frame import _tally

__all__ = ["slope_albedo", "ray_reference", "ray_integral"]

#: the ray's cut: e^(-R_MAX^2) = e^-40, as the 1-D path's Z_MAX (beyond it a bound joins the error)
R_MAX = math.sqrt(40.0)

#: the smallest mu the slope path takes (below it the nested engine, as before): c = (wi_x, wi_y) / mu and the roots
#: stay far from overflow
MU_MIN = 1e-100

#: the most intervals of one ray
RAY_MAX = 64
#: the ray's cuts on the Gaussian's scale (measured: with the graded cuts below them, one 10/21 rule per piece is within
#: 1.1e-11 of scipy's ray integral over 7 pairs of slopes x 8 mu x 23 theta; two pieces [0, R/2], [R/2, R] were 2e-4
#: off)
RAY_CUTS = np.array([1.6, 3.2])
#: the smallest relative tolerance of a ray: its estimate has the floor 50 eps of every piece (QUADPACK's), and below
#: about that a ray bisected to RAY_MAX intervals (rtol 3e-14: 7e8 evaluations for one mu)
RAY_ITOL_MIN = 4e-14
#: the rule over theta
THETA_RULE = "gk15"
#: the rule on a ray
RAY_RULE = "gk21"
#: the most first pieces of a ray
N_RAY_CUTS = 24

#: the first theta cut on either side of a ray parallel to the disc's nearest edge, in units of the edge's distance from
#: the origin in the stretched plane, and the grading's factor from there; only where that distance is below EDGE_MAX
#: (beyond it the Gaussian barely reaches the edge)
EDGE_GRADE = 0.125
EDGE_FACTOR = 4.0
EDGE_MAX = 1.0
#: the most graded cuts per side
N_GRADE = 40
#: room for the first cuts over theta (the edge's and the axes' gradings, :func:`_slope_one`)
OFFS_CAP = 8 * N_GRADE + 32


@njit(cache=True, nogil=True, inline="always")
def _ray_f(r, w, b, e2, rm):  # pragma: no cover - compiled; see ray_reference
    """The integrand r e^(-r^2) (1 + r b) sqrt(w (r - r_-)) (1 + r^2 |e|^2)^(-5/2), with w = R - r given
    (no cancellation).
    """
    hz2 = 1.0 / (1.0 + r * r * e2)
    return r * math.exp(-r * r) * (1.0 + r * b) * math.sqrt(w * (r - rm)) * hz2 * hz2 * math.sqrt(hz2)


@njit(cache=True, nogil=True)
def _ray_rule(lo, hi, base, top, b, e2, rm, nodes, wk, wg, mode, buf):  # pragma: no cover - compiled
    """(value, error) of the 10/21 rule on [lo, hi]: in r where ``base`` < 0, else in tau with r = top - base tau^2
    (the piece next to the horizon r = R = top, base = R - its start).
    """
    h = hi - lo
    for j in range(nodes.shape[0]):
        x = lo + h * nodes[j]
        if base < 0.0:
            buf[j] = _ray_f(x, top - x, b, e2, rm)
        else:
            w = base * x * x  # R - r
            buf[j] = 2.0 * base * x * _ray_f(top - w, w, b, e2, rm)
    k, diff, asc, ab = rule_sums(buf, wk, wg)
    return k * h, calibrated(diff * h, asc * h, ab * h, mode)


@njit(cache=True, nogil=True)
def _roots(b, e2):  # pragma: no cover - compiled
    """(R, r_-): the roots of |e|^2 r^2 - 2 b r - 1, R > 0 > r_-, each without cancellation."""
    d = math.sqrt(b * b + e2)
    if b >= 0.0:
        return (b + d) / e2, -1.0 / (d + b)
    return 1.0 / (d - b), (b - d) / e2


@njit(cache=True, nogil=True)
def _ray(b, e2, itol, tol_abs, nodes, wk, wg, mode, buf, rw):  # pragma: no cover - compiled
    """(J, error, evaluations) of the ray integral (module docstring), globally adaptive: the first pieces below, the
    one next to the horizon in tau where R <= R_MAX, the worst bisected until the error is at most
    max(itol |J|, tol_abs) or RAY_MAX intervals are used (the error is returned either way).
    """
    big, rm = _roots(b, e2)
    lo, hi, val, err, kind = rw[0], rw[1], rw[2], rw[3], rw[4]
    top = min(big, R_MAX)
    tail = 0.0
    if big > R_MAX:  # the Gaussian's tail beyond R_MAX, bounded (module docstring)
        a2 = R_MAX * R_MAX
        i15 = 0.5 * math.sqrt(R_MAX) * math.exp(-a2) / (1.0 - 0.25 / a2)  # integral_a^inf r^1.5 e^(-r^2) dr at most
        i25 = 0.5 * R_MAX * math.sqrt(R_MAX) * math.exp(-a2) / (1.0 - 0.75 / a2)  # ... r^2.5 ...
        tail = math.sqrt(big * (1.0 - rm / R_MAX)) * (i15 + abs(b) * i25)
    # the first pieces: graded by 4 from twice the scale of the singularities next to r = 0 (r_- and the pole of h_z at
    # r = i / |e|: wide lobes), then the Gaussian's RAY_CUTS, each below 3/4 of the range; the last piece ends at the
    # horizon (in tau) where R <= R_MAX
    n = nodes.shape[0]
    m = 0
    a = 0.0
    c = 2.0 * min(-rm, 1.0 / math.sqrt(e2))
    j = 0
    while m < N_RAY_CUTS:
        if c < RAY_CUTS[0]:
            nxt = c
            c *= 4.0
        elif j < RAY_CUTS.shape[0]:
            nxt = RAY_CUTS[j]
            j += 1
        else:
            break
        if nxt >= 0.75 * top:
            break
        lo[m], hi[m], kind[m] = a, nxt, -1.0
        val[m], err[m] = _ray_rule(a, nxt, -1.0, big, b, e2, rm, nodes, wk, wg, mode, buf)
        a = nxt
        m += 1
    if big <= R_MAX:  # tau in [0, 1]: r from R down to a
        lo[m], hi[m], kind[m] = 0.0, 1.0, big - a
    else:
        lo[m], hi[m], kind[m] = a, top, -1.0
    val[m], err[m] = _ray_rule(lo[m], hi[m], kind[m], big, b, e2, rm, nodes, wk, wg, mode, buf)
    m += 1
    evals = m * n
    while True:
        tot, e, worst = _tally(val, err, m, 0.0, tail)
        if e <= max(itol * abs(tot), tol_abs) or m >= lo.shape[0]:
            return tot, e, evals
        c = 0.5 * (lo[worst] + hi[worst])
        lo[m], hi[m], kind[m] = c, hi[worst], kind[worst]
        hi[worst] = c
        val[worst], err[worst] = _ray_rule(lo[worst], c, kind[worst], big, b, e2, rm, nodes, wk, wg, mode, buf)
        val[m], err[m] = _ray_rule(c, hi[m], kind[m], big, b, e2, rm, nodes, wk, wg, mode, buf)
        m += 1
        evals += 2 * n


@njit(cache=True, nogil=True)
def _theta_rule(lo, hi, ax, ay, cx, cy, itol, tol_abs, tnodes, twk, twg, nodes, wk, wg, mode, buf,  # pragma: no cover
                ibuf, rw):
    """(value, error, sum |K|, evaluations) of the rule over theta (:data:`THETA_RULE`) in [lo, hi] for |e| J(theta),
    the rays' errors added through the Kronrod weights.
    """
    h = hi - lo
    inner = 0.0
    evals = 0
    for j in range(tnodes.shape[0]):
        th = lo + h * tnodes[j]
        ex = ax * math.cos(th)
        ey = ay * math.sin(th)
        e2 = ex * ex + ey * ey
        el = math.sqrt(e2)
        v, ve, ne = _ray(ex * cx + ey * cy, e2, itol, tol_abs / el, nodes, wk, wg, mode, ibuf, rw)
        buf[j] = el * v
        inner += twk[j] * el * ve
        evals += ne
    k, diff, asc, ab = rule_sums(buf, twk, twg)
    return k * h, calibrated(diff * h, asc * h, ab * h, mode) + inner * h, ab * h, evals


@njit(cache=True, nogil=True)
def _slope_one(mu, phi, ax, ay, rtol, atol, max_intervals, rounding, tnodes, twk, twg, nodes, wk,  # pragma: no cover
               wg, mode, work, buf, ibuf, rw):
    """(integral of |e| J over theta, error, converged, evaluations) at one wi = (s cos phi, s sin phi, mu); ``atol``
    applies to this integral (the caller divides by the scale c mu / pi).
    """
    s = math.sqrt((1.0 - mu) * (1.0 + mu))
    cx = s * math.cos(phi) / mu
    cy = s * math.sin(phi) / mu
    cp = math.cos(phi)
    sp = math.sin(phi)
    # the disc's edge nearest to h = N is m* = -(cos phi, sin phi)(1 - s) / mu; in the stretched plane it lies in the
    # direction th0, its tangent in the directions tpar and tpar + pi (not th0 +- pi / 2 unless a_x = a_y), at the
    # distance edge from the origin
    th0 = math.atan2(-sp / ay, -cp / ax)
    tpar = math.atan2(cp / ay, -sp / ax)
    edge = mu / (1.0 + s) / (ax * ay * math.sqrt((sp / ax) ** 2 + (cp / ay) ** 2))
    lo, hi, val, err, ab = work[0], work[1], work[2], work[3], work[4]
    # wi in the plane of a tangent axis (cx or cy = 0): J is even about th0, half the turn is integrated and doubled
    half = cx == 0.0 or cy == 0.0
    twice = 2.0 if half else 1.0
    # the first intervals, as offsets from th0: th0 + pi, the edge's parallels and, where the edge is inside the
    # Gaussian (edge < EDGE_MAX, near grazing incidence), cuts graded from each parallel towards th0, where the rays' R
    # falls from beyond R_MAX to about the edge's distance within an angle of a few times that distance; gaps wider than
    # pi / 2 halved
    offs = np.empty(OFFS_CAP)
    n = 0
    offs[n] = 0.0
    offs[n + 1] = math.pi
    n += 2
    if not half:
        offs[n] = -math.pi
        n += 1
    for j in range(2):
        o = tpar + math.pi * j - th0
        o -= 2.0 * math.pi * math.floor(o / (2.0 * math.pi) + 0.5)  # in [-pi, pi)
        if half and o < 0.0:
            continue  # (the mirror image of the other parallel)
        offs[n] = o
        n += 1
        grade = EDGE_GRADE * edge
        while edge < EDGE_MAX and grade < 0.5 * abs(o) and n < offs.shape[0] - 8:  # towards th0
            offs[n] = o - math.copysign(grade, o)
            n += 1
            grade *= EDGE_FACTOR
        grade = EDGE_GRADE * edge
        while edge < EDGE_MAX and grade < 0.5 * (math.pi - abs(o)) and n < offs.shape[0] - 8:  # away from it
            offs[n] = o + math.copysign(grade, o)
            n += 1
            grade *= EDGE_FACTOR
    # |e|^2 = a_x^2 cos^2(theta) + a_y^2 sin^2(theta) vanishes at theta = theta_a +- i atanh(a_min / a_max), theta_a the
    # direction of the smaller slope's axis (pi / 2 and 3 pi / 2 where a_y < a_x): |e| J(theta) has a branch point that
    # close to the real axis.  The rule's 7 and 15 points on an interval ending near theta_a agreed while both missed:
    # a_x = 0.743, a_y = 0.0149 at mu = 1 (phi = 5.898) was 8.0e-10 off with an estimate of 4.7e-11 at rtol 1e-8, 72 x
    # at mu = 1 - 1e-9 and rtol 1e-10 (scripts/studies/fuzz_engines.py --registry 47).
    # Cuts at theta_a and graded by EDGE_FACTOR from the branch point's distance on both sides
    if ax != ay:
        dist = math.atanh(min(ax, ay) / max(ax, ay))
        for j in range(2):
            o = (0.5 * math.pi if ay < ax else 0.0) + math.pi * j - th0
            o -= 2.0 * math.pi * math.floor(o / (2.0 * math.pi) + 0.5)  # in [-pi, pi)
            if half:
                o = abs(o)  # (J is even about th0: its mirror image)
            for side in (-1.0, 1.0):
                grade = dist
                while grade < 0.25 * math.pi and n < offs.shape[0] - 8:
                    q = o + side * grade
                    if -math.pi < q < math.pi and not (half and q <= 0.0):
                        offs[n] = q
                        n += 1
                    grade *= EDGE_FACTOR
            if -math.pi < o < math.pi and not (half and o <= 0.0) and n < offs.shape[0] - 8:
                offs[n] = o
                n += 1
    offs[:n].sort()
    for i in range(n - 1):
        if offs[i + 1] - offs[i] > 0.5 * math.pi:
            offs[n] = 0.5 * (offs[i] + offs[i + 1])
            n += 1
    offs[:n].sort()
    itol = max(0.25 * rtol, RAY_ITOL_MIN)
    evals = 0
    # the rays' share of the tolerance: over the turn, at most a quarter of atol, or of rtol times the lower bound so
    # far
    tol_abs = 0.25 * atol / (2.0 * math.pi)
    for i in range(n - 1):
        lo[i] = th0 + offs[i]
        hi[i] = th0 + offs[i + 1]
        val[i], err[i], ab[i], ne = _theta_rule(lo[i], hi[i], ax, ay, cx, cy, itol, tol_abs, tnodes, twk, twg, nodes,
                                                wk, wg, mode, buf, ibuf, rw)
        evals += ne
    m = n - 1
    while True:
        tot = 0.0
        e = 0.0
        sab = 0.0
        worst = 0
        for i in range(m):
            tot += val[i]
            e += err[i]
            sab += ab[i]
            if err[i] > err[worst]:
                worst = i
        tot *= twice
        e_all = twice * (e + rounding * sab)
        if e_all <= max(rtol * abs(tot), atol):
            return tot, e_all, True, evals
        if m >= min(max_intervals, lo.shape[0]):
            return tot, e_all, False, evals
        tol_abs = 0.25 * max(rtol * max(tot - twice * e, 0.0), atol) / (2.0 * math.pi)
        c = 0.5 * (lo[worst] + hi[worst])
        lo[m], hi[m] = c, hi[worst]
        hi[worst] = c
        val[worst], err[worst], ab[worst], ne = _theta_rule(lo[worst], c, ax, ay, cx, cy, itol, tol_abs, tnodes, twk,
                                                            twg, nodes, wk, wg, mode, buf, ibuf, rw)
        evals += ne
        val[m], err[m], ab[m], ne = _theta_rule(c, hi[m], ax, ay, cx, cy, itol, tol_abs, tnodes, twk, twg, nodes, wk,
                                                wg, mode, buf, ibuf, rw)
        evals += ne
        m += 1


@njit(cache=True, nogil=True)
def _slope_all(mu, phi, ax, ay, rtol, atol, max_intervals, rounding, tnodes, twk, twg, nodes, wk,  # pragma: no cover
               wg, mode, val, err, conv, evals):
    work = np.empty((5, max(max_intervals, OFFS_CAP) + 1))
    buf = np.empty(tnodes.shape[0])
    ibuf = np.empty(nodes.shape[0])
    rw = np.empty((5, RAY_MAX))
    for i in range(mu.shape[0]):
        val[i], err[i], conv[i], evals[i] = _slope_one(mu[i], phi[i], ax, ay, rtol, atol[i], max_intervals, rounding,
                                                       tnodes, twk, twg, nodes, wk, wg, mode, work, buf, ibuf, rw)


def slope_albedo(brdf, mu: np.ndarray, phi: np.ndarray, rtol: float, atol: float, max_regions: int):
    """(value, error, converged, evaluations) of the albedo of anisotropic Ward ``brdf`` at every (mu, phi) (1-D float
    arrays of one length; phi the azimuth of wi from the tangent x axis).
    """
    from .lobe_frame import ROUNDING
    from .outer_rule import _RULES

    ax, ay, c = brdf.slope_hint()
    mu = np.ascontiguousarray(mu, dtype=np.float64)
    phi = np.ascontiguousarray(np.broadcast_to(phi, mu.shape), dtype=np.float64)
    if ax == ay:  # isotropic: the albedo does not depend on phi, and phi = 0 takes half the turn
        phi = np.zeros(mu.shape)
    scale = c * mu / math.pi
    with np.errstate(divide="ignore"):
        atol_q = np.where(scale != 0, float(atol) / np.abs(scale), np.inf)
    val = np.empty(mu.shape)
    err = np.empty(mu.shape)
    conv = np.empty(mu.shape, bool)
    evals = np.empty(mu.shape, np.int64)
    _slope_all(mu, phi, float(ax), float(ay), float(rtol), atol_q, int(min(max(max_regions, 4), 10000)), ROUNDING,
               *_RULES[THETA_RULE], *_RULES[RAY_RULE], mode_code(), val, err, conv, evals)
    return scale * val, np.abs(scale) * err, conv, evals


def ray_integral(b: float, e2: float, rtol: float = 1e-13) -> tuple:
    """(J, error, evaluations) of the compiled ray integral (module docstring) at b = e.c and e2 = |e|^2."""
    from .outer_rule import _RULES

    nodes, wk, wg = _RULES[RAY_RULE]
    return _ray(float(b), float(e2), float(rtol), 0.0, nodes, wk, wg, mode_code(), np.empty(len(nodes)),
                np.empty((5, RAY_MAX)))


def ray_reference(b: float, e2: float) -> float:
    """J by scipy's adaptive quadrature on [0, min(R, 12)] in r, the horizon's square root taken by the substitution
    r = R - w^2 (plain numpy and scipy; the tests' reference for :func:`_ray`).
    """
    from scipy.integrate import quad

    d = math.hypot(b, math.sqrt(e2))
    big = (b + d) / e2 if b >= 0 else 1.0 / (d - b)
    rm = -1.0 / (big * e2)  # the roots' product is -1 / |e|^2

    def f(r):
        return r * np.exp(-r * r) * (1.0 + r * b) * np.sqrt(max((big - r) * (r - rm), 0.0)) * (1.0 + r * r * e2) ** -2.5

    if big <= 12.0:
        top = math.sqrt(big)
        return quad(lambda w: 2.0 * w * f(big - w * w), 0.0, top, epsabs=0.0, epsrel=2e-14, limit=500)[0]
    return quad(f, 0.0, 12.0, epsabs=0.0, epsrel=2e-14, limit=500, points=[1.0, 2.0, 3.0, 5.0])[0]
