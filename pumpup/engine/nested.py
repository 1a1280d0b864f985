"""Nested quadrature for the albedo: adaptive in the radial variable, a fixed rule on each smooth arc.

Method
------
The 2-D engine of :mod:`pumpup.albedo` integrates a(mu) over (tau_x, tau_t): tau_x is the
(smoothed) radial variable of the Lobe hint's map, tau_t the smoothed position on one *piece*
of the visible arc of the azimuth beta, the pieces being cut at the levels of the hint (a kink
N.wo = u), the model's own kinks (a + b cos(beta) = 0) and the horizon.  On each piece the
integrand is smooth in beta by construction, so bisecting rectangles in beta rediscovers what
the hint already says.  This module integrates the same integrand as a nested quadrature
(issue 14, item 2):

* outer: globally adaptive 7/15 Gauss-Kronrod in tau_x on [0, 1] (QUADPACK's qk15), started on
  the 2-D engine's breaks (eight intervals, :data:`NX_INIT`, the horizon breaks ``horizon_breaks``, the kink breaks
  ``kink_breaks`` including the crossings of two cuts), a grid graded geometrically towards each
  break (ratio 16: :func:`_graded_coarse`) and one above the "power" map's split
  (:func:`_split_breaks`); the intervals whose error exceeds their share of the tolerance are
  refined.  An interval that ends at a break is integrated in v with x = x0 + h v^2 (x1 - h (1 - v)^2,
  both ends: x0 + h v^2 (3 - 2 v)) towards it (:data:`OUTER_SUB`): where the arc starts to be cut
  (a horizon or a kink entering the arc) the arc's integral behaves like (x - x_b)^(3/2) on one side,
  which the substitution makes analytic in v (a 7/15 rule on an interval ending at such a point
  converges only algebraically: ggx alpha = 0.1 at mu = 0.7 had |K - G| = 4.8e-6 on the first
  interval ending at the horizon break, the largest of its first grid).
  The crossings of two cuts are breaks too: the pieces there change order and the arc's integral,
  while continuous with its derivative, is not analytic (Cook-Torrance m = 0.4 at mu = 0.1, rtol
  1e-10: the three geometry-factor cuts cross at tau_x = 0.02559 inside an interval whose 7- and
  15-point values agreed to 2.0e-12 while both were 2.6e-11 off; before the substitution the
  refinement it spent elsewhere had hidden this);
* inner, at each of the 15 outer nodes of an interval: the visible arc of beta cut at the same
  cuts as the 2-D engine (the geometry, the cuts and the Cook-Torrance kink coefficients are
  computed once per outer node, issue 14 item 3), and on each non-empty piece the fixed 15-point
  Kronrod rule on each of the interval's sub-intervals ("segments") of the piece variable v, its
  error measured by the embedded 7-point Gauss rule (:func:`inner_error`).  The substitution
  beta = lo + t(v) width is t = 1 - (1 - v)^2 where the piece ends at the horizon (square-root
  behaviour, sqrt(N.wo) for Ward) and t = v elsewhere (beta = 0, a full arc's end and the cuts are
  analytic ends of a piece); a piece end at the cut of a small level is graded (:func:`_end_grading`);
* the error of an interval is the outer |K - G| plus the inner errors carried through the
  (positive) outer Kronrod weights (:func:`interval_error`; the integral of |I_h - I| over the
  interval is bounded by the latter), plus, for the whole value, the 2-D engine's rounding term
  (``lobe_rounding``);
* refinement: an interval whose inner error is the larger part of its error has its segments
  above their share (and its worst one) bisected in v (never silently accepted); one whose
  outer error dominates is bisected in tau_x (in v where it has the substitution: at x0 + h / 4,
  the child at the break keeping it), its children inheriting its segments.
  ``max_regions`` is a budget on what refinement adds per value of mu, counted in segments per
  piece (an outer interval with its initial segments counts once); when it runs out, the
  (larger) error estimate is returned with converged = False (``pumpup.albedo`` warns).

The geometry runs in two compiled passes per batch (:func:`_nodes_kernel`: per outer node;
:func:`_points_kernel`: per point), the model's ``_eval`` once per batch on all points (twice
where the hint is not even in beta), and two compiled passes (:func:`pumpup.engine.cubature.accumulate`,
:func:`_rule_kernel`) form the Kronrod and Gauss sums; each has a plain numpy twin (``*_reference``) that the tests
compare with it.

Groups with wi turned out of the xz-plane (``phi != 0``) are integrated in the frame of wi at phi = 0 and the points
turned by phi about N before ``_eval``, as the 2-D engine does.  Left to the 2-D engine, such groups lose the visible
tail of a ridge just past a break from its first grid: ward_aniso ax = 1, ay = 0.001 at mu = 0.9877, phi = 0.4 was
1.3e-8 off there with an estimate of 5e-14, where the outer substitution towards a break (``OUTER_SUB``) puts a node
within 2e-6 of the interval of it.  Hint-less BRDFs (a :func:`pumpup.from_function`,
integrated by the 2-D engine's generic path) are left to the 2-D engine.  ``engine="2d"`` leaves this path out (the 2-D
engine stays the reference), as does ``pumpup.engine.routes.using(without={"nested"})``.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from ..core import budget
from .arc_breaks import horizon_breaks, kink_breaks, tau_of_angle
from .lobe_geometry import (
    AXIS_CODE,
    NODES,
    RADIAL_CODE,
    WG,
    WK,
    accumulate,
    kink_coefficients,
    lobe_rounding,
    power_split,
    radial_map,
    radial_map_scalar,
    rotate_wi,
    smooth,
    smooth_inverse,
)

__all__ = ["inner_error", "integrate", "interval_error", "supports"]

#: initial intervals of tau_x before the breaks are added (as the 2-D engine's NX_INIT).  4 saved 5-40 %
#: of the evaluations per mu and stayed honest on scripts/calibration/error_calibration.py (max ratio 0.126), but the
#: doctest of pumpup.luts.audit then failed: GGX alpha = 1e-8 at mu = 1e-6, which converges at no
#: budget, gave values 9e-6 apart (within their estimates, 3.5e-4) at rtol 1e-7 and 1e-8 with 200
#: regions; 2 under-reported (Kulla-Conty lobe of Phong n = 20, mu = 0.3: 2.7 x the estimate)
NX_INIT = 8
#: initial sub-intervals of v on every piece of the arc (the 2-D engine starts with 2 in tau_t)
M_INIT = 1
#: largest number of sub-intervals per piece before an interval is bisected instead
M_MAX = 4096

#: sub-intervals per compiled pass (15 points each): the buffers stay in the cache
CHUNK = 2048

#: the outer (tau_x) and inner (beta) rules: (nodes, Kronrod weights, embedded Gauss weights) on [0, 1]
_OUTER = (NODES, WK, WG)
_INNER = (NODES, WK, WG)

#: evaluation counter: integrand evaluations per problem of the last call (for the benchmark)
LAST_EVALS: np.ndarray | None = None


def supports(g) -> bool:
    """Whether this path integrates the group ``g`` (a ``pumpup.engine.cubature._Group``)."""
    lobe = g.lobe
    return not lobe.generic and lobe.axis in AXIS_CODE and lobe.radial in RADIAL_CODE


def inner_error(kronrod, gauss):
    """Error estimate of one inner sub-interval at one outer node: |K - G| of the 15-point Kronrod
    rule and its embedded 7-point Gauss rule.  QUADPACK's calibration of it (``pumpup.physics.quadrature``)
    was measured here too and under-reported (modified_ward m = 0.1 at mu = 0.2, rtol 1e-10: true
    error 2.4 x the estimate), so the raw difference stays.
    """
    return np.abs(kronrod - gauss)


def interval_error(kronrod, gauss, inner):
    """Error estimate of outer intervals: |K - G| of the outer rule plus the inner errors carried
    through the outer weights (an upper bound of the integral of |I_h - I|).
    """
    return np.abs(kronrod - gauss) + inner


# --- per outer node: the radial map, the visible arc and its cuts ---------------------------------

def _nodes_reference(axis: str, radial: str, k: float, mu, levels, ka, kb, tx):
    """Plain numpy twin of :func:`_nodes_kernel`: (s, ca, sa, wr, edges, lab, dn) per outer node.

    ``wr`` = |d cos(alpha) / d tau_x| (the radial Jacobian times dx/dtau); ``edges`` (N, E) are
    0, the sorted cuts (levels, then the model's kinks, each clipped to the arc) and beta0;
    ``lab`` (N, E) the index of the level an edge is the cut of (-1 for the ends, the model's kinks
    and cuts beyond the arc) and ``dn`` = b0 sin(edge) = |d N.wo / d beta| there (0 elsewhere).
    """
    s = np.sqrt((1.0 - mu) * (1.0 + mu))
    x, xc, dx = smooth(tx)
    ca, sa, jac = radial_map(radial, k, x, xc)
    if axis == "normal":
        a0, b0 = ca, np.zeros_like(ca)
    elif axis in ("mirror", "retro"):
        a0, b0 = mu * ca, s * sa
    else:
        a0, b0 = mu * (ca * ca - sa * sa), 2.0 * s * sa * ca
    with np.errstate(divide="ignore", invalid="ignore"):
        beta0 = np.where(b0 > 0, np.arccos(np.clip(-a0 / b0, -1.0, 1.0)), np.where(a0 > 0, np.pi, 0.0))
        cuts = [np.where(b0 > 0, np.arccos(np.clip((levels[:, j] - a0) / b0, -1.0, 1.0)), 0.0)
                for j in range(levels.shape[1])]
        cuts += [np.where(kb[:, j] != 0, np.arccos(np.clip(-ka[:, j] / kb[:, j], -1.0, 1.0)), 0.0)
                 for j in range(ka.shape[1])]
    N, L = len(tx), levels.shape[1]
    if cuts:
        raw = np.stack(cuts, axis=-1)
        lab = np.where((np.arange(raw.shape[1])[None, :] < L) & (b0[:, None] > 0) & (raw < beta0[:, None]),
                       np.arange(raw.shape[1])[None, :], -1)
        raw = np.minimum(raw, beta0[:, None])
        order = np.argsort(raw, axis=-1, kind="stable")
        inner = np.take_along_axis(raw, order, axis=-1)
        lab = np.take_along_axis(lab, order, axis=-1)
    else:
        inner, lab = np.zeros((N, 0)), np.zeros((N, 0), np.int64)
    edges = np.concatenate([np.zeros((N, 1)), inner, beta0[:, None]], axis=-1)
    lab = np.concatenate([np.full((N, 1), -1), lab, np.full((N, 1), -1)], axis=-1)
    dn = np.where(lab >= 0, b0[:, None] * np.sin(edges), 0.0)
    with np.errstate(invalid="ignore"):
        wr = np.where(dx > 0, jac * dx, 0.0)
    return s, ca, sa, wr, edges, lab, dn


@njit(cache=True, nogil=True)
def _nodes_kernel(axis, radial, k, mu, levels, ka, kb, tx, s_o, ca_o, sa_o, wr_o, edges, lab, dn):  # pragma: no cover
    """Compiled twin of :func:`_nodes_reference` (fills the output arrays)."""
    L = levels.shape[1]
    K = ka.shape[1]
    for i in range(tx.shape[0]):
        m = mu[i]
        s = math.sqrt((1.0 - m) * (1.0 + m))
        u = tx[i]
        x = u * u * (3.0 - 2.0 * u)  # smoothing substitution x = tau^2 (3 - 2 tau)
        xc = (1.0 - u) ** 2 * (1.0 + 2.0 * u)
        dx = 6.0 * u * (1.0 - u)
        ca, sa, jac = radial_map_scalar(radial, k, x, xc)
        if axis == 0:
            a0, b0 = ca, 0.0
        elif axis == 3:
            a0, b0 = m * (ca * ca - sa * sa), 2.0 * s * sa * ca  # N.wo = mu cos 2a + s sin 2a cos beta
        else:
            a0, b0 = m * ca, s * sa
        if b0 > 0:
            beta0 = math.acos(min(1.0, max(-1.0, -a0 / b0)))
        else:
            beta0 = math.pi if a0 > 0 else 0.0
        n = 0
        edges[i, n] = 0.0
        lab[i, n] = -1
        n += 1
        for j in range(L):
            c = math.acos(min(1.0, max(-1.0, (levels[i, j] - a0) / b0))) if b0 > 0 else 0.0
            lab[i, n] = j if (b0 > 0 and c < beta0) else -1
            edges[i, n] = min(c, beta0)
            n += 1
        for j in range(K):
            c = math.acos(min(1.0, max(-1.0, -ka[i, j] / kb[i, j]))) if kb[i, j] != 0 else 0.0
            edges[i, n] = min(c, beta0)
            lab[i, n] = -1
            n += 1
        edges[i, n] = beta0
        lab[i, n] = -1
        n += 1
        for a in range(2, n - 1):  # insertion sort of the interior cuts (stable, labels with them)
            val = edges[i, a]
            lv = lab[i, a]
            b = a - 1
            while b >= 1 and edges[i, b] > val:
                edges[i, b + 1] = edges[i, b]
                lab[i, b + 1] = lab[i, b]
                b -= 1
            edges[i, b + 1] = val
            lab[i, b + 1] = lv
        for a in range(n):
            dn[i, a] = b0 * math.sin(edges[i, a]) if lab[i, a] >= 0 else 0.0
        s_o[i] = s
        ca_o[i] = ca
        sa_o[i] = sa
        wr_o[i] = jac * dx if dx > 0 else 0.0


# --- per point: directions and weights -------------------------------------------------------------

def _end_map(sm, v):
    """t(v) and dt/dv of the inner substitution: 0 none, 1 t = v^2 (square-root end at beta = lo),
    2 t = 1 - (1 - v)^2 (at beta = lo + width), 3 t = v^2 (3 - 2 v) (both).
    """
    sm = np.broadcast_to(np.asarray(sm)[..., None] if np.ndim(sm) else sm, v.shape)
    t = np.where(sm == 0, v, np.where(sm == 1, v * v, np.where(sm == 2, 1.0 - (1.0 - v) ** 2, v * v * (3.0 - 2.0 * v))))
    dt = np.where(sm == 0, 1.0, np.where(sm == 1, 2.0 * v, np.where(sm == 2, 2.0 * (1.0 - v), 6.0 * v * (1.0 - v))))
    return t, dt


def _points_reference(axis: str, node, lo, width, t0, t1, mu, s, ca, sa, wr, sm=3):
    """Plain numpy twin of :func:`_points_kernel`: (wi, wo, weight) of the 15 inner nodes of every
    segment (sub-interval [t0, t1] of v on the piece [lo, lo + width] of beta at outer node
    ``node``); ``weight`` is d omega_o per d tau_x d v, including the width of [t0, t1].
    """
    v = t0[:, None] + (t1 - t0)[:, None] * NODES[None, :]
    t, dt = _end_map(sm, v)
    j = np.broadcast_to(node[:, None], v.shape)
    m_, s_, ca_, sa_, wr_ = mu[j], s[j], ca[j], sa[j], wr[j]
    beta = lo[:, None] + t * width[:, None]
    cb, sb = np.cos(beta), np.sin(beta)
    wi = np.stack([s_, np.zeros_like(s_), m_], axis=-1)
    if axis in ("normal", "half"):
        d = np.stack([sa_ * cb, sa_ * sb, ca_], axis=-1)
    elif axis == "mirror":  # A = R = (-s, 0, mu), e1 = (mu, 0, s)
        d = np.stack([-s_ * ca_ + m_ * sa_ * cb, sa_ * sb, m_ * ca_ + s_ * sa_ * cb], axis=-1)
    else:  # retro: A = wi = (s, 0, mu), e1 = (-mu, 0, s)
        d = np.stack([s_ * ca_ - m_ * sa_ * cb, sa_ * sb, m_ * ca_ + s_ * sa_ * cb], axis=-1)
    if axis == "half":
        ih = s_ * d[..., 0] + m_ * d[..., 2]
        wo = 2.0 * ih[..., None] * d - wi
        extra = 4.0 * ih  # d omega_o = 4 (wo.h) d omega_h
    else:
        wo, extra = d, 1.0
    weight = wr_ * extra * width[:, None] * dt * (t1 - t0)[:, None]
    weight = np.where(width[:, None] > 0, weight, 0.0)
    return wi.reshape(-1, 3), wo.reshape(-1, 3), weight.ravel()


@njit(cache=True, nogil=True)
def _points_kernel(axis, node, lo, width, t0, t1, sm, mu, s_n, ca_n, sa_n, wr_n, nodes, wi, wo,  # pragma: no cover
                   weight):
    """Compiled twin of :func:`_points_reference` (fills ``wi``, ``wo`` (N, 3), ``weight`` (N))."""
    R = nodes.shape[0]
    for q in range(node.shape[0]):
        j = node[q]
        m, s, ca, sa = mu[j], s_n[j], ca_n[j], sa_n[j]
        h = t1[q] - t0[q]
        base = wr_n[j] * width[q] * h
        for r in range(R):
            i = q * R + r
            v = t0[q] + h * nodes[r]
            c = sm[q]
            if c == 0:
                t, dt = v, 1.0
            elif c == 1:
                t, dt = v * v, 2.0 * v
            elif c == 2:
                t, dt = 1.0 - (1.0 - v) * (1.0 - v), 2.0 * (1.0 - v)
            else:
                t, dt = v * v * (3.0 - 2.0 * v), 6.0 * v * (1.0 - v)
            beta = lo[q] + t * width[q]
            cb, sb = math.cos(beta), math.sin(beta)
            if axis == 0 or axis == 3:
                d0, d1, d2 = sa * cb, sa * sb, ca
            elif axis == 1:
                d0, d1, d2 = -s * ca + m * sa * cb, sa * sb, m * ca + s * sa * cb
            else:
                d0, d1, d2 = s * ca - m * sa * cb, sa * sb, m * ca + s * sa * cb
            wi[i, 0] = s
            wi[i, 1] = 0.0
            wi[i, 2] = m
            if axis == 3:
                ih = s * d0 + m * d2
                wo[i, 0] = 2.0 * ih * d0 - s
                wo[i, 1] = 2.0 * ih * d1
                wo[i, 2] = 2.0 * ih * d2 - m
                extra = 4.0 * ih
            else:
                wo[i, 0] = d0
                wo[i, 1] = d1
                wo[i, 2] = d2
                extra = 1.0
            weight[i] = base * extra * dt if width[q] > 0 else 0.0


# --- Kronrod and Gauss sums per segment --------------------------------------------------------------

def _values_reference(f, cos_o, weight):
    """Plain numpy twin of :func:`pumpup.engine.cubature.accumulate` as this module uses it (on zeros): f cos(theta_o)
    weight where all three are positive.
    """
    return np.where((f > 0) & (cos_o > 0) & (weight > 0), f * cos_o * weight, 0.0)


def _rule_reference(vals, wk, wg):
    """Plain numpy twin of :func:`_rule_kernel`: (K, G) per block of len(wk) values."""
    v = vals.reshape(-1, len(wk))
    return v @ wk, v @ wg


@njit(cache=True, nogil=True)
def _rule_kernel(vals, wk, wg, K, G):  # pragma: no cover - compiled
    """Per block of len(wk) values: the Kronrod sum K and the Gauss sum G (the rule on [0, 1])."""
    R = wk.shape[0]
    for q in range(K.shape[0]):
        sk = 0.0
        sg = 0.0
        for r in range(R):
            sk += wk[r] * vals[q * R + r]
            sg += wg[r] * vals[q * R + r]
        K[q] = sk
        G[q] = sg


# --- one batch of segments ------------------------------------------------------------------------

def _evaluate(brdf, g, i_prob, i_x0, i_x1, seg_int, seg_piece, seg_t0, seg_t1, i_sub=None):
    """The segments (piece ``seg_piece``, sub-interval [t0, t1] of v) of outer intervals ``seg_int``
    (indices into ``i_prob``, ``i_x0``, ``i_x1``) at the 15 outer nodes of their interval: per segment
    its share of the outer Kronrod and Gauss sums, its inner error carried through the outer Kronrod
    weights, and the sum of |values| (all including the interval width); and the evaluations per
    problem.
    """
    budget.check("the nested quadrature refined its intervals")  # (a time budget: pumpup.core.budget)
    lobe = g.lobe
    RO, RI = len(_OUTER[0]), len(_INNER[0])
    onodes, owk, owg = _OUTER
    inodes, iwk, iwg = _INNER
    uniq, loc = np.unique(seg_int, return_inverse=True)
    h = i_x1[uniq] - i_x0[uniq]
    if i_sub is None:
        tx = (i_x0[uniq][:, None] + h[:, None] * onodes[None, :]).ravel()
        hw = np.broadcast_to(h[:, None], (len(uniq), RO))
    else:  # the outer substitution towards a break (OUTER_SUB): x = x0 + h t(v), dx = h t'(v) dv
        tv, dtv = _end_map(i_sub[uniq], np.broadcast_to(onodes, (len(uniq), RO)))
        tx = (i_x0[uniq][:, None] + h[:, None] * tv).ravel()
        hw = h[:, None] * dtv
    pnode = np.repeat(i_prob[uniq], RO)
    mu_n = np.ascontiguousarray(g.mu[pnode])
    lev_n = np.ascontiguousarray(g.levels[pnode])
    if lobe.kinks is not None:  # the model's kink coefficients: once per outer node (issue 14 item 3)
        x, xc, _ = smooth(tx)
        ka, kb = kink_coefficients(lobe, mu_n, x, xc)
    else:
        ka = kb = np.zeros((len(tx), 0))
    N = len(tx)
    E = lev_n.shape[1] + ka.shape[1] + 2
    s_n, ca_n, sa_n, wr_n = (np.empty(N) for _ in range(4))
    edges = np.empty((N, E))
    lab = np.empty((N, E), np.int64)
    dn = np.empty((N, E))
    _nodes_kernel(AXIS_CODE[lobe.axis], RADIAL_CODE[lobe.radial], float(lobe.sharpness), mu_n, lev_n,
                  np.ascontiguousarray(ka), np.ascontiguousarray(kb), tx, s_n, ca_n, sa_n, wr_n, edges, lab, dn)
    # blocks: (segment, outer node) pairs where the segment's piece is not empty at that node
    S = len(seg_int)
    node = (loc[:, None] * RO + np.arange(RO)[None, :]).ravel()  # (S * R,)
    piece = np.repeat(seg_piece, RO)
    lo = edges[node, piece]
    width = edges[node, piece + 1] - lo
    live = (width > 0) & (wr_n[node] > 0)
    b_seg = np.nonzero(live)[0]  # block -> segment * R + r
    b_node = node[b_seg]
    b_piece = piece[b_seg]
    b_t0 = np.repeat(seg_t0, RO)[b_seg]
    b_t1 = np.repeat(seg_t1, RO)[b_seg]
    # the inner substitution: square-root behaviour only where the arc ends at the horizon (beta0 < pi;
    # sqrt(N.wo) for Ward); beta = 0, a full arc's end and the cuts are analytic ends of a piece
    hi_edge = edges[b_node, b_piece + 1]
    beta0 = edges[b_node, E - 1]
    sm = np.where((hi_edge == beta0) & (beta0 < math.pi), 2, 0).astype(np.int64)
    if brdf.azimuth_range() is not None:
        # an anisotropic lobe narrow across one tangent axis is a ridge along beta = 0 or along the
        # cut the hint puts on the other axis (ward_aniso ax = 1e-6, ay = 1e-3 at mu = 1: 0.761 +- 6e-12
        # for 0.9999985 with t = v there): both ends smoothed, as the 2-D engine does everywhere
        sm[:] = 3
    row, b_t0, b_t1 = _end_grading(lev_n, lab, dn, b_node, b_piece, width[b_seg], b_t0, b_t1, sm)
    b_seg, b_node, sm = b_seg[row], b_node[row], sm[row]
    B = len(b_seg)
    b_lo, b_w = lo[b_seg], width[b_seg]
    # in chunks that stay in the cache, through buffers allocated once
    C = min(B, CHUNK)
    wi = np.empty((C * RI, 3))
    wo = np.empty((C * RI, 3))
    weight = np.empty(C * RI)
    Kb = np.zeros(B)
    Gb = np.zeros(B)
    vals = np.empty(C * RI)
    signs = (1.0,) if lobe.symmetric else (1.0, -1.0)
    axis = AXIS_CODE[lobe.axis]
    for c0 in range(0, B, CHUNK):
        if c0:
            budget.check("the nested quadrature refined its intervals")
        sl = slice(c0, min(B, c0 + CHUNK))
        n = (sl.stop - sl.start) * RI
        wi_, wo_, w_, v_ = wi[:n], wo[:n], weight[:n], vals[:n]
        v_[:] = 0.0
        _points_kernel(axis, b_node[sl], b_lo[sl], b_w[sl], b_t0[sl], b_t1[sl], sm[sl], mu_n, s_n, ca_n, sa_n, wr_n,
                       inodes, wi_, wo_, w_)
        # wi at azimuth phi: the whole configuration turned by phi about N, as the 2-D engine does
        if g.phi is not None:
            ph = np.repeat(g.phi[pnode[b_node[sl]]], RI)
            cp, sp = np.cos(ph), np.sin(ph)
        for sign in signs:
            if sign < 0:
                wo_[:, 1] *= -1.0  # beta -> -beta flips wo_y in every frame (wi_y = 0), before the turn
            wi_t, wo_t = (wi_, wo_) if g.phi is None else (rotate_wi(wi_, cp, sp), rotate_wi(wo_, cp, sp))
            f = np.ascontiguousarray(brdf._eval(wi_t, wo_t), dtype=np.float64)
            i = accumulate(f, wo_[:, 2], w_, v_)  # (N.wo is unchanged by the turn)
            if i >= 0:
                raise ValueError(
                    f"{brdf!r} returned {f[i]!r} at wi={wi_t[i].tolist()}, wo={wo_t[i].tolist()}: "
                    "a BRDF must be finite and non-negative above the horizon"
                )
        _rule_kernel(v_, iwk, iwg, Kb[sl], Gb[sl])
    sym = 2.0 if lobe.symmetric else 1.0
    r = b_seg % RO
    seg = b_seg // RO
    hb = sym * hw[loc[seg], r]
    # per segment and outer node: the arc integral's share (the outer rule's value, in its variable)
    sv = np.bincount(seg * RO + r, hb * Kb, minlength=S * RO).reshape(S, RO)
    inner = np.bincount(seg, hb * owk[r] * inner_error(Kb, Gb), minlength=S)
    absk = np.bincount(seg, hb * owk[r] * np.abs(Kb), minlength=S)
    evals = np.bincount(i_prob[seg_int[seg]], minlength=len(g.mu)) * RI * len(signs)
    return sv, inner, absk, evals


#: segments per call of :func:`_evaluate`: its block arrays (a dozen of 8 bytes per segment and outer node, more where
#: the ends are graded) grow with the segments a refinement round adds.  Found by
#: ``scripts/studies/fuzz_engines.py --fmax 22``: a nested reference at max_regions
#: 200000 grew past 23 GB and the kernel killed it.  Each segment's values do not depend on the others in its call, so
#: the chunks change no bit
SEG_CHUNK = 100_000


def _evaluate_chunked(brdf, g, i_prob, i_x0, i_x1, seg_int, seg_piece, seg_t0, seg_t1, i_sub=None):
    """:func:`_evaluate` in calls of at most :data:`SEG_CHUNK` segments (memory bounded), concatenated."""
    if len(seg_int) <= SEG_CHUNK:
        return _evaluate(brdf, g, i_prob, i_x0, i_x1, seg_int, seg_piece, seg_t0, seg_t1, i_sub)
    parts = [_evaluate(brdf, g, i_prob, i_x0, i_x1, seg_int[a:a + SEG_CHUNK], seg_piece[a:a + SEG_CHUNK],
                       seg_t0[a:a + SEG_CHUNK], seg_t1[a:a + SEG_CHUNK], i_sub)
             for a in range(0, len(seg_int), SEG_CHUNK)]
    return (np.concatenate([q[0] for q in parts]), np.concatenate([q[1] for q in parts]),
            np.concatenate([q[2] for q in parts]), sum(q[3] for q in parts))


#: outer intervals that end at a break integrate in v with x = x0 + h v^2 towards it (module docstring)
OUTER_SUB = True
#: the crossings of two cuts are breaks of the outer variable too (module docstring)
CROSSINGS = True

#: ratio of the geometric grid above the power map's split (_split_breaks)
SPLIT_RATIO = 4.0
#: ratio of the geometric grid towards a break (the 2-D engine's graded uses 4)
GRADE_RATIO = 16.0


def _graded_coarse(points: np.ndarray) -> np.ndarray:
    """Breakpoints with a grid graded geometrically towards each, as ``pumpup.engine.cubature.graded`` but
    with steps d 16^k: the outer rule's |K - G| sees the variation on one step (measured on the
    tests' references), and a break 7e-18 from an end (Cook-Torrance's second horizon at mu = 0.5)
    costs 14 intervals instead of 27.
    """
    out = list(points)
    for t in points:
        d = min(t, 1.0 - t)
        if not d > 0:  # a break on an end of the range is the end itself: nothing to grade (d = 0 never grew)
            continue
        step = d * GRADE_RATIO
        while step <= 0.25:
            out.extend(v for v in (t - step, t + step) if 0 < v < 1)
            step *= GRADE_RATIO
    return np.array(out)


#: near normal incidence (theta_i below this many times a microfacet lobe's roughness) the outer grid is also graded
#: towards the horizon breaks on the roughness's scale (:func:`_alpha_grading`)
ALPHA_NEAR = 64.0


def _alpha_grading(lobe, mu: float) -> np.ndarray:
    """Values of tau_x graded geometrically towards the horizon breaks of a microfacet lobe's half vector (alpha_h =
    pi/4 -+ theta_i / 2) on its roughness's scale a (GGX's alpha, the sqrt of the "ggx" map's sharpness; Beckmann's m):
    alpha_f -+ (a / 2) 4^k up to 1/4 rad away.  The shadowing G1(wo) falls to 0 where N.wo is within a of the horizon,
    which is (a / 2) in alpha_h from a break; away from normal incidence the arc's integral over beta spreads that over
    theta_i, but near it the outer integrand has the whole feature next to the break, where the grading towards the
    break (on the scale of its distance to the end of the range) did not see it: GGX alpha = 1.4e-3 at mu = 1 was 6.4 x
    its estimate at rtol 1e-10, alpha = 3e-4 at mu = 1 - 1e-9 26 x at 1e-12
    (``scripts/studies/fuzz_engines.py``).
    """
    if lobe.axis != "half" or lobe.radial not in ("ggx", "beckmann"):
        return np.array([])
    a = math.sqrt(lobe.sharpness) if lobe.radial == "ggx" else float(lobe.sharpness)
    s = math.sqrt((1.0 - mu) * (1.0 + mu))
    th = math.atan2(s, mu)
    if not th < ALPHA_NEAR * a:
        return np.array([])
    out = []
    for af in (0.25 * math.pi - 0.5 * th, 0.25 * math.pi + 0.5 * th):
        off = 0.5 * a
        while off < 0.25:
            for ab in (af - off, af + off):
                tau = tau_of_angle(lobe, ab) if 0.0 < ab < 0.5 * math.pi else None
                if tau is not None:
                    out.append(tau)
            off *= 4.0
    return np.array(out)


def _merged(breaks: np.ndarray) -> np.ndarray:
    """The sorted breaks with those within 1e-12 of their distance to the nearer end of [0, 1] of the
    previous one dropped: three cuts of Cook-Torrance's geometry factor cross at one point (m = 0.4,
    mu = 0.1: tau_x = 0.0255861562 three times, 1e-17 apart), and each interval costs a full rule.
    """
    b = np.sort(breaks)
    if len(b) < 2:
        return b
    keep = np.r_[True, np.diff(b) > 1e-12 * np.minimum(b[1:], 1.0 - b[1:])]
    return b[keep]


def _split_breaks(lobe) -> np.ndarray:
    """Values of tau_x graded geometrically above the split x = 1/2 of the two-piece "power" map.

    Above the split, y = y_s + (1 - y_s)(2 x - 1) and cos(alpha) = y^(1/(n+1)) with y_s = 2^-(n+1):
    cos(alpha) changes on the scale y - y_s ~ y_s, which is tiny for a sharp lobe (n = 20: 5e-7),
    so the integrand varies like y^(1/(n+1)) there; the bisection found it interval by interval
    (14 levels for n = 20).  The breaks y = y_s 4^k put it on a geometric grid from the start.
    """
    if lobe.radial != "power":
        return np.array([])
    _, ys = power_split(float(lobe.sharpness))
    out = []
    # below y = 1e-16 the rest of the peak piece weighs at most 1e-16 of it (u^n du = dy / (n + 1)); for
    # n > 1073 y_s underflows to 0, so the grid starts there
    y = max(SPLIT_RATIO * ys, 1e-16)
    while y < 0.25:
        xc = 0.5 * (1.0 - y) / (1.0 - ys)  # 1 - x, x = 1/2 + (y - y_s) / (2 (1 - y_s))
        out.append(smooth_inverse(1.0 - xc, xc))
        y *= SPLIT_RATIO
    return np.array(out)


#: a piece end at a level cut is graded when the integrand's scale there is below this (in v)
D_GRADE = 0.05
#: at most this many graded sub-intervals towards one end
K_GRADE = 16


def _end_grading(levels, lab, dn, node, piece, width, t0, t1, sm):
    """Sub-intervals of v for blocks whose piece ends at the cut of a small level u.

    Beside the cut of a level u (N.wo = u), N.wo - u = dn w (1 - v) (t = v at a cut; dn w v at the
    lower end): a factor max(u, N.wo)^-p with a fractional p (stretched Phong p = 0.5, 000 eq. 12)
    makes the integrand vary on the scale d = u / (dn w) in v there (sqrt(d / 3) at an end with the
    square-root substitution, ``sm``), which is tiny near grazing
    incidence (u = mu).  A fixed rule neither resolves it nor sees that it does not (measured:
    |K - G| 2.4e-12 against an error of 6.5e-12 at mu = 1e-7), so such ends get sub-intervals
    graded geometrically, d 4^k from the end.
    Returns (row, t0, t1): the block of every sub-interval and its ends.
    """
    B = len(node)
    if not levels.shape[1]:
        return np.arange(B), t0, t1
    kk = 4.0 ** np.arange(K_GRADE)
    ends = []  # (rows, sign, d) of the ends to grade; only those rows are expanded
    for edge, sign in ((piece + 1, -1.0), (piece, 1.0)):
        j = lab[node, edge]
        end = t1 if sign < 0 else t0
        maybe = np.nonzero((j >= 0) & (end == (1.0 if sign < 0 else 0.0)))[0]
        if not len(maybe):
            continue
        jm = j[maybe]
        u = levels[node[maybe], jm]
        with np.errstate(divide="ignore", invalid="ignore"):
            d = u / (dn[node[maybe], edge[maybe]] * width[maybe])
            smooth = (sm[maybe] & (2 if sign < 0 else 1)) > 0  # t ~ 3 v^2 at a smoothed end: the scale is sqrt(d / 3)
            d = np.where(smooth, np.sqrt(d / 3.0), d)
        need = (u > 0) & (d < D_GRADE)
        if need.any():
            ends.append((maybe[need], sign, d[need]))
    if not ends:
        return np.arange(B), t0, t1
    graded = np.unique(np.concatenate([r for r, _, _ in ends]))
    pos = np.full(B, -1)
    pos[graded] = np.arange(len(graded))
    G = len(graded)
    cand = [t0[graded, None], t1[graded, None]]
    for rows, sign, d in ends:
        d = np.maximum(d, 0.25 / kk[-1])
        off = d[:, None] * kk[None, :]
        pts = (1.0 - off) if sign < 0 else off
        ok = (off < 0.25) & (pts > t0[rows, None]) & (pts < t1[rows, None])
        full = np.full((G, K_GRADE), np.nan)
        full[pos[rows]] = np.where(ok, pts, np.nan)
        cand.append(full)
    allp = np.sort(np.concatenate(cand, axis=1), axis=1)  # NaN last
    a, b = allp[:, :-1], allp[:, 1:]
    okp = np.isfinite(a) & np.isfinite(b) & (b > a)
    r, col = np.nonzero(okp)
    plain = np.ones(B, bool)
    plain[graded] = False
    row = np.concatenate([np.nonzero(plain)[0], graded[r]])
    order = np.argsort(row, kind="stable")  # blocks in their order, sub-intervals in increasing v
    return row[order], np.concatenate([t0[plain], a[r, col]])[order], np.concatenate([t1[plain], b[r, col]])[order]


def _weighted_columns(F: np.ndarray, w: np.ndarray) -> np.ndarray:
    """sum_r F[:, r] w[r], summed in the order of r for every row (independent of the number of rows)."""
    out = F[:, 0] * w[0]
    for r in range(1, F.shape[1]):
        out += F[:, r] * w[r]
    return out


def integrate(brdf, g, rtol: float, atol: float, max_regions: int):
    """a(mu) of the group ``g`` by nested quadrature: (value, error, converged) per problem, as
    ``pumpup.engine.cubature._integrate_group`` returns them.
    """
    global LAST_EVALS
    P = len(g.mu)
    n_pieces = 1 + g.levels.shape[1] + (len(g.lobe.kinks(np.array([0.5]), np.array([0.5]), np.array([0.5]),
                                                         np.array([0.5]))) if g.lobe.kinks else 0)
    # the crossings of two cuts change the order of the pieces; the arc's integral is not analytic there
    # (module docstring): breaks here too, as in the 2-D engine
    arc_kinks = kink_breaks(g.lobe, g.mu, g.levels, crossings=CROSSINGS)
    split = _split_breaks(g.lobe)
    cols = []
    for p_ in range(P):
        breaks = _merged(np.concatenate([horizon_breaks(g.lobe, float(g.mu[p_])), arc_kinks[p_]]))
        gx = np.unique(np.concatenate([np.linspace(0, 1, NX_INIT + 1), _graded_coarse(breaks), split,
                                       _alpha_grading(g.lobe, float(g.mu[p_]))]))
        at_break = np.isin(gx, breaks) if OUTER_SUB else np.zeros(len(gx), bool)
        cols.append((np.full(len(gx) - 1, p_), gx[:-1], gx[1:], at_break[:-1] * 1 + at_break[1:] * 2))
    # intervals (growing arrays; a bisected interval is dead) and their segments
    i_prob, i_x0, i_x1, i_sub = (np.concatenate(c) for c in zip(*cols))
    alive = np.ones(len(i_prob), bool)
    nI = len(i_prob)
    grid = np.linspace(0.0, 1.0, M_INIT + 1)
    s_int = np.repeat(np.arange(nI), n_pieces * M_INIT)
    s_piece = np.tile(np.repeat(np.arange(n_pieces), M_INIT), nI)
    s_t0 = np.tile(grid[:-1], nI * n_pieces)
    s_t1 = np.tile(grid[1:], nI * n_pieces)
    s_v, s_e, s_a, evals = _evaluate_chunked(brdf, g, i_prob, i_x0, i_x1, s_int, s_piece, s_t0, s_t1, i_sub)

    # the budget counts outer intervals, an interval with m sub-intervals per piece m times
    def seg_count():
        """The outer intervals of each problem, read from the arrays of the current round."""
        return np.bincount(i_prob[s_int], minlength=P) / n_pieces

    budget = max_regions + seg_count()
    rounding = lobe_rounding(g.lobe)
    while True:
        nI = len(i_prob)
        RO = s_v.shape[1]
        F = np.bincount((s_int[:, None] * RO + np.arange(RO)).ravel(), s_v.ravel(), minlength=nI * RO).reshape(nI, RO)
        # the outer sums column by column, not by a matrix product: BLAS's order of the terms depends on
        # the matrix's size and alignment, and so did the last bits of the error, with the batch a value
        # of mu was computed in (a table then depended on the number of threads; tests/tables/test_tables.py)
        kron, gauss = _weighted_columns(F, _OUTER[1]), _weighted_columns(F, _OUTER[2])
        inner = np.bincount(s_int, s_e, minlength=nI)
        outer = np.abs(kron - gauss)
        err = np.where(alive, interval_error(kron, gauss, inner), 0.0)
        total = np.bincount(i_prob, kron, minlength=P)
        E = np.bincount(i_prob, err, minlength=P)
        Rr = rounding * np.bincount(i_prob[s_int], s_a, minlength=P)
        tol = np.maximum(rtol * np.abs(total), atol)
        # done when the quadrature error meets the tolerance or is below the rounding error of the
        # integrand (as the 2-D engine); the reported error is both
        converged = E <= np.maximum(tol, Rr)
        E = E + Rr
        active = ~converged & (seg_count() < budget)
        if not active.any():
            break
        nint = np.bincount(i_prob[alive], minlength=P)
        share = tol / nint
        pick = alive & active[i_prob] & (err > 0.5 * share[i_prob])
        order = np.lexsort((-err, i_prob))
        order = order[alive[order]]
        first = order[np.r_[True, i_prob[order][1:] != i_prob[order][:-1]]]
        pick[first[active[i_prob[first]]]] = True
        # inner error dominant: bisect the interval's worst segments in v; else bisect the interval
        deeper = pick & (inner > outer)
        split = pick & ~deeper
        # segments of "deeper" intervals: those above half their interval's share, and the worst
        nseg = np.bincount(s_int, minlength=nI)
        sel = deeper[s_int] & (s_e > 0.5 * share[i_prob[s_int]] / np.maximum(nseg[s_int], 1))
        o2 = np.lexsort((-s_e, s_int))
        f2 = o2[np.r_[True, s_int[o2][1:] != s_int[o2][:-1]]]
        sel[f2[deeper[s_int[f2]]]] = True
        # children of split intervals, with copies of the parent's segments
        sp = np.nonzero(split)[0]
        # bisected in the interval's own variable v: at x0 + h / 4 (x1 - h / 4) where it is x0 + h v^2
        # (x1 - h (1 - v)^2); a child keeps the substitution at the parent's break end only
        hs = i_x1[sp] - i_x0[sp]
        ss = i_sub[sp]
        xm = np.where(ss == 1, i_x0[sp] + 0.25 * hs, np.where(ss == 2, i_x1[sp] - 0.25 * hs,
                                                              0.5 * (i_x0[sp] + i_x1[sp])))
        i_sub = np.concatenate([i_sub, ss & 1, ss & 2])
        base = len(i_prob)
        child = np.full(nI, -1)
        child[sp] = base + np.arange(len(sp))  # lower children; upper ones follow at + len(sp)
        i_prob = np.concatenate([i_prob, i_prob[sp], i_prob[sp]])
        i_x0 = np.concatenate([i_x0, i_x0[sp], xm])
        i_x1 = np.concatenate([i_x1, xm, i_x1[sp]])
        alive = np.concatenate([alive, np.ones(2 * len(sp), bool)])
        alive[sp] = False
        moved = split[s_int]
        tm = 0.5 * (s_t0[sel] + s_t1[sel])
        new_int = np.concatenate([s_int[sel], s_int[sel], child[s_int[moved]], child[s_int[moved]] + len(sp)])
        new_piece = np.concatenate([s_piece[sel], s_piece[sel], s_piece[moved], s_piece[moved]])
        new_t0 = np.concatenate([s_t0[sel], tm, s_t0[moved], s_t0[moved]])
        new_t1 = np.concatenate([tm, s_t1[sel], s_t1[moved], s_t1[moved]])
        cv, ce, ca, cev = _evaluate_chunked(brdf, g, i_prob, i_x0, i_x1, new_int, new_piece, new_t0, new_t1, i_sub)
        evals = evals + cev
        keep = ~(sel | moved)
        s_int = np.concatenate([s_int[keep], new_int])
        s_piece = np.concatenate([s_piece[keep], new_piece])
        s_t0, s_t1 = np.concatenate([s_t0[keep], new_t0]), np.concatenate([s_t1[keep], new_t1])
        s_v = np.concatenate([s_v[keep], cv])
        s_e, s_a = np.concatenate([s_e[keep], ce]), np.concatenate([s_a[keep], ca])
    LAST_EVALS = evals
    return total, E, converged
