"""Albedo tables: tabulation on an adaptive grid, interpolation with a stated error, netCDF
files, mean albedo and maximum constants.

A table is an ``xarray.Dataset`` with the data variables ``albedo`` and ``albedo_error``
over the coordinate ``mu`` = cos(theta_i) (with ``theta`` in degrees beside it) and
attributes that make the file self-describing: the model spec as JSON, the method and
tolerances, the interpolation error, and the pumpup version.
"""

from __future__ import annotations

import contextlib
import json
import math
import os
import reprlib
import stat
import sys
import tempfile
import time
import weakref
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any, NamedTuple

import numpy as np

from .._version import __version__
from ..core import BRDF, check_count, check_open_unit, check_tolerance, provide
from ..core.budget import check as check_budget
from ..core.budget import current as current_budget
from ..core.budget import time_budget
from ..engine.cubature import DEFAULT_ATOL, DEFAULT_RTOL, albedo, check_mu
from . import reuse as _reuse
from .brent import bounded_minimum

if TYPE_CHECKING:
    import xarray as xr
    from numpy.typing import ArrayLike

__all__ = [
    "tabulate",
    "AlbedoTable",
    "write_table",
    "open_table",
    "mean_albedo",
    "max_constant",
    "max_albedo",
    "default_grid",
]

TABLE_KIND = "pumpup albedo table"
#: the largest ``max_points`` of an adaptive table
MAX_POINTS_LIMIT = 1_000_000


def _check_brdf(func: str, brdf) -> None:
    if not isinstance(brdf, BRDF):
        raise TypeError(f"{func} needs a pumpup BRDF (pumpup.load(spec)), got {type(brdf).__name__}")
METHOD = "adaptive 15x15 Gauss-Kronrod cubature in a lobe-adapted frame (pumpup.albedo)"


def default_grid(n_theta: int = 33, mu_min: float = 1e-8) -> np.ndarray:
    """Initial grid: uniform in theta from 0 to 90 degrees, plus decades of mu down to mu_min.

    Returns increasing mu in (0, 1].
    """
    theta = np.linspace(0.0, np.pi / 2, n_theta)[:-1]
    mu = np.cos(theta)
    mu = mu[mu > max(0.02, mu_min)]
    if mu_min >= 0.02:  # (no decades: the grid starts at mu_min itself)
        return np.unique(np.concatenate([mu, [mu_min, 1.0]]))
    # (log10(0.02) - log10(mu_min), not log10(0.02 / mu_min): that overflows for a subnormal mu_min)
    lo = math.log10(mu_min)
    decades = np.logspace(math.log10(0.02), lo, max(2, int(round(math.log10(0.02) - lo)) * 2 + 1))
    return np.unique(np.concatenate([mu, decades, [1.0]]))


#: a table whose estimated time exceeds this many seconds announces it and shows its progress (:func:`_long_work_bar`)
LONG_WORK_SECONDS = 30.0
#: an adaptive table computes about this many times the values of its first grid (measured over the registry's
#: examples: 1.3 to 2.6 times, the checks near mu = 1 and between nodes included)
ADAPTIVE_FACTOR = 3.0


@contextlib.contextmanager
def _compile_seconds():
    """A list whose first item, after the block, is the wall time numba spent compiling kernels in it (any thread; a
    kernel loaded from numba's cache is not compiled).
    """
    from numba.core import event

    spent = [0.0]
    with event.install_timer("numba:compile", lambda seconds: spent.__setitem__(0, seconds)):
        yield spent


@contextlib.contextmanager
def _long_work_bar(bar, brdf, seconds: float, done: int, compiling: float = 0.0):
    """``bar`` itself, or, where it is silent and the first ``done`` values took ``seconds`` (of which ``compiling``
    went to compiling kernels, which the rest of the table does not repeat) so that the whole table will take longer
    than :data:`LONG_WORK_SECONDS` (``ADAPTIVE_FACTOR`` times as many values), one line on stderr with the estimate
    and a progress bar there with the remaining time.
    """
    estimate = max(seconds - compiling, 0.0) * ADAPTIVE_FACTOR
    if not bar.disable or estimate < LONG_WORK_SECONDS:
        yield bar
        return
    from tqdm.auto import tqdm

    spent = f"{seconds:.1f} s" if compiling < 0.05 else f"{seconds:.1f} s, {compiling:.1f} s of it compiling kernels"
    print(f"pumpup: the albedo table of {brdf!r} will take about {estimate:.0f} s (its first {done} values took "
          f"{spent}); progress follows on stderr", file=sys.stderr, flush=True)
    with tqdm(total=done, initial=done, desc=f"albedo {brdf.type}", unit="mu", leave=True, file=sys.stderr,
              mininterval=5.0) as loud:
        yield loud


def _progress(total: int, desc: str, progress: bool | None):
    """A tqdm bar on a terminal, silent otherwise (or as forced by ``progress``)."""
    from tqdm.auto import tqdm

    show = sys.stderr.isatty() if progress is None else progress
    return tqdm(total=total, desc=desc, disable=not show, unit="mu", leave=False)


class AlbedoTable:
    """a(mu) anywhere in (0, 1], interpolated from a table, with a stated error.

    Interpolation is an interpolating spline in log(mu) of odd degree ``degree`` with
    not-a-knot ends: quintic by default (C4, sixth order), so the adaptive grid needs few
    nodes (measured on pumped Phong: 55-66 instead of the cubic's 88-114) and a pumped
    integrand f / g, which carries the spline's pieces, stays smooth enough for the cubature;
    cubic (C2) for tables of fewer than 6 nodes and for files written before the quintic
    (their ``interpolation_degree`` attribute is missing).  Below the smallest tabulated mu
    the table extrapolates the power law through its last two nodes (linear in log a versus
    log mu).

    ``breaks`` are values of mu where the albedo has a kink, nodes of the table: the spline is split there
    into independent splines on either side (a pumped level's albedo has a kink where the level below changes
    its g's form, :meth:`pumpup.operators.pumping.Pumped.albedo_kinks`; one spline across it rounds the kink off and the
    adaptive grid bunches its nodes towards it).

    ``interp_error`` is the largest difference between the interpolant and the computed
    albedo at the midpoints of the intervals, measured when the grid was built (or 0 if
    the grid was given and not checked).  :meth:`upper` is an upper bound of the true
    albedo: interpolant + SAFETY x interpolation error + the largest quadrature error of
    the table (one constant, so that the bound is as smooth and as monotone as the spline).
    """

    #: the default degree of the interpolating spline
    DEGREE = 5

    def __init__(self, mu, value, error, interp_error: float = 0.0, spec: dict | None = None,
                 degree: int | None = None, breaks=()):
        from scipy.interpolate import PPoly

        mu = np.asarray(mu, dtype=np.float64).reshape(-1)
        value = np.asarray(value, dtype=np.float64).reshape(-1)
        error = np.asarray(error, dtype=np.float64).reshape(-1)
        if len(mu) < 2:
            raise ValueError("an albedo table needs at least two values of mu")
        if not (len(value) == len(mu) == len(error)):
            raise ValueError(f"an albedo table needs one value and one error per mu: {len(mu)} mu, {len(value)} "
                             f"values, {len(error)} errors")
        if not np.all((mu > 0) & (mu <= 1)):
            raise ValueError(f"an albedo table's mu must lie in (0, 1], got {mu[~((mu > 0) & (mu <= 1))][:3].tolist()}")
        if not (np.all(np.isfinite(value)) and np.all(np.isfinite(error)) and np.all(error >= 0)):
            raise ValueError("an albedo table's values must be finite and its errors finite and >= 0")
        order = np.argsort(mu)
        self.mu = mu[order]
        lx = np.log(self.mu)  # (the spline's variable: its nodes must be distinct in it)
        if np.any(np.diff(lx) <= 0):
            raise ValueError("an albedo table's mu must be distinct (in log(mu), the interpolant's variable)")
        self.value = value[order]
        self.error = error[order]
        self.interp_error = float(interp_error)
        self.spec = spec
        inner = np.unique(np.asarray(breaks, dtype=np.float64).reshape(-1))
        inner = inner[(inner > self.mu[0]) & (inner < self.mu[-1])]
        at = np.searchsorted(self.mu, inner)
        if inner.size and not np.array_equal(self.mu[at], inner):
            raise ValueError(f"an albedo table's breaks must be nodes of its mu, got {inner[self.mu[at] != inner][:3]}")
        #: the values of mu where the spline is split (inner nodes)
        self.breaks = tuple(float(b) for b in inner)
        ends = [0, *at.tolist(), len(self.mu) - 1]
        pieces = [self._piece(lx[i:j + 1], self.value[i:j + 1], degree) for i, j in zip(ends[:-1], ends[1:])]
        self.degree = max(d for d, _ in pieces)
        if len(pieces) == 1:
            self._spline = pieces[0][1]
        else:  # one piecewise polynomial in log(mu): the pieces' intervals of positive length (a B-spline's PPoly
            # repeats its end knots) and their coefficients, lower degrees padded
            cs, xs = [], [pieces[0][1].x[:1]]
            for _, p in pieces:
                keep = np.diff(p.x) > 0
                cs.append(np.pad(p.c[:, keep], ((self.degree + 1 - p.c.shape[0], 0), (0, 0))))
                xs.append(p.x[1:][keep])
            self._spline = PPoly(np.concatenate(cs, axis=1), np.concatenate(xs), extrapolate=True)
        a0, a1 = self.value[0], self.value[1]
        #: slope of the power law below the first node (0: constant extrapolation)
        self.slope_below = ((math.log(a1) - math.log(a0)) / (math.log(self.mu[1]) - math.log(self.mu[0]))
                            if a0 > 0 and a1 > 0 else 0.0)
        #: added to the interpolant in :meth:`upper`
        self.margin = self.SAFETY * self.interp_error + float(np.max(self.error))
        #: added below the first node, where the extrapolation is a guess: also the spread of the
        #: first interval and the first node's quadrature error
        self.margin_below = self.margin + float(self.error[0]) + abs(float(a1) - float(a0))

    @classmethod
    def _piece(cls, lx, value, degree):
        """(degree, PPoly): the interpolating spline of :meth:`degree_for` (not-a-knot ends) through (lx, value)."""
        from scipy.interpolate import CubicSpline, PPoly, make_interp_spline

        d = cls.degree_for(len(lx), degree)
        if d == 5:  # a piecewise polynomial in log(mu), breakpoints at the inner knots
            return d, PPoly.from_spline(make_interp_spline(lx, value, k=5), extrapolate=True)
        return d, CubicSpline(lx, value, bc_type="not-a-knot", extrapolate=True)

    @classmethod
    def degree_for(cls, n: int, degree: int | None = None) -> int:
        """The spline degree a table of n nodes uses: ``degree`` (default :attr:`DEGREE`), 3 below 6 nodes."""
        degree = cls.DEGREE if degree is None else int(degree)
        if degree not in (3, 5):
            raise ValueError(f"an albedo table interpolates with degree 3 or 5, got {degree}")
        return 5 if degree == 5 and n >= 6 else 3

    #: the :func:`tabulate` Dataset this table was made from, or a function that makes it (:func:`albedo_table`)
    _dataset_or_maker: object = None

    @property
    def dataset(self):
        """The xarray Dataset of this table as :func:`tabulate` returns it (what a file stores), or None for a table
        made from arrays alone.  A table from :func:`albedo_table` makes it when it is first read.
        """
        if callable(self._dataset_or_maker):
            self._dataset_or_maker = self._dataset_or_maker()
        return self._dataset_or_maker

    @dataset.setter
    def dataset(self, ds) -> None:
        self._dataset_or_maker = ds

    @classmethod
    def from_dataset(cls, ds) -> AlbedoTable:
        """The table of a dataset over mu alone; one over (mu, phi) (an anisotropic model's, ``tabulate(f, phi=...)``)
        must be cut to one azimuth first (``ds.isel(phi=0)``): before, scipy's spline raised an unreadable error.
        """
        if ds["albedo"].dims != ("mu",):
            raise ValueError(f"an albedo table is a function of mu alone, got a dataset over {ds['albedo'].dims}; "
                             "take one azimuth first, e.g. ds.isel(phi=0)")
        return cls(ds["mu"].values, ds["albedo"].values, ds["albedo_error"].values,
                   float(ds.attrs.get("interpolation_error", 0.0)), json.loads(ds.attrs["spec"]),
                   degree=int(ds.attrs.get("interpolation_degree", 3)),  # files from before the quintic: cubic
                   breaks=np.atleast_1d(ds.attrs.get("interpolation_breaks", [])))

    def __call__(self, mu) -> np.ndarray:
        """The interpolated albedo at ``mu`` (in (0, 1], checked); below the smallest node, the power law through the
        first two.
        """
        m = check_mu(mu)
        lm = np.log(m)
        out = self._spline(lm)
        lo = m < self.mu[0]
        if np.any(lo):
            out = np.where(lo, self.value[0] * np.exp(self.slope_below * (lm - math.log(self.mu[0]))), out)
        return out

    #: the measured interpolation error is multiplied by this in :meth:`upper` (the largest miss
    #: between nodes found against 400 random mu, quintic tables of Phong, Blinn, Ward, Cook-Torrance
    #: and a pumped Phong level: 0.62-0.97 x the one measured at the midpoints)
    SAFETY = 2.0

    def upper(self, mu) -> np.ndarray:
        """An upper bound of the true albedo: interpolant + ``margin`` (2 x interpolation error +
        the largest quadrature error), ``margin_below`` below the first node.  The pumping
        operator's compiled look-up uses the same margins.
        """
        m = check_mu(mu)
        return self(m) + np.where(m < self.mu[0], self.margin_below, self.margin)

    def is_increasing(self) -> bool:
        """True if the spline is non-decreasing on [mu_0, mu_last] (checked exactly: its derivative is
        >= 0 at every breakpoint and at every root of the second derivative).  Then so is
        :meth:`upper` there, and max(upper(x), upper(y)) = upper(max(x, y)) for x, y >= mu_0.
        """
        return nondecreasing(self._spline)


def nondecreasing(spline) -> bool:
    """True if a scipy PPoly is non-decreasing between its first and last breakpoints (exact: its
    derivative is >= 0 at every breakpoint and at every root of the second derivative).
    """
    d1 = spline.derivative()
    crit = d1.derivative().roots(extrapolate=False)
    pts = np.concatenate([spline.x, crit[np.isfinite(crit)]])
    # (and every piece's derivative at its right end: a spline split at a kink, AlbedoTable's breaks, is only C0 there;
    # within the rounding of its terms, as a piece that ends where the derivative has a root, at a flat's start in
    # pumping._monotone_envelope, ends at +-1e-17 or so)
    h = np.diff(spline.x)
    terms = [d1.c[j] * h ** (d1.c.shape[0] - 1 - j) for j in range(d1.c.shape[0])]
    right, size = sum(terms), sum(np.abs(t) for t in terms)
    return bool(np.all(d1(pts) >= 0) and np.all(right >= -64.0 * np.finfo(float).eps * size))


def _near_new_nodes(order: np.ndarray, n_new: int) -> np.ndarray:
    """The intervals to check again after the last ``n_new`` of the nodes (sorted by ``order``) were
    added: every interval within three nodes of a new one (a new node changes the spline mostly there).
    """
    is_new = np.concatenate([np.zeros(len(order) - n_new, bool), np.ones(n_new, bool)])[order]
    near = is_new.copy()
    for shift in (1, 2, 3):
        near[shift:] |= is_new[:-shift]
        near[:-shift] |= is_new[shift:]
    return near[:-1] | near[1:]


def _midpoints(mu: np.ndarray) -> np.ndarray:
    """Midpoints of consecutive nodes in log(mu) (sqrt(a b), or sqrt(a) sqrt(b) where a b underflows)."""
    ab = mu[:-1] * mu[1:]
    return np.where(ab > 1e-290, np.sqrt(ab), np.sqrt(mu[:-1]) * np.sqrt(mu[1:]))


#: the adaptive grid also checks the interval that ends at mu = 1 at 1 - mu = (1 - a) 2^-k, k = 1, 2, ... down to this
NEAR_ONE_MIN = 1e-9


def _near_one(a: float) -> np.ndarray:
    """The check points of the interval [a, 1] (:data:`NEAR_ONE_MIN`), increasing, strictly inside in log(mu)."""
    d = (1.0 - a) * 0.5 ** np.arange(1, 64)
    pts = 1.0 - d[d >= NEAR_ONE_MIN]
    return pts[(np.log(pts) > math.log(a)) & (pts < 1.0)]


def _splittable(mu: np.ndarray) -> np.ndarray:
    """Whether each interval of consecutive nodes has its midpoint (:func:`_midpoints`) strictly inside in log(mu), the
    spline's variable (whose doubles are coarser than mu's: 3.6e-15 at log(mu) = -18.4, mu's relative step 1.1e-16).
    """
    lx = np.log(mu)
    lm = np.log(_midpoints(mu))
    return (lm > lx[:-1]) & (lm < lx[1:])


#: the models whose BRDF reads pumpup's own albedo tables (pumping's g, compensation's E): :func:`adaptive_grid` also
#: checks their tables off the dyadic points (:func:`built_on_tables`)
TABLE_MODELS = ("pumped", "kulla_conty", "scaled")


def built_on_tables(spec) -> bool:
    """Whether a spec, at any depth, holds a model of :data:`TABLE_MODELS`."""
    if isinstance(spec, dict):
        return spec.get("type") in TABLE_MODELS or any(built_on_tables(v) for v in spec.values())
    if isinstance(spec, (list, tuple)):
        return any(built_on_tables(v) for v in spec)
    return False


def adaptive_grid(grid, val, err, values, interp_tol, max_points, breaks=(), bar=None, off_grid=False):
    """The adaptive grid of :func:`tabulate` (and of :meth:`pumpup.spectral.Spectral.tabulate`), from the values
    ``val``, ``err`` at the nodes ``grid``: (grid, val, err, interp), ``interp`` the interpolation error per column.

    ``val``, ``err`` are (n,) or (n, columns) (a table over (mu, phi), or (mu, wavelength)); ``values(mu)`` gives them
    at new mu.  Every interval where the interpolant (:class:`AlbedoTable`, split at ``breaks``) of any column misses
    the value at the midpoint in log(mu) by more than ``interp_tol`` is bisected, until none does or the grid has
    ``max_points`` nodes; ``interp`` is each column's largest miss over the accepted intervals (all the last misses when
    ``max_points`` stopped it), and over the checks of the last interval at 1 - mu = (1 - a) 2^-k (:func:`_near_one`).
    ``off_grid``: also over checks of every interval at its thirds in log(mu) (:func:`built_on_tables`).
    """
    one = val.ndim == 1
    V, E = (val[:, None], err[:, None]) if one else (val, err)

    def column_values(pts):
        check_budget(f"refining the table's grid ({len(pts)} more values)")
        if bar is not None:
            bar.total += len(pts)
        v, e = values(pts)
        return (v[:, None], e[:, None]) if one else (v, e)

    def misses(grid, V, E, pts, pv):
        return np.column_stack([np.abs(AlbedoTable(grid, V[:, j], E[:, j], breaks=breaks)(pts) - pv[:, j])
                                for j in range(V.shape[1])])

    interp = np.zeros(V.shape[1])
    todo = np.ones(len(grid) - 1, bool)  # intervals not yet checked
    miss = None
    while todo.any() and len(grid) < max_points:
        mids = _midpoints(grid)[todo]
        mv, me = column_values(mids)
        miss = misses(grid, V, E, mids, mv)
        # an interval whose midpoint is not a new value of log(mu) is not split: its miss counts as an accepted one.
        # The bisection reaches one where the values' own noise exceeds interp_tol (a divergent albedo, 3.5e6 at mu =
        # 1.08e-8 with errors of 1e-5: interp_tol 1e-7 is 3e-14 of it), or at a jump of the albedo.  Splitting such an
        # interval would give two nodes of one log(mu) (ValueError from scipy)
        split = _splittable(grid)[todo]
        bad = (miss > interp_tol).any(axis=1) & split
        # (within such an interval the spline takes one end's value at every mu: its ends' spread counts too)
        miss = np.where(split[:, None], miss, np.maximum(miss, np.abs(V[1:] - V[:-1])[todo]))
        if (~bad).any():
            interp = np.maximum(interp, miss[~bad].max(axis=0))
        # accept the good intervals; add the bad midpoints as nodes
        new_mu = np.concatenate([grid, mids[bad]])
        order = np.argsort(new_mu)
        grid = new_mu[order]
        V = np.concatenate([V, mv[bad]])[order]
        E = np.concatenate([E, me[bad]])[order]
        # a new node changes the spline everywhere, mostly within a few intervals: check
        # again every interval within three nodes of a new one
        todo = _near_new_nodes(order, int(bad.sum()))
    if todo.any():
        if miss is None:  # (max_points below the first grid's size: its misses, measured once)
            mids = _midpoints(grid)[todo]
            miss = misses(grid, V, E, mids, column_values(mids)[0])
        interp = np.maximum(interp, miss.max(axis=0))
    # the interval that ends at mu = 1: its midpoint in log(mu) lies at theta / sqrt(2) of its lower end's theta, so
    # 70 % of it in theta had no check.  A sharp lobe's pumped level turns there (the lobe reaches the normal below
    # theta ~ its width: pumped plastic n = 5284 was 3.1e-7 off at mu = 0.99995 with a margin of 2.0e-7, found by
    # scripts/studies/fuzz_engines.py --tables 43), and so does a g2 level whose bound crosses the diagonal within it (a
    # kink the table's one spline goes across: Pumped.albedo_kinks).  It is checked at 1 - mu = (1 - a) 2^-k too, down
    # to NEAR_ONE_MIN, and the largest miss there counts
    pts = _near_one(grid[-2])
    if off_grid:
        # a model that reads pumpup's own tables (a pumped level's g, a compensation's E) inherits their interpolation
        # error between their nodes, and those nodes are this grid's and its midpoints: a check there is blind to it.
        # Kulla-Conty over Torrance-Sparrow D1 (s 844, ior 1.53) was exact at its nodes and midpoints and 6.0e-8 off at
        # mu = 0.039 with a margin of 5.9e-9 (scripts/studies/fuzz_engines.py --tables 44).  The thirds of each
        # interval in log(mu) are no nodes of a dyadic refinement; one third alone left it 1.24 x its margin (the
        # interval held two of E's pieces), both 0.58 x
        lx = np.log(grid)
        thirds = np.concatenate([np.exp((2.0 * lx[:-1] + lx[1:]) / 3.0), np.exp((lx[:-1] + 2.0 * lx[1:]) / 3.0)])
        inside = (np.log(thirds) > np.tile(lx[:-1], 2)) & (np.log(thirds) < np.tile(lx[1:], 2))
        pts = np.concatenate([thirds[inside], pts])
    if len(pts):
        interp = np.maximum(interp, misses(grid, V, E, pts, column_values(pts)[0]).max(axis=0))
    return grid, (V[:, 0] if one else V), (E[:, 0] if one else E), interp


def tabulate(brdf: BRDF, mu: ArrayLike | None = None, *, rtol: float = DEFAULT_RTOL, atol: float = DEFAULT_ATOL,
             interp_tol: float = 1e-7, mu_min: float = 1e-8, max_points: int = 2049, progress: bool | None = None,
             threads: int | None = None, phi: ArrayLike | str | None = None,
             breaks: ArrayLike | None = None, max_seconds: float | None = None) -> xr.Dataset:
    """Tabulate the directional albedo of ``brdf``.

    Parameters
    ----------
    brdf : BRDF
        Or a spectral model (:mod:`pumpup.spectral`): a table with dims (``mu``, ``wavelength``).
    mu : array_like, optional
        The grid of cos(theta_i) in (0, 1].  If omitted, the grid adapts: it starts from
        :func:`default_grid` (down to ``mu_min``) and bisects (in log mu) every interval
        where the interpolant misses the computed albedo at the midpoint by more than
        ``interp_tol``; the largest miss found is stored as ``interpolation_error``, with
        the misses at 1 - mu = (1 - a) 2^-k in the last interval [a, 1] (whose midpoint in
        log(mu) lies at theta_a / sqrt(2)) and the spread of any interval too narrow to split.
    rtol, atol : float
        Quadrature tolerance of every value (see :func:`pumpup.albedo`).
    interp_tol : float
        Absolute interpolation tolerance of the adaptive grid.
    mu_min : float
        Smallest mu of the adaptive grid.
    max_points : int
        Upper limit on the adaptive grid.
    progress : bool, optional
        Show a progress bar (default: when stderr is a terminal).
    threads : int, optional
        Threads that compute the values (default :data:`THREADS`: one per core, one for a BRDF on
        the 1-D path).  The table does not depend on it.
    phi : None, float, array_like or "sup", optional
        Azimuth(s) of wi in radians (see :func:`pumpup.albedo`).  None: phi = 0 (wi in the
        xz-plane), a table over ``mu``.  A number or an array: a table over (``mu``, ``phi``)
        (an isotropic model's values are the same in every column, computed once); the
        adaptive grid in mu then meets ``interp_tol`` in every column.  ``"sup"``: a table
        over ``mu`` of an upper bound of the supremum over phi of a(mu, phi), what the pumping
        operator needs of an anisotropic base (:func:`pumpup.tables.azimuth.sup_albedo`; the plain
        table for an isotropic model).
    breaks : array_like, optional
        Values of mu in (``mu_min``, 1) where the albedo has a kink, for an adaptive grid over ``mu`` alone: they
        join the grid, and the interpolating spline is split there (:class:`AlbedoTable`; the attribute
        ``interpolation_breaks``).  The pumping operator gives those of a pumped level's albedo.  Default: the
        model's own, :meth:`pumpup.core.BRDF.albedo_breaks` (none for most models).
    max_seconds : float, optional
        A time budget: past it, the work stops with :class:`pumpup.core.budget.BudgetExceeded` (a TimeoutError)
        instead of running on.  None: no bound.

    Returns
    -------
    xarray.Dataset
        ``albedo`` and ``albedo_error`` over ``mu`` (and ``phi``), coordinate ``theta`` [deg], and
        attributes ``spec`` (JSON), ``method``, ``rtol``, ``atol``,
        ``interpolation_error``, ``pumpup_version``.

    Examples
    --------
    >>> import pumpup
    >>> ds = pumpup.tabulate(pumpup.load({"type": "lambert", "albedo": 0.5}), mu=[0.1, 0.5, 1.0])
    >>> ds["albedo"].values.round(12).tolist()
    [0.5, 0.5, 0.5]
    """
    with time_budget("tabulate", max_seconds):
        made = _tabulate(brdf, mu, rtol=rtol, atol=atol, interp_tol=interp_tol, mu_min=mu_min, max_points=max_points,
                         progress=progress, threads=threads, phi=phi, breaks=breaks)
    return made.dataset() if isinstance(made, _Tabulated) else made


def albedo_table(brdf: BRDF, *, rtol: float, interp_tol: float, progress: bool | None = None,
                 phi: str | None = None, breaks: ArrayLike | None = None) -> AlbedoTable:
    """The :class:`AlbedoTable` of :func:`tabulate`'s adaptive table over mu (``phi`` None or ``"sup"``), without
    building its xarray Dataset: the table's :attr:`AlbedoTable.dataset` (the Dataset :func:`tabulate` returns, bit for
    bit) is made when it is first read, e.g. when the table is saved.  The operators' session tables use this: xarray's
    import and the Dataset cost a new process about half a second.
    """
    made = _tabulate(brdf, None, rtol=rtol, atol=DEFAULT_ATOL, interp_tol=interp_tol, mu_min=1e-8, max_points=2049,
                     progress=progress, threads=None, phi=phi, breaks=breaks)  # (tabulate's defaults)
    if not isinstance(made, _Tabulated) or made.phis is not None:  # (a spectral model, or a table over (mu, phi))
        ds = made if not isinstance(made, _Tabulated) else made.dataset()
        table = AlbedoTable.from_dataset(ds)
        table.dataset = ds
        return table
    spec = json.loads(json.dumps(brdf.spec, sort_keys=True))  # (as from_dataset reads the Dataset's)
    table = AlbedoTable(made.mu, made.val, made.err, made.interp_error, spec,
                        degree=AlbedoTable.degree_for(len(made.mu)), breaks=() if made.breaks is None else made.breaks)
    table.dataset = made.dataset
    return table


class _Tabulated(NamedTuple):
    """What :func:`_tabulate` computed: the arguments of :func:`_dataset`."""

    brdf: BRDF
    mu: np.ndarray
    val: np.ndarray
    err: np.ndarray
    rtol: float
    atol: float
    interp_error: float
    grid_kind: str
    phis: np.ndarray | None = None
    phi_kind: str | None = None
    breaks: np.ndarray | None = None

    def dataset(self) -> xr.Dataset:
        """The table as :func:`tabulate` returns it."""
        return _dataset(*self)


def _tabulate(brdf, mu, *, rtol, atol, interp_tol, mu_min, max_points, progress, threads, phi, breaks):
    """:func:`tabulate`'s work (within its time budget): a spectral model's Dataset, else a :class:`_Tabulated`."""
    if threads is not None and (isinstance(threads, bool) or not isinstance(threads, (int, np.integer))
                                or not 1 <= threads <= MAX_THREADS):
        raise ValueError(f"tabulate: threads must be an integer in [1, {MAX_THREADS}], got {reprlib.repr(threads)}")
    if getattr(brdf, "is_spectral", False):  # pumpup.spectral: dims (mu, wavelength)
        return brdf.tabulate(mu=mu, rtol=rtol, atol=atol, interp_tol=interp_tol, mu_min=mu_min, max_points=max_points,
                             progress=progress, threads=threads, phi=phi)
    _check_brdf("tabulate", brdf)
    rtol = check_tolerance("tabulate", "rtol", rtol)
    atol = check_tolerance("tabulate", "atol", atol, hi=math.inf, zero=True)
    interp_tol = check_tolerance("tabulate", "interp_tol", interp_tol, hi=math.inf)
    mu_min = check_open_unit("tabulate", "mu_min", mu_min)
    max_points = check_count("tabulate", "max_points", max_points, 2, MAX_POINTS_LIMIT)
    from .azimuth import table_values

    if breaks is None and mu is None and (phi is None or isinstance(phi, str) and phi == "sup"):
        # the model's own kinks (BRDF.albedo_breaks: a Fresnel factor's total reflection): metal n = 5, eta = 0.551 took
        # 748 nodes and 15 s without them, 322 and 7.3 s with them
        own = [b for b in brdf.albedo_breaks() if mu_min < b < 1.0]
        breaks = own or None
    if breaks is not None:
        try:
            breaks = np.unique(np.asarray(breaks, dtype=np.float64).reshape(-1))
        except (TypeError, ValueError):
            raise ValueError(f"tabulate: breaks must be numbers in (mu_min, 1), got {breaks!r}") from None
        if mu is not None or phi is not None and not (isinstance(phi, str) and phi == "sup"):
            raise ValueError("tabulate: breaks need an adaptive grid (mu=None) over mu alone (phi None or 'sup')")
        if not np.all((breaks > mu_min) & (breaks < 1.0)):
            raise ValueError(f"tabulate: breaks must lie in (mu_min, 1) = ({mu_min:g}, 1), got {breaks.tolist()}")
    values, phis, phi_kind = table_values(brdf, phi, rtol, atol, threads, interp_tol)
    # mean_albedo and max_albedo of this object may reuse a table at phi = 0 (not a supremum, not a grid)
    reusable = phis is None and phi_kind != "sup"
    if mu is not None:
        grid = np.unique(check_mu(np.atleast_1d(mu)).ravel())
        with _progress(len(grid), f"albedo {brdf.type}", progress) as bar:
            val, err = values(grid, bar)
        if reusable:
            _reuse.remember(brdf, grid, val, err, rtol)
        return _Tabulated(brdf, grid, val, err, rtol, atol, 0.0, "given", phis, phi_kind)
    check_mu(mu_min)
    grid = default_grid(mu_min=mu_min)
    if breaks is not None:
        grid = np.unique(np.concatenate([grid, breaks]))
    with contextlib.ExitStack() as stack:
        bar = stack.enter_context(_progress(len(grid), f"albedo {brdf.type}", progress))
        start = time.monotonic()
        with _compile_seconds() as compiling:
            val, err = values(grid, bar)
        if progress is None:  # a long table says so, and shows its progress, even where stderr is no terminal
            bar = stack.enter_context(_long_work_bar(bar, brdf, time.monotonic() - start, len(grid), compiling[0]))
        grid, val, err, interp = adaptive_grid(grid, val, err, lambda m: values(m, bar), interp_tol, max_points,
                                               () if breaks is None else breaks, bar, built_on_tables(brdf.spec))
        interp_error = float(interp.max())
    if reusable:
        _reuse.remember(brdf, grid, val, err, rtol)
    return _Tabulated(brdf, grid, val, err, rtol, atol, interp_error, "adaptive", phis, phi_kind, breaks)


#: threads that compute the albedos of a table (None: one per core, or one for a BRDF on the 1-D path,
#: ``pumpup.engine.polar``).  The compiled kernels release the GIL; a value of mu does not depend on the
#: others computed with it, so the table is the same for any number of threads (tested).  The nested
#: engine gains (Blinn n = 16: 74 -> 64 ms on 2 cores); the 1-D path's values cost microseconds, and
#: the Python around them (a pumped lobe's levels and cuts per mu) holds the GIL, so there a second
#: thread only adds its cost (3-level g2 pumped Phong's three tables 40 -> 52 ms, Phong n = 20 2.7 -> 5 ms).
THREADS: int | None = None


#: the BRDF objects whose kernels have run in this process (see :func:`_chunked`)
_WARM: weakref.WeakSet = weakref.WeakSet()


#: the most threads :func:`tabulate` accepts (each holds its own work arrays)
MAX_THREADS = 1024


def _cores() -> int:
    """The cores this process may run on (its CPU affinity where the system tells it)."""
    try:
        return max(1, len(os.sched_getaffinity(0)))
    except (AttributeError, OSError):
        return os.cpu_count() or 1


def _chunked(brdf, mu, rtol, atol, bar, threads: int | None = None, chunk: int = 32, phi: float = 0.0):
    """Albedo and error at every mu (at the azimuth ``phi`` of wi), in chunks, on ``threads`` threads
    (default :data:`THREADS`; every k-th mu to thread k: grazing values, the dear ones, are spread over all).
    """
    val = np.empty_like(mu)
    err = np.empty_like(mu)
    from ..engine.routes import one_d_everywhere

    if one_d_everywhere(brdf, mu):
        # its values cost microseconds: one call for them all (chunks of 32 cost Phong n = 20's 257-point table
        # 1.8 ms against 1.4 ms); the values do not depend on the batch
        chunk = max(chunk, len(mu))
        if threads is None and THREADS is None:
            threads = 1
    threads = max(1, min(threads or THREADS or _cores(), len(mu)))

    import contextvars
    import threading

    stop = threading.Event()  # set when the caller is interrupted (Ctrl-C): the threads end soon
    deadline = current_budget()

    def work(idx):
        for a in range(0, len(idx), chunk):
            if stop.is_set():
                return
            if deadline is not None:
                deadline.check(f"computing {len(mu)} albedo values of {brdf.type}")
            part = idx[a:a + chunk]
            val[part], err[part] = albedo(brdf, mu[part], return_error=True, rtol=rtol, atol=atol, phi=phi)
            bar.update(len(part))

    todo = np.arange(len(mu))
    if threads > 1 and brdf not in _WARM:
        # the first value for a BRDF on this thread (the largest mu, usually the cheapest): it
        # compiles whatever its kernels still need (two threads compiling one numba ufunc at
        # once race; numba warns), then the rest on the pool
        first = int(np.argmax(mu))
        work(np.array([first]))
        _WARM.add(brdf)
        todo = np.delete(todo, first)
    if threads == 1 or len(todo) < 2:
        work(todo)
        return val, err
    from concurrent.futures import ThreadPoolExecutor

    with ThreadPoolExecutor(threads) as pool:
        try:
            # (each thread in a copy of this context: the engine's route choice and the time budget hold there too)
            for done in [pool.submit(contextvars.copy_context().run, work, todo[k::threads]) for k in range(threads)]:
                done.result()
        except BaseException:
            stop.set()
            raise
    return val, err


def _dataset(brdf, mu, val, err, rtol, atol, interp_error, grid_kind, phis=None, phi_kind=None, breaks=None):
    import xarray as xr

    if phis is not None:
        from .azimuth import phi_dataset

        return phi_dataset(_dataset(brdf, mu, val[:, 0], err[:, 0], rtol, atol, interp_error, grid_kind),
                           val, err, phis)

    degree = AlbedoTable.degree_for(len(mu))

    theta = np.degrees(np.arccos(mu))
    ds = xr.Dataset(
        {
            "albedo": ("mu", val, {"long_name": "directional albedo a(mu)", "units": "1",
                                   "definition": "integral of f_r(wi, wo) cos(theta_o) d omega_o (000 eq. 2)"}),
            "albedo_error": ("mu", err, {"long_name": "estimated absolute quadrature error of albedo", "units": "1"}),
        },
        coords={
            "mu": ("mu", mu, {"long_name": "cosine of the incidence angle, cos(theta_i)", "units": "1"}),
            "theta": ("mu", theta, {"long_name": "incidence angle theta_i", "units": "degree"}),
        },
        attrs={
            "title": f"Directional albedo of {brdf.type}",
            "pumpup_kind": TABLE_KIND,
            "spec": json.dumps(brdf.spec, sort_keys=True),
            "model": brdf.type,
            "method": METHOD,
            "rtol": float(rtol),
            "atol": float(atol),
            "grid": grid_kind,
            "interpolation": (f"interpolating spline of degree {degree} in log(mu), not-a-knot ends; "
                              "power-law extrapolation below the smallest mu"),
            "interpolation_degree": int(degree),
            "interpolation_error": float(interp_error),
            "pumpup_version": __version__,
        },
    )
    if breaks is not None and len(breaks):
        # (one break as a number: netCDF reads a one-element array attribute back as a number, and the file's digest
        # must see what is read back)
        ds.attrs["interpolation_breaks"] = (float(breaks[0]) if len(breaks) == 1
                                            else np.asarray(breaks, dtype=np.float64))
        ds.attrs["interpolation"] += "; split at interpolation_breaks, the kinks of the albedo"
    if phi_kind is not None:  # an anisotropic model: say which azimuth of wi the values hold
        from .azimuth import describe_phi

        describe_phi(ds, brdf, phi_kind)
    return ds


def _umask() -> int:
    """The process's umask, read without changing it where the system tells it (Linux), else by
    setting and restoring it.
    """
    try:
        with open("/proc/self/status") as fh:
            for line in fh:
                if line.startswith("Umask:"):
                    return int(line.split()[1], 8)
    except (OSError, ValueError):
        pass
    mask = os.umask(0o022)
    os.umask(mask)
    return mask


def _pid_alive(pid: int) -> bool:
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except (PermissionError, OSError):
        return True  # it exists (another user's) or we cannot tell: leave its file alone
    return True


#: the temporary files of a target ``NAME`` are ``.NAME.<pid>.<random>.pumpup-tmp`` beside it
_TMP_SUFFIX = ".pumpup-tmp"


def stale_temporaries(path, any_target: bool = False) -> list[str]:
    """Temporary files of ``path`` (``any_target``: of any file in its directory) left by writes that were killed
    (their process is gone).  A temporary is named ``.<target>.<pid>.<random>`` plus :data:`_TMP_SUFFIX`.
    """
    path = os.fspath(path)
    directory = os.path.dirname(os.path.abspath(path))
    prefix = "." if any_target else "." + os.path.basename(path) + "."
    out = []
    try:
        names = os.listdir(directory)
    except OSError:
        return out
    for name in names:
        if not (name.startswith(prefix) and name.endswith(_TMP_SUFFIX)):
            continue
        parts = name[:-len(_TMP_SUFFIX)].rsplit(".", 2)  # [".<target>", "<pid>", "<random>"]
        pid = parts[1] if len(parts) == 3 else ""
        if pid.isdigit() and not _pid_alive(int(pid)):
            out.append(os.path.join(directory, name))
    return out


def _fsync_path(path: str, directory: bool = False) -> None:
    try:
        fd = os.open(path, os.O_RDONLY | (getattr(os, "O_DIRECTORY", 0) if directory else 0))
    except OSError:
        return
    try:
        os.fsync(fd)
    except OSError:
        pass
    finally:
        os.close(fd)


def check_output_path(path, probe: bool = True) -> str:
    """``path`` as a string if a file can be written there, else an OSError naming it, before any work: not empty, not
    a directory (nor ending with a separator), a name the file system allows, and a directory that exists and takes a
    new file (``probe``: tried with a hidden temporary, since a read-only mount or ``/proc`` pass the permission bits;
    :func:`atomic_path` creates its own temporary instead).
    """
    path = os.fspath(path)
    if not path:
        raise OSError("cannot write to an empty path: give a file name")
    if path.endswith(os.sep) or os.path.isdir(path):
        raise OSError(f"cannot write {path!r}: it names a directory; give a file name")
    directory = os.path.dirname(os.path.abspath(path))
    if not os.path.isdir(directory):
        raise OSError(f"cannot write {path!r}: directory {directory!r} does not exist")
    if not os.access(directory, os.W_OK):
        raise OSError(f"cannot write {path!r}: directory {directory!r} is not writable")
    try:
        name_max = os.pathconf(directory, "PC_NAME_MAX")
    except (OSError, ValueError):
        name_max = 255
    if len(os.fsencode(os.path.basename(path))) > name_max - 24:  # (room for the temporary's prefix and suffix)
        raise OSError(f"cannot write {path!r}: its name is {len(os.path.basename(path))} characters long; this file "
                      f"system allows {name_max} (less the {24} a temporary file adds)")
    if probe:
        try:
            fd, tmp = tempfile.mkstemp(prefix=".pumpup-probe.", dir=directory)
            os.close(fd)
            os.unlink(tmp)
        except OSError as exc:
            raise _no_new_file(path, directory, exc) from None
    return path


def _no_new_file(path: str, directory: str, exc: OSError) -> OSError:
    return OSError(f"cannot write {path!r}: directory {directory!r} takes no new file ({exc.strerror})")


@contextlib.contextmanager
def atomic_path(path):
    """Yield a temporary file beside ``path``; rename it into place only if the block succeeds.

    An interrupted write never leaves a half file at ``path`` (nor a temporary one; one left by a
    process that was killed is removed by the next pumpup write in the same directory).  The file gets the
    permissions the user's umask gives a new file (0666 & ~umask), also when it replaces one, and
    its data reach the disk (fsync) before the rename.
    """
    path = check_output_path(path, probe=False)  # (the temporary below is the probe)
    directory = os.path.dirname(os.path.abspath(path))
    for stale in stale_temporaries(path, any_target=True):  # (a killed write's, of any file here)
        with contextlib.suppress(OSError):
            os.unlink(stale)
    try:
        fd, tmp = tempfile.mkstemp(prefix=f".{os.path.basename(path)}.{os.getpid()}.", suffix=_TMP_SUFFIX,
                                   dir=directory)
    except OSError as exc:
        raise _no_new_file(path, directory, exc) from None
    os.close(fd)
    try:
        yield tmp
        os.chmod(tmp, 0o666 & ~_umask())
        _fsync_path(tmp)
        os.replace(tmp, path)
        _fsync_path(directory, directory=True)
    except BaseException:
        if os.path.exists(tmp):
            os.unlink(tmp)
        raise


def write_table(ds: xr.Dataset, path: str | os.PathLike[str]) -> str:
    """Write a Dataset to netCDF atomically (a temporary file renamed into place), with a
    Fletcher-32 checksum on every numeric variable (:func:`pumpup.tables.validate.checksum_encoding`) and
    a digest of the whole content in the attribute ``pumpup_digest``, which :func:`open_table`
    checks (:func:`pumpup.tables.validate.content_digest`).
    """
    import xarray as xr

    from .validate import checksum_encoding

    if not isinstance(ds, xr.Dataset):
        raise TypeError(f"write_table needs an xarray.Dataset (pumpup.tabulate's), got {type(ds).__name__}")
    ds = _digested(ds)
    with atomic_path(path) as tmp:
        ds.to_netcdf(tmp, engine="netcdf4", format="NETCDF4", encoding=checksum_encoding(ds))
    return os.fspath(path)


def _digested(ds):
    """A shallow copy of ``ds`` carrying the digest of its content (the caller's attributes stay)."""
    from .validate import DIGEST_ATTR, content_digest

    ds = ds.copy()
    ds.attrs.pop(DIGEST_ATTR, None)
    ds.attrs[DIGEST_ATTR] = content_digest(ds)
    return ds


def write_groups(path, root, groups) -> str:
    """Write ``root`` and the (name, Dataset) ``groups`` into one netCDF file, atomically, each with
    its digest and the Fletcher-32 checksums of :func:`write_table` (saved pumped and compensated BRDFs).
    """
    from .validate import checksum_encoding

    with atomic_path(path) as tmp:
        _digested(root).to_netcdf(tmp, mode="w", engine="netcdf4")
        for name, ds in groups:
            ds = _digested(ds)
            ds.to_netcdf(tmp, mode="a", group=name, engine="netcdf4", encoding=checksum_encoding(ds))
    return os.fspath(path)


#: the kinds of file that hold a saved BRDF (its tables in groups), and the function that reads each
SAVED_BRDF_READERS = {"pumpup pumped BRDF": "pumpup.load_pumped", "pumpup compensated BRDF": "pumpup.load_compensated",
                      "pumpup spectral pumped BRDF": "pumpup.load_pumped"}


def saved_kind(path: str | os.PathLike[str]) -> str:
    """The ``pumpup_kind`` of a file pumpup wrote (``"pumpup albedo table"``, a key of :data:`SAVED_BRDF_READERS`,
    ...), its root validated as :func:`open_table` does.
    """
    return str(open_table(path, _container=True).attrs.get("pumpup_kind", ""))


@contextlib.contextmanager
def snapshot(path: str | os.PathLike[str]):
    """A private copy of the file at ``path``, read through one open: the path of the copy, inside the block.

    A saved BRDF is several groups of one file; reading them with one open each, an atomic save between two opens
    would give an object built from two files.  The copy is read whole through one open (the file that was at
    ``path`` then, whatever replaces it later), so every group comes from one writer's file.  Non-regular files (a
    FIFO would block the reader forever) are refused before anything is read.
    """
    import shutil

    from .validate import TableError

    path = os.fspath(path)
    if not os.path.exists(path):
        raise FileNotFoundError(f"no such file: {path!r}")
    try:  # O_NONBLOCK: a FIFO put at the path after the check above still cannot block the open
        fd = os.open(path, os.O_RDONLY | getattr(os, "O_NONBLOCK", 0))
    except OSError as exc:
        raise TableError(f"{path!r} cannot be read: {exc.strerror}") from None
    with os.fdopen(fd, "rb") as src:
        if not stat.S_ISREG(os.fstat(fd).st_mode):
            raise TableError(f"{path!r} is not a regular file (a directory, a FIFO or a device): saved BRDFs are read "
                             "from files")
        with tempfile.TemporaryDirectory(prefix="pumpup-snapshot-") as folder:
            copy = os.path.join(folder, "snapshot.nc")
            with open(copy, "wb") as dst:
                shutil.copyfileobj(src, dst)
            yield copy


def open_table(path: str | os.PathLike[str], group: str | None = None, *,
               require_digest: bool = True, _container: bool = False, _name: str | None = None) -> xr.Dataset:
    """Open a netCDF table written by pumpup, fully loaded into memory, and validate it
    (:func:`pumpup.tables.validate.validate_dataset`: variables, coordinates, shapes, finite values,
    mu in (0, 1] strictly increasing, albedo >= 0, a loadable spec; the checksum, which every file pumpup writes
    carries: ``require_digest=False`` reads a file without one, from another tool).

    Raises
    ------
    FileNotFoundError
        If there is no such file.
    pumpup.tables.validate.TableError (a ValueError)
        If the file is damaged, not netCDF, not a pumpup table, or fails a check; the message
        names the file and what is wrong.
    """
    import xarray as xr

    from .validate import TableError, validate_dataset

    path = os.fspath(path)
    name = path if _name is None else _name  # (a snapshot's reader names the user's file)
    if not os.path.exists(path):
        raise FileNotFoundError(f"no such table: {name!r}")
    if not stat.S_ISREG(os.stat(path).st_mode):  # (a FIFO would block the reader forever)
        raise TableError(f"{name!r} is not a regular file (a directory, a FIFO or a device): tables are read from "
                         "files")
    where = name if group is None else f"{name}, group {group!r}"
    try:
        with xr.open_dataset(path, engine="netcdf4", group=group) as ds:
            ds = ds.load()
    except MemoryError:
        raise
    except Exception as exc:  # netCDF/HDF5 raise OSError, RuntimeError, KeyError, AttributeError, ... on damage
        raise TableError(f"{where!r} is not a readable netCDF file (damaged or another format): "
                         f"{type(exc).__name__}: {exc}") from None
    validate_dataset(ds, where, require_digest=require_digest)
    reader = SAVED_BRDF_READERS.get(ds.attrs.get("pumpup_kind")) if group is None and not _container else None
    if reader is not None and not ds.data_vars:  # (its tables are in groups: this root holds none)
        raise TableError(f"{name!r} is a {ds.attrs['pumpup_kind'][len('pumpup '):]}, not a table: read it with "
                         f"{reader}, or give group= one of its tables")
    from .validate import DIGEST_ATTR

    ds.attrs.pop(DIGEST_ATTR, None)  # verified; the Dataset is what was written
    return ds


# --------------------------------------------------------------------------------------------
# Mean albedo and maximum constants
# --------------------------------------------------------------------------------------------


def mean_albedo(brdf: BRDF, *, rtol: float = 1e-9, return_error: bool = False,
                max_intervals: int = 400) -> float | tuple[float, float]:
    """Mean albedo 2 * integral_0^1 a(mu) mu dmu (000 eq. 33): the albedo under uniform sky light.

    Computed by adaptive Gauss-Kronrod (7/15) quadrature over mu with the smoothing
    substitution mu = tau^2 (3 - 2 tau); every a(mu) comes from :func:`pumpup.albedo` at
    a tolerance 10 times tighter.  The error estimate adds the outer |K - G| and the
    propagated albedo errors.

    Examples
    --------
    >>> import pumpup
    >>> round(pumpup.mean_albedo(pumpup.load({"type": "lambert", "albedo": 0.25})), 12)
    0.25
    """
    from ..engine.lobe_geometry import NODES, WG, WK

    if getattr(brdf, "is_spectral", False):  # pumpup.spectral: one mean albedo per wavelength
        return brdf.mean_albedo(rtol=rtol, return_error=return_error, max_intervals=max_intervals)
    _check_brdf("mean_albedo", brdf)
    rtol = check_tolerance("mean_albedo", "rtol", rtol)
    max_intervals = check_count("mean_albedo", "max_intervals", max_intervals, 8, 10**6)
    # a table of this object just computed: its values, the part below its smallest mu afresh
    reused = _reuse.mean_from_table(
        brdf, rtol, lambda mu_min, scale: _reuse.fresh_low(brdf, mu_min, 0.25 * rtol * scale, rtol / 10))
    if reused is not None:
        return reused if return_error else reused[0]

    def rule(a, b):
        tau = a[:, None] + (b - a)[:, None] * NODES[None, :]
        mu = tau * tau * (3 - 2 * tau)
        w = 6 * tau * (1 - tau) * (b - a)[:, None]
        v, e = albedo(brdf, mu, return_error=True, rtol=rtol / 10, atol=1e-15)
        fv = 2 * v * mu * w
        fe = 2 * e * mu * w
        k = fv @ WK
        return k, np.abs(k - fv @ WG), fe @ WK

    # a pumped level's albedo has kinks (BRDF.albedo_kinks): first intervals end there.  Without them a 2-level g1
    # pumped stretched Phong (n = 0.127, p = 1: kinks at mu = 0.309, 0.345, 0.741, 0.745) had a mean 1.05e-9 off with an
    # estimate of 1.0e-10 (scripts/studies/fuzz_engines.py --mean)
    from ..engine.lobe_geometry import smooth_inverse

    # and two more towards grazing incidence, tau = 1/16 and 1/32 (mu = 0.011, 0.0029): the albedo there turns on the
    # roughness's scale, and the first interval [0, 1/8] (mu up to 0.043) was 4.2 x its |K - G| off for a 1-level g2
    # pumped GGX alpha 0.0194 (the mean 1.05e-9 off, 2.6 x its estimate; fuzz_engines --mean)
    kinks = brdf.albedo_kinks() or []
    edges = np.unique(np.concatenate([np.linspace(0, 1, 9), [1.0 / 16, 1.0 / 32],
                                      [smooth_inverse(v, 1.0 - v) for v in kinks]]))
    a, b = edges[:-1], edges[1:]
    k, qe, pe = rule(a, b)
    while True:
        total = k.sum()
        err = qe.sum() + pe.sum()
        if qe.sum() <= rtol * abs(total) / 2 or len(a) >= max_intervals:
            break
        pick = qe > 0.25 * qe.sum() / len(a)
        pick[np.argmax(qe)] = True
        m = 0.5 * (a[pick] + b[pick])
        na = np.concatenate([a[pick], m])
        nb = np.concatenate([m, b[pick]])
        nk, nqe, npe = rule(na, nb)
        a = np.concatenate([a[~pick], na])
        b = np.concatenate([b[~pick], nb])
        k, qe, pe = np.concatenate([k[~pick], nk]), np.concatenate([qe[~pick], nqe]), np.concatenate([pe[~pick], npe])
    total = float(total)
    err = float(err + 50 * np.finfo(float).eps * abs(total))
    return (total, err) if return_error else total


@dataclass
class AlbedoMaximum:
    """Where the albedo of a model (with its constant set to 1) peaks."""

    albedo: float  #: maximum albedo with the constant set to 1
    error: float  #: its estimated error
    mu: float  #: cos(theta_i) at the maximum
    theta_deg: float  #: theta_i at the maximum [deg]
    constant: float  #: 1 / albedo, the largest energy-conserving constant
    constant_error: float  #: propagated error of the constant
    at_boundary: bool  #: the maximum is at the end of the scanned range (mu = 1 or mu = mu_min)
    #: half-width [deg] of the theta interval the maximum may lie in: where a(mu) is within the
    #: albedo errors of the maximum (a flat maximum is located only to about sqrt(error / curvature))
    theta_error: float = 0.0
    #: the albedo grows without bound towards grazing incidence (then ``albedo`` is inf, ``constant`` 0, ``mu`` 0)
    diverges: bool = False
    #: for a diverging albedo, k of a(mu) ~ mu^-k over the last decade probed, and the change of k from the decade
    #: before (0 otherwise)
    exponent: float = 0.0
    exponent_error: float = 0.0
    #: for a diverging albedo, the smallest mu probed and the albedo there (nan otherwise)
    mu_probed: float = math.nan
    albedo_probed: float = math.nan

    def __str__(self) -> str:
        if self.diverges:
            return (f"unbounded: a(mu) ~ mu^-{self.exponent:.3g} (+- {self.exponent_error:.1g}) towards grazing "
                    f"incidence ({self.albedo_probed:.6g} at mu = {self.mu_probed:.3g}); maximum constant 0")
        return (f"{self.albedo:.12g} +- {self.error:.2g} at theta = {self.theta_deg:.6f} +- {self.theta_error:.2g} "
                f"deg; maximum constant {self.constant:.12g}")


#: :func:`max_albedo` probes these decades of mu below its ``mu_min`` when the albedo peaks there
DIVERGENCE_DECADES = 4
#: an albedo that still grows by at least this exponent per decade over the last decade probed, and by at least half
#: the previous decade's exponent, diverges: a bounded albedo that rises to its limit (Schlick's model,
#: a ~ a0 - c mu) has an exponent that falls tenfold per decade, below 1e-5 under mu = 1e-6; Ward's stays 0.5
DIVERGENCE_EXPONENT_MIN = 1e-3


def _grazing_trend(f, mu_min: float, a_min: float, e_min: float, rtol: float):
    """(diverges, exponent, exponent_error, mu, albedo) of ``f``'s albedo over :data:`DIVERGENCE_DECADES` decades below
    ``mu_min``, where the albedo is ``a_min`` +- ``e_min``.
    """
    mu = mu_min * 10.0 ** -np.arange(1, DIVERGENCE_DECADES + 1)
    a, e = albedo(f, mu, return_error=True, rtol=rtol)
    a, e = np.concatenate([[a_min], a]), np.concatenate([[e_min], e])
    if not (np.isfinite(a).all() and (a > 0).all()):
        return False, 0.0, 0.0, math.nan, math.nan
    k = np.log10(a[1:] / a[:-1])  # a ~ mu^-k per decade
    rising = bool((np.diff(a) > e[1:] + e[:-1]).all())
    last, before = float(k[-1]), float(k[-2])
    diverges = rising and last >= DIVERGENCE_EXPONENT_MIN and last >= 0.5 * before
    return diverges, last, abs(last - before), float(mu[-1]), float(a[-1])


def _unit_constant(brdf: BRDF) -> BRDF:
    if brdf.constant is None or brdf.constant not in brdf.p:
        return brdf
    return brdf.with_params(**{brdf.constant: 1.0})


def max_albedo(brdf: BRDF, *, mu_min: float = 1e-6, n_scan: int = 91, rtol: float = 1e-11) -> AlbedoMaximum:
    """Locate the maximum of a(mu) over [mu_min, 1] with the model's constant set to 1.

    A scan uniform in theta (plus decades of mu down to ``mu_min``) finds the best node;
    a bounded Brent search between its neighbours refines it (:func:`pumpup.tables.brent.bounded_minimum`, the
    steps of scipy's ``minimize_scalar(method="bounded")``).

    Where the albedo peaks at ``mu_min``, four more decades below it are probed: an albedo that keeps growing there
    as a power of mu (Ward's, a ~ mu^-0.5) has no maximum, and the result says so (``diverges``, with the exponent;
    ``albedo`` inf and ``constant`` 0) instead of giving the value at ``mu_min``.  ``pumpup.divergence`` fits the law
    over a wider window.

    Examples
    --------
    >>> import pumpup
    >>> m = pumpup.max_albedo(pumpup.load("ward:m=0.1"))
    >>> m.diverges, m.constant, round(m.exponent, 3)
    (True, 0.0, 0.5)
    """
    _check_brdf("max_albedo", brdf)
    mu_min = check_open_unit("max_albedo", "mu_min", mu_min)
    n_scan = check_count("max_albedo", "n_scan", n_scan, 3, 10**6)
    rtol = check_tolerance("max_albedo", "rtol", rtol)
    f = _unit_constant(brdf)
    theta = np.linspace(0, math.acos(mu_min), n_scan)
    mu = np.unique(np.concatenate([np.cos(theta), np.logspace(-1, math.log10(mu_min), 6), [1.0, mu_min]]))
    mu = mu[(mu >= mu_min) & (mu <= 1)]
    # a table of this object just computed stands for the scan (fresh values below its smallest mu)
    scan = _reuse.scan_from_table(brdf, f, mu, mu_min, lambda m: albedo(f, m, return_error=True, rtol=rtol))
    if scan is not None:
        mu, a, e = scan
    else:
        a, e = albedo(f, mu, return_error=True, rtol=rtol)
    i = int(np.argmax(a))
    best_mu, best_a, best_e = float(mu[i]), float(a[i]), float(e[i])
    if 0 < i < len(mu) - 1:
        lo, hi = float(mu[i - 1]), float(mu[i + 1])

        def neg(m):
            return -float(albedo(f, m, rtol=rtol))

        x, fx, _ = bounded_minimum(neg, lo, hi, xatol=1e-9 * hi)
        if -fx > best_a:
            best_mu = float(x)
            best_a, best_e = (float(v) for v in albedo(f, best_mu, return_error=True, rtol=rtol))
        elif scan is not None:  # the table's value was computed at its own tolerance
            best_a, best_e = (float(v) for v in albedo(f, best_mu, return_error=True, rtol=rtol))
    elif scan is not None:
        best_a, best_e = (float(v) for v in albedo(f, best_mu, return_error=True, rtol=rtol))
    at_boundary = i in (0, len(mu) - 1)
    if i == 0:  # the albedo peaks at the smallest mu scanned: does it go on growing below it?
        diverges, k, k_error, mu_probed, a_probed = _grazing_trend(f, best_mu, best_a, best_e, rtol)
        if diverges:
            return AlbedoMaximum(albedo=math.inf, error=0.0, mu=0.0, theta_deg=90.0, constant=0.0, constant_error=0.0,
                                 at_boundary=True, diverges=True, exponent=k, exponent_error=k_error,
                                 mu_probed=mu_probed, albedo_probed=a_probed)
    theta_error = 0.0 if at_boundary else _location_error(f, best_mu, best_a, best_e, rtol, lo, hi)
    return AlbedoMaximum(
        albedo=best_a,
        error=best_e,
        mu=best_mu,
        theta_deg=math.degrees(math.acos(best_mu)),
        constant=1.0 / best_a if best_a > 0.0 else math.inf,  # (a model that reflects nothing: any constant)
        constant_error=best_e / best_a**2 if best_a > 0.0 else 0.0,
        at_boundary=at_boundary,
        theta_error=theta_error,
    )


def _location_error(f, mu0, a0, e0, rtol, lo, hi) -> float:
    """Half-width [deg] of the theta interval around an interior maximum at mu0 in which the true
    maximum may lie.

    With a(mu) ~ a0 - k (mu - mu0)^2 / 2 near the maximum, every mu where a is within the albedo
    errors of a0 (a drop of 2 e, e the largest error of the three values) could be the maximum:
    |mu - mu0| <= sqrt(4 e / k).  k comes from a centred second difference at a step h of a
    twentieth of the bracket [lo, hi] of the scan (its own noise 4 e / h^2 is subtracted: a
    curvature that noise could explain is treated as zero, and then the whole bracket counts), plus
    the Brent search's tolerance.  Converted to theta through d theta = d mu / sin(theta).
    """
    h = min(0.05 * (hi - lo), mu0 - lo, hi - mu0)
    if not h > 0:
        return math.degrees(math.acos(lo) - math.acos(hi)) / 2
    (am, ap), (em, ep) = albedo(f, np.array([mu0 - h, mu0 + h]), return_error=True, rtol=rtol)
    e = max(e0, em, ep)
    k = (2.0 * a0 - am - ap) / (h * h) - 4.0 * e / (h * h)  # the curvature noise could not explain
    dmu = math.sqrt(4.0 * e / k) if k > 0 else max(hi - mu0, mu0 - lo)
    dmu = min(dmu, max(hi - mu0, mu0 - lo)) + 1e-9 * hi  # never beyond the bracket; Brent's xatol
    s = math.sqrt(max((1.0 - mu0) * (1.0 + mu0), 0.0))
    lo_t, hi_t = math.acos(min(1.0, mu0 + dmu)), math.acos(max(-1.0, mu0 - dmu))
    return math.degrees(max(math.acos(mu0) - lo_t, hi_t - math.acos(mu0), dmu / s if s > 0 else 0.0))


def max_constant(brdf: BRDF, **kw: Any) -> tuple[float, float]:
    """The maximum constant of a model and the angle of its albedo maximum.

    The constant is 1 / max over mu of the albedo computed with the model's constant
    (``c``; ``albedo`` for Lambert) set to 1 (000 Tables 2 and 4).

    Returns
    -------
    (constant, theta_deg)
        For an albedo that grows without bound towards grazing incidence (:attr:`AlbedoMaximum.diverges`), (0.0, 90.0)
        with an :class:`~pumpup.engine.AlbedoWarning` that gives the exponent.

    Examples
    --------
    >>> import pumpup
    >>> c, theta = pumpup.max_constant(pumpup.load({"type": "lambert"}))
    >>> round(c, 12)
    1.0
    """
    _check_brdf("max_constant", brdf)
    m = max_albedo(brdf, **kw)
    if m.diverges:
        import warnings

        from ..engine.cubature import AlbedoWarning

        warnings.warn(f"max_constant: the albedo of {brdf!r} has no maximum: {m}", AlbedoWarning, stacklevel=2)
    return m.constant, m.theta_deg


provide("max_albedo", max_albedo)  # for plastic's energy check (models may not import this layer)

from .._lazy import submodules  # noqa: E402

__getattr__ = submodules(__name__)  # the package's modules on first use (pumpup.tables.<module>)
