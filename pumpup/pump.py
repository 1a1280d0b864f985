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
"""

from __future__ import annotations

import json
import math
import os

import numpy as np
from numba import njit

from .core import BRDF, Lobe, Param, SpecError, check_reciprocity, load, register

__all__ = ["pump", "Pumped", "save_pumped", "load_pumped", "base_table"]

#: accuracy of the albedo tables that pumped BRDFs divide by: g is an upper bound that exceeds
#: the albedo by about 2 x TABLE_INTERP_TOL, so the pumped albedo is lower than the ideal by
#: that much (relative); tighter tolerances cost 3 x more time per table, looser ones save 2-4 x
#: (README); keep TABLE_RTOL <= TABLE_INTERP_TOL / 100, or quadrature noise makes the grid refine
#: (1e-8 with 1e-7: 6 x slower, measured)
TABLE_RTOL = 1e-9
TABLE_INTERP_TOL = 1e-7

_TABLES: dict[str, object] = {}  # JSON spec of a base -> AlbedoTable (computed once per session)


def _key(brdf: BRDF) -> str:
    """Cache key of a base: its spec (and, for a user function, which function object)."""
    key = json.dumps(brdf.spec, sort_keys=True)
    fn = getattr(brdf, "fn", None)
    return key if fn is None else f"{key}#{id(fn)}"


def base_table(base: BRDF, progress: bool | None = None):
    """The albedo table of ``base`` used by the pumping operator (cached per session)."""
    from .tables import AlbedoTable, tabulate

    key = _key(base)
    if key not in _TABLES:
        ds = tabulate(base, rtol=TABLE_RTOL, interp_tol=TABLE_INTERP_TOL, progress=progress)
        _TABLES[key] = AlbedoTable.from_dataset(ds)
        _TABLES[key].dataset = ds
    return _TABLES[key]


# --- the compiled look-up: upper bound of a(mu) from the spline pieces ---------------------


@njit(cache=True)
def _upper_scalar(mu, logx, coef, v0, slope0, margin_lo, margin, cap):  # pragma: no cover - compiled
    """Upper bound of a(mu): the table's spline piece in log(mu) (power law below the first node) + margin,
    at most ``cap``."""
    return _upper_log(math.log(mu), logx, coef, v0, slope0, margin_lo, margin, cap)


@njit(cache=True)
def _upper_log(lm, logx, coef, v0, slope0, margin_lo, margin, cap):  # pragma: no cover - compiled
    """:func:`_upper_scalar` of mu = exp(lm) (binary search for the piece)."""
    n = logx.shape[0]
    if lm <= logx[0]:
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


@njit(cache=True)
def _upper_array(mu, logx, coef, v0, slope0, margin_lo, margin, cap, out):  # pragma: no cover - compiled
    for k in range(mu.shape[0]):
        out[k] = _upper_scalar(mu[k], logx, coef, v0, slope0, margin_lo, margin, cap)


#: cells of the uniform index over log(mu) that the chain kernel uses to find a table interval
_INDEX_CELLS = 4096


@njit(cache=True)
def _chain_kernel(f, wi, wo, offsets, logx, coef, v0, slope0, margin_lo, cap, controlled, increasing, mu0,
                  index, index_lo, index_h_inv):  # pragma: no cover - compiled
    """All levels of a pumped chain in one pass: f / (g_1 g_2 ... g_k) (001 eq. 16), in place.

    The tables of the levels are concatenated (level j owns nodes offsets[j]:offsets[j+1]);
    ``coef`` holds the upper bound (spline + margin, as :func:`_upper_scalar`) and a uniform
    index over log(mu) finds the piece in O(1).  Where a level's bound is non-decreasing
    (``increasing``, :meth:`AlbedoTable.is_increasing`) and both cosines lie on its spline
    (above ``mu0``), max(u(mu_i), u(mu_o)) = u(max(mu_i, mu_o)): one look-up serves the level.
    ``wi`` and ``wo`` are (n, 3) arrays of any strides (no copies).  The look-up is written
    out here rather than called (a call per look-up cost 20 x the look-up, measured).  Tested
    against the plain numpy reference, :meth:`Pumped.reference`, which pumps level by level.
    """
    ncell = index.shape[1]
    for k in range(f.shape[0]):
        mi, mo = wi[k, 2], wo[k, 2]
        if f[k] == 0.0 or mi <= 0.0 or mo <= 0.0:
            f[k] = 0.0
            continue
        mmax, mmin = max(mi, mo), min(mi, mo)
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
                if lm <= logx[a]:
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
        f[k] = f[k] / g_all  # 001 eq. 16, all levels


class _Lookup:
    """The table's upper bound in the flat form the compiled kernel takes."""

    def __init__(self, table):
        t = table
        self.logx = np.ascontiguousarray(t._spline.x)  # the breakpoints of the spline pieces, in log(mu)
        self.coef = np.ascontiguousarray(t._spline.c)
        self.margin, self.margin_lo = t.margin, t.margin_below  # as in AlbedoTable.upper
        self.increasing = t.is_increasing()
        self.mu0 = float(t.mu[0])
        self.v0, self.slope0 = float(t.value[0]), t.slope_below
        # 001 eq. 17 asks max(a(L), a(V)) <= g <= 1.  The upper bound can exceed 1 by its
        # margin where a = 1, which would lower the albedo there (a* < a): cap g at 1 when the
        # table says the base conserves energy.  A base that reflects more than it receives
        # (a > 1 beyond its error) cannot meet both sides; then g stays >= a so that the first
        # pumping makes it plausible (001, after eq. 17).
        self.cap = 1.0 if float(np.max(t.value - t.error)) <= 1.0 else math.inf
        self.table = t

    def args(self):
        return self.logx, self.coef, self.v0, self.slope0, self.margin_lo, self.margin, self.cap

    def upper(self, mu):
        """Upper bound of the base's albedo at ``mu`` (any shape), as the kernel sees it."""
        mu = np.asarray(mu, dtype=np.float64)
        out = np.empty(mu.size)
        _upper_array(np.ascontiguousarray(mu.ravel()), *self.args(), out)
        return out.reshape(mu.shape)


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
        "g": Param("g1", kind="str", choices=("g1", "g2")),
        "levels": Param(1, lo=1, kind="int"),
        "force": Param(False, kind="bool"),
    }
    constant = None

    def __init__(self, **kwargs):
        levels = kwargs.get("levels", 1)
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
                    "BRDF (001 sec. 3). Pass force=True to pump it anyway."
                )
        self._lookup = None

    @property
    def base(self) -> BRDF:
        return self.p["base"]

    @property
    def controlled(self) -> bool:
        return self.p["g"] == "g2"

    @property
    def spec(self) -> dict:
        out = {"type": "pumped", "base": self.base.spec, "g": self.p["g"]}
        if self.p["force"]:
            out["force"] = True
        return out

    @property
    def depth(self) -> int:
        """Number of pumping levels from the first non-pumped base."""
        return 1 + (self.base.depth if isinstance(self.base, Pumped) else 0)

    def table(self, progress: bool | None = None):
        """The albedo table of the base (the a in g)."""
        return base_table(self.base, progress=progress)

    def lookup(self) -> _Lookup:
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
        """f / g (001 eq. 16) in plain numpy: the readable reference for :func:`_chain_kernel`."""
        mi = np.broadcast_to(wi[..., 2], fbase.shape)
        mo = np.broadcast_to(wo[..., 2], fbase.shape)
        up = (fbase > 0) & (mi > 0) & (mo > 0)
        with np.errstate(divide="ignore", invalid="ignore"):
            out = fbase / self.g(np.clip(mi, 1e-300, 1), np.clip(mo, 1e-300, 1))
        return np.where(up, out, 0.0)

    def chain(self) -> list["Pumped"]:
        """The pumped levels from the innermost (level 1) to this one."""
        levels = [self]
        while isinstance(levels[-1].base, Pumped):
            levels.append(levels[-1].base)
        return levels[::-1]

    def _chain_args(self):
        """The upper bounds of all levels, concatenated for :func:`_chain_kernel` (built once)."""
        if getattr(self, "_chain_cache", None) is None:
            looks = [lev.lookup() for lev in self.chain()]
            sizes = [len(lk.logx) for lk in looks]
            offsets = np.concatenate([[0], np.cumsum(sizes)]).astype(np.int64)
            coef = np.zeros((looks[0].coef.shape[0], offsets[-1]))
            index = np.zeros((len(looks), _INDEX_CELLS), dtype=np.int64)
            lo = np.array([lk.logx[0] for lk in looks])
            h = np.array([(lk.logx[-1] - lk.logx[0]) / _INDEX_CELLS for lk in looks])
            for j, (lk, a) in enumerate(zip(looks, offsets[:-1])):
                n = lk.coef.shape[1]
                coef[:, a:a + n] = lk.coef
                coef[-1, a:a + n] += lk.margin  # the same upper bound as _upper_scalar
                starts = lo[j] + h[j] * np.arange(_INDEX_CELLS)
                index[j] = a + np.clip(np.searchsorted(lk.logx, starts, side="right") - 1, 0, n - 1)
            self._chain_cache = (
                offsets, np.concatenate([lk.logx for lk in looks]), coef,
                *(np.array([getattr(lk, name) for lk in looks], dtype=float)
                  for name in ("v0", "slope0", "margin_lo", "cap")),
                np.array([lev.controlled for lev in self.chain()]),
                np.array([lk.increasing for lk in looks]), np.array([lk.mu0 for lk in looks]),
                index, lo, 1.0 / h,
            )
        return self._chain_cache

    def _eval(self, wi, wo):
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
        _chain_kernel(f.reshape(-1), wi.reshape(-1, 3), wo.reshape(-1, 3), *self._chain_args())
        return f

    def reference(self, wi, wo):
        wi = np.asarray(wi, dtype=np.float64)
        wo = np.asarray(wo, dtype=np.float64)
        return self.divide(np.asarray(self.base.reference(wi, wo), dtype=np.float64), wi, wo)

    # --- hints for the albedo engine: the base's lobe plus the kinks of g ------------------
    def kink_levels(self, mu: float) -> tuple:
        """Values v of N.wo where g(mu, v) has a kink (roots on the tabulated albedo).

        g is the max of U = u(mu), u(v) and, for g2, mu and v (u the upper bound of the base's
        albedo).  A kink is where the two largest terms cross: a crossing of two terms that lie
        below a third is no kink, and is dropped (for Phong, whose albedo is above mu, g2 has
        the kinks of g1 only; two spurious levels within 5e-4 of v = mu once made the cubature
        refine to rectangles of width 1e-16 there).
        """
        from scipy.optimize import brentq

        up = self.lookup().upper
        t = self.lookup().table
        am = float(up(mu))
        grid = np.unique(np.concatenate([t.mu, np.sqrt(t.mu[:-1] * t.mu[1:]), [1.0]]))
        au = up(grid)
        funcs = [lambda u: float(up(u)) - am]
        if self.controlled:
            funcs += [lambda u: float(up(u)) - u, lambda u: float(up(u)) - mu]
        out = [mu]  # u(v) = U at v = mu, or (g2) v = mu against U: a kink either way
        if self.controlled and float(up(am)) <= am * (1 + 1e-12) and am >= mu * (1 - 1e-12):
            out.append(am)  # v = U, where v and U are the two largest
        for k, fn in enumerate(funcs):
            vals = au - am if k == 0 else (au - grid if k == 1 else au - mu)
            vals = np.where(np.abs(vals) < 1e-13 * max(1.0, am), 0.0, vals)  # rounding of a flat spline: no root
            idx = np.nonzero(np.sign(vals[:-1]) * np.sign(vals[1:]) < 0)[0]
            for i in idx:
                v = brentq(fn, grid[i], grid[i + 1], xtol=1e-15)
                if self.controlled:
                    # the crossing value c and the terms that are not crossing there
                    c, others = [(am, (mu, v)), (v, (am, mu)), (mu, (am, v))][k]
                    if c < max(others) * (1 - 1e-12):
                        continue  # both crossing terms are below a third: g has no kink here
                out.append(v)
        levels = []
        for u in sorted(out):  # one level per kink: roots that agree to 1e-12 are the same kink
            if 0 < u < 1 and (not levels or u - levels[-1] > 1e-12 * u):
                levels.append(u)
        return tuple(levels)

    def lobe(self, mu: float) -> Lobe:
        b = self.base.lobe(mu)
        return Lobe(axis=b.axis, radial=b.radial, sharpness=b.sharpness,
                    levels=tuple(sorted(set(b.levels) | set(self.kink_levels(mu)))),
                    kinks=b.kinks, symmetric=b.symmetric)

    def sampling_lobe(self, mu: float) -> Lobe:
        return self.base.sampling_lobe(mu)  # f / g has the lobe of f; g only rescales it

    def albedo_terms(self):
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

    def lobe(self, mu):
        b = self.term.lobe(mu)
        return Lobe(axis=b.axis, radial=b.radial, sharpness=b.sharpness,
                    levels=tuple(sorted(set(b.levels) | set(self.pumped.kink_levels(mu)))),
                    kinks=b.kinks, symmetric=b.symmetric)


def pump(brdf: BRDF | dict, g: str = "g1", levels: int = 1, force: bool = False) -> Pumped:
    """Pump up the albedo of a symmetric BRDF (001 sec. 3), ``levels`` times.

    Parameters
    ----------
    brdf : BRDF or spec
        Reciprocal (checked); any symmetric function will do, even one that does not
        conserve energy: the first pumping makes it plausible (001, after eq. 17).
    g : {"g1", "g2"}
        The correction term: g1 (001 eq. 20) or the controlled g2 (001 eq. 21).
    levels : int
        Number of nested pumpings; each uses the albedo of the level below.
    force : bool
        Accept a base that :func:`pumpup.check_reciprocity` finds non-reciprocal.

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
    if isinstance(levels, bool) or not isinstance(levels, (int, np.integer)) or levels < 1:
        raise SpecError(f"pump: levels must be an integer >= 1, got {levels!r}")
    base = load(brdf)
    return Pumped(base=base, g=g, levels=int(levels), force=force)


# --- saving and loading: one netCDF file, a group per level -----------------------------------


def save_pumped(f: Pumped, path) -> str:
    """Write a pumped BRDF and the albedo tables of all its levels to one netCDF file.

    Group ``level1`` holds the table of the innermost base, ``level2`` that of the first
    pumped level, and so on; the root attributes hold the spec.  Written atomically.
    """
    import xarray as xr

    from ._version import __version__

    if not isinstance(f, Pumped):
        raise TypeError("save_pumped needs a pumped BRDF (pumpup.pump)")
    chain = []
    cur = f
    while isinstance(cur, Pumped):
        chain.append(cur)
        cur = cur.base
    chain.reverse()  # innermost first
    from .tables import atomic_path

    with atomic_path(path) as tmp:
        root = xr.Dataset(attrs={"pumpup_kind": "pumpup pumped BRDF", "spec": json.dumps(f.spec, sort_keys=True),
                                 "levels": len(chain), "pumpup_version": __version__})
        root.to_netcdf(tmp, mode="w", engine="netcdf4")
        for i, level in enumerate(chain, start=1):
            base_table(level.base)
            ds = _TABLES[_key(level.base)].dataset
            ds.to_netcdf(tmp, mode="a", group=f"level{i}", engine="netcdf4")
    return os.fspath(path)


def load_pumped(path) -> Pumped:
    """Load a pumped BRDF saved by :func:`save_pumped`, without recomputing its tables."""
    from .tables import AlbedoTable, open_table

    root = open_table(path)
    if root.attrs.get("pumpup_kind") != "pumpup pumped BRDF":
        raise ValueError(f"{os.fspath(path)!r} is a pumpup table, not a saved pumped BRDF")
    for i in range(1, int(root.attrs["levels"]) + 1):
        ds = open_table(path, group=f"level{i}")
        t = AlbedoTable.from_dataset(ds)
        t.dataset = ds
        _TABLES[_key(load(json.loads(ds.attrs["spec"])))] = t
    return load(json.loads(root.attrs["spec"]))
