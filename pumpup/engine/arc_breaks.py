"""The breakpoints of a lobe's kinks and levels on the arcs of the 2-D cubature and the nested quadrature: where the
horizon and the levels cut the arc, found by a compiled scan with bisection and golden-section refinement, and its
plain numpy reference (:func:`kink_breaks_reference`); :mod:`pumpup.engine.cubature` describes the method.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from ..core import Lobe
from .lobe_geometry import (
    AXIS_CODE,
    RADIAL_CODE,
    radial_map,
    radial_map_inverse,
    radial_map_scalar,
    smooth,
    smooth_inverse,
)

#: horizon breaks whose map variable x or 1 - x is below this are the end itself (horizon_breaks)
_BREAK_MIN = 1e-30


def horizon_breaks(lobe: Lobe, mu: float) -> np.ndarray:
    """Values of tau_x where the visible arc starts to shrink and where it vanishes.

    N.wo = a(alpha) + b(alpha) cos(beta) in every frame; the arc is complete while a >= b
    and empty once a <= -b.  At normal incidence (b = 0) the second is a jump of the
    integrand, which must sit on a rectangle edge.
    """
    s = math.sqrt((1.0 - mu) * (1.0 + mu))
    theta = math.atan2(s, mu)
    if lobe.axis in ("mirror", "retro"):
        alphas = [math.pi / 2 - theta]  # mu cos(alpha) = s sin(alpha); a <= -b only beyond 90 deg
    elif lobe.axis == "half":
        alphas = [math.pi / 4 - theta / 2, math.pi / 4 + theta / 2]  # mu cos 2a = +-s sin 2a
    else:
        alphas = []
    out = []
    for a in alphas:
        if 0 < a < math.pi / 2:
            tau = tau_of_angle(lobe, a)
            if tau is not None:
                out.append(tau)
    return np.array(out)


def tau_of_angle(lobe: Lobe, alpha: float) -> float | None:
    """tau_x of the polar angle ``alpha`` in the lobe's radial map, or None where the map variable x or 1 - x is below
    :data:`_BREAK_MIN`: x is the radial weight's measure, and a break there closes a region that weighs nothing (below x
    the integrand per unit x is at most about 1 / mu; beyond 1 - x, GGX's tail, about alpha / (mu sqrt(1 - x));
    Cook-Torrance m = 0.2 at mu = 0.359: x = 1.7e-315 put a break at tau_x = 2.4e-158, where the map's Jacobian
    k^2 cos^3 / (2 x) overflowed; a break at 3e-56 would cost the nested engine 46 graded intervals).
    """
    x, xc = radial_map_inverse(lobe.radial, lobe.sharpness, alpha)
    return smooth_inverse(x, xc) if x > _BREAK_MIN and xc > _BREAK_MIN**2 else None


_TAU_SCAN = np.unique(np.concatenate([
    np.linspace(0.0, 1.0, 401),
    np.logspace(-13, math.log10(0.5), 120),
    1.0 - np.logspace(-13, math.log10(0.5), 120),
]))


#: kink breaks closer than this to an end of the radial range are the end itself (kink_breaks)
_END_GAP = 1e-10
#: two cuts whose crossing function a_j b_k - a_k b_j stays within COINCIDENT eps S_j S_k at every node of the scan
#: (S a bound of the magnitudes a cut's coefficients are computed from: |a| + |b| of a model's kink, |a0 - u| + |b0| +
#: |u| of a level N.wo = u, |a0| + |b0| of the horizon) are one curve, computed twice: its "roots" are rounding noise.
#: A pumped Cook-Torrance has the level N.wo = mu of g2 and g1 (:meth:`pumpup.operators.pumping.Pumped.kink_levels`) and
#: the geometry factor's kink N.wo = mu (:func:`pumpup.models.cook_torrance._g_kinks`): 292 such breaks at mu = 0.5 gave
#: the nested engine 448 first intervals where the base model has 25, 40-60 x its evaluations
COINCIDENT = 64.0
_EPS = float(np.finfo(float).eps)


def kink_breaks_reference(lobe: Lobe, mu: np.ndarray, levels: np.ndarray, crossings: bool = True) -> list[np.ndarray]:
    """Plain numpy reference of :func:`kink_breaks`: the same breaks, bit for bit and in the same
    order (``tests/engine/test_cubature.py`` checks the two against each other).

    The functions whose roots are breaks are sampled on ``_TAU_SCAN`` for all problems at once (an
    (F P, G) array), and every sign change and every touching pair (:func:`_touching_pairs_reference`)
    is refined with ``h_rows``, which evaluates the cuts' coefficients at the points asked for, one
    step of the bisection (or of the golden-section search) at a time for all roots together.
    """
    P = len(mu)
    if not levels.shape[1] and lobe.kinks is None:
        return [np.array([]) for _ in range(P)]

    def values(p_sel, tau):
        """(A, B): (n_cuts + 1, n) coefficients a + b cos(beta) of the cuts (the levels N.wo = u, then
        the model's kinks) and, last, of the horizon N.wo = 0, for problems p_sel at tau.
        """
        m, lev = mu[p_sel], levels[p_sel]
        with np.errstate(all="ignore"):
            s = np.sqrt((1.0 - m) * (1.0 + m))
            x, xc, _ = smooth(tau)
            ca, sa, _ = radial_map(lobe.radial, lobe.sharpness, x, xc)
            if lobe.axis == "normal":
                a0, b0 = ca, np.zeros_like(ca)
            elif lobe.axis in ("mirror", "retro"):
                a0, b0 = m * ca, s * sa
            else:
                a0, b0 = m * (ca * ca - sa * sa), 2.0 * s * sa * ca
            pairs = [(a0 - lev[:, j], b0) for j in range(lev.shape[1])]
            if lobe.kinks is not None:
                pairs += list(lobe.kinks(m, s, ca, sa))
            pairs.append((a0, b0))
        return (np.stack([np.broadcast_to(np.asarray(a, float), m.shape) for a, _ in pairs]),
                np.stack([np.broadcast_to(np.asarray(b, float), m.shape) for _, b in pairs]))

    L = levels.shape[1]
    n_cuts = L + (len(lobe.kinks(*(np.full(1, 0.5) for _ in range(4)))) if lobe.kinks is not None else 0)
    # the functions whose roots are breaks, one row each per problem: (kind, j, k, sign) with kind 0,
    # a_j - sign b_j (the cut j enters or leaves the arc), and kind 1, a_j b_k - a_k b_j (the cuts j
    # and k cross; k = n_cuts is the horizon end beta0).  The pieces are the cuts in sorted order,
    # so where two cross, or a cut meets beta0, each piece's ends have a kink in x: Cook-Torrance
    # m = 0.3, ior 1.5 at mu = 0.3414 has its three geometry-factor cuts meet at tau_x = 0.0022
    # inside a rectangle whose 15 x 15 and 7 x 7 rules agreed to 1e-15 and were both 1.3e-11 off
    # (rtol 3e-11); ward_aniso ax = 0.05, ay = 0.5 at mu = 0.1, phi = 0.7 has the hint's constant
    # cuts at the model's axes meet beta0 (8.2e-10 off, estimate 2.2e-14).  Two levels never cross
    # (distinct values of N.wo on the same arc), nor a level and beta0 (N.wo = 0).
    funcs = [(0, j, j, sign) for j in range(n_cuts) for sign in (1.0, -1.0)]
    if crossings:
        funcs += [(1, j, k, 0.0) for j in range(L, n_cuts) for k in list(range(j)) + [n_cuts]]
    kind, fj, fk, fs = (np.array(c) for c in zip(*funcs))
    F = len(funcs)

    def h_rows(rows, tau):
        """The function of each row (function rows // P, problem rows % P) at tau."""
        f_ = rows // P
        a_, b_ = values(rows % P, tau)
        i = np.arange(len(rows))
        aj, bj, ak, bk = a_[fj[f_], i], b_[fj[f_], i], a_[fk[f_], i], b_[fk[f_], i]
        with np.errstate(all="ignore"):
            return np.where(kind[f_] == 0, aj - fs[f_] * bj, aj * bk - ak * bj)

    G = len(_TAU_SCAN)
    # on the scan the coefficients are computed once for all functions: (n_cuts + 1, P, G)
    a_, b_ = values(np.repeat(np.arange(P), G), np.tile(_TAU_SCAN, P))
    a_, b_ = a_.reshape(-1, P, G), b_.reshape(-1, P, G)
    aj, bj, ak, bk = a_[fj], b_[fj], a_[fk], b_[fk]  # (F, P, G)
    with np.errstate(all="ignore"):
        h = np.where((kind == 0)[:, None, None], aj - fs[:, None, None] * bj, aj * bk - ak * bj).reshape(F * P, G)
        # a crossing of two cuts that are one curve (COINCIDENT): no roots
        s_ = np.abs(a_) + np.abs(b_)
        s_[:L] += np.abs(levels.T[:, :, None])  # (a level's a = a0 - u: its rounding is of |a0| + |u|)
        noise = (COINCIDENT * _EPS * s_[fj] * s_[fk]).reshape(F * P, G)
        same = np.repeat(kind == 1, P) & np.all((np.abs(h) <= noise) | ~np.isfinite(h), axis=1)
    h[same] = np.nan
    r_idx, t = _roots_reference(h, h_rows)
    # a root within 1e-10 of an end is the end itself (a level through the lobe axis, N.wo = mu on
    # the mirror axis, touches the arc at alpha = 0): grading the grid towards it cost ~100
    # rectangles per mu and changed nothing
    keep = (_END_GAP < t) & (t < 1.0 - _END_GAP)
    f_ = r_idx // P
    if np.any(kind[f_] == 1):  # a crossing counts where both cuts are on the arc
        a_, b_ = values(r_idx % P, t)
        i = np.arange(len(r_idx))
        on = (np.abs(a_[fj[f_], i]) <= np.abs(b_[fj[f_], i])) & (np.abs(a_[fk[f_], i]) <= np.abs(b_[fk[f_], i]))
        keep &= (kind[f_] == 0) | on
    out = [[] for _ in range(P)]
    for p_, t_ in zip(r_idx[keep] % P, t[keep]):
        out[p_].append(t_)
    return [np.array(o) for o in out]


_GOLDEN = (math.sqrt(5.0) - 1.0) / 2.0


def _roots_reference(h: np.ndarray, h_at) -> tuple[np.ndarray, np.ndarray]:
    """(problem, tau) of the roots of a function sampled as ``h`` (P, G) on ``_TAU_SCAN``, with
    ``h_at(p, tau)`` to evaluate it: every sign change between scan nodes and every pair of roots
    around a local minimum of |h| (:func:`_touching_pairs_reference`), refined by bisection.
    """
    ok = np.isfinite(h)
    p_idx, i_idx = np.nonzero(ok[:, :-1] & ok[:, 1:] & (np.sign(h[:, :-1]) * np.sign(h[:, 1:]) < 0))
    lo, hi = _TAU_SCAN[i_idx].copy(), _TAU_SCAN[i_idx + 1].copy()
    h_lo = h[p_idx, i_idx]
    tp, tlo, thi, tmid, th_lo, th_mid = _touching_pairs_reference(h, ok, h_at)
    p_idx = np.concatenate([p_idx, tp, tp])
    lo = np.concatenate([lo, tlo, tmid])
    hi = np.concatenate([hi, tmid, thi])
    h_lo = np.concatenate([h_lo, th_lo, th_mid])
    if not len(p_idx):
        return p_idx, lo
    for _ in range(64):  # bisection: the cells are at least 1e-13 wide
        mid = 0.5 * (lo + hi)
        h_mid = h_at(p_idx, mid)
        left = np.sign(h_mid) == np.sign(h_lo)
        lo = np.where(left, mid, lo)
        h_lo = np.where(left, h_mid, h_lo)
        hi = np.where(left, hi, mid)
    return p_idx, 0.5 * (lo + hi)


def _touching_pairs_reference(h: np.ndarray, ok: np.ndarray, h_at):
    """Brackets of root pairs that the scan of :func:`kink_breaks` shows no sign change for.

    ``h`` (P, G) are the values of one kink function a -+ b on ``_TAU_SCAN`` (``ok`` where finite)
    and ``h_at(p, tau)`` evaluates it for problems ``p`` at ``tau``.  At every interior node i where
    |h| has a local minimum and h keeps its sign on the nodes i - 1, i, i + 1, a golden-section search
    of [tau_{i-1}, tau_{i+1}] minimises sign(h_i) h; where it finds the opposite sign at some t, the
    cells [tau_{i-1}, t] and [t, tau_{i+1}] each hold a root.  Returns the arrays
    (problem, tau_{i-1}, tau_{i+1}, t, h(tau_{i-1}), h(t)) of those found.
    """
    empty = np.zeros(0, np.int64), *(np.zeros(0) for _ in range(5))
    if h.shape[1] < 3:
        return empty
    ah = np.abs(h)
    sg = np.sign(h)
    c = (ok[:, :-2] & ok[:, 1:-1] & ok[:, 2:] & (sg[:, 1:-1] != 0) & (sg[:, :-2] == sg[:, 1:-1])
         & (sg[:, 2:] == sg[:, 1:-1]) & (ah[:, 1:-1] < ah[:, :-2]) & (ah[:, 1:-1] <= ah[:, 2:]))
    p_idx, i_idx = np.nonzero(c)
    if not len(p_idx):
        return empty
    i_idx = i_idx + 1
    s0 = sg[p_idx, i_idx]
    a, b = _TAU_SCAN[i_idx - 1].copy(), _TAU_SCAN[i_idx + 1].copy()
    found = np.full(len(p_idx), np.nan)
    h_found = np.zeros(len(p_idx))
    for _ in range(48):  # (0.618)^48 ~ 1e-10 of a cell (< 1e-12 in tau)
        x1 = b - _GOLDEN * (b - a)
        x2 = a + _GOLDEN * (b - a)
        q1, q2 = s0 * h_at(p_idx, x1), s0 * h_at(p_idx, x2)
        for x, q in ((x1, q1), (x2, q2)):
            new = np.isnan(found) & (q < 0)
            found = np.where(new, x, found)
            h_found = np.where(new, s0 * q, h_found)
        if not np.isnan(found).any():
            break
        left = ~(q1 >= q2)  # NaN (outside the map's range) keeps the left part
        b = np.where(left, x2, b)
        a = np.where(left, a, x1)
    hit = ~np.isnan(found)
    p_idx, i_idx = p_idx[hit], i_idx[hit]
    return (p_idx, _TAU_SCAN[i_idx - 1].copy(), _TAU_SCAN[i_idx + 1].copy(), found[hit],
            h[p_idx, i_idx - 1], h_found[hit])

#: points of the kink functions evaluated per round of :func:`kink_breaks`'s searches: one evaluation
#: (the model's ``Lobe.kinks`` and the radial map in numpy) costs ~0.1 ms whatever its size, so while
#: few searches are left each gets several steps per round (a tree of the possible steps)
_ROUND_POINTS = 2048
#: the deepest such tree (2^8 - 1 points of a bisection)
_MAX_DEPTH = 8
_BISECT_STEPS = 64  # bisection: the cells are at least 1e-13 wide
_GOLDEN_STEPS = 48  # (0.618)^48 ~ 1e-10 of a cell (< 1e-12 in tau)
#: room for this many roots and touching candidates per kink function and problem in the first pass
#: of :func:`_scan_kernel` (a second pass if there are more)
_SCAN_ROOM = 16
#: the coefficients are evaluated this many points at a time: numpy's temporaries (64 kB) stay below
#: malloc's mmap threshold and are reused, where larger ones were mapped and faulted in page by page
#: on every call (measured: filling the kinks of 19 000 points 0.7 ms, against 0.03 ms in place)
_CHUNK = 8192


@njit(cache=True, nogil=True)
def _horizon_ab(axis, m, s, ca, sa):  # pragma: no cover - compiled
    """(a0, b0): N.wo = a0 + b0 cos(beta) on the arc around the lobe axis (``values`` of
    :func:`kink_breaks_reference`, the same operations in the same order).
    """
    if axis == 0:  # normal
        return ca, 0.0
    if axis == 1 or axis == 2:  # mirror, retro
        return m * ca, s * sa
    return m * (ca * ca - sa * sa), 2.0 * s * sa * ca  # half


@njit(cache=True, nogil=True)
def _cut_ab(c, L, K, a0, b0, lev, KA, KB, i):  # pragma: no cover - compiled
    """(a, b) of cut c: a level N.wo = lev[c] (c < L), the model's kink c - L (its coefficients in
    column i of KA, KB), or the horizon (c = L + K).
    """
    if c < L:
        return a0 - lev[c], b0
    if c < L + K:
        return KA[c - L, i], KB[c - L, i]
    return a0, b0


@njit(cache=True, nogil=True)
def _scan_row(kind, j, k, sign, L, K, a0, b0, lev, KA, KB, base, h):  # pragma: no cover - compiled
    """The kink function (``kind``, cuts j and k, ``sign``; as :func:`_kink_h`) of one problem at the G
    nodes of the scan, into h: a0, b0 (G,) its horizon there, lev its levels, the model's kinks in
    columns base + g of KA, KB; one loop for each kind of cut j (and k), so that every loop vectorises
    (the cuts of a crossing: j is a kink of the model, k a level, a kink or the horizon).
    """
    G = h.shape[0]
    if kind == 0:
        if j < L:
            u = lev[j]
            for g in range(G):
                h[g] = (a0[g] - u) - sign * b0[g]
        elif j < L + K:
            ka, kb = KA[j - L, base:base + G], KB[j - L, base:base + G]
            for g in range(G):
                h[g] = ka[g] - sign * kb[g]
        else:
            for g in range(G):
                h[g] = a0[g] - sign * b0[g]
        return
    ka, kb = KA[j - L, base:base + G], KB[j - L, base:base + G]
    if k < L:
        u = lev[k]
        for g in range(G):
            h[g] = ka[g] * b0[g] - (a0[g] - u) * kb[g]
    elif k < L + K:
        la, lb = KA[k - L, base:base + G], KB[k - L, base:base + G]
        for g in range(G):
            h[g] = ka[g] * lb[g] - la[g] * kb[g]
    else:
        for g in range(G):
            h[g] = ka[g] * b0[g] - a0[g] * kb[g]


@njit(cache=True, nogil=True)
def _coincident(j, k, L, K, a0, b0, lev, KA, KB, base, h):  # pragma: no cover - compiled
    """Whether the crossing function of cuts j (a kink of the model) and k, ``h`` on the G nodes of the scan (from
    :func:`_scan_row`), is within rounding of 0 at every node where it is finite: the two cuts are one curve
    (:data:`COINCIDENT`, the test of :func:`kink_breaks_reference`).
    """
    tol = COINCIDENT * _EPS
    for g in range(h.shape[0]):
        x = h[g]
        if not abs(x) < math.inf:
            continue
        sj = abs(KA[j - L, base + g]) + abs(KB[j - L, base + g])
        if k < L:
            u = lev[k]
            sk = (abs(a0[g] - u) + abs(b0[g])) + abs(u)
        elif k < L + K:
            sk = abs(KA[k - L, base + g]) + abs(KB[k - L, base + g])
        else:
            sk = abs(a0[g]) + abs(b0[g])
        if not abs(x) <= tol * sj * sk:
            return False
    return True


@njit(cache=True, nogil=True)
def _kink_h(kind, j, k, sign, aj, bj, ak, bk):  # pragma: no cover - compiled
    """A kink function: a_j - sign b_j (kind 0: cut j enters or leaves the arc) or a_j b_k - a_k b_j
    (kind 1: cuts j and k cross).
    """
    if kind == 0:
        return aj - sign * bj
    return aj * bk - ak * bj


@njit(cache=True, nogil=True)
def _prepare_points(prob, tau, mu, s_p, radial, k, m, s, x, xc, ca, sa, rest):  # pragma: no cover
    """For the points (problem ``prob[i]``, tau[i]): m = mu and s = sqrt(1 - mu^2)
    of the problem, x and 1 - x of :func:`smooth`, and cos(alpha), sin(alpha) of :func:`radial_map`
    where the map is exact arithmetic and square roots (the cosine and GGX maps, the power map's
    tail x < 1/2: :func:`radial_map_scalar` gives numpy's bits there); ``rest`` marks the others (logs
    and exponentials, left to numpy).  Returns how many those are.
    """
    n_rest = 0
    for i in range(prob.shape[0]):
        m[i] = mu[prob[i]]
        s[i] = s_p[prob[i]]
        t = tau[i]
        u = 1.0 - t
        x[i] = t * t * (3.0 - 2.0 * t)
        xc[i] = (u * u) * (1.0 + 2.0 * t)
        if radial == 0 or radial == 3 or (radial == 1 and x[i] < 0.5):
            c, sn, _ = radial_map_scalar(radial, k, x[i], xc[i])
            ca[i] = c
            sa[i] = sn
            rest[i] = False
        else:
            rest[i] = True
            n_rest += 1
    return n_rest


@njit(cache=True, nogil=True, inline="always")
def _cut_pair(f, p_, i, L, K, axis, m, s, ca, sa, KA, KB, levels, fj, fk):  # pragma: no cover - compiled
    """(a_j, b_j, a_k, b_k): the coefficients of the two cuts of kink function f, problem p_, at point i."""
    lev = levels[p_]
    a0, b0 = _horizon_ab(axis, m[i], s[i], ca[i], sa[i])
    aj, bj = _cut_ab(fj[f], L, K, a0, b0, lev, KA, KB, i)
    ak, bk = _cut_ab(fk[f], L, K, a0, b0, lev, KA, KB, i)
    return aj, bj, ak, bk


@njit(cache=True, nogil=True)
def _kink_h_points(func, prob, L, K, axis, m, s, ca, sa, KA, KB, levels, kind, fj, fk, fs, out):  # pragma: no cover
    """The kink function ``func[i]`` of problem ``prob[i]`` at every point i (``h_rows`` of
    :func:`kink_breaks_reference`).
    """
    for i in range(func.shape[0]):
        f = func[i]
        aj, bj, ak, bk = _cut_pair(f, prob[i], i, L, K, axis, m, s, ca, sa, KA, KB, levels, fj, fk)
        out[i] = _kink_h(kind[f], fj[f], fk[f], fs[f], aj, bj, ak, bk)


@njit(cache=True, nogil=True)
def _crossings_on_arc(func, prob, L, K, axis, m, s, ca, sa, KA, KB, levels, fj, fk, out):  # pragma: no cover
    """Whether both cuts of function ``func[i]`` of problem ``prob[i]`` are on the arc (|a| <= |b|)
    at point i.
    """
    for i in range(func.shape[0]):
        aj, bj, ak, bk = _cut_pair(func[i], prob[i], i, L, K, axis, m, s, ca, sa, KA, KB, levels, fj, fk)
        out[i] = (abs(aj) <= abs(bj)) & (abs(ak) <= abs(bk))


@njit(cache=True, nogil=True)
def _same_sign(x, y):  # pragma: no cover - compiled
    """np.sign(x) == np.sign(y) (False where either is NaN)."""
    return (x > 0.0 and y > 0.0) or (x < 0.0 and y < 0.0) or (x == 0.0 and y == 0.0)


@njit(cache=True, nogil=True)
def _scan_kernel(n_prob, p0, G, L, K, axis, mu, s_p, ca, sa, levels, KA, KB, kind, fj, fk, fs,
                 b_row, b_i, b_h, c_row, c_i, c_s0, c_h):  # pragma: no cover - compiled
    """The brackets of the scan of problems p0 + p (p < P = len(mu), of n_prob): every kink function
    (row f n_prob + p0 + p) on the G nodes of ``_TAU_SCAN`` (``ca``, ``sa`` there; the model's kinks
    in columns p G + g of KA, KB); its sign changes (row, cell i, h at node i) and its touching
    candidates (row, interior node i, sign of h there, h at node i - 1), in the order of
    ``np.nonzero`` in :func:`_roots_reference` and :func:`_touching_pairs_reference` (for all
    problems at once: after a stable sort by row), as many as the arrays hold.  Returns the two
    counts (the arrays were too short where they exceed them).
    """
    P = mu.shape[0]
    A0 = np.empty((P, G))
    B0 = np.empty((P, G))
    for p in range(P):
        for g in range(G):
            A0[p, g], B0[p, g] = _horizon_ab(axis, mu[p], s_p[p], ca[g], sa[g])
    h = np.empty(G)
    sign_change = np.zeros(G, np.bool_)
    touching = np.zeros(G, np.bool_)
    nb = 0
    nc = 0
    inf = math.inf
    for f in range(kind.shape[0]):
        for p in range(P):
            _scan_row(kind[f], fj[f], fk[f], fs[f], L, K, A0[p], B0[p], levels[p], KA, KB, p * G, h)
            if kind[f] == 1 and _coincident(fj[f], fk[f], L, K, A0[p], B0[p], levels[p], KA, KB, p * G, h):
                continue  # (one curve computed twice: no crossing)
            # the conditions of the reference with & and | (no branches: these loops vectorise)
            for g in range(G - 1):
                x, y = h[g], h[g + 1]
                sign_change[g] = ((((x > 0.0) & (y < 0.0)) | ((x < 0.0) & (y > 0.0)))
                                  & (abs(x) < inf) & (abs(y) < inf))
            for g in range(1, G - 1):
                x, y, z = h[g - 1], h[g], h[g + 1]
                ay = abs(y)
                touching[g] = ((((y > 0.0) & (x > 0.0) & (z > 0.0)) | ((y < 0.0) & (x < 0.0) & (z < 0.0)))
                               & (ay < abs(x)) & (ay <= abs(z)) & (abs(x) < inf) & (ay < inf) & (abs(z) < inf))
            r = f * n_prob + p0 + p
            for g in range(G - 1):
                if sign_change[g]:
                    if nb < b_row.shape[0]:
                        b_row[nb] = r
                        b_i[nb] = g
                        b_h[nb] = h[g]
                    nb += 1
            for g in range(1, G - 1):
                if touching[g]:
                    if nc < c_row.shape[0]:
                        c_row[nc] = r
                        c_i[nc] = g
                        c_s0[nc] = 1.0 if h[g] > 0.0 else -1.0
                        c_h[nc] = h[g - 1]
                    nc += 1
    return nb, nc


@njit(cache=True, nogil=True)
def _bisect_points(lo, hi, pts):  # pragma: no cover - compiled
    """Fills ``pts`` (n, 2^d - 1) with the midpoints of the next d bisection steps of every bracket [lo, hi] for
    either outcome of each step, as a heap (node q's children: 2 q + 1 where the root is above the
    midpoint, 2 q + 2 where below).
    """
    nn = pts.shape[1]
    tlo = np.empty(nn)
    thi = np.empty(nn)
    for r in range(lo.shape[0]):
        tlo[0] = lo[r]
        thi[0] = hi[r]
        for q in range(nn):
            mid = 0.5 * (tlo[q] + thi[q])
            pts[r, q] = mid
            c = 2 * q + 1
            if c < nn:
                tlo[c] = mid
                thi[c] = thi[q]
                tlo[c + 1] = tlo[q]
                thi[c + 1] = mid


@njit(cache=True, nogil=True)
def _bisect_walk(lo, hi, h_lo, rem, pts, hv):  # pragma: no cover - compiled
    """Up to d steps of bisection of every bracket with the values ``hv`` at the points of
    :func:`_bisect_points` (as the loop of :func:`_roots_reference`); ``rem`` counts the steps left,
    and is set to 0 where a step changes nothing (lo and hi adjacent: so would every later step).
    """
    depth = 0
    while (1 << (depth + 1)) - 1 <= pts.shape[1]:
        depth += 1
    for r in range(lo.shape[0]):
        q = 0
        for _ in range(depth):
            if rem[r] == 0:
                break
            mid, h_mid = pts[r, q], hv[r, q]
            if _same_sign(h_mid, h_lo[r]):
                moved = mid != lo[r]
                lo[r] = mid
                h_lo[r] = h_mid
                q = 2 * q + 1
            else:
                moved = mid != hi[r]
                hi[r] = mid
                q = 2 * q + 2
            rem[r] -= 1
            if not moved:
                rem[r] = 0


@njit(cache=True, nogil=True)
def _golden_points(a, b, pts):  # pragma: no cover - compiled
    """Fills ``pts`` (n, 2 (2^d - 1)) with the points x1, x2 of the next d steps of the golden-section search of
    every [a, b] for either outcome of each step (a heap as in :func:`_bisect_points`; child 2 q + 1
    keeps the left part [a, x2], child 2 q + 2 the right part [x1, b]).
    """
    nn = pts.shape[1] // 2
    ta = np.empty(nn)
    tb = np.empty(nn)
    for r in range(a.shape[0]):
        ta[0] = a[r]
        tb[0] = b[r]
        for q in range(nn):
            x1 = tb[q] - _GOLDEN * (tb[q] - ta[q])
            x2 = ta[q] + _GOLDEN * (tb[q] - ta[q])
            pts[r, 2 * q] = x1
            pts[r, 2 * q + 1] = x2
            c = 2 * q + 1
            if c < nn:
                ta[c] = ta[q]
                tb[c] = x2
                ta[c + 1] = x1
                tb[c + 1] = tb[q]


@njit(cache=True, nogil=True)
def _golden_walk(a, b, s0, rem, pts, hv, found, h_found):  # pragma: no cover - compiled
    """Up to d steps of the golden-section search of every candidate with the values ``hv`` at the
    points of :func:`_golden_points` (as the loop of :func:`_touching_pairs_reference`): the first
    point where sign(h_i) h < 0 (x1 before x2) is ``found`` (h there in ``h_found``), and ``rem``, the
    steps left, is set to 0.
    """
    depth = 0
    while (1 << (depth + 1)) - 1 <= pts.shape[1] // 2:
        depth += 1
    for r in range(a.shape[0]):
        q = 0
        for _ in range(depth):
            if rem[r] == 0:
                break
            x1, x2 = pts[r, 2 * q], pts[r, 2 * q + 1]
            q1, q2 = s0[r] * hv[r, 2 * q], s0[r] * hv[r, 2 * q + 1]
            rem[r] -= 1
            if q1 < 0:
                found[r] = x1
                h_found[r] = s0[r] * q1
                rem[r] = 0
            elif q2 < 0:
                found[r] = x2
                h_found[r] = s0[r] * q2
                rem[r] = 0
            elif q1 >= q2:  # NaN (outside the map's range) keeps the left part
                a[r] = x1
                q = 2 * q + 2
            else:
                b[r] = x2
                q = 2 * q + 1


def _depth(points_per_task: float, steps_left: int) -> int:
    """The depth d of the tree of steps a task gets in one round: 2^d - 1 nodes within its share."""
    d = math.floor(math.log2(max(points_per_task, 1.0) + 1.0))
    return max(1, min(d, _MAX_DEPTH, int(steps_left)))


def _refine(h_at, b_row, b_lo, b_hi, b_h, c_row, c_lo, c_hi, c_s0, c_h):
    """(rows, tau) of the roots: the brackets (b_row, [b_lo, b_hi], h(b_lo)) refined by bisection,
    and every touching candidate (c_row, [c_lo, c_hi], sign of h at its node, h(c_lo)) searched by
    golden section and, where it finds the opposite sign at t, its two brackets [c_lo, t] and
    [t, c_hi] refined likewise; in the order of :func:`_roots_reference` (the sign changes, then
    the left roots of the pairs, then the right ones) and to the same bits: every search takes the
    same steps at the same points.  ``h_at(rows, tau)`` evaluates the kink functions.

    All searches advance together, one call of ``h_at`` per round; a bracket whose step changes
    nothing (adjacent floats) is done, a candidate is done when found, and its two brackets start
    at the next round.
    """
    nb0, nc = len(b_row), len(c_row)
    rows, lo, hi, h_lo = b_row.copy(), b_lo.copy(), b_hi.copy(), b_h.copy()
    rem = np.full(nb0, _BISECT_STEPS, np.int64)
    key = np.arange(nb0)
    g_idx = np.arange(nc)
    ga, gb = c_lo.copy(), c_hi.copy()
    g_rem = np.full(nc, _GOLDEN_STEPS, np.int64)
    done_key, done_row, done_t = [], [], []
    while len(rows) or len(g_idx):
        nb, ng = len(rows), len(g_idx)
        share = _ROUND_POINTS / ((nb > 0) + (ng > 0))
        db = _depth(share / max(nb, 1), rem.max() if nb else 1)
        dg = _depth(share / max(2 * ng, 1), g_rem.max() if ng else 1)
        pb = np.empty((nb, (1 << db) - 1))
        _bisect_points(lo, hi, pb)
        pg = np.empty((ng, 2 * ((1 << dg) - 1)))
        _golden_points(ga, gb, pg)
        hv = h_at(np.concatenate([np.repeat(rows, pb.shape[1]), np.repeat(c_row[g_idx], pg.shape[1])]),
                  np.concatenate([pb.ravel(), pg.ravel()]))
        _bisect_walk(lo, hi, h_lo, rem, pb, hv[:pb.size].reshape(pb.shape))
        found = np.full(ng, np.nan)
        h_found = np.zeros(ng)
        _golden_walk(ga, gb, c_s0[g_idx], g_rem, pg, hv[pb.size:].reshape(pg.shape), found, h_found)
        fin = rem == 0
        if fin.any():
            done_key.append(key[fin])
            done_row.append(rows[fin])
            done_t.append(0.5 * (lo[fin] + hi[fin]))
            live = ~fin
            rows, lo, hi, h_lo, rem, key = rows[live], lo[live], hi[live], h_lo[live], rem[live], key[live]
        hit = ~np.isnan(found)
        if hit.any():  # each found pair: [tau_{i-1}, t] and [t, tau_{i+1}]
            gi = g_idx[hit]
            rows = np.concatenate([rows, c_row[gi], c_row[gi]])
            lo = np.concatenate([lo, c_lo[gi], found[hit]])
            hi = np.concatenate([hi, found[hit], c_hi[gi]])
            h_lo = np.concatenate([h_lo, c_h[gi], h_found[hit]])
            rem = np.concatenate([rem, np.full(2 * len(gi), _BISECT_STEPS, np.int64)])
            key = np.concatenate([key, nb0 + gi, nb0 + nc + gi])
        live = g_rem > 0
        if not live.all():
            g_idx, ga, gb, g_rem = g_idx[live], ga[live], gb[live], g_rem[live]
    if not done_key:
        return np.zeros(0, np.int64), np.zeros(0)
    order = np.argsort(np.concatenate(done_key))
    return np.concatenate(done_row)[order], np.concatenate(done_t)[order]


def kink_breaks(lobe: Lobe, mu: np.ndarray, levels: np.ndarray, crossings: bool = True) -> list[np.ndarray]:
    """Values of tau_x where a kink of the integrand enters or leaves the arc of beta, for
    every problem (mu (P,), levels (P, L)); a list of P arrays.

    A kink a + b cos(beta) = 0 (a level N.wo = u, or a model's own kink) lies on the arc
    only while |a| <= |b|; where a = +-b it appears or vanishes with a square-root
    behaviour in x (and at normal incidence, where b = 0, it becomes a circle: a jump in
    the derivative along x).  Roots of a -+ b are found on a graded scan and refined by
    bisection to full precision, all problems at once.

    Two roots in one cell of the scan leave no sign change on it: a level u near 1 is on the arc
    only where the arc's highest point a + |b| = cos(alpha - theta) exceeds u, a window of width
    2 arccos(u) around the axis (6e-4 rad for u = 1 - 1.9e-7, the cap of ``scaled`` Phong n = 5's
    table at mu = 0.823, inside one 2.5e-3 cell).  Unseen, the piece above the level had width 0 at
    every node of every first rectangle: K = G = 0, never refined, and the cap (5.1e-7 of the
    albedo) was missing with an estimate of 1e-13.  So every interior local minimum of |a -+ b| on
    the scan is followed by a golden-section search of its two cells for a change of sign
    (:func:`_touching_pairs_reference`), and both roots are refined like the others.

    The scan (:func:`_scan_kernel`: the radial map once at its G nodes, the cuts' coefficients once
    per problem and node) and the steps of the searches (:func:`_refine`: all searches advance
    together, several steps per call where few are left) are compiled; the coefficients at the
    points a search asks for stay numpy where they are not exact arithmetic (the model's
    ``Lobe.kinks``, and ``radial_map`` where it takes logs or exponentials: :func:`_prepare_points`), so
    the breaks are those of :func:`kink_breaks_reference`, the plain numpy twin, bit for bit and in
    the same order (``tests/engine/test_cubature.py``).
    """
    P = len(mu)
    if not levels.shape[1] and lobe.kinks is None:
        return [np.array([]) for _ in range(P)]
    L = levels.shape[1]
    K = len(lobe.kinks(*(np.full(1, 0.5) for _ in range(4)))) if lobe.kinks is not None else 0
    n_cuts = L + K
    # the kink functions, one row each per problem (rows f P + p), as in kink_breaks_reference
    funcs = [(0, j, j, sign) for j in range(n_cuts) for sign in (1.0, -1.0)]
    if crossings:
        funcs += [(1, j, k, 0.0) for j in range(L, n_cuts) for k in list(range(j)) + [n_cuts]]
    kind, fj, fk = (np.array([c[i] for c in funcs], np.int64) for i in range(3))
    fs = np.array([c[3] for c in funcs], np.float64)
    mu = np.ascontiguousarray(mu, dtype=np.float64)
    levels = np.ascontiguousarray(levels, dtype=np.float64)
    axis, radial, k = AXIS_CODE[lobe.axis], RADIAL_CODE[lobe.radial], float(lobe.sharpness)
    with np.errstate(all="ignore"):
        s_p = np.sqrt((1.0 - mu) * (1.0 + mu))

    def kink_coefficients(m, s, ca, sa, KA, KB):
        """The model's kinks at the points (numpy: ``Lobe.kinks`` is the model's) into KA, KB (K, n)."""
        if K:
            with np.errstate(all="ignore"):
                for q, (a, b) in enumerate(lobe.kinks(m, s, ca, sa)):
                    KA[q] = a
                    KB[q] = b

    # the scan: the radial map once at the G nodes, the model's kinks at every problem and node, in
    # chunks of problems (numpy's temporaries of _CHUNK points stay in malloc's heap, and are reused)
    G = len(_TAU_SCAN)
    with np.errstate(all="ignore"):
        x, xc, _ = smooth(_TAU_SCAN)
        ca_g, sa_g, _ = radial_map(lobe.radial, lobe.sharpness, x, xc)
    step = max(1, _CHUNK // G)
    scanned = []
    for p0 in range(0, P, step):
        sl = slice(p0, min(P, p0 + step))
        n = sl.stop - sl.start
        KA, KB = np.empty((K, n * G)), np.empty((K, n * G))
        kink_coefficients(np.repeat(mu[sl], G), np.repeat(s_p[sl], G), np.tile(ca_g, n), np.tile(sa_g, n), KA, KB)
        nb = nc = _SCAN_ROOM * len(kind) * n  # else a second pass with the counts of the first
        while True:
            b_row, b_i, c_row, c_i = (np.empty(size, np.int64) for size in (nb, nb, nc, nc))
            b_h, c_s0, c_h = np.empty(nb), np.empty(nc), np.empty(nc)
            nb_, nc_ = _scan_kernel(P, p0, G, L, K, axis, mu[sl], s_p[sl], ca_g, sa_g, levels[sl], KA, KB, kind, fj,
                                    fk, fs, b_row, b_i, b_h, c_row, c_i, c_s0, c_h)
            if nb_ <= nb and nc_ <= nc:
                break
            nb, nc = max(nb, nb_), max(nc, nc_)
        scanned.append((b_row[:nb_], b_i[:nb_], b_h[:nb_], c_row[:nc_], c_i[:nc_], c_s0[:nc_], c_h[:nc_]))
    b_row, b_i, b_h, c_row, c_i, c_s0, c_h = (np.concatenate(a) for a in zip(*scanned))
    ob, oc = np.argsort(b_row, kind="stable"), np.argsort(c_row, kind="stable")  # row by row, as np.nonzero
    b_row, b_i, b_h, c_row, c_i, c_s0, c_h = b_row[ob], b_i[ob], b_h[ob], c_row[oc], c_i[oc], c_s0[oc], c_h[oc]

    # the searches: the coefficients at the points they ask for, _CHUNK points at a time, in buffers
    # reused round after round
    n_buf = _CHUNK
    buf_v = np.empty((6, n_buf))  # mu, s, x, 1 - x, cos(alpha), sin(alpha)
    buf_rest = np.empty(n_buf, np.bool_)
    buf_k = np.empty((2, K, n_buf))  # the model's kinks

    def at_points(prob, tau):
        """(m, s, ca, sa, KA, KB) at the points (problem prob, tau); at most _CHUNK of them."""
        n = len(prob)
        m, s, x, xc, ca, sa = buf_v[:, :n]
        rest = buf_rest[:n]
        KA, KB = buf_k[:, :, :n]
        if _prepare_points(prob, tau, mu, s_p, radial, k, m, s, x, xc, ca, sa, rest):
            idx = np.flatnonzero(rest)
            with np.errstate(all="ignore"):
                ca[idx], sa[idx], _ = radial_map(lobe.radial, lobe.sharpness, x[idx], xc[idx])
        kink_coefficients(m, s, ca, sa, KA, KB)
        return m, s, ca, sa, KA, KB

    def h_at(rows, tau):
        out = np.empty(len(rows))
        func, prob = np.divmod(rows, P)
        for i in range(0, len(rows), n_buf):
            sl = slice(i, i + n_buf)
            _kink_h_points(func[sl], prob[sl], L, K, axis, *at_points(prob[sl], tau[sl]), levels, kind, fj, fk, fs,
                           out[sl])
        return out

    r_idx, t = _refine(h_at, b_row, _TAU_SCAN[b_i], _TAU_SCAN[b_i + 1], b_h,
                       c_row, _TAU_SCAN[c_i - 1], _TAU_SCAN[c_i + 1], c_s0, c_h)
    # a root within 1e-10 of an end is the end itself (kink_breaks_reference)
    keep = (_END_GAP < t) & (t < 1.0 - _END_GAP)
    cross = kind[r_idx // P] == 1
    if cross.any():  # a crossing counts where both cuts are on the arc
        on = np.empty(int(cross.sum()), np.bool_)
        func, prob = np.divmod(r_idx[cross], P)
        tc = t[cross]
        for i in range(0, len(on), n_buf):
            sl = slice(i, i + n_buf)
            _crossings_on_arc(func[sl], prob[sl], L, K, axis, *at_points(prob[sl], tc[sl]), levels, fj, fk, on[sl])
        keep[cross] &= on
    p_keep, t_keep = r_idx[keep] % P, t[keep]
    order = np.argsort(p_keep, kind="stable")
    return np.split(t_keep[order], np.cumsum(np.bincount(p_keep, minlength=P))[:-1])


def graded(points: np.ndarray) -> np.ndarray:
    """Breakpoints with a grid graded geometrically towards each (see horizon_breaks)."""
    out = list(points)
    for t in points:
        d = min(t, 1.0 - t)
        for k in range(1, 30):
            step = d * 4.0**k
            if step > 0.25:
                break
            out.extend(v for v in (t - step, t + step) if 0 < v < 1)
    return np.array(out)
