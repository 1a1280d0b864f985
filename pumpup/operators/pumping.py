"""The albedo pumping-up operator (001 sec. 3).

    f*(wi, wo) = f(wi, wo) / g(wi, wo)                                   (001 eq. 16)
    g1 = max(a(wi), a(wo))                                               (001 eq. 20)
    g2 = max(a(wi), a(wo), N.wi, N.wo)          (controlled pumping-up,   001 eq. 21)

with a the directional albedo of f.  If f is symmetric, f* is symmetric, and since
max(a(L), a(V)) <= g <= 1 (001 eq. 17), its albedo satisfies a(L) <= a*(L) <= 1
(001 eq. 18-19).  The proof needs g >= the *true* albedo: pumpup divides by an upper bound
of the tabulated albedo (interpolant + measured interpolation error + quadrature error),
never by a value that could dip below it.  A pumped BRDF is an ordinary BRDF: it
evaluates, tabulates, pumps again and round-trips through its spec.

This module is over 1,000 lines because ``Pumped``, its compiled chain kernel, the chain's look-up layout
(:class:`pumpup.physics.lookups.GChain`) and the pumped-table file format describe one object.
"""

from __future__ import annotations

import functools
import json
import math
import os
import threading

import numpy as np
from numba import njit

from ..core import BRDF, Lobe, Param, SpecError, check_reciprocity, load, register, registry
from ..core.budget import check_max_seconds, time_budget
from ..physics.lookups import (
    CELL_SHIFT,
    INDEX_CELLS,
    PRODUCT_DEGREE,
    GChain,
    cell_entries,
    cell_piece_reference,
    float_bits_reference,
    g_levels,
    g_levels_call,
    g_pair,
    g_product,
    g_split,
    horner,
    kink_roots,
    upper_array,
)

__all__ = ["pump", "Pumped", "save_pumped", "load_pumped", "base_table", "pump_model", "FILE_KINDS"]

#: the ``pumpup_kind`` of a saved pumped model that another module reads -> its reader ``(path, root) -> model``
#: (:func:`load_pumped`; :mod:`pumpup.spectral` adds its own)
FILE_KINDS: dict = {}

#: accuracy of the albedo tables that pumped BRDFs divide by: g is an upper bound that exceeds
#: the albedo by about 2 x TABLE_INTERP_TOL, so the pumped albedo is lower than the ideal by
#: that much (relative); tighter tolerances cost 3 x more time per table, looser ones save 2-4 x
#: (docs/user-guide/pumping.md); keep TABLE_RTOL <= TABLE_INTERP_TOL / 100, or quadrature noise makes the grid refine
#: (1e-8 with 1e-7: 6 x slower, measured)
TABLE_RTOL = 1e-9
TABLE_INTERP_TOL = 1e-7
#: the most nested pumping levels accepted (each level's table costs about a second; the spec
#: nests one dict per level)
MAX_LEVELS = 64

_TABLES: dict[str, object] = {}  # JSON spec of a base -> AlbedoTable (computed once per session)


def _key(brdf: BRDF) -> str:
    """Cache key of a base: its spec (and, for a user function, which function object)."""
    key = json.dumps(brdf.spec, sort_keys=True)
    fn = getattr(brdf, "fn", None)
    return key if fn is None else f"{key}#{id(fn)}"


#: tables read from a file while that file's BRDF is being built (``file_tables``): (kind, key) -> AlbedoTable
_FILE = threading.local()


class file_tables:
    """Within this context (one thread), :func:`base_table` and the compensation tables come from
    ``tables`` ({(kind, key): AlbedoTable}, kind "pump" or "compensate") and never enter the session's
    shared caches: a file's tables serve only the objects built from that file (issue 13 item 5).
    """

    def __init__(self, tables: dict):
        self.tables = tables

    def __enter__(self):
        self.saved = getattr(_FILE, "tables", None)
        _FILE.tables = self.tables
        return self

    def __exit__(self, *exc):
        _FILE.tables = self.saved
        return False


def from_file(kind: str, key: str):
    """The table a file being loaded provides for (kind, key), or None."""
    tables = getattr(_FILE, "tables", None)
    return None if tables is None else tables.get((kind, key))


def base_table(base: BRDF, progress: bool | None = None):
    """The albedo table of ``base`` used by the pumping operator (cached per session), built with every route whatever
    :func:`pumpup.engine.routes.using` block encloses the call (:func:`pumpup.engine.routes.default_routes`).
    """
    from ..engine.routes import default_routes
    from ..tables import albedo_table

    own = from_file("pump", _key(base))
    if own is not None:
        return own
    if _uses_file_tables(base):  # computed from a file's tables: serves this object only
        with _lock_for(f"derived#{id(base)}"):
            if getattr(base, "_derived_table", None) is None:
                with default_routes():
                    base._derived_table = albedo_table(base, rtol=TABLE_RTOL, interp_tol=TABLE_INTERP_TOL,
                                                       progress=progress, breaks=base.albedo_kinks(*grid_interior()))
        return base._derived_table
    key = _key(base)
    if key not in _TABLES:
        with _lock_for(key):  # one thread computes a base's table; the others wait for it
            if key not in _TABLES:
                # an anisotropic base: the table bounds the supremum over the azimuth of wi (001 eq. 17
                # needs g >= a(L) for every L, not only for L in the xz-plane; pumpup.tables.azimuth)
                phi = None if base.azimuth_range() is None else "sup"
                with default_routes():
                    _TABLES[key] = albedo_table(base, rtol=TABLE_RTOL, interp_tol=TABLE_INTERP_TOL,
                                                progress=progress, phi=phi, breaks=base.albedo_kinks(*grid_interior()))
    return _TABLES[key]


def grid_interior() -> tuple[float, float]:
    """The second and the next-to-last node of the grid a table starts from (:func:`pumpup.tables.default_grid`): only
    kinks between them split a base table (:meth:`Pumped.albedo_kinks`).
    """
    from ..tables import default_grid

    grid = default_grid()
    return grid[1], grid[-2]


def _sign_roots(grid, vals, fn) -> list:
    """The roots of ``fn`` in every cell of ``grid`` where ``vals`` (fn on the grid) changes sign (scipy's brentq, xtol
    1e-15).
    """
    from scipy.optimize import brentq

    idx = np.nonzero(np.sign(vals[:-1]) * np.sign(vals[1:]) < 0)[0]
    return [brentq(fn, grid[i], grid[i + 1], xtol=1e-15) for i in idx]


_LOCKS: dict[str, threading.Lock] = {}
_LOCKS_LOCK = threading.Lock()


def _lock_for(key: str) -> threading.Lock:
    with _LOCKS_LOCK:
        return _LOCKS.setdefault(key, threading.Lock())


def _uses_file_tables(brdf: BRDF) -> bool:
    """True if ``brdf`` is a pumped chain with a level whose table came from a file (load_pumped):
    what is computed from it must not enter the shared cache.
    """
    cur = brdf
    while isinstance(cur, Pumped):
        if cur._own_table is not None:
            return True
        cur = cur.base
    return False


# --- the compiled look-up: upper bound of a(mu) from the spline pieces ---------------------


@njit(cache=True, nogil=True)
def _chain_kernel(f, wi, wo, offsets, logx, coef, v0, slope0, margin_lo, cap, controlled, increasing, mu0,
                  index, index_lo, index_h_inv, pmlo, pcbase, pcell, plo, prow, pinv, qmlo, qshift, qcbase, qcell,
                  qlo, qrow, rcells, rpattern, rfid, rhid, rshift, rcbase, rcell, rlo,
                  rcoef):  # pragma: no cover - compiled
    """All levels of a pumped chain in one pass: f / (g_1 g_2 ... g_k) (001 eq. 16), in place.

    The tables of the levels are concatenated (level j owns nodes offsets[j]:offsets[j+1]);
    ``coef`` holds the upper bound (spline + margin, as :func:`upper_scalar`) and a uniform
    index over log(mu) finds the piece in O(1).  Where a level's bound is non-decreasing
    (``increasing``, :meth:`AlbedoTable.is_increasing`) and both cosines lie on its spline
    (above ``mu0``), max(u(mu_i), u(mu_o)) = u(max(mu_i, mu_o)): one look-up serves the level
    (:func:`g_levels`).  ``wi`` and ``wo`` are (n, 3) arrays of any strides (no copies).  Tested
    against the plain numpy reference, :meth:`Pumped.reference`, which pumps level by level.

    Fast path: where every level's bound increases, the product of all levels' g is one function
    of mmax, and the kernel multiplies by its tabulated inverse (:class:`_Product`, :func:`g_product` on its
    ``inverse_rows``; ``pmlo`` = inf turns it off).  Tested against :meth:`_Product.inverse` and the reference.
    Otherwise, where both cosines exceed ``qmlo``, every level's bound
    from the level table, one piece per direction (:class:`_LevelTable`, :func:`g_pair`; ``qmlo`` = inf turns it
    off, :meth:`Pumped._eval_levelwise`); there, first, the split table (:class:`_SplitTable`, :func:`g_split`: one
    product of two look-ups whatever the number of levels, in the cells where every level's term is fixed;
    ``rcells`` = 0 turns it off, :meth:`Pumped._eval_level_table`).
    """
    for k in range(f.shape[0]):
        mi, mo = wi[k, 2], wo[k, 2]
        if mi <= 0.0 or mo <= 0.0:
            f[k] = 0.0
            continue
        mmax, mmin = max(mi, mo), min(mi, mo)
        if mmin > pmlo:  # the fast path: one look-up for all levels (no branch on f = 0: 0 / g = 0)
            f[k] = f[k] * g_product(mmax, pcbase, pcell, plo, pinv)  # 001 eq. 16, all levels (times 1 / G)
        elif mmin > qmlo:  # one piece per direction for all levels (0 / g = 0)
            g = 0.0
            if rcells > 0:  # one product F(mmin) H(mmax), 0 where the cell has no pattern
                g = g_split(mmin, mmax, rcells, rpattern, rfid, rhid, rshift, rcbase, rcell, rlo,
                            rcoef)
            if g == 0.0:
                g = g_pair(mi, mo, controlled, qshift, qcbase, qcell, qlo, qrow)
            f[k] = f[k] / g  # 001 eq. 16, all levels
        elif f[k] != 0.0:
            f[k] = f[k] / g_levels_call(mmax, mmin, offsets, logx, coef, v0, slope0, margin_lo, cap, controlled,
                                        increasing, mu0, index, index_lo, index_h_inv)  # 001 eq. 16, all levels


@njit(cache=True, nogil=True)
def _chain_kernel_levelwise(f, wi, wo, offsets, logx, coef, v0, slope0, margin_lo, cap, controlled, increasing, mu0,
                            index, index_lo, index_h_inv, pmlo, pcbase, pcell, plo, prow):  # pragma: no cover
    """:func:`_chain_kernel` without the level table, as it was before it (the product table's path, else every level
    looked up level by level, :func:`g_levels` inlined): the baseline :meth:`Pumped._eval_levelwise` runs, for the
    tests of the level table and scripts/bench/bench_eval.py.
    """
    for k in range(f.shape[0]):
        mi, mo = wi[k, 2], wo[k, 2]
        if mi <= 0.0 or mo <= 0.0:
            f[k] = 0.0
            continue
        mmax, mmin = max(mi, mo), min(mi, mo)
        if mmin > pmlo:
            f[k] = f[k] / g_product(mmax, pcbase, pcell, plo, prow)  # 001 eq. 16, all levels
            continue
        if f[k] == 0.0:
            continue
        f[k] = f[k] / g_levels(mmax, mmin, offsets, logx, coef, v0, slope0, margin_lo, cap, controlled,
                                increasing, mu0, index, index_lo, index_h_inv)  # 001 eq. 16, all levels


def _monotone_envelope(spline, margin: float):
    """The running maximum of a PPoly spline over its breakpoints' range, as (x, c) of a PPoly
    and the list of its flat pieces (start, end, value), or None when the spline falls anywhere
    more than ``margin`` below its running maximum.

    An albedo table that is flat near mu = 1 (a pumped level there is 1 - 1e-7) can wiggle
    down by less than its own error margin; its running maximum is then an upper bound of the
    albedo that exceeds it by at most two margins, and it is non-decreasing, which lets the
    chain kernel take one look-up per level.  The spline is unchanged outside the flat pieces.
    """
    from numpy.polynomial import Polynomial

    x, c = spline.x, spline.c
    d1 = spline.derivative()
    d2 = d1.derivative()
    crit = d1.roots(extrapolate=False)
    crit = np.sort(crit[np.isfinite(crit)])
    peaks = crit[d2(crit) < 0]
    if d1(x[0]) < 0:  # falling from the first node: that is a peak too
        peaks = np.concatenate([[x[0]], peaks])
    flats = []
    for p in peaks:
        if flats and p <= flats[-1][1]:
            continue
        v = float(spline(p))
        if flats and v <= flats[-1][2]:
            continue
        # q: where the spline next rises above v (not the double root at the peak itself)
        h = 1e-7 * (x[-1] - x[0])
        after = spline.solve(v, extrapolate=False)
        after = after[np.isfinite(after) & (after > p + h)]
        after = after[spline(after + h) > v]
        q = float(after.min()) if after.size else float(x[-1])
        inside = np.concatenate([[p, q], crit[(crit > p) & (crit < q)]])
        if v - float(np.min(spline(inside))) > margin:
            return None
        flats.append((float(p), q, v))
    if not flats:
        return x, c, []
    nx = np.unique(np.concatenate([x, [b for fl in flats for b in fl[:2]]]))
    nc = np.empty((c.shape[0], len(nx) - 1))
    for i, (a, b) in enumerate(zip(nx[:-1], nx[1:])):
        flat = [fl for fl in flats if fl[0] <= a and b <= fl[1]]
        if flat:
            nc[:, i] = 0.0
            nc[-1, i] = flat[0][2]
        else:  # the old piece, re-expanded about a
            j = min(max(int(np.searchsorted(x, a, side="right")) - 1, 0), c.shape[1] - 1)
            shifted = Polynomial(c[::-1, j])(Polynomial([a - x[j], 1.0])).coef
            nc[:, i] = 0.0
            nc[-len(shifted):, i] = shifted[::-1]
    return nx, nc, flats


#: where :func:`fit_pieces` checks a piece: 4 (degree + 1) + 1 points evenly over its [-1, 1]
FIT_TEST_POINTS = np.linspace(-1.0, 1.0, 4 * (PRODUCT_DEGREE + 1) + 1)


#: :func:`fit_pieces`: a miss of at most this many ulps (of 1) that bisection did not halve is the rounding of the
#: functions themselves, which no narrower piece removes (5-level g2 pumped Phong's power laws below its splines miss
#: by up to 8 ulps on some machines, at every width)
ROUNDING_ULPS = 16


def fit_pieces(functions, lo: np.ndarray, hi: np.ndarray, tol: float, what: str, degree: int = PRODUCT_DEGREE):
    """Polynomial pieces of degree ``degree`` (:data:`PRODUCT_DEGREE` unless given) on the intervals [lo, hi) for
    each of ``functions`` (positive, of an array of m): each interpolated at the Chebyshev points of every piece, the
    pieces bisected until every function's relative miss at :data:`FIT_TEST_POINTS` (4 (degree + 1) + 1 points) is at
    most ``tol``, unless the miss is the rounding of the functions themselves: a piece already narrower than 1e-9 m,
    or one whose miss is at most :data:`ROUNDING_ULPS` ulps and at least half its parent's (bisection, which cuts an
    interpolant's miss by about 2^(degree + 1), did not halve it).  Returns (coefficients, one (degree + 1, pieces)
    array per function with the highest power first, lo, hi, centres, half-widths, the largest miss of each piece);
    :class:`_ProductError` (naming ``what``) beyond 100000 pieces or 64 rounds.
    """
    deg = degree
    xk = np.cos(np.pi * (np.arange(deg + 1) + 0.5) / (deg + 1))  # Chebyshev points
    vand = np.polynomial.chebyshev.chebvander(xk, deg)
    to_mono = np.array([np.pad(np.polynomial.chebyshev.cheb2poly(np.eye(deg + 1)[k]), (0, deg - k))
                        for k in range(deg + 1)])  # row k: monomial coefficients of T_k (low first)
    fit = np.linalg.solve(vand, np.eye(deg + 1)).T @ to_mono  # values at xk -> monomial (low first)
    tt = FIT_TEST_POINTS if deg == PRODUCT_DEGREE else np.linspace(-1.0, 1.0, 4 * (deg + 1) + 1)
    parent = np.full(len(lo), np.inf)  # the miss of each piece's parent (inf: not made by bisection)
    for _ in range(64):
        center, half = 0.5 * (lo + hi), 0.5 * (hi - lo)
        coefs, worst = [], np.zeros(len(lo))
        for fn in functions:
            coef = (fn(center[:, None] + half[:, None] * xk[None, :]) @ fit)[:, ::-1].T
            miss = np.abs(horner(coef[..., None], tt) / fn(center[:, None] + half[:, None] * tt) - 1.0)
            coefs.append(coef)
            worst = np.maximum(worst, miss.max(axis=1))
        rounding = (worst <= ROUNDING_ULPS * np.finfo(np.float64).eps) & (worst >= 0.5 * parent)
        bad = (worst > tol) & (hi - lo > 1e-9 * hi) & ~rounding
        if not bad.any():
            return coefs, lo, hi, center, half, worst
        if len(lo) + bad.sum() > 100_000:
            raise _ProductError(f"the {what} needs more than 100000 pieces to reach {tol:g}")
        mid = 0.5 * (lo[bad] + hi[bad])
        new_lo = np.sort(np.concatenate([lo, mid]))
        old = np.searchsorted(lo, new_lo, side="right") - 1  # the piece each new one lies in
        parent = np.where(bad[old], worst[old], np.inf)
        lo, hi = new_lo, np.sort(np.concatenate([hi, mid]))
    raise _ProductError(f"the {what} did not reach {tol:g} (worst {worst.max():.3g})")


class _ProductError(RuntimeError):
    """The product table cannot reach its tolerance (the kernel then looks up level by level)."""


class _Product:
    """g_1 g_2 ... g_k of a chain whose levels' bounds all increase, as one function of
    m = max(N.wi, N.wo): the chain kernel's fast path.

    When every level's bound u_j is non-decreasing, max(u_j(mu_i), u_j(mu_o)) = u_j(m), and g2
    adds max(., m): so the product of all levels' g is a function G(m) of one variable.  This
    class tabulates it as a piecewise polynomial in m itself, so the kernel takes no logarithm.
    Pieces: at most an eighth of an octave, split at every breakpoint of the levels' splines and
    at every kink (u_j = cap, u_j = m), so that G is analytic on each; on each a Chebyshev
    interpolant of degree PRODUCT_DEGREE, bisected until it matches G to ``TOL`` (relative) at
    4 (degree + 1) + 1 test points (G itself is computed to about 1e-14: the levels' splines are
    polynomials in log m).  The coefficients are then scaled by 1 + ``epsilon`` (twice the
    largest miss, plus 4 ulp; about 2e-14), so the albedo engine divides by at least G and at most
    G (1 + 2 ``epsilon``): the pumped BRDF it integrates is lower than the level-by-level reference by
    at most 2 ``epsilon`` (relative).  The eval kernels multiply by 1 / G instead, which costs less than a
    division: with ``inverse`` (a pumped chain's table; the compensations' one-level tables do without),
    ``inverse_rows``, the interpolant of 1 / G on the same pieces (bisected until both G and 1 / G meet ``TOL``),
    scaled by 1 - ``epsilon`` and checked never to exceed 1 / G, so the value eval gives is at most the level-by-level
    reference and lower by at most 2 ``epsilon``, as the value the engine integrates.
    The kernel finds the piece from the bits of m: cell c = (bits(m) >> CELL_SHIFT) - cbase,
    2^CELL_BITS cells per octave, ``cstart[c]`` the piece where the cell starts (most cells
    hold one piece); the kernel reads ``entries[c]``, that piece and where the next starts in one int64.
    :meth:`__call__` is the plain numpy version of that look-up.
    """

    TOL = 1e-14

    def __init__(self, looks, controlled, inverse: bool = False):
        self.looks, self.controlled = looks, controlled
        # above mlo every level is on its spline (not the power law below its first node; the
        # 1e-12 keeps log(m) clear of the first breakpoint's rounding)
        self.mlo = max(max(lk.mu0, math.exp(lk.logx[0])) for lk in looks) * (1.0 + 1e-12)
        b0 = int(float_bits_reference(self.mlo)) >> CELL_SHIFT
        b1 = int(float_bits_reference(1.0)) >> CELL_SHIFT
        self.cbase = b0
        bounds = (np.arange(b0, b1 + 1, dtype=np.int64) << CELL_SHIFT).view(np.float64)
        knots = np.exp(np.concatenate([lk.logx for lk in looks]))
        eighths = 2.0 ** np.arange(math.floor(math.log2(self.mlo)), 0, 0.125)  # pieces span at most 1/8 octave
        br = np.unique(np.concatenate([[self.mlo, 1.0], eighths, knots]))
        br = br[(br >= self.mlo) & (br <= 1.0)]
        br = np.unique(np.concatenate([br, self._kinks(br)]))
        lo, hi = br[:-1], br[1:]
        # G, and with ``inverse`` 1 / G, on one set of pieces (bisected until both meet TOL: 1 / G needs about a
        # fifth more pieces)
        fns = [self.exact, self.inverse_exact] if inverse else [self.exact]
        coefs, lo, hi, center, half, worst = fit_pieces(fns, lo, hi, self.TOL, "product table")
        self.epsilon = 2.0 * float(worst.max()) + 4 * np.finfo(float).eps
        self.coef = np.ascontiguousarray(coefs[0] * (1.0 + self.epsilon))
        self.center, self.ihalf = center, 1.0 / half
        #: what the albedo engine reads for piece s: coefficients, centre, inverse half-width
        self.rows = np.ascontiguousarray(np.concatenate([self.coef, center[None], self.ihalf[None]]).T)
        #: what the eval kernels read for piece s to multiply by 1 / G, in the layout of ``rows`` (None without
        #: ``inverse``)
        self.inverse_coef = self.inverse_rows = None
        if inverse:
            self.inverse_coef = np.ascontiguousarray(coefs[1] * (1.0 - self.epsilon))
            self.inverse_rows = np.ascontiguousarray(
                np.concatenate([self.inverse_coef, center[None], self.ihalf[None]]).T)
            tt = np.linspace(-1.0, 1.0, 8 * (PRODUCT_DEGREE + 1) + 1)
            m = np.clip(center[:, None] + half[:, None] * tt, lo[:, None], hi[:, None])
            if not np.all(horner(self.inverse_coef[:, :, None], (m - center[:, None]) * self.ihalf[:, None])
                          <= self.inverse_exact(m)):  # pragma: no cover - the scaling leaves 2 ulp at least
                raise _ProductError("the product table's inverse exceeds 1 / G")
        self.lo = np.concatenate([lo, [math.inf]])  # a sentinel ends the search
        # cell c = (bits(m) >> CELL_SHIFT) - cbase starts at bounds[c]; the last starts at m = 1
        self.cstart = np.clip(np.searchsorted(lo, bounds, side="right") - 1, 0, len(lo) - 1).astype(np.int32)
        #: the cells as the kernel reads them: each cell's first piece and where the next starts, one int64
        #: (:func:`pumpup.physics.lookups.cell_entries`)
        self.entries = cell_entries(self.lo, self.cstart)

    def inverse_exact(self, m):
        """1 / G(m) (:meth:`exact`)."""
        return 1.0 / self.exact(m)

    def inverse(self, m):
        """The eval kernels' 1 / G(m) in plain numpy (m > mlo): the reference of their fast path."""
        m = np.asarray(m, dtype=np.float64)
        s = self.piece(m)
        return horner(self.inverse_coef[:, s], (m - self.center[s]) * self.ihalf[s])

    def _g(self, j, m):
        g = self.looks[j].upper(m)  # already at most the cap
        return np.maximum(g, m) if self.controlled[j] else g  # 001 eq. 21

    def exact(self, m):
        """G(m): the product of the levels' g at mu_i = mu_o = m, from the levels' look-ups."""
        m = np.asarray(m, dtype=np.float64)
        out = np.ones_like(m)
        for j in range(len(self.looks)):
            out = out * self._g(j, m)
        return out

    def _kinks(self, br):
        """Values of m in (mlo, 1) where a level's g switches term (u = cap, or u = m for g2)."""
        from scipy.optimize import brentq

        grid = np.unique(np.concatenate([br, np.sqrt(br[:-1] * br[1:])]))
        out = []
        for j, lk in enumerate(self.looks):
            fns = [] if not math.isfinite(lk.cap) else [lambda m, lk=lk: lk.upper(m, capped=False) - lk.cap]
            if self.controlled[j]:
                fns.append(lambda m, lk=lk: lk.upper(m) - m)
            for fn in fns:
                v = fn(grid)
                for i in np.nonzero(np.sign(v[:-1]) * np.sign(v[1:]) < 0)[0]:
                    out.append(brentq(lambda m: float(fn(np.array([m]))[0]), grid[i], grid[i + 1], xtol=1e-300,
                                      rtol=1e-15))
        return np.array(out)

    def piece(self, m):
        """The piece that holds m (> mlo), found as the kernel finds it: the cell's entry from the bits of m, then
        forward (:func:`pumpup.physics.lookups.cell_piece_reference`).
        """
        return cell_piece_reference(m, CELL_SHIFT, self.cbase, self.entries, self.lo)

    def __call__(self, m):
        """The kernel's G(m) in plain numpy (m > mlo): the reference of the fast path."""
        m = np.asarray(m, dtype=np.float64)
        s = self.piece(m)
        return horner(self.coef[:, s], (m - self.center[s]) * self.ihalf[s])


def _cap_kinks(looks, br) -> np.ndarray:
    """Values of m in the range of ``br`` (sorted) where a level's uncapped bound crosses its cap (u_j = cap: a kink of
    the capped bound), by bisection of the sign changes on ``br`` and its geometric midpoints.
    """
    from scipy.optimize import brentq

    grid = np.unique(np.concatenate([br, np.sqrt(br[:-1] * br[1:])]))
    out = []
    for lk in looks:
        if not math.isfinite(lk.cap):
            continue
        v = lk.upper(grid, capped=False) - lk.cap
        for i in np.nonzero(np.sign(v[:-1]) * np.sign(v[1:]) < 0)[0]:
            out.append(brentq(lambda m, lk=lk: float(lk.upper(np.array([m]), capped=False)[0]) - lk.cap,
                              grid[i], grid[i + 1], xtol=1e-300, rtol=1e-15))
    return np.array(out)


def _meet_kinks(looks, br) -> np.ndarray:
    """Values of m in the range of ``br`` (sorted) where a level's bound meets m (U_j(m) = m: a kink of
    max(U_j(m), m), 001 eq. 21), by bisection of the sign changes on ``br`` and its geometric midpoints.
    """
    from scipy.optimize import brentq

    grid = np.unique(np.concatenate([br, np.sqrt(br[:-1] * br[1:])]))
    out = []
    for lk in looks:
        v = lk.upper(grid) - grid
        for i in np.nonzero(np.sign(v[:-1]) * np.sign(v[1:]) < 0)[0]:
            out.append(brentq(lambda m, lk=lk: float(lk.upper(np.array([m]))[0]) - m, grid[i], grid[i + 1],
                              xtol=1e-300, rtol=1e-15))
    return np.array(out)


def _level_breaks(looks, mlo: float) -> np.ndarray:
    """The first breakpoints in m of a table of the levels' bounds on [mlo, 1] (:class:`_LevelTable`,
    :class:`_PairTable`): at most an eighth of an octave apart, at every breakpoint of every level's spline and where a
    level's bound reaches its cap, so that each bound is analytic between two of them.
    """
    knots = np.exp(np.concatenate([lk.logx for lk in looks]))
    eighths = 2.0 ** np.arange(math.floor(math.log2(mlo)), 0, 0.125)  # pieces span at most 1/8 octave
    br = np.unique(np.concatenate([[mlo, 1.0], eighths, knots]))
    br = br[(br >= mlo) & (br <= 1.0)]
    return np.unique(np.concatenate([br, _cap_kinks(looks, br)]))


def _piece_cells(lo: np.ndarray, mlo: float, max_bits: int) -> tuple[int, int, np.ndarray, np.ndarray]:
    """The cell index of pieces that start at ``lo`` (sorted, the first at ``mlo``): 2^bits cells per octave, cell
    c = (bits(m) >> shift) - cbase starting at piece cstart[c], with bits from CELL_BITS up until no cell of the top
    two octaves, where most cosines lie, holds more than two piece starts, at most ``max_bits``.  Returns (shift,
    cbase, cstart, entries), the cells' entries the kernels read (:func:`pumpup.physics.lookups.cell_entries`).
    """
    for bits in range(52 - CELL_SHIFT, max_bits + 1):
        shift = 52 - bits
        top = lo[lo >= 0.25]
        per = np.bincount((float_bits_reference(top) >> shift) - (int(float_bits_reference(0.25)) >> shift))
        if per.size == 0 or per.max() <= 2:
            break
    b0 = int(float_bits_reference(mlo)) >> shift
    b1 = int(float_bits_reference(1.0)) >> shift
    bounds = (np.arange(b0, b1 + 1, dtype=np.int64) << shift).view(np.float64)
    cstart = np.clip(np.searchsorted(lo, bounds, side="right") - 1, 0, len(lo) - 1).astype(np.int32)
    return shift, b0, cstart, cell_entries(np.concatenate([lo, [math.inf]]), cstart)


class _LevelTable:
    """Every level's bound U_j(m) (the capped upper bound :meth:`_Lookup.upper`) as polynomials in m on one set of
    pieces: the chain kernel's path where some level's bound is not monotone (GGX's albedo falls, then rises), so that
    the product of the levels' g is no function of max(N.wi, N.wo) alone (:class:`_Product`).

    One piece per direction then serves every level, found from the bits of m (no logarithm; :func:`g_pair`), where
    the level-by-level path (:func:`g_levels`) took a logarithm per cosine and a table search per level and cosine.
    Pieces: at most an eighth of an octave, split at every breakpoint of every level's spline and where a level's bound
    reaches its cap, so that each U_j is analytic on each; on each a Chebyshev interpolant of degree PRODUCT_DEGREE per
    level, bisected until every level matches its U_j to ``TOL`` (relative) at 4 (degree + 1) + 1 test points.  The
    coefficients are then scaled by 1 - ``epsilon`` (twice the largest miss, plus 16 ulp), so every piece is at most
    U_j and at least U_j (1 - 2 ``epsilon``): g_j = max(U_j(mu_i), U_j(mu_o)[, mu_i, mu_o]) is at most the
    level-by-level g_j, so the pumped BRDF is at least the level-by-level one (and lower than the ideal operator's while
    U_j (1 - 2 ``epsilon``) stays above the albedo, which the table's margin, about 1e-7 of it, leaves room for).  The
    albedo engine divides by the level-by-level g (:func:`g_levels`, so tables are unchanged): what ``eval`` gives
    exceeds what it integrates by at most 2 ``epsilon`` (about 1e-14) per level, relative.  The layout of
    ``rows``: per piece its centre, inverse half-width, then each level's coefficients, highest power first; the cells
    that find a piece are finer than the product table's where the pieces crowd (:meth:`_cells`).
    :meth:`g` is the plain numpy version of :func:`g_pair`.
    """

    TOL = 1e-15

    def __init__(self, looks, controlled):
        self.looks, self.controlled = looks, np.asarray(controlled, dtype=np.bool_)
        self.mlo = max(max(lk.mu0, math.exp(lk.logx[0])) for lk in looks) * (1.0 + 1e-12)  # (as _Product)
        br = _level_breaks(looks, self.mlo)
        lo, hi = br[:-1], br[1:]
        coefs, lo, hi, center, half, worst = fit_pieces([lk.upper for lk in looks], lo, hi, self.TOL, "level table")
        self.epsilon = 2.0 * float(worst.max()) + 16 * np.finfo(float).eps
        #: (levels, degree + 1, pieces): each level's coefficients, scaled down by 1 - epsilon
        self.coef = np.stack(coefs) * (1.0 - self.epsilon)
        self.center, self.ihalf = center, 1.0 / half
        self.rows = np.ascontiguousarray(np.concatenate(
            [center[None], self.ihalf[None], self.coef.reshape(-1, len(lo))]).T)
        self.lo = np.concatenate([lo, [math.inf]])  # a sentinel ends the search
        self._cells(lo)
        self._check(FIT_TEST_POINTS)

    #: the most cells per octave (2^CELLS_MAX_BITS): 4096 int32 per octave, 16 kB, for the octaves that most
    #: cosines fall in
    CELLS_MAX_BITS = 12

    def _cells(self, lo) -> None:
        """The cell index: 2^bits cells per octave (cell c = (bits(m) >> ``shift``) - ``cbase`` starts at piece
        ``cstart[c]``), with bits from CELL_BITS up until no cell of the top two octaves, where most cosines lie, holds
        more than two piece starts (3-level g2 pumped GGX alpha 0.3: 462 pieces in [0.5, 1], up to 41 forward steps
        with 256 cells per octave), at most CELLS_MAX_BITS (:func:`_piece_cells`).
        """
        self.shift, self.cbase, self.cstart, self.entries = _piece_cells(lo, self.mlo, self.CELLS_MAX_BITS)

    def _check(self, tt) -> None:
        """Refuse the table (:class:`_ProductError`) unless every piece is at most its level's bound at the fit's test
        points and at 2000 points spread over [mlo, 1] (the bound the level-by-level path divides by).
        """
        m = np.concatenate([(self.center[:, None] + tt[None, :] / self.ihalf[:, None]).ravel(),
                            np.geomspace(self.mlo * (1 + 1e-12), 1.0, 2000)])
        m = m[(m > self.mlo) & (m <= 1.0)]
        got = self.levels(m)
        for j, lk in enumerate(self.looks):
            if np.any(got[j] > lk.upper(m)):
                raise _ProductError("the level table exceeds a level's bound")

    def piece(self, m):
        """The piece that holds m (> mlo), found as the kernel finds it (:meth:`_Product.piece`)."""
        return cell_piece_reference(m, self.shift, self.cbase, self.entries, self.lo)

    def levels(self, m) -> np.ndarray:
        """Every level's U_j(m) (m > mlo) as the kernel computes it: an array (levels,) + m's shape."""
        m = np.asarray(m, dtype=np.float64)
        s = self.piece(m)
        t = (m - self.center[s]) * self.ihalf[s]
        return np.stack([horner(self.coef[j][:, s], t) for j in range(len(self.looks))])

    def g(self, mu_i, mu_o) -> np.ndarray:
        """g_1 ... g_k at (mu_i, mu_o), both > mlo: the plain numpy reference of :func:`g_pair` (001 eq. 20, 21)."""
        mu_i, mu_o = np.broadcast_arrays(np.asarray(mu_i, np.float64), np.asarray(mu_o, np.float64))
        ui, uo = self.levels(mu_i), self.levels(mu_o)
        mmax = np.maximum(mu_i, mu_o)
        out = np.ones(mu_i.shape)
        for j in range(len(self.looks)):
            g = np.maximum(ui[j], uo[j])  # 001 eq. 20
            if self.controlled[j]:
                g = np.maximum(g, mmax)  # 001 eq. 21
            out = out * g
        return out


class _SplitTable:
    """g_1 g_2 ... g_k of a chain with a level table (:class:`_LevelTable`) as one product of two functions of one
    variable, F(l) H(m) with l = min(N.wi, N.wo) and m = max(N.wi, N.wo), chosen by the cell of (l, m): the chain
    kernel's path that costs the same for any number of levels (:func:`pumpup.physics.lookups.g_split`).

    Each level's g_j = max(U_j(l), U_j(m)[, m]) (001 eq. 20, 21) takes one of its two or three terms throughout most
    cells of a grid of CELLS x CELLS cells in (l, m) (l < m: the cells above the diagonal): the term is certified when
    its smallest value over the cell exceeds the other terms' largest by the relative SAFETY, each U_j's range over a
    cell's interval taken from its values at the ends and at the zeros of its spline's derivative inside.  Where
    neither U_j(m) nor m is certified but both exceed U_j(l) (g2, U_j within the cell's variation of m: Phong's albedo),
    the level's term is W_j(m) = max(U_j(m), m), one function of m (code 3; kept only in cells where another level's
    term is its bound below its cap, :meth:`_slack`).  A cell whose levels all have a certified term holds a pattern
    (the term of every level); then g_1 ... g_k = F_A(l) H_B(m) with F_A the product of the U_j of the levels A that
    take U_j(l), and H_B the product of the U_j of the levels B that take U_j(m) times m^c, c the number of levels that
    take m (001 eq. 21), times the W_j of the levels that take it.  The other cells (the diagonal ones, and those a
    kink crosses: U_j(l) = U_j(m), U_j = m, U_j = cap) hold -1, and the kernel takes the level table there.

    Every product of bounds used (:attr:`functions`; row 0, the empty product, is exactly 1) is tabulated on one set of
    pieces in m, as the level table tabulates the U_j (pieces split at every breakpoint of every level's spline, where
    a level's bound reaches its cap and, for a W_j, where U_j meets m; a Chebyshev interpolant of degree
    PRODUCT_DEGREE on each, bisected until it matches its function to ``TOL``, relative, at 4 (degree + 1) + 1 test
    points), scaled by 1 - ``epsilon`` (twice the largest miss plus 16 ulp) and checked never to exceed its function:
    the product the kernel divides by is at most the level-by-level product of g (the pumped BRDF at least the
    level-by-level one) and at least that product times (1 - 2 ``epsilon``), as the level table's.  The cells where
    every level takes m hold -1: there the ideal operator's g is m^k itself, with no room below it for a scaled table.
    ``coef[f, s]`` holds function f's coefficients on piece s
    (highest power first), the piece's centre and inverse half-width: one cache line per look-up.  ``pattern[i, k]``
    (int8) is the pattern of the cell i = floor(l CELLS), k = floor(m CELLS) (-1: none; the kernel reads ``packed``, its
    cells with i <= k, 32 kB), ``fid[p]`` and ``hid[p]`` the rows of ``coef`` that hold its F_A and H_B. :meth:`g` is
    the plain numpy version of the kernel.
    """

    #: the fit's relative tolerance (a product of k bounds is itself only good to a few k ulp: at 1e-15 the
    #: pieces of 5-level GGX's products were bisected beyond 100000 chasing that rounding)
    TOL = 1e-14
    #: cells per axis of the grid in (l, m) (512: 3 % more pairs served, 128 kB packed, no faster, measured)
    CELLS = 256
    #: how far (relative) a level's certified term stays above its others throughout a cell
    SAFETY = 1e-12
    #: the most cells per octave of the piece index (2^CELLS_MAX_BITS, :func:`_piece_cells`): 1024 int64, 8 kB per
    #: octave (4096 cells, 32 kB, left less of the cache to the rest: 3- and 5-level GGX and 5-level Phong took 4 to
    #: 13 % longer per pair, measured in one run with scripts/bench/bench_eval.py's pairs)
    CELLS_MAX_BITS = 10
    #: the share of served cells with an empty F (all levels' terms functions of m) from which the kernel skips F there
    SKIP_SHARE = 0.8

    def __init__(self, levels: _LevelTable):
        self.levels_table = levels
        self.looks, self.controlled, self.mlo = levels.looks, levels.controlled, levels.mlo
        n = self.ncell = self.CELLS
        edges = np.arange(n + 1, dtype=np.float64) / n
        lo_e, hi_e = np.maximum(edges[:-1], self.mlo), edges[1:]
        rlo, rhi = self._ranges(lo_e, hi_e)  # (levels, n)
        codes = self._codes(rlo[:, :, None], rhi[:, :, None], rlo[:, None, :], rhi[:, None, :],
                            lo_e[None, :], hi_e[None, :])  # (levels, n, n)
        ok = (self._certified(codes) & self._slack(codes, rhi[:, :, None], rhi[:, None, :])
              & np.triu(np.ones((n, n), dtype=bool), 1) & (hi_e > self.mlo)[:, None])
        keys, inverse = _unique_rows(codes[:, ok].T)
        if len(keys) > 127:
            raise _ProductError("the split table needs more than 127 patterns")
        self.pattern = np.full((n, n), -1, dtype=np.int8)
        self.pattern[ok] = inverse.ravel().astype(np.int8)
        k_, i_ = np.tril_indices(n)  # (k >= i: the cells with l <= m, row by row of k)
        #: ``pattern``'s cells with i <= k packed as the kernel reads them: cell (i, k) at k (k + 1) / 2 + i
        self.packed = np.ascontiguousarray(self.pattern[i_, k_])
        #: the term of every level in each pattern (0: U_j(l), 1: U_j(m), 2: m, 3: max(U_j(m), m))
        self.patterns = keys.astype(np.int8)
        if len(keys) == 0:  # (no cell certified: a table of nothing; the chain keeps the level table alone)
            raise _ProductError("no cell of the split table has one term per level")
        fkeys = {self._f_key(k) for k in keys}
        hkeys = {self._h_key(k) for k in keys}
        #: the functions tabulated, each (levels, c, wlevels): the product of the bounds of ``levels`` times m^c times
        #: max(U_j(m), m) for j in ``wlevels``; row 0 the empty product, exactly 1
        self.functions = [((), 0, ())] + sorted((fkeys | hkeys) - {((), 0, ())},
                                                key=lambda a: (len(a[0]) + len(a[2]), a))
        self.fid = np.array([self.functions.index(self._f_key(k)) for k in keys], dtype=np.int64)
        self.hid = np.array([self.functions.index(self._h_key(k)) for k in keys], dtype=np.int64)
        #: whether the kernel skips F where it is the empty product (fid 0, :func:`g_split`): where fewer than
        #: SKIP_SHARE of the served cells have an empty F, their patterns read a copy of row 0 instead (the last
        #: row, the same exact 1), so that the kernel's branch on fid 0 is never taken and never mispredicted
        cells = np.bincount(inverse, minlength=len(keys))
        self.skips = bool(np.sum(cells[self.fid == 0]) >= self.SKIP_SHARE * np.sum(cells))
        if not self.skips and np.any(self.fid == 0):
            self.fid[self.fid == 0] = len(self.functions)
            self.functions.append(((), 0, ()))
        wlevels = sorted({j for fn in self.functions for j in fn[2]})
        br = _level_breaks(self.looks, self.mlo)
        br = np.unique(np.concatenate([br, _meet_kinks([self.looks[j] for j in wlevels], br)]))
        fns = [self._function(fn) for fn in self.functions[1:] if fn != ((), 0, ())]
        coefs, lo, hi, center, half, worst = fit_pieces(fns, br[:-1], br[1:], self.TOL, "split table")
        self.epsilon = 2.0 * float(worst.max()) + 16 * np.finfo(float).eps
        one = np.zeros((1, PRODUCT_DEGREE + 1, len(lo)))
        one[0, -1] = 1.0  # the empty product: Horner's rule gives exactly 1
        copy = [one] if self.functions[-1] == ((), 0, ()) and len(self.functions) > 1 else []
        coef = np.concatenate([one, np.stack(coefs) * (1.0 - self.epsilon)] + copy)  # (functions, degree + 1, pieces)
        self.coef = _aligned(np.concatenate(
            [coef.transpose(0, 2, 1), np.broadcast_to(center[None, :, None], (len(coef), len(lo), 1)),
             np.broadcast_to(1.0 / half[None, :, None], (len(coef), len(lo), 1))], axis=2))
        self.center, self.ihalf = center, 1.0 / half
        self.lo = np.concatenate([lo, [math.inf]])  # a sentinel ends the search
        self.shift, self.cbase, self.cstart, self.entries = _piece_cells(lo, self.mlo, self.CELLS_MAX_BITS)
        self._check([self._function(fn) for fn in self.functions])

    @staticmethod
    def _f_key(k) -> tuple:
        """The function F of pattern ``k`` (a level's term per level): the product of the U_j(l) it takes."""
        return tuple(int(j) for j in np.nonzero(k == 0)[0]), 0, ()

    @staticmethod
    def _h_key(k) -> tuple:
        """The function H of pattern ``k``: the U_j(m), the m and the max(U_j(m), m) it takes."""
        return (tuple(int(j) for j in np.nonzero(k == 1)[0]), int(np.count_nonzero(k == 2)),
                tuple(int(j) for j in np.nonzero(k == 3)[0]))

    def _function(self, fn):
        """The exact function of one of :attr:`functions`, of an array of m: a product of levels' bounds times m^c
        times max(U_j(m), m) of the levels ``fn[2]``.
        """
        looks = self.looks

        def f(m):
            m = np.asarray(m, dtype=np.float64)
            out = np.ones_like(m)
            for j in fn[0]:
                out = out * looks[j].upper(m)
            for _ in range(fn[1]):
                out = out * m  # 001 eq. 21: g_j = m
            for j in fn[2]:
                out = out * np.maximum(looks[j].upper(m), m)  # 001 eq. 21: g_j = max(U_j(m), m)
            return out

        return f

    def _ranges(self, lo_e, hi_e):
        """Each level's smallest and largest bound over each interval [lo_e[i], hi_e[i]]: (levels, intervals) twice.
        The bound is the level's spline in log(m) plus its margin, at most its cap: its extremes lie at the ends or
        at zeros of the spline's derivative.
        """
        from scipy.interpolate import PPoly

        rlo = np.empty((len(self.looks), len(lo_e)))
        rhi = np.empty_like(rlo)
        for j, lk in enumerate(self.looks):
            crit = PPoly(lk.coef, lk.logx).derivative().roots(extrapolate=False)
            crit = np.exp(np.sort(crit[np.isfinite(crit)]))
            pts = np.unique(np.concatenate([lo_e, hi_e, crit[(crit > self.mlo) & (crit < 1.0)]]))
            u = lk.upper(pts)
            a = np.searchsorted(pts, lo_e, side="left")  # (increasing: the intervals follow each other)
            b = np.searchsorted(pts, hi_e, side="right") - 1  # each interval's last point, its hi_e
            rlo[j] = np.minimum(np.minimum.reduceat(u, a), u[b])  # (reduceat: from a[i] to a[i + 1] - 1)
            rhi[j] = np.maximum(np.maximum.reduceat(u, a), u[b])
        return rlo, rhi

    def _codes(self, ll, lh, ml, mh, m0, m1) -> np.ndarray:
        """The certified term of each level in each cell: 0 U_j(l), 1 U_j(m), 2 m (g2 only), -1 none; an array
        (levels,) + the cells' shape.  ``ll``, ``lh`` (levels,) + cells: U_j's range over the cell's interval of l;
        ``ml``, ``mh`` over its interval of m, [``m0``, ``m1``] (broadcast).
        """
        s = 1.0 + self.SAFETY
        shape = np.broadcast_shapes(ll.shape, ml.shape, (1,) + np.shape(m1))
        out = np.empty(shape, dtype=np.int8)
        for j in range(len(self.looks)):
            ctl = bool(self.controlled[j])
            top = np.maximum(mh[j], m1) if ctl else mh[j]
            c0 = ll[j] >= top * s  # U_j(l) above U_j(m) and m throughout
            c1 = (ml[j] >= lh[j] * s) & ((ml[j] >= m1 * s) if ctl else True)
            c2 = (m0 >= np.maximum(lh[j], mh[j]) * s) if ctl else False
            # max(U_j(m), m) above U_j(l) throughout (U_j(m) and m too close to tell apart over the cell: both are
            # functions of m, so their max is one)
            c3 = (np.maximum(ml[j], m0) >= lh[j] * s) if ctl else False
            out[j] = np.where(c0, 0, np.where(c1, 1, np.where(c2, 2, np.where(c3, 3, -1))))
        return out

    def _slack(self, codes, lh, mh) -> np.ndarray:
        """Cells where a term max(U_j(m), m) (code 3) is used only beside a level whose certified term is its bound
        U_j below its cap throughout the cell (code 0 with U_j(l) < cap, or 1 with U_j(m) < cap; ``lh``, ``mh`` the
        largest U_j over the cell's intervals of l and m).  Where max(U_j(m), m) = m, that level's g is the ideal
        operator's itself; the level with its bound below the cap keeps the room (its table's margin) that the fit's
        scaling down by 1 - epsilon takes.
        """
        cap = np.array([lk.cap for lk in self.looks])[:, None, None]
        room = ((codes == 0) & (lh < cap)) | ((codes == 1) & (mh < cap))
        return ~np.any(codes == 3, axis=0) | np.any(room, axis=0)

    @staticmethod
    def _certified(codes) -> np.ndarray:
        """Cells where every level has a certified term, but not m for every level: there (001 eq. 21) the ideal
        operator's g is m^k itself, with no room below it for a table scaled down, and the level table, which
        multiplies m in exactly as the level-by-level path, serves.
        """
        return np.all(codes >= 0, axis=0) & ~np.all(codes == 2, axis=0)

    def _check(self, fns) -> None:
        """Refuse the table (:class:`_ProductError`) unless every function's pieces are at most the function at the
        fit's test points and at 2000 points spread over [mlo, 1].
        """
        tt = FIT_TEST_POINTS
        m = np.concatenate([(self.center[:, None] + tt[None, :] / self.ihalf[:, None]).ravel(),
                            np.geomspace(self.mlo * (1 + 1e-12), 1.0, 2000)])
        m = m[(m > self.mlo) & (m <= 1.0)]
        for f, fn in enumerate(fns):
            if np.any(self.function(f, m) > fn(m)):
                raise _ProductError("the split table exceeds a product of the levels' bounds")

    def piece(self, m):
        """The piece that holds m (> mlo), found as the kernel finds it (:meth:`_Product.piece`)."""
        return cell_piece_reference(m, self.shift, self.cbase, self.entries, self.lo)

    def function(self, f, m) -> np.ndarray:
        """Tabulated function ``f`` (a row of ``coef``) at m (> mlo), as the kernel computes it."""
        m = np.asarray(m, dtype=np.float64)
        s = self.piece(m)
        row = self.coef[f, s]
        return horner(np.moveaxis(row[..., :PRODUCT_DEGREE + 1], -1, 0), (m - row[..., -2]) * row[..., -1])

    def cell(self, mu_i, mu_o) -> np.ndarray:
        """The pattern of the cell of each pair (-1 where the level table serves), as the kernel finds it."""
        lo, hi = np.minimum(mu_i, mu_o), np.maximum(mu_i, mu_o)
        n = self.ncell
        i, k = np.minimum((lo * n).astype(np.int64), n - 1), np.minimum((hi * n).astype(np.int64), n - 1)
        return self.packed[k * (k + 1) // 2 + i]

    def g(self, mu_i, mu_o) -> np.ndarray:
        """g_1 ... g_k at (mu_i, mu_o), both > mlo: the plain numpy reference of :func:`g_split` followed, in the cells
        without a pattern, by the level table's (:meth:`_LevelTable.g`).
        """
        mu_i, mu_o = np.broadcast_arrays(np.asarray(mu_i, np.float64), np.asarray(mu_o, np.float64))
        lo, hi = np.minimum(mu_i, mu_o), np.maximum(mu_i, mu_o)
        p = self.cell(mu_i, mu_o)
        out = self.levels_table.g(mu_i, mu_o)
        on = p >= 0
        if np.any(on):
            pp = p[on]
            f = np.empty(pp.shape)
            h = np.empty(pp.shape)
            for q in np.unique(pp):
                w = pp == q
                f[w] = self.function(self.fid[q], lo[on][w])
                h[w] = self.function(self.hid[q], hi[on][w])
            out[on] = f * h  # F_A(l) H_B(m)
        return out

    def share(self) -> float:
        """The share of pairs with both cosines uniform on [0, 1] (the cells' area) that the split table serves."""
        n = self.ncell
        return 2.0 * np.count_nonzero(self.pattern >= 0) / (n * n)


def _aligned(a: np.ndarray, line: int = 64) -> np.ndarray:
    """A C-contiguous copy of ``a`` whose data starts on a ``line``-byte boundary (a row of 8 float64 is then one cache
    line, not two).
    """
    buf = np.empty(a.nbytes + line, dtype=np.uint8)
    off = (-buf.ctypes.data) % line
    out = buf[off:off + a.nbytes].view(a.dtype).reshape(a.shape)
    out[...] = a
    return out


def _unique_rows(rows: np.ndarray):
    """np.unique(rows, axis=0, return_inverse=True) for rows of digits 0-3 (each row read as a number in base 4: the
    sort of rows as records took 0.14 s of a 3-level split table's 0.4 s).
    """
    if rows.shape[1] > 31:  # (beyond int64)
        keys, inverse = np.unique(rows, axis=0, return_inverse=True)
        return keys, inverse.ravel()
    weight = 4 ** np.arange(rows.shape[1] - 1, -1, -1, dtype=np.int64)  # (the first digit the most significant)
    u, inverse = np.unique(rows.astype(np.int64) @ weight, return_inverse=True)
    keys = (u[:, None] // weight[None, :]) % 4
    return keys.astype(rows.dtype), inverse.ravel()


#: the split table's arguments of the kernels when there is none (:meth:`Pumped._split_args`)
_SPLIT_OFF = (0, np.full(1, -1, dtype=np.int8), np.zeros(1, np.int64), np.zeros(1, np.int64), CELL_SHIFT, 0,
              np.zeros(1, np.int64), np.full(2, math.inf), np.zeros((1, 1, PRODUCT_DEGREE + 3)))


class _Lookup:
    """The table's upper bound in the flat form the compiled kernel takes."""

    def __init__(self, table):
        from scipy.interpolate import PPoly

        from ..tables import nondecreasing

        t = table
        if not float(np.max(t.value)) > 0.0:
            import json

            name = json.dumps(t.spec) if t.spec else "the model"
            raise SpecError(f"{name} reflects nothing (its albedo is 0 at every incidence): pumping's g and 1/E "
                            "compensation divide by its albedo, so it can be neither a pumping base nor a compensation "
                            "white (pumping it would give 0 again)")
        self.margin, self.margin_lo = t.margin, t.margin_below  # as in AlbedoTable.upper
        x, c = t._spline.x, t._spline.c  # the breakpoints of the spline pieces, in log(mu)
        self.increasing = t.is_increasing()
        self.flats = []
        if not self.increasing:  # a dip within the table's margin: use the running maximum
            env = _monotone_envelope(t._spline, self.margin)
            if env is not None and nondecreasing(PPoly(env[1], env[0])):
                x, c, flats = env
                self.increasing = True
                #: the flat pieces in mu, with the bound there (g has a kink where one ends)
                self.flats = [(math.exp(p), math.exp(q), v + self.margin) for p, q, v in flats]
        self.logx = np.ascontiguousarray(x)
        self.coef = np.ascontiguousarray(c)
        self.mu0 = float(t.mu[0])
        self.v0, self.slope0 = float(t.value[0]), t.slope_below
        # 001 eq. 17 asks max(a(L), a(V)) <= g <= 1.  The upper bound can exceed 1 by its
        # margin where a = 1, which would lower the albedo there (a* < a): cap g at 1 when the
        # table says the base conserves energy.  A base that reflects more than it receives
        # (a > 1 beyond its error) cannot meet both sides; then g stays >= a so that the first
        # pumping makes it plausible (001, after eq. 17).
        self.cap = 1.0 if float(np.max(t.value - t.error)) <= 1.0 else math.inf
        self.table = t

    @property
    def envelope(self) -> bool:
        """True if the bound is the running maximum of the table (it has flat pieces)."""
        return bool(self.flats)

    def args(self):
        return self.logx, self.coef, self.v0, self.slope0, self.margin_lo, self.margin, self.cap

    def upper(self, mu, capped: bool = True):
        """Upper bound of the base's albedo at ``mu`` (any shape), as the kernel sees it (without
        the cap at 1 if not ``capped``).
        """
        mu = np.asarray(mu, dtype=np.float64)
        out = np.empty(mu.size)
        args = self.args() if capped else self.args()[:-1] + (math.inf,)
        upper_array(np.ascontiguousarray(mu.ravel()), *args, out)
        return out.reshape(mu.shape)


#: levels N.wo = 10^-k that a lobe about the normal adds where it carries a factor tabulated in log(N.wo) (the nested
#: and 2-D engines): g of a pumped level (the albedo table of the level below), 1 / U(N.wo) of a scaled model and
#: D(N.wo) of the Kulla-Conty lobe (``pumpup.compensate``).  Such a spline has features on every scale of N.wo down to
#: its table's smallest node; about the normal a level is one value of the radial variable, and those scales all lie in
#: the first grid's last interval, [7/8, 1] (N.wo < 0.21), whose 7- and 15-point rules agreed while both missed.  Scaled
#: Lafortune n = 148 (cx = cy = -1, cz = 1) at rtol 1e-6 was 1.14-1.56 x its estimate at every mu from 0.01 down to
#: 2.6e-6, the Kulla-Conty lobe of Phong n = 987 (f_avg 0.69) at rtol 1e-12 3.4 x on the 2-D engine, the fuzz's
#: reference (scripts/studies/fuzz_engines.py --registry 47), and g2 pumped Minnaert k = 0.31 at mu = 0.88 4.1 x at
#: every rtol from 1e-6 to 1e-12.  A lobe about another axis has N.wo vary along its
#: arcs, where the estimate held (levels there cut every arc: 1.2-2.5 x the time)
TABLE_DECADES = tuple(10.0 ** -k for k in range(1, 9))


def table_decades(b: Lobe) -> set:
    """:data:`TABLE_DECADES` for a hint ``b`` about the normal, or none: not for another axis, and not for the generic
    hint of a model without one (about the normal, the cosine map, not symmetric: :func:`pumpup.from_function`'s), which
    the 2-D engine's generic path integrates without trusting it (there the levels cost a pumped user function 12 x the
    time, and its estimate held without them against a ring quadrature).
    """
    return set(TABLE_DECADES) if b.axis == "normal" and not b.generic else set()


def _divided_lobe(b: Lobe, pumped: Pumped, mu: float) -> Lobe:
    """The hint of f / g for the hint ``b`` of f (a pumped model's base, or one term of its sum): b with g's kink levels
    at incidence ``mu`` and, about the normal, :func:`table_decades` (g is a table in log(N.wo)).
    """
    return b.with_levels(pumped.kink_levels(mu), table_decades(b))


@register("pumped")
class Pumped(BRDF):
    """One level of albedo pumping-up, f*(wi, wo) = f(wi, wo) / g(wi, wo) (001 eq. 16).

    Parameters
    ----------
    base : spec
        The BRDF to pump; it must be reciprocal (checked with :func:`check_reciprocity`)
        unless ``force`` is true.
    g : {"g1", "g2"}
        g1 = max(a(wi), a(wo)) (001 eq. 20); g2 = max(a(wi), a(wo), N.wi, N.wo), the
        controlled pumping-up (001 eq. 21).
    levels : int, >= 1
        ``levels`` > 1 builds nested levels (each pumping the one below); the object and
        its spec are then nested with one level each.
    force : bool
        Pump a base that ``check_reciprocity`` finds non-reciprocal.

    Notes
    -----
    a is the base's albedo table (:func:`base_table`), computed once per session or
    loaded with :func:`load_pumped`; g uses its upper bound, so the pumped albedo is at
    most 1.
    """

    params = {
        "base": Param(kind="spec", doc="the BRDF to pump"),
        "g": Param("g1", kind="str", choices=("g1", "g2"),
                   doc="g1 = max(a(wi), a(wo)) (001 eq. 20) or g2, also max with N.wi, N.wo (001 eq. 21)"),
        "levels": Param(1, lo=1, hi=MAX_LEVELS, kind="int",
                        doc="nested pumpings, each dividing by g of the level below"),
        "force": Param(False, kind="bool", doc="pump a base that is not reciprocal"),
    }
    constant = None

    def __init__(self, **kwargs):
        levels = kwargs.get("levels", 1)
        if "levels" in kwargs:  # checked before nesting (levels = 1e5 would recurse 1e5 deep)
            levels = self.params["levels"].check("pumped", "levels", levels)
        if isinstance(levels, (int, float)) and not isinstance(levels, bool) and levels > 1 and levels == int(levels):
            inner = dict(kwargs, levels=int(levels) - 1)
            kwargs = dict(kwargs, levels=1, base=Pumped(**inner))
        super().__init__(**kwargs)
        base = self.p["base"]
        if isinstance(base, Pumped):  # reciprocal by construction (or forced below)
            self.reciprocal = base.reciprocal
        else:
            r = check_reciprocity(base, n_mu=16, n_phi=16)
            self.reciprocal = bool(r.reciprocal and base.reciprocal)
            if not self.reciprocal and not self.p["force"]:
                raise SpecError(
                    f"pumped: the base {base.type!r} is not reciprocal ({r}); pumping needs a symmetric "
                    "BRDF (001 sec. 3). Pass force=True (--force on the command line) to pump it anyway."
                )
        self._lookup = None
        self._own_table = None  # a table loaded from a file serves this object only (load_pumped)
        self._init_lock = threading.RLock()

    def __getstate__(self):
        state = self.__dict__.copy()
        state.pop("_init_lock", None)  # a lock does not pickle
        return state

    def __setstate__(self, state):
        self.__dict__.update(state)
        self._init_lock = threading.RLock()

    @property
    def base(self) -> BRDF:
        """The BRDF this level divides by g."""
        return self.p["base"]

    @property
    def controlled(self) -> bool:
        """Whether g is g2 (001 eq. 21: the max also with N.wi and N.wo)."""
        return self.p["g"] == "g2"

    @property
    def spec(self) -> dict:
        """The model as a plain-JSON dict: the base, ``g``, and ``force`` where it is set (several levels are nested
        pumped specs).
        """
        out = {"type": "pumped", "base": self.base.spec, "g": self.p["g"]}
        if self.p["force"]:
            out["force"] = True
        return out

    @property
    def depth(self) -> int:
        """Number of pumping levels from the first non-pumped base."""
        return 1 + (self.base.depth if isinstance(self.base, Pumped) else 0)

    def table(self, progress: bool | None = None):
        """The albedo table of the base (the a in g): its own if it was loaded from a file
        (:func:`load_pumped`), else the session's shared one (:func:`base_table`).
        """
        own = getattr(self, "_own_table", None)
        return own if own is not None else base_table(self.base, progress=progress)

    def lookup(self) -> _Lookup:
        """The base table's upper bound in the compiled kernel's form, built once per object (thread-safe)."""
        if self._lookup is None:
            with self._init_lock:  # threads that evaluate a fresh object build it once
                if self._lookup is None:
                    self._lookup = _Lookup(self.table())
        return self._lookup

    def g(self, mu_i, mu_o) -> np.ndarray:
        """g(wi, wo) as a function of mu_i = N.wi and mu_o = N.wo (001 eq. 20, 21)."""
        up = self.lookup().upper
        g = np.maximum(up(mu_i), up(mu_o))  # 001 eq. 20
        if self.controlled:
            g = np.maximum(g, np.maximum(mu_i, mu_o))  # 001 eq. 21
        return g

    def divide(self, fbase, wi, wo) -> np.ndarray:
        """The quotient f / g (001 eq. 16) in plain numpy: the readable reference for :func:`_chain_kernel`."""
        mi = np.broadcast_to(wi[..., 2], fbase.shape)
        mo = np.broadcast_to(wo[..., 2], fbase.shape)
        up = (fbase > 0) & (mi > 0) & (mo > 0)
        with np.errstate(divide="ignore", invalid="ignore"):
            out = fbase / self.g(np.clip(mi, 1e-300, 1), np.clip(mo, 1e-300, 1))
        return np.where(up, out, 0.0)

    @property
    def delta_albedo(self):
        """The base's delta lobe pumped, or None if the base has none (he_torrance's specular part).

        A delta in the mirror direction of weight w(mu) (000 eq. 2 then picks wo = the mirror of wi,
        N.wo = N.wi = mu) is divided by g at that pair like the rest of f: its share of the pumped
        albedo is w(mu) / g(mu, mu) (001 eq. 16, 20, 21).  The bound still holds: the base's table,
        and so g >= a(mu), includes the delta, so (integral of f + w) / g <= a(mu) / a(mu) = 1.
        """
        base = self.base.delta_albedo
        if base is None:
            return None

        def delta(mu):
            mu = np.asarray(mu, dtype=np.float64)
            return np.asarray(base(mu), dtype=np.float64) / self.g(mu, mu)

        return delta

    @property
    def eval_rtol(self) -> float:
        """The base's relative error of eval (a truncated series), unchanged by the division by g."""
        return self.base.eval_rtol

    def chain(self) -> list[Pumped]:
        """The pumped levels from the innermost (level 1) to this one."""
        levels = [self]
        while isinstance(levels[-1].base, Pumped):
            levels.append(levels[-1].base)
        return levels[::-1]

    def _chain_args(self):
        """The upper bounds of all levels, concatenated for :func:`_chain_kernel` (built once)."""
        cache = getattr(self, "_chain_cache", None)
        if cache is not None:
            return cache
        with self._init_lock:  # built once, whole, before any thread sees it
            if getattr(self, "_chain_cache", None) is None:
                self._chain_cache = self._build_chain_args()
        return self._chain_cache

    def _build_chain_args(self):
        """:meth:`_chain_args`, computed."""
        looks = [lev.lookup() for lev in self.chain()]
        sizes = [len(lk.logx) for lk in looks]
        offsets = np.concatenate([[0], np.cumsum(sizes)]).astype(np.int64)
        coef = np.zeros((looks[0].coef.shape[0], offsets[-1]))
        index = np.zeros((len(looks), INDEX_CELLS), dtype=np.int64)
        lo = np.array([lk.logx[0] for lk in looks])
        h = np.array([(lk.logx[-1] - lk.logx[0]) / INDEX_CELLS for lk in looks])
        for j, (lk, a) in enumerate(zip(looks, offsets[:-1])):
            n = lk.coef.shape[1]
            coef[:, a:a + n] = lk.coef
            coef[-1, a:a + n] += lk.margin  # the same upper bound as upper_scalar
            starts = lo[j] + h[j] * np.arange(INDEX_CELLS)
            index[j] = a + np.clip(np.searchsorted(lk.logx, starts, side="right") - 1, 0, n - 1)
        return GChain(
            offsets, np.concatenate([lk.logx for lk in looks]), coef,
            *(np.array([getattr(lk, name) for lk in looks], dtype=float)
              for name in ("v0", "slope0", "margin_lo", "cap")),
            np.array([lev.controlled for lev in self.chain()]),
            np.array([lk.increasing for lk in looks]), np.array([lk.mu0 for lk in looks]),
            index, lo, 1.0 / h, *self._product_args(), *self._level_args(), *self._split_args(),
        )

    def product(self) -> _Product | None:
        """The fast path's table of the product of all levels' g (None unless every level's bound
        increases and the table reaches its tolerance; the kernel then looks up level by level).
        """
        def build():
            if not all(lev.lookup().increasing for lev in self.chain()):
                return None
            return _Product([lev.lookup() for lev in self.chain()], [lev.controlled for lev in self.chain()],
                            inverse=True)

        return self._built_once("_product", build)

    def level_table(self) -> _LevelTable | None:
        """The level table of the chain (:class:`_LevelTable`), where it has no product table (None where it has one,
        or where the level table cannot reach its tolerance: the kernel then looks up level by level).
        """
        def build():
            if self.product() is not None:
                return None
            return _LevelTable([lev.lookup() for lev in self.chain()], [lev.controlled for lev in self.chain()])

        return self._built_once("_levels_table", build)

    def split_table(self) -> _SplitTable | None:
        """The split table of the chain (:class:`_SplitTable`) where it has a level table of at least two levels (None
        otherwise, or where the split table cannot reach its tolerance: the kernel then takes the level table).  With
        one level the level table already takes one polynomial per direction.
        """
        def build():
            q = self.level_table()
            return _SplitTable(q) if q is not None and len(q.looks) >= 2 else None

        return self._built_once("_split_table", build)

    def _built_once(self, name: str, build):
        """The table ``build()`` returns (None where it raises _ProductError: the kernel then takes a slower path),
        built once and kept as attribute ``name``: another thread never sees a half-decided None (a race once made
        threaded values differ by 3e-14).
        """
        if not hasattr(self, name):
            with self._init_lock:
                if not hasattr(self, name):
                    try:
                        table = build()
                    except _ProductError:
                        table = None
                    setattr(self, name, table)
        return getattr(self, name)

    def _split_args(self):
        r = self.split_table()
        if r is None:  # off: split_cells = 0
            return _SPLIT_OFF
        return r.ncell, r.packed, r.fid, r.hid, r.shift, r.cbase, r.entries, r.lo, r.coef

    def _level_args(self):
        q = self.level_table()
        if q is None:  # off: qmlo = inf
            return (math.inf, CELL_SHIFT, 0, np.zeros(1, np.int64), np.full(2, math.inf),
                    np.zeros((1, 2 + PRODUCT_DEGREE + 1)))
        return q.mlo, q.shift, q.cbase, q.entries, q.lo, q.rows

    def _product_args(self):
        p = self.product()
        if p is None:  # off: pmlo = inf
            empty = np.zeros((1, PRODUCT_DEGREE + 3))
            return math.inf, 0, np.zeros(1, np.int64), np.full(2, math.inf), empty, empty
        return p.mlo, p.cbase, p.entries, p.lo, p.rows, p.inverse_rows

    #: pairs per pass when many are evaluated at once: the base's values and the directions are
    #: still in the cache when the chain kernel reads them (2e6 pairs, 3-level Phong: 26 -> 21 ns
    #: per pair, measured with scripts/bench/bench_eval.py)
    BLOCK = 8192

    def _eval(self, wi, wo, levelwise: bool = False):
        from ..core import slabs

        if not levelwise:  # the base's fused kernel: its value and the division in one pass (BRDF.eval_divided)
            out = self.chain()[0].base.eval_divided(wi, wo, self._chain_args())
            if out is not None:
                return out
        shape = np.broadcast_shapes(wi.shape[:-1], wo.shape[:-1])
        n = math.prod(shape)
        if n <= 2 * self.BLOCK:
            return self._eval_block(wi, wo, levelwise)
        if wi.shape == wo.shape and wi.flags.c_contiguous and wo.flags.c_contiguous:
            a, b = wi.reshape(-1, 3), wo.reshape(-1, 3)  # views
            out = np.empty(n)
            for s in range(0, n, self.BLOCK):
                out[s:s + self.BLOCK] = self._eval_block(a[s:s + self.BLOCK], b[s:s + self.BLOCK], levelwise)
            return out.reshape(shape)
        # broadcast (or strided) inputs: read-only views of the full shape, cut into slabs of about
        # BLOCK pairs along the leading axes; only a slab's directions are ever copied (a copy of
        # both arrays cost 4.6 GB for 1e8 pairs)
        a, b = np.broadcast_to(wi, shape + (3,)), np.broadcast_to(wo, shape + (3,))
        out = np.empty(shape)
        for idx in slabs(shape, self.BLOCK):
            out[idx] = self._eval_block(a[idx], b[idx], levelwise)
        return out

    def _eval_block(self, wi, wo, levelwise: bool = False):
        base = self.chain()[0].base
        f = base._eval(wi, wo)  # the innermost base, once
        own = (isinstance(f, np.ndarray) and f.dtype == np.float64 and f.flags.owndata and f.flags.c_contiguous
               and f.flags.writeable and getattr(base, "fn", None) is None)  # a user function's array is theirs
        shape = np.broadcast_shapes(wi.shape[:-1], wo.shape[:-1])
        if not own or f.shape != shape:
            f = np.array(np.broadcast_to(f, shape), dtype=np.float64)  # a copy we own
        if wi.shape[:-1] != shape or wo.shape[:-1] != shape:
            wi, wo = np.broadcast_to(wi, shape + (3,)), np.broadcast_to(wo, shape + (3,))  # read-only views
        # (n, 3) views of the directions when their strides allow it (the engine's do): no copies
        if levelwise:
            _chain_kernel_levelwise(f.reshape(-1), wi.reshape(-1, 3), wo.reshape(-1, 3),
                                    *self._chain_args()[:GChain._fields.index("product_inverse_rows")])
        else:
            _chain_kernel(f.reshape(-1), wi.reshape(-1, 3), wo.reshape(-1, 3), *self._chain_args())
        return f

    def _level_table_args(self):
        """:meth:`_chain_args` with the split table off (``split_cells`` = 0): the kernels take the level table where
        the split table would serve.
        """
        return self._chain_args()._replace(**dict(zip(GChain._fields[GChain._fields.index("split_cells"):],
                                                      _SPLIT_OFF)))

    def _eval_level_table(self, wi, wo):
        """f_r as :meth:`_eval` without the split table (:class:`_SplitTable`): every level's bound from the level
        table.  The baseline of the split table, for its tests (it divides by at least the split table's g) and
        scripts/bench/bench_eval.py.
        """
        wi, wo = np.asarray(wi, dtype=np.float64), np.asarray(wo, dtype=np.float64)
        args = self._level_table_args()
        out = self.chain()[0].base.eval_divided(wi, wo, args)
        if out is not None:
            return out
        f = np.array(np.broadcast_to(self.chain()[0].base._eval(wi, wo), np.broadcast_shapes(wi.shape[:-1],
                                                                                            wo.shape[:-1])))
        shape = f.shape
        _chain_kernel(f.reshape(-1), np.broadcast_to(wi, shape + (3,)).reshape(-1, 3),
                      np.broadcast_to(wo, shape + (3,)).reshape(-1, 3), *args)
        return f

    def _eval_levelwise(self, wi, wo):
        """f_r as :meth:`_eval` without the level table (:class:`_LevelTable`): where the chain has no product table,
        every level's bound looked up level by level (:func:`g_levels`).  The baseline of the level table, for its tests
        (it divides by at least the level table's g) and scripts/bench/bench_eval.py.
        """
        return self._eval(np.asarray(wi, dtype=np.float64), np.asarray(wo, dtype=np.float64), levelwise=True)

    def reference(self, wi, wo):
        """The plain numpy f_r: the base's reference divided by g (001 eq. 16)."""
        wi = np.asarray(wi, dtype=np.float64)
        wo = np.asarray(wo, dtype=np.float64)
        return self.divide(np.asarray(self.base.reference(wi, wo), dtype=np.float64), wi, wo)

    # --- hints for the albedo engine: the base's lobe plus the kinks of g ------------------
    def kink_levels(self, mu: float) -> tuple:
        """Values v of N.wo where g(mu, v) has a kink (roots on the tabulated albedo), or a jump (the
        table's first node, near grazing incidence).

        g is the max of U = u(mu), u(v) and, for g2, mu and v (u the upper bound of the base's
        albedo).  A kink is where the two largest terms cross: a crossing of two terms that lie
        below a third is no kink, and is dropped (for Phong, whose albedo is above mu, g2 has
        the kinks of g1 only; two spurious levels within 5e-4 of v = mu once made the cubature
        refine to rectangles of width 1e-16 there).
        """
        cache = self.lookup().__dict__.setdefault("kink_cache", {})  # tied to the bound they come from
        hit = cache.get(float(mu))
        if hit is not None:
            return hit
        if len(cache) > 4096:  # (a table of every level asks again at the same mu)
            cache.clear()
        out = cache[float(mu)] = self._kink_levels(float(mu))
        return out

    def _kink_fixed(self):
        """What :meth:`_kink_levels` needs at every mu, computed once per bound: the grid of the
        root search (the table's nodes and their midpoints), the bound on it, and the kinks that do not
        depend on mu: v where u(v) = v (g2) and where u(v) reaches its cap.
        """
        lk = self.lookup()
        hit = lk.__dict__.get("kink_fixed")
        if hit is not None:
            return hit
        up = lk.upper
        t = lk.table
        grid = np.unique(np.concatenate([t.mu, np.sqrt(t.mu[:-1] * t.mu[1:]), [1.0]]))
        au = up(grid)

        diag = []
        if self.controlled:  # (:meth:`_kink_levels` uses these where U(mu) <= 1, as the threshold assumes)
            vals = au - grid
            diag = _sign_roots(grid, np.where(np.abs(vals) < 1e-13, 0.0, vals), lambda u: float(up(u)) - u)
        caps = []
        if math.isfinite(lk.cap):
            caps = _sign_roots(grid, up(grid, capped=False) - lk.cap, lambda u: float(up(u, capped=False)) - lk.cap)
        lk.kink_fixed = out = (grid, au, diag, caps)
        return out

    def _kink_normal(self) -> list:
        """The incidences v < 1 where the bound u(v) equals u(1), its value at wo = N: there the set of wo whose bound
        exceeds u(v) (g1: where g = u(N.wo)) is born at the normal or vanishes, so this level's albedo has a near-kink
        at v (a jump of its second derivative) although no cut of g sits there for a wo (g2: only where u(1) > 1,
        below).  Only a bound that is not monotone has one (rough Ward's albedo falls from mu = 1 and rises again at
        grazing; a metal's has a minimum).  Without the break, a 2-level g1 pumped Ward m = 0.885 had its
        level-2 table bunch 37 nodes between v = 0.05 and 0.07 (4 with the break) and round the kink at 0.0605 off,
        and the nested engine was 1.6e-12 off at mu = 1 with an estimate of 8.1e-13.
        """
        lk = self.lookup()
        hit = lk.__dict__.get("kink_normal")
        if hit is None:
            grid, au = self._kink_turns()
            a1 = float(lk.upper(1.0))
            if self.controlled and a1 <= 1.0:
                # g2 at wo = N is max(u(v), v, u(1), 1) = max(u(v), 1): the set is born at the normal where u(v) = 1,
                # the cap's kink (:meth:`_kink_fixed`), not where u(v) = u(1)
                lk.kink_normal = []
                return []
            inner = grid < 1.0
            hit = lk.kink_normal = _sign_roots(grid[inner], au[inner] - a1, lambda u: float(lk.upper(u)) - a1)
        return hit

    def albedo_kinks(self, lo: float = 0.0, hi: float = 1.0) -> list:
        """The kinks in (lo, hi) of the albedo of this pumped level and of every level below it, and its innermost
        base's own (:meth:`pumpup.core.BRDF.albedo_breaks`), for its table's spline to be split there
        (:class:`pumpup.tables.AlbedoTable`'s breaks): the albedo at incidence v of a pumped level has a kink where the
        g of that level or of one below changes its form at incidences that do not depend on wo -- its bound crosses
        the diagonal, u(v) = v (g2), or reaches its cap (:meth:`_kink_fixed`).  One spline across them rounded them
        off between knots the adaptive grid bunched towards them, and the 1-D path cut the elevation at those knots
        (:meth:`table_kinks`): ~25 more pieces per mu in a 2-level g2 pumped GGX alpha 0.1.

        A base table (:func:`base_table`) asks for the kinks between the second and the next-to-last node of the grid
        it starts from (:func:`grid_interior`): Phong's, Beckmann's and stretched Phong's levels cross the diagonal
        within 3e-4 of mu = 1, inside the grid's last interval, where a piece of two or three nodes made a 3-level g2
        pumped Phong's third bound dip; those keep the one spline, and :meth:`table_kinks`' cuts at the knots bunched
        around them.  :func:`pumpup.mean_albedo`'s first intervals end at every kink in (0, 1).
        """
        chain = self.chain()
        out = {v for v in chain[0].base.albedo_breaks() if lo < v < hi}  # the innermost base's
        for lev in chain:
            out.update(v for v in lev._albedo_kinks() if lo < v < hi)
        return sorted(out)

    def _albedo_kinks(self) -> list:
        """The incidences where this level's albedo has a kink that does not depend on wo: its bound crosses the
        diagonal or reaches its cap (:meth:`_kink_fixed`), or equals its value at the normal (:meth:`_kink_normal`).
        """
        _, _, diag, caps = self._kink_fixed()
        return [float(v) for v in (*diag, *caps, *self._kink_normal())]

    def _kink_turns(self):
        """The root search's grid with the cells next to every turn of the bound on it split into 16 (those of a
        non-monotone base, metal's albedo with a minimum), and the bound there; once per bound (per mu it was 60 % of
        a 3-level g2 pumped GGX's build, 19,000 ``linspace`` calls).
        """
        lk = self.lookup()
        hit = lk.__dict__.get("kink_turns")
        if hit is None:
            grid, au, _, _ = self._kink_fixed()
            turn = np.nonzero(np.diff(np.sign(np.diff(au))) != 0)[0]
            cells = sorted(set(turn) | set(turn + 1))
            extra = [np.linspace(grid[i], grid[i + 1], 17)[1:-1] for i in cells if i + 1 < len(grid)]
            g = np.unique(np.concatenate([grid, *extra]))
            g = g[(g > 0) & (g <= 1.0)]
            hit = lk.kink_turns = (g, lk.upper(g))
        return hit

    def _kink_levels(self, mu: float) -> tuple:
        """:meth:`kink_levels`, computed (the parts that do not depend on mu once, :meth:`_kink_fixed`)."""
        lk = self.lookup()
        up = lk.upper
        grid, au, diag, caps = self._kink_fixed()
        am = float(up(mu))
        out = [mu]  # u(v) = U at v = mu, or (g2) v = mu against U: a kink either way
        if self.controlled and float(up(am)) <= am * (1 + 1e-12) and am >= mu * (1 - 1e-12):
            out.append(am)  # v = U, where v and U are the two largest
        for k in ((0, 1, 2) if self.controlled else (0,)):
            if k == 1 and am <= 1.0:
                found = diag  # u(v) = v, found once (with the threshold below at am <= 1)
            else:
                # two roots in one cell show no sign change there: where u turns (a non-monotone base, metal's albedo
                # with a minimum), the cells next to the turn are searched on 16 points each (:meth:`_kink_turns`), and
                # for k = 0 the cell of mu (a root itself) is split at mu -+ 1e-6 of it: a pumped metal
                # (eta 0.9, k 0.3, n 20) lost the kink at v = 0.9699 next to mu = 0.9659 and the 1-D path was 5.0e-9 off
                # with an estimate of 1.0e-9.  The search is compiled (:func:`kink_roots`)
                g, ug = (grid, au) if k == 1 else self._kink_turns()
                found = [float(v) for v in kink_roots(g, ug, k, am if k == 0 else mu, mu, max(1.0, am), *lk.args())]
            for v in found:
                if self.controlled:
                    # the crossing value c and the terms that are not crossing there
                    c, others = [(am, (mu, v)), (v, (am, mu)), (mu, (am, v))][k]
                    if c < max(others) * (1 - 1e-12):
                        continue  # both crossing terms are below a third: g has no kink here
                out.append(v)
        if math.isfinite(lk.cap) and am < lk.cap * (1 - 1e-12):
            # u(v) reaches its cap (1 where the base conserves energy): there u(v) is the largest term
            # (the others are U < cap and mu, v <= 1), so g has a kink (the product table's _kinks
            # has it too); the capped u is flat beyond it, so the roots above do not see it
            out += caps
        if lk.mu0 < 1.0 and mu < 1e3 * lk.mu0:
            # below the table's first node the bound is a power law with its own margin: it jumps there
            # (by margin_lo - margin, ~1e-8 of it), which matters where N.wo that small carries weight, at
            # incidence within 1e3 of it (the 1-D path was 7.5e-11 off at mu = 1e-8 without the cut,
            # estimate 5.2e-11: 3-level g1 stretched Phong n = 3); further up its share is below 1e-14
            out.append(lk.mu0)
        for p, q, value in lk.flats:  # mu on a flat piece of the bound: u(v) = U up to its end q
            if p <= mu <= q and value < lk.cap:
                out.append(q)
        # the table's breaks (its spline's split points: the base's albedo_breaks, Cook-Torrance's
        # pumpup.models.cook_torrance.RETRO_BREAK, and a lower level's kinks) are kinks of u(v), so of g where u(v) is
        # its largest term
        for v in lk.table.breaks:
            uv = float(up(v))
            if uv >= am * (1 - 1e-12) and (not self.controlled or uv >= max(mu, v) * (1 - 1e-12)):
                out.append(v)
        levels = []
        for u in sorted(out):  # one level per kink: roots that agree to 1e-12 are the same kink
            if 0 < u < 1 and (not levels or u - levels[-1] > 1e-12 * u):
                levels.append(u)
        return tuple(levels)

    def table_kinks(self) -> tuple:
        """Values v of N.wo where a level's bound u(v) has a near-kink: a level's table is the albedo of the level
        below, whose g changes form at incidences that do not depend on wo (where a lower level's bound crosses the
        diagonal, u(v) = v for g2, or reaches its cap: :meth:`_kink_fixed`), so every higher level's table inherits
        those kinks.  Its spline follows each with knots bunched towards it (the table's refinement), and rounds the
        kink off between the nearest ones (1e-6 wide at level 1's u(v) = v, v = 0.98814, of a 2-level g2 pumped GGX,
        alpha 0.1, height-correlated): a feature that no rule on a piece across those knots sees (at mu = 0.993068
        6.4e-8 off on one piece of the elevation, 9.6 x its |K - G|; with a cut at the kink but not at the knots,
        Beckmann alpha 0.3 at mu = 0.99888 was 2.1e-12 off on the piece beside it, 4.8 x the estimate).  So these are
        the kinks and, in every table above them, a graded mesh of the knots of the bunch around each (those closer than
        a quarter of the table's median spacing in log(v)): on each side the nearest knot, then every knot at least
        twice as far from the kink as the last one kept, and the bunch's last (the pieces between grow geometrically
        away from the feature, as for a singularity; every knot of the bunch cost 2 x 50 cuts and 3000 evaluations per
        mu).
        """
        lk = self.lookup()  # (tied to the bounds they come from, as kink_cache)
        hit = lk.__dict__.get("table_kinks")
        if hit is None:
            out, kinks = set(), []
            for lev in self.chain():
                logx = lev.lookup().logx
                if kinks and len(logx) > 2:
                    small = 0.25 * float(np.median(np.diff(logx)))
                    for v in kinks:
                        i = int(np.searchsorted(logx, math.log(v)))
                        lo, hi = max(i - 1, 0), min(i, len(logx) - 1)
                        while lo > 0 and logx[lo] - logx[lo - 1] < small:
                            lo -= 1
                        while hi < len(logx) - 1 and logx[hi + 1] - logx[hi] < small:
                            hi += 1
                        lv = math.log(v)
                        for side in (logx[lo:i][::-1], logx[i:hi + 1]):  # nearest first
                            last = 0.0
                            for j, x in enumerate(side):
                                d = abs(x - lv)
                                if d > 0 and (last == 0.0 or d >= 2.0 * last or j == len(side) - 1):
                                    out.add(math.exp(x))
                                    last = d
                kinks += [v for v in lev._albedo_kinks() if 0.0 < v < 1.0]
            out |= set(kinks)
            hit = lk.table_kinks = tuple(sorted(v for v in out if 0.0 < v < 1.0))
        return hit

    def _hint_levels(self, mu: float) -> tuple:
        """The 1-D path's levels of g at incidence mu: the lobe's (:meth:`lobe`) and :meth:`table_kinks` (the nested
        engine, whose estimate was calibrated without them, keeps the lobe's alone).  The lobe's levels are every
        level's :meth:`kink_levels` and the innermost base's lobe levels, gathered here without the Lobe of every level
        (this runs for every mu of a table, in Python: the Lobes and their sorts took ~15 % of a cached 2-level table).
        """
        out = set(self.table_kinks())
        cur = self
        while isinstance(cur, Pumped):
            out.update(cur.kink_levels(mu))
            cur = cur.base
        out.update(cur.lobe(mu).levels)
        return tuple(sorted(out))

    def lobe(self, mu: float) -> Lobe:
        """The base's Lobe hint with g's kink levels at ``mu`` and, about the normal, the table's decades."""
        return _divided_lobe(self.base.lobe(mu), self, mu)

    def sampling_lobe(self, mu: float) -> Lobe:
        """The base's sampling hint (f / g has the lobe of f; g only rescales it)."""
        return self.base.sampling_lobe(mu)  # f / g has the lobe of f; g only rescales it

    def azimuth_hint(self):
        """The innermost base's hint divided by g_1 ... g_k (mu, N.wo) (001 eq. 16), a function of N.wo for a fixed wi,
        with g's kinks (:class:`~pumpup.core.hints.DivideByG`); None where the base has no hint.
        """
        from ..core.hints import DivideByG

        hint = self.chain()[0].base.azimuth_hint()
        return None if hint is None else hint.times(DivideByG(self._chain_args(), self._hint_levels))

    def azimuth_range(self):
        """The base's (g depends on N.wi and N.wo only)."""
        return self.base.azimuth_range()  # g depends on N.wi and N.wo only

    def albedo_terms(self):
        """Itself for a base of one term, else each of the base's terms divided by the same g."""
        terms = self.base.albedo_terms()
        if len(terms) == 1 and terms[0][1] is self.base:
            return [(1.0, self)]
        return [(w, _Divided(t, self)) for w, t in terms]


class _Divided(BRDF):
    """One linear term of a pumped sum, f_k / g (the albedo engine integrates it alone)."""

    type = "pumped-term"
    params = {}

    def __init__(self, term: BRDF, pumped: Pumped):
        self.p = {}
        self.term, self.pumped = term, pumped
        self.reciprocal = term.reciprocal

    @property
    def spec(self):
        return {"type": "pumped-term", "term": self.term.spec, "of": self.pumped.spec}

    def _eval(self, wi, wo):
        return self.pumped.divide(np.asarray(self.term._eval(wi, wo), dtype=np.float64), wi, wo)

    def sampling_lobe(self, mu):
        return self.term.sampling_lobe(mu)

    def azimuth_range(self):
        return self.term.azimuth_range()

    def lobe(self, mu):
        return _divided_lobe(self.term.lobe(mu), self.pumped, mu)


def pump(brdf: BRDF | dict, g: str = "g1", levels: int = 1, force: bool = False,
         max_seconds: float | None = None) -> Pumped:
    """Pump up the albedo of a symmetric BRDF (001 sec. 3), ``levels`` times.

    Parameters
    ----------
    brdf : BRDF or spec
        Reciprocal (checked); any symmetric function will do, even one that does not
        conserve energy: the first pumping makes it plausible (001, after eq. 17).  A
        spectral model or spec gives a :class:`pumpup.spectral.SpectralPumped`, each
        wavelength divided by its own g.
    g : {"g1", "g2"}
        The correction term: g1 (001 eq. 20) or the controlled g2 (001 eq. 21).
    levels : int
        Number of nested pumpings; each uses the albedo of the level below.
    force : bool
        Accept a base that :func:`pumpup.check_reciprocity` finds non-reciprocal.
    max_seconds : float, optional
        A time budget: the tables of every level are computed now (by default, on first use), and past the budget
        the work stops with :class:`pumpup.core.budget.BudgetExceeded` (a TimeoutError) instead of running on.

    Returns
    -------
    Pumped
        A BRDF: ``pump(pump(f))`` works and ``pumped.spec`` is a nested spec.

    Examples
    --------
    >>> import pumpup
    >>> f = pumpup.pump(pumpup.load({"type": "phong", "n": 20}), g="g2", levels=2)
    >>> f.spec["base"]["type"], f.depth
    ('pumped', 2)
    """
    if g not in ("g1", "g2"):
        raise SpecError(f"pump: g must be 'g1' or 'g2', got {g!r}")
    if isinstance(levels, bool) or not isinstance(levels, (int, np.integer)) or not 1 <= levels <= MAX_LEVELS:
        raise SpecError(f"pump: levels must be an integer in [1, {MAX_LEVELS}], got {levels!r}")
    if not isinstance(force, (bool, np.bool_)):
        raise SpecError(f"pump: force must be true or false, got {force!r}")
    check_max_seconds("pump", max_seconds)
    pumped = pump_model(load(brdf), g, int(levels), force)
    if max_seconds is not None:
        with time_budget("pump", max_seconds):
            prepare(pumped)
    return pumped


def prepare(f) -> None:
    """Compute the tables ``f`` reads (a pumped or compensated BRDF builds them on first use): one evaluation."""
    normal = np.array([0.0, 0.0, 1.0])
    f.eval(normal, normal)


@functools.singledispatch
def pump_model(base, g: str, levels: int, force) -> Pumped:
    """:func:`pump` of a loaded model, its arguments checked: a :class:`Pumped`.  Other kinds of model register their
    own (:mod:`pumpup.spectral`: each wavelength divided by its own g).
    """
    return Pumped(base=base, g=g, levels=levels, force=force)


# --- saving and loading: one netCDF file, a group per level -----------------------------------


@functools.singledispatch
def save_pumped(f: Pumped, path: str | os.PathLike[str]) -> str:
    """Write a pumped BRDF and the albedo tables of all its levels to one netCDF file.

    Group ``level1`` holds the table of the innermost base, ``level2`` that of the first
    pumped level, and so on up to the pumped BRDF itself (``level<levels + 1>``: its albedo curve,
    ``pumpup.open_table(path, group=f"level{levels + 1}")``); the root attributes hold the spec.
    Written atomically.
    """
    import xarray as xr

    from .._version import __version__

    if not isinstance(f, Pumped):
        raise TypeError("save_pumped needs a pumped BRDF (pumpup.pump)")
    chain = []
    cur = f
    while isinstance(cur, Pumped):
        chain.append(cur)
        cur = cur.base
    chain.reverse()  # innermost first
    from ..tables import write_groups

    root = xr.Dataset(attrs={"pumpup_kind": "pumpup pumped BRDF", "spec": json.dumps(f.spec, sort_keys=True),
                             "levels": len(chain), "pumpup_version": __version__})
    groups = [(f"level{i}", level.table().dataset) for i, level in enumerate(chain, start=1)]
    groups.append((f"level{len(chain) + 1}", base_table(f).dataset))  # the top level's own albedo
    return write_groups(path, root, groups)


def load_pumped(path: str | os.PathLike[str]) -> Pumped:
    """Load a pumped BRDF saved by :func:`save_pumped`, without recomputing its tables.

    The file is validated (:func:`pumpup.open_table` for the root and every level's group; the
    levels' specs must be the chain of the root's spec).  Its tables serve only the returned
    object: they never enter the session's shared cache, so an edited file cannot change what
    later ``pump()`` calls on the same base compute.

    Raises
    ------
    pumpup.tables.validate.TableError (a ValueError)
        If the file is damaged, edited, or not a saved pumped BRDF (the message says what).
    """
    from ..tables import snapshot

    with snapshot(path) as copy:  # every group from one file, whatever a concurrent save puts at path meanwhile
        return _load_pumped(copy, os.fspath(path))


def _load_pumped(path: str, where: str) -> Pumped:
    """:func:`load_pumped` of the file at ``path`` (a snapshot), named ``where`` in messages."""
    from ..tables import open_table
    from ..tables.validate import TableError, spec_attribute

    root = open_table(path, _container=True, _name=where)  # (the saved BRDF's root)
    registry()  # (the providers: a kind of file below may be theirs)
    other = FILE_KINDS.get(root.attrs.get("pumpup_kind"))
    if other is not None:  # another kind of pumped model's file (pumpup.spectral's, with a wavelength dimension)
        return other(path, root, where)
    if root.attrs.get("pumpup_kind") != "pumpup pumped BRDF":
        raise TableError(f"{where!r} is a pumpup table, not a saved pumped BRDF")
    spec = spec_attribute(where, root)
    try:
        f = load(spec)
    except (SpecError, ValueError, TypeError) as exc:
        raise TableError(f"{where!r}: its spec does not load: {exc}") from None
    if not isinstance(f, Pumped):
        raise TableError(f"{where!r}: its spec is a {spec.get('type')!r}, not a pumped BRDF")
    chain = f.chain()  # innermost first, as the groups level1, level2, ...
    levels = int(np.asarray(root.attrs["levels"]).item())
    if levels != len(chain):
        raise TableError(f"{where!r}: attribute 'levels' = {levels} but its spec has {len(chain)} levels")
    for i, level in enumerate(chain, start=1):
        attach_level_table(path, where, f"level{i}", level, f"level {i} of the spec")
    attach_top_table(path, where, f"level{len(chain) + 1}", f)
    return f


def attach_top_table(path, where: str, group: str, f: Pumped) -> None:
    """Read the albedo table of the pumped BRDF ``f`` itself from ``group`` of a saved pumped file where the file has
    that group (files saved before it was written have not), and make it the table that pumping ``f`` again uses;
    checked as :func:`attach_level_table` checks a level's.
    """
    import netCDF4

    with netCDF4.Dataset(path) as nc:  # (path: the loader's snapshot, validated by its reader already)
        node = nc
        for name in group.split("/"):
            node = node.groups.get(name) if node is not None else None
        present = node is not None
    if present:
        f._derived_table = read_level_table(path, where, group, f.spec, "the pumped BRDF is")


def attach_level_table(path, where: str, group: str, level: Pumped, what: str) -> None:
    """Read the albedo table in ``group`` of a saved pumped file, check that it is the table of
    ``level``'s base (``what`` names the level in the message) and make it that object's own table;
    every problem is one :class:`TableError` naming the file and the group.
    """
    level._own_table = read_level_table(path, where, group, level.base.spec, f"{what} pumps")  # never the shared cache


def read_level_table(path, where: str, group: str, spec: dict, what: str):
    """The :class:`~pumpup.tables.AlbedoTable` in ``group`` of a saved pumped file, checked to be the table of the
    model ``spec`` (``what``: the message's words before the spec); every problem is one :class:`TableError` naming
    the file and the group.
    """
    from ..tables import AlbedoTable, open_table
    from ..tables.validate import TableError

    try:
        ds = open_table(path, group=group, _name=where)
    except OSError as exc:  # a missing group
        raise TableError(f"{where!r}: group {group!r} is missing or unreadable: {exc}") from None
    if ds.attrs.get("pumpup_kind") != "pumpup albedo table":
        raise TableError(f"{where!r}: group {group!r} is not an albedo table")
    if json.loads(ds.attrs["spec"]) != spec:
        raise TableError(f"{where!r}: group {group!r} holds the table of {ds.attrs['spec']}, but {what} "
                         f"{json.dumps(spec, sort_keys=True)}")
    try:
        t = AlbedoTable.from_dataset(ds)
    except (ValueError, KeyError, TypeError) as exc:
        raise TableError(f"{where!r}: group {group!r}: {exc}") from None
    t.dataset = ds
    return t
