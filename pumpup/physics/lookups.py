"""The bounded look-ups that pumped and compensated BRDFs read, compiled, each beside its plain numpy twin.

An albedo table (``pumpup.tables.AlbedoTable``) is flattened into arrays: its spline pieces in log(mu) with the margin
that makes them an upper bound of the albedo (:func:`upper_scalar`, :func:`upper_array`; below the first node a power
law), and, for a chain of pumped levels or a 1/E scaling, one product table of polynomial pieces in m = max(N.wi, N.wo)
found from the bits of m (:func:`g_product`, :func:`scale_bound`), or, where a level's bound is not monotone, one
level table of every level's bound as polynomial pieces in m on shared pieces, one piece per direction
(:func:`g_pair`), and the split table that gives the product of all levels as F(min) H(max), one look-up per
direction, wherever every level's term is fixed (:func:`g_split`).  The pumped BRDF divides by g (001 eq. 16, 20,
21), the engine integrates it node by node, and the Mitsuba plugin evaluates it: all three read these functions.
"""

from __future__ import annotations

import math
from collections import namedtuple

import numpy as np
from numba import njit, types
from numba.extending import intrinsic


@njit(cache=True, nogil=True)
def upper_scalar(mu, logx, coef, v0, slope0, margin_lo, margin, cap):  # pragma: no cover - compiled
    """Upper bound of a(mu): the table's spline piece in log(mu) (power law below the first node) + margin,
    at most ``cap``.
    """
    return upper_log(math.log(mu), logx, coef, v0, slope0, margin_lo, margin, cap)


@njit(cache=True, nogil=True)
def upper_log(lm, logx, coef, v0, slope0, margin_lo, margin, cap):  # pragma: no cover - compiled
    """:func:`upper_scalar` of mu = exp(lm) (binary search for the piece)."""
    n = logx.shape[0]
    # below the first node only, as AlbedoTable.upper: at mu = mu0 itself the power law's margin (|a1 - a0| + ...,
    # 24 for Ward m = 0.885's 651 at mu0 = 1e-8) made the bound jump up there, a pumped level's albedo at exactly mu0
    # 3.6 % below its limit from above, and the level above's table bisected towards its first node (504 nodes within
    # 1e-9 of it, 2e-23 apart)
    if lm < logx[0]:
        return min(cap, v0 * math.exp(slope0 * (lm - logx[0])) + margin_lo)
    lo, hi = 0, n - 1
    while hi - lo > 1:  # binary search for the interval
        mid = (lo + hi) // 2
        if logx[mid] <= lm:
            lo = mid
        else:
            hi = mid
    d = lm - logx[lo]
    val = coef[0, lo]
    for r in range(1, coef.shape[0]):  # Horner: the spline piece in d = log(mu) - logx[lo]
        val = val * d + coef[r, lo]
    return min(cap, val + margin)


@njit(cache=True, nogil=True)
def upper_array(mu, logx, coef, v0, slope0, margin_lo, margin, cap, out):  # pragma: no cover - compiled
    """Compiled :func:`upper_scalar` at every value of ``mu``, written into ``out``."""
    for k in range(mu.shape[0]):
        out[k] = upper_scalar(mu[k], logx, coef, v0, slope0, margin_lo, margin, cap)


@njit(cache=True, nogil=True)
def upper_root(lo, hi, kind, target, logx, coef, v0, slope0, margin_lo, margin, cap):  # pragma: no cover - compiled
    """The u in [lo, hi] where the bound U(u) (:func:`upper_scalar`) meets ``target`` (``kind`` 0 or 2) or u itself (1),
    given a change of sign of the difference at the ends: bisection until the bracket is at most 1e-15 + 4 eps u wide
    (where scipy's brentq at xtol 1e-15 stops too); its midpoint.  Compiled: called from Python in
    :meth:`Pumped._kink_levels`, brentq takes ~60 us per call in cProfile, and the per-mu kink search two thirds of a
    first 2-level pumped GGX table.
    """
    flo = upper_scalar(lo, logx, coef, v0, slope0, margin_lo, margin, cap) - (lo if kind == 1 else target)
    while hi - lo > 1e-15 + 8.9e-16 * hi:
        mid = 0.5 * (lo + hi)
        fm = upper_scalar(mid, logx, coef, v0, slope0, margin_lo, margin, cap) - (mid if kind == 1 else target)
        if fm == 0.0:
            return mid
        if (fm < 0.0) == (flo < 0.0):
            lo, flo = mid, fm
        else:
            hi = mid
    return 0.5 * (lo + hi)


@njit(cache=True, nogil=True)
def kink_roots(g, ug, kind, target, mu, scale, logx, coef, v0, slope0, margin_lo, margin,  # pragma: no cover - compiled
               cap):
    """The roots v of U(v) = ``target`` (``kind`` 0 or 2) or U(v) = v (1) that the grid ``g`` (U's values ``ug``)
    brackets (:meth:`Pumped._kink_levels`, its search for one k in one compiled pass): differences below 1e-13 ``scale``
    count as 0 (the rounding of a flat spline: no root), every cell where they change sign gives its root
    (:func:`upper_root`); for kind 0 the points mu (1 -+ 1e-6) join the grid and the cell between them, which holds the
    root v = mu itself, is skipped.
    """
    n = g.shape[0]
    extra = np.empty(2)
    ne = 0
    if kind == 0:
        for e in (mu * (1.0 - 1e-6), mu * (1.0 + 1e-6)):
            if e <= 1.0:
                extra[ne] = e
                ne += 1
    m = n + ne
    x = np.empty(m)
    vals = np.empty(m)
    i = j = 0
    for q in range(m):  # the grid and the extra points, merged (an extra point before a grid node it equals)
        if j < ne and (i >= n or extra[j] <= g[i]):
            x[q] = extra[j]
            u = upper_scalar(extra[j], logx, coef, v0, slope0, margin_lo, margin, cap)
            j += 1
        else:
            x[q] = g[i]
            u = ug[i]
            i += 1
        d = u - (x[q] if kind == 1 else target)
        vals[q] = 0.0 if abs(d) < 1e-13 * scale else d
    out = np.empty(m)
    k = 0
    for q in range(m - 1):
        if not ((vals[q] < 0.0 and vals[q + 1] > 0.0) or (vals[q] > 0.0 and vals[q + 1] < 0.0)):
            continue
        if kind == 0 and x[q] <= mu <= x[q + 1] and x[q + 1] - x[q] <= 2.01e-6 * mu:
            continue  # (the root v = mu itself, already a level)
        out[k] = upper_root(x[q], x[q + 1], kind, target, logx, coef, v0, slope0, margin_lo, margin, cap)
        k += 1
    return out[:k]


#: cells of the uniform index over log(mu) that the chain kernel uses to find a table interval
INDEX_CELLS = 4096


#: the product table of a monotone chain (:class:`_Product`): polynomials of degree
#: PRODUCT_DEGREE in m, their pieces found through 2^CELL_BITS cells per octave numbered by the
#: float's bits (measured on 3-level Phong: 4 bits 28 ns per pair, 6 bits 25, 8 bits 21; degree 4
#: needs twice the pieces of degree 5 and was slower)
CELL_BITS = 8


CELL_SHIFT = 52 - CELL_BITS


PRODUCT_DEGREE = 5


@intrinsic
def float_bits(typingctx, x):  # pragma: no cover - compiled
    """The IEEE-754 bits of a float64 as an int64 (a free bit cast; for x > 0 the bits increase
    with x, and ``bits >> CELL_SHIFT`` numbers the cells of :class:`_Product`).
    """
    if not isinstance(x, types.Float):
        return None

    def codegen(context, builder, signature, args):
        return builder.bitcast(args[0], context.get_value_type(types.int64))

    return types.int64(types.float64), codegen


def float_bits_reference(x) -> np.ndarray:
    """The numpy reference of :func:`float_bits`."""
    return np.asarray(x, dtype=np.float64).view(np.int64)


#: the high half of a cell entry (:func:`cell_entries`): the bits of m at and above which the cell's second piece starts
CELL_HIGH = -(1 << 32)


#: the low half of a cell entry: the cell's first piece
CELL_LOW = (1 << 32) - 1


def cell_entries(lo: np.ndarray, cstart: np.ndarray) -> np.ndarray:
    """The cells of a table of pieces as the kernels read them, one int64 per cell: in the low 32 bits the piece where
    the cell starts (``cstart[c]``), in the high 32 bits the top 32 bits of the next piece's start ``lo[cstart[c] + 1]``
    rounded up (``lo`` ends with its sentinel, inf).  One load then gives both the piece and where the next begins:
    m is in a later piece when bits(m) >= (entry & CELL_HIGH) (never wrongly: the bound is rounded up; m in the
    2^-20 relative sliver below it, or in a third piece of the cell, is found by the forward search that follows,
    :func:`cell_piece`).
    """
    nxt = float_bits_reference(np.asarray(lo, dtype=np.float64)[np.asarray(cstart, dtype=np.int64) + 1])
    top = (nxt >> 32) + ((nxt & CELL_LOW) != 0)  # rounded up
    return np.ascontiguousarray((top << 32) | np.asarray(cstart, dtype=np.int64))


def cell_piece_reference(m, shift: int, cbase: int, cell: np.ndarray, lo: np.ndarray) -> np.ndarray:
    """The numpy reference of :func:`cell_piece`: the piece of each m (> the table's ``mlo``), found as the kernel
    finds it.
    """
    m = np.asarray(m, dtype=np.float64)
    mb = float_bits_reference(m)
    e = cell[np.minimum((mb >> shift) - cbase, len(cell) - 1)]
    s = (e & CELL_LOW) + (mb >= (e & CELL_HIGH))
    while True:
        step = m >= lo[s + 1]
        if not np.any(step):
            return s
        s = s + step


@njit(cache=True, nogil=True, inline="always")
def cell_piece(m, shift, cbase, cell, plo):  # pragma: no cover - compiled
    """The piece of a table in m (> its ``mlo``) that holds m: the cell from the bits of m (2^(52 - ``shift``) cells
    per octave), whose entry (:func:`cell_entries`) gives the cell's first piece and, in the same load, whether m lies
    in the next (a branch-free step); then a forward search that is rarely entered (a third piece in the cell).  One
    load before the piece's coefficients (a cell index and then the pieces' starts would take two dependent loads).
    Inlined where it is called; its numpy reference is :func:`cell_piece_reference`.
    """
    mb = float_bits(m)
    e = cell[min((mb >> shift) - cbase, cell.shape[0] - 1)]
    s = (e & CELL_LOW) + (mb >= (e & CELL_HIGH))
    while m >= plo[s + 1]:
        s += 1
    return s


@njit(cache=True, nogil=True, inline="always")
def g_product(mmax, pcbase, pcell, plo, prow):  # pragma: no cover - compiled
    """The chain kernel's fast path: g_1 g_2 ... g_k as one function of mmax = max(N.wi, N.wo)
    (:class:`_Product`; mmax above its ``mlo``): the piece found from the bits of mmax (no logarithm;
    :func:`cell_piece`, ``pcell`` the cells' entries), evaluated by Horner's rule; ``prow[s]`` holds the piece's
    coefficients, centre and inverse half-width (one cache line).  Inlined where it is called.
    """
    deg = prow.shape[1] - 3
    s = cell_piece(mmax, CELL_SHIFT, pcbase, pcell, plo)
    t = (mmax - prow[s, deg + 1]) * prow[s, deg + 2]
    if deg == 5:  # written out (Horner, the order of horner)
        return (((((prow[s, 0] * t + prow[s, 1]) * t + prow[s, 2]) * t + prow[s, 3]) * t
                 + prow[s, 4]) * t + prow[s, 5])
    g_all = prow[s, 0] * t
    for r in range(1, deg):
        g_all = (g_all + prow[s, r]) * t
    return g_all + prow[s, deg]


@njit(cache=True, nogil=True, inline="always")
def g_levels(mmax, mmin, offsets, logx, coef, v0, slope0, margin_lo, cap, controlled, increasing, mu0,
              index, index_lo, index_h_inv):  # pragma: no cover - compiled
    """The product of all levels' g (001 eq. 20, 21) at N.wi, N.wo with max ``mmax`` and min ``mmin``
    (both > 0), level by level: each level's upper bound looked up (spline piece in log(mu), power
    law below its first node, at most its cap).  Inlined where it is called (a call per look-up
    cost 20 x the look-up, measured).
    """
    ncell = index.shape[1]
    lmax = math.log(mmax)
    lmin = 1.0  # log(mmin), taken only when needed (it is <= 0)
    g_all = 1.0
    for j in range(offsets.shape[0] - 1):
        a, b = offsets[j], offsets[j + 1]
        nlook = 1 if (increasing[j] and mmin > mu0[j]) else 2
        g = 0.0
        for t in range(nlook):
            if t == 0:
                lm = lmax
            else:
                if lmin > 0.0:
                    lmin = math.log(mmin)
                lm = lmin
            if lm < logx[a]:  # (as upper_log)
                u = v0[j] * math.exp(slope0[j] * (lm - logx[a])) + margin_lo[j]
            else:
                c = int((lm - index_lo[j]) * index_h_inv[j])
                i = index[j, min(max(c, 0), ncell - 1)]
                while i < b - 2 and logx[i + 1] <= lm:
                    i += 1
                d = lm - logx[i]
                if coef.shape[0] == 6:  # the quintic, written out (Horner)
                    u = ((((coef[0, i] * d + coef[1, i]) * d + coef[2, i]) * d + coef[3, i]) * d
                         + coef[4, i]) * d + coef[5, i]
                else:
                    u = coef[0, i]
                    for r in range(1, coef.shape[0]):  # Horner
                        u = u * d + coef[r, i]
            g = max(g, min(cap[j], u))  # 001 eq. 20
        if controlled[j]:
            g = max(g, mmax)  # 001 eq. 21
        g_all *= g
    return g_all


@njit(cache=True, nogil=True, inline="always")
def g_pair(mi, mo, controlled, shift, pcbase, pcell, plo, prow):  # pragma: no cover - compiled
    """g_1 g_2 ... g_k at N.wi = ``mi``, N.wo = ``mo`` (both above the table's ``mlo``) from the level table in m: every
    level's bound U_j as a polynomial piece in m, all levels on one set of pieces, so one piece per direction serves
    every level (:class:`pumpup.operators.pumping._LevelTable`; no logarithm; its cells are ``shift``'s, finer than
    :func:`g_product`'s where the pieces crowd).  Row ``prow[s]``: the piece's centre,
    inverse half-width, then each level's PRODUCT_DEGREE + 1 coefficients, highest power first.
    g_j = max(U_j(mi), U_j(mo)) (001 eq. 20), and max(., mi, mo) where ``controlled[j]`` (001 eq. 21).  Inlined where
    it is called.  Its numpy reference is :meth:`pumpup.operators.pumping._LevelTable.g`.
    """
    si = cell_piece(mi, shift, pcbase, pcell, plo)
    so = cell_piece(mo, shift, pcbase, pcell, plo)
    ti = (mi - prow[si, 0]) * prow[si, 1]
    to = (mo - prow[so, 0]) * prow[so, 1]
    mmax = max(mi, mo)
    nlev = controlled.shape[0]
    width = PRODUCT_DEGREE + 1  # (a constant of the compiled code)
    g_all = 1.0
    for j in range(nlev):
        a = 2 + j * width
        if width == 6:  # the quintic, written out (Horner, the order of horner)
            ui = ((((prow[si, a] * ti + prow[si, a + 1]) * ti + prow[si, a + 2]) * ti + prow[si, a + 3]) * ti
                  + prow[si, a + 4]) * ti + prow[si, a + 5]
            uo = ((((prow[so, a] * to + prow[so, a + 1]) * to + prow[so, a + 2]) * to + prow[so, a + 3]) * to
                  + prow[so, a + 4]) * to + prow[so, a + 5]
        else:
            ui = prow[si, a] * ti
            uo = prow[so, a] * to
            for r in range(1, width - 1):
                ui = (ui + prow[si, a + r]) * ti
                uo = (uo + prow[so, a + r]) * to
            ui += prow[si, a + width - 1]
            uo += prow[so, a + width - 1]
        g = max(ui, uo)  # 001 eq. 20
        if controlled[j]:
            g = max(g, mmax)  # 001 eq. 21
        g_all *= g
    return g_all


@njit(cache=True, nogil=True, inline="always")
def g_split(mmin, mmax, ncell, pattern, fid, hid, shift, pcbase, pcell, plo, pcoef):  # pragma: no cover - compiled
    """g_1 g_2 ... g_k at min(N.wi, N.wo) = ``mmin`` and max = ``mmax`` (both above the table's ``mlo``) as ONE product
    F(mmin) H(mmax) of two tabulated functions, whatever the number of levels, or 0.0 where the cell of (mmin, mmax)
    has no pattern (the caller then takes :func:`g_pair`): the cell i = floor(mmin ``ncell``), k = floor(mmax
    ``ncell``) gives the pattern p = ``pattern[k (k + 1) / 2 + i]`` (the cells with i <= k, packed; int8, -1 none),
    whose functions are rows ``fid[p]`` and ``hid[p]`` of ``pcoef`` (int8 patterns: a packing of both rows in an int16
    cost 1.5 ns more per pair, measured) (:class:`pumpup.operators.pumping._SplitTable`; 001 eq. 20, 21
    with every level's term fixed in the cell); each function's piece found by :func:`cell_piece` (``pcell`` the
    cells' entries); F's look-up is skipped where it is row 0, the empty product (exactly 1: a table whose patterns
    rarely have an empty F points them to a copy of row 0 instead, so this branch stays predictable,
    :attr:`pumpup.operators.pumping._SplitTable.skips`).  ``pcoef[f, s]``: piece s's PRODUCT_DEGREE + 1 coefficients,
    highest power first, its centre and inverse half-width.  Inlined where it is called.  Its numpy reference is
    :meth:`pumpup.operators.pumping._SplitTable.g`.
    """
    i = min(int(mmin * ncell), ncell - 1)
    k = min(int(mmax * ncell), ncell - 1)
    p = pattern[((k * (k + 1)) >> 1) + i]  # (the cells with i <= k, packed)
    if p < 0:
        return 0.0
    a, b = fid[p], hid[p]
    so = cell_piece(mmax, shift, pcbase, pcell, plo)
    to = (mmax - pcoef[b, so, 6]) * pcoef[b, so, 7]
    # the quintics, written out (Horner, the order of horner; PRODUCT_DEGREE = 5)
    go = ((((pcoef[b, so, 0] * to + pcoef[b, so, 1]) * to + pcoef[b, so, 2]) * to + pcoef[b, so, 3]) * to
          + pcoef[b, so, 4]) * to + pcoef[b, so, 5]
    if a == 0:  # F is row 0, the empty product: exactly 1 (1 * go = go), its look-up skipped
        return go
    si = cell_piece(mmin, shift, pcbase, pcell, plo)
    ti = (mmin - pcoef[a, si, 6]) * pcoef[a, si, 7]
    gi = ((((pcoef[a, si, 0] * ti + pcoef[a, si, 1]) * ti + pcoef[a, si, 2]) * ti + pcoef[a, si, 3]) * ti
          + pcoef[a, si, 4]) * ti + pcoef[a, si, 5]
    return gi * go


@njit(cache=True, nogil=True)
def g_levels_call(mmax, mmin, offsets, logx, coef, v0, slope0, margin_lo, cap, controlled, increasing, mu0, index,
                  index_lo, index_h_inv):  # pragma: no cover - compiled
    """:func:`g_levels`, called (not inlined) where it is the rare path of a loop (the pumped chain kernel, the models'
    fused kernels ``BRDF.eval_divided``), whose fast paths then stay small: inlined there, it made the level table's
    path 2 x slower (21 against 10 ns per pair, measured).  Those kernels choose the path as
    ``pumpup.operators.pumping._chain_kernel`` does, written out in each: a helper inlined with the chain's 15 arrays
    as arguments cost 94 ns per pair, not 8 (numba's reference counting of each array argument, per pair).
    """
    return g_levels(mmax, mmin, offsets, logx, coef, v0, slope0, margin_lo, cap, controlled, increasing, mu0, index,
                    index_lo, index_h_inv)


def horner(coef, t):
    """sum_r coef[r] t^(d - r) by Horner's rule, in the order the compiled kernel uses."""
    v = coef[0] * t
    for r in range(1, coef.shape[0] - 1):
        v = (v + coef[r]) * t
    return v + coef[-1]


@njit(cache=True, nogil=True)
def scale_bound(m, pmlo, pcbase, pcell, plo, prow, logx, coef, v0, slope0, margin_lo, margin,  # pragma: no cover
                cap):
    """U(m) >= E(m): above ``pmlo`` the polynomial piece of the product table (pump._Product, scaled up by its
    1 + epsilon) by :func:`g_product`; below it the table's spline look-up (:func:`upper_scalar`).  The compensation
    kernels write this branch out with :func:`g_product` inlined and the spline called, its rare path (with this
    function inlined whole, Kulla-Conty cost 2.1 x GGX against 1.16 x, ``python scripts/bench/bench_eval.py
    --issue55``).
    """
    if m > pmlo:
        return g_product(m, pcbase, pcell, plo, prow)
    return upper_scalar(m, logx, coef, v0, slope0, margin_lo, margin, cap)


#: a pumped chain's look-ups, as the compiled kernels read them (:meth:`pumpup.operators.pumping.Pumped._chain_args`):
#: every level's upper bound (:func:`g_levels`' arguments), the product table of all levels (:func:`g_product`'s,
#: with the N.wo above which it applies, ``product_mlo``; inf when there is none; the albedo engine divides by it, and
#: the eval kernels multiply by its inverse, ``product_inverse_rows``, rows of the same layout) and, where there is no
#: product table (a level's bound falls somewhere), the level table (:func:`g_pair`'s, with the smaller cosine above
#: which it applies, ``pair_mlo``; inf when there is none) and, above the same ``pair_mlo``, the split table that serves
#: most pairs with one product of two look-ups (:func:`g_split`'s; ``split_cells`` 0 when there is none)
GChain = namedtuple("GChain", [
    "offsets", "logx", "coef", "v0", "slope0", "margin_lo", "cap", "controlled", "increasing", "mu0", "index",
    "index_lo", "index_h_inv", "product_mlo", "product_cbase", "product_cell", "product_lo", "product_rows",
    "product_inverse_rows", "pair_mlo", "pair_shift", "pair_cbase", "pair_cell", "pair_lo", "pair_rows",
    "split_cells", "split_pattern", "split_fid", "split_hid", "split_shift", "split_cbase", "split_cell", "split_lo",
    "split_coef",
])

