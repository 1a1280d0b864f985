"""Energy compensation beside pumping: the Kulla-Conty lobe and the 1/E scaling, as operators.

Renderers restore the energy that a microfacet lobe loses to single scattering in two ways:

* **Kulla-Conty** (Kulla and Conty, "Revisiting physically based shading at Imageworks",
  SIGGRAPH 2017 course; appleseed, OSPRay, OSL's BSDL) add a diffuse-like lobe

      f_ms(wi, wo) = (1 - E(mu_i)) (1 - E(mu_o)) / (pi (1 - E_avg)),
      E_avg = 2 integral_0^1 E(mu) mu dmu                              (KC eq. 1-2)

  with E the directional albedo of f (000 eq. 2).  Reciprocal; the albedo of f + f_ms is 1.
  For a coloured (Fresnel) lobe f = F f_1, E is the albedo of the Fresnel-1 lobe f_1 and f_ms
  is weighted by F_ms = F_avg^2 E_avg / (1 - F_avg (1 - E_avg)), F_avg = 2 integral F mu dmu
  (KC, "Fresnel" slide).
* **Scaling** (Turquin, "Practical multiple scattering compensation for microfacet models",
  2019; Blender Cycles' ``microfacet_ggx_preserve_energy``, Filament, Unity):

      f_s(wi, wo) = f(wi, wo) (1 + F0 (1 / E(mu_o) - 1))                (Turquin eq. 6)

  which with F0 = 1 is f / E(mu_o): the white furnace toward wo is exactly 1, but f_s is not
  reciprocal (E(mu_o), not E(mu_i)).

Both are BRDFs here (``{"type": "kulla_conty", "base": {...}}``, ``{"type": "scaled",
"base": {...}, "f0": 1}``): they evaluate, tabulate, sample, pump, save and load like any
other.  :func:`compensate` builds either, or the pumped BRDFs of 001 (``"g1"``, ``"g2"``),
so one call compares all four.

Bounds (why the Kulla-Conty albedo never exceeds 1)
---------------------------------------------------
pumpup knows E only through its table, to within a margin: E <= U, U the table's upper bound
(:meth:`AlbedoTable.upper`, capped at 1 when the table says E <= 1, and raised by the
relative 2e-14 of the fast look-up).  The lobe uses the *upper* bound of E in both factors,
D(mu) = max(0, 1 - U(mu)) <= 1 - E(mu): a *lower* bound of the deficit.  The denominator is
pi I_hi with I_hi >= I = 2 integral_0^1 D(mu) mu dmu, the integral of the D actually used
(exact Gauss-Legendre on the look-up's polynomial pieces, plus mu_min^2 for the range below
its first piece).  Then, for any direction (the lobe is symmetric, so either integral)

    a_kc(mu) = E(mu) + F_ms D(mu) I / I_hi <= E(mu) + D(mu) <= 1     where E(mu) <= 1,

since F_ms <= 1 and I <= I_hi, and from below a_kc >= 1 - (U - E) - (I_hi - I) / I_hi
(F_ms = 1): the compensated albedo is 1 to within about two table margins (2e-7 with
the default tables).  Taking a lower bound of E instead would put D above the true deficit
and the albedo above 1 by the table's margin (tests/operators/test_compensate.py shows both).  A base
whose albedo exceeds 1 beyond its error (Ward near grazing) would need D < 0 (f_ms < 0):
``kulla_conty`` refuses it; pumping (g1, g2) handles it.

For ``scaled`` the same upper bound U goes into 1 / U(mu_o), so the furnace toward wo is
E / U <= 1, and 1 - E / U <= (U - E) / E.

This module is over 1,000 lines because Kulla-Conty and the 1/E scaling share their white model, its tabulated
albedo E and the compiled look-ups of E and its average.
"""

from __future__ import annotations

import functools
import json
import math
import os
import reprlib
from typing import TYPE_CHECKING, Any

import numpy as np
from numba import njit

from ..core import BRDF, Lobe, Param, SpecError, check_reciprocity, load, register
from ..core.budget import check_max_seconds, time_budget
from ..physics.lookups import g_product, scale_bound, upper_scalar
from .pumping import (
    TABLE_DECADES,
    Pumped,
    _key,
    _Lookup,
    _Product,
    _ProductError,
    file_tables,
    from_file,
    prepare,
    table_decades,
)

if TYPE_CHECKING:
    from numpy.typing import ArrayLike

__all__ = ["compensate", "KullaConty", "Scaled", "save_compensated", "load_compensated", "furnace",
           "compensation_table", "METHODS", "fresnel_average"]

#: the methods of :func:`compensate`
METHODS = ("kulla_conty", "scale", "g1", "g2")

#: quadrature and interpolation tolerance of the E tables (rtol 1e-8 gives the same grid and
#: margin as the pumping tables' 1e-9 on GGX alpha = 0.3, for fewer integrand evaluations; the margin is set by the
#: interpolation, 2 x its error)
TABLE_RTOL = 1e-8
TABLE_INTERP_TOL = 1e-7

_TABLES: dict[str, object] = {}  # cache key of the white base -> AlbedoTable (with .dataset)


def compensation_table(white: BRDF, progress: bool | None = None):
    """The albedo table E of ``white`` used by the compensation operators (cached per session), built with every route
    whatever :func:`pumpup.engine.routes.using` block encloses the call (:func:`pumpup.engine.routes.default_routes`).
    """
    from ..engine.routes import default_routes
    from ..tables import albedo_table

    key = _key(white)
    own = from_file("compensate", key)  # a file being loaded: its table serves only its objects
    if own is not None:
        return own
    if key not in _TABLES:
        with default_routes():
            _TABLES[key] = albedo_table(white, rtol=TABLE_RTOL, interp_tol=TABLE_INTERP_TOL, progress=progress)
    return _TABLES[key]


# --- the bound U(mu) >= E(mu): the fast look-up and its numpy reference ---------------------


@njit(cache=True, nogil=True)
def _kc_kernel(f, wi, wo, scale, pmlo, pcbase, pcell, plo, prow, logx, coef, v0, slope0, margin_lo, margin,
               cap):  # pragma: no cover - compiled
    """Compute f += scale D(mu_i) D(mu_o) in place, D = max(0, 1 - U) (KC eq. 1; see the module docstring), U by
    :func:`scale_bound`.  Tested against :meth:`KullaConty.reference`.
    """
    for k in range(f.shape[0]):
        mi, mo = wi[k, 2], wo[k, 2]
        if mi <= 0.0 or mo <= 0.0:
            f[k] = 0.0
            continue
        ui = (g_product(mi, pcbase, pcell, plo, prow) if mi > pmlo
              else upper_scalar(mi, logx, coef, v0, slope0, margin_lo, margin, cap))  # scale_bound
        uo = (g_product(mo, pcbase, pcell, plo, prow) if mo > pmlo
              else upper_scalar(mo, logx, coef, v0, slope0, margin_lo, margin, cap))  # scale_bound
        di, do = 1.0 - ui, 1.0 - uo
        if di > 0.0 and do > 0.0:
            f[k] += scale * (di * do)  # KC eq. 1 (di * do: the same bits for (wi, wo) and (wo, wi))


@njit(cache=True, nogil=True)
def _scale_kernel(f, wi, wo, f0, pmlo, pcbase, pcell, plo, prow, logx, coef, v0, slope0, margin_lo, margin,
                  cap):  # pragma: no cover - compiled
    """Compute f *= 1 + F0 (1 / U(mu_o) - 1) in place (Turquin eq. 6), U by :func:`scale_bound`.  Tested against
    :meth:`Scaled.reference`.
    """
    for k in range(f.shape[0]):
        mi, mo = wi[k, 2], wo[k, 2]
        if mi <= 0.0 or mo <= 0.0:
            f[k] = 0.0
            continue
        u = (g_product(mo, pcbase, pcell, plo, prow) if mo > pmlo
              else upper_scalar(mo, logx, coef, v0, slope0, margin_lo, margin, cap))  # scale_bound
        if f0 == 1.0:
            f[k] = f[k] / u  # Turquin eq. 6 with F0 = 1: f / E(mu_o)
        else:
            f[k] = f[k] * (1.0 + f0 * (1.0 / u - 1.0))  # Turquin eq. 6


class _Bound:
    """U(mu) >= E(mu) of one table, the integral of its deficit, and the arguments of the kernels."""

    def __init__(self, table):
        self.table = table
        self.lookup = lk = _Lookup(table)
        self.cap = lk.cap
        try:
            self.product = _Product([lk], [False])
        except _ProductError:  # pragma: no cover - no table has needed it
            self.product = None
        if self.product is not None and self.product.rows.shape[1] != 8:  # pragma: no cover
            raise AssertionError("the kernels are written for a product table of degree 5 "
                                 "(pumpup.physics.lookups.PRODUCT_DEGREE)")
        if self.product is None:
            pargs = (math.inf, 0, np.zeros(1, np.int64), np.full(2, math.inf), np.zeros((1, 8)))
        else:
            p = self.product
            pargs = (p.mlo, p.cbase, p.entries, p.lo, p.rows)
        self.args = pargs + lk.args()
        self.deficit_integral, kinks = self._integral()
        #: the kinks of D in (0, 1): where U reaches 1, and the table's breaks
        #: (:attr:`pumpup.tables.AlbedoTable.breaks`, the spline's split points: the albedo's own, Cook-Torrance's
        #: pumpup.models.cook_torrance.RETRO_BREAK, a Fresnel factor's total reflection), the levels of every lobe that
        #: carries U(N.wo)
        self.kinks = sorted(set(kinks) | {b for b in table.breaks if 0.0 < b < 1.0})

    def upper(self, mu) -> np.ndarray:
        """U(mu) in plain numpy (the reference of :func:`scale_bound`)."""
        mu = np.asarray(mu, dtype=np.float64)
        out = self.lookup.upper(np.clip(mu, 1e-300, 1.0))
        if self.product is not None:
            hi = mu > self.product.mlo
            if np.any(hi):
                out = np.array(out, dtype=np.float64)
                out[hi] = self.product(np.clip(mu[hi], self.product.mlo * (1 + 1e-15), 1.0))
        return out

    def deficit(self, mu) -> np.ndarray:
        """D(mu) = max(0, 1 - U(mu)) <= 1 - E(mu)."""
        return np.maximum(0.0, 1.0 - self.upper(mu))

    def _integral(self):
        """(I_hi, kinks): an upper bound of I = 2 integral_0^1 D(mu) mu dmu and the mu in (0, 1) where
        D reaches 0 (kinks of the lobe).  Exact on each polynomial piece of the product table (Gauss-
        Legendre of 8 nodes is exact to degree 15; the pieces are split where U crosses 1); below the
        first piece D <= 1 adds at most mu_min^2.
        """
        p = self.product
        if p is None:  # pragma: no cover - adaptive quadrature of the spline look-up instead
            from scipy.integrate import quad

            v, err = quad(lambda m: 2.0 * float(self.deficit(np.array([m]))[0]) * m, 0.0, 1.0, limit=400,
                          points=np.exp(self.lookup.logx[1:-1]))
            return v + 10 * err + 1e-15, []
        xg, wg = np.polynomial.legendre.leggauss(8)
        parts, kinks = self._parts()
        total = 0.0
        for s, t0, t1 in parts:
            t = 0.5 * (t0 + t1) + 0.5 * (t1 - t0) * xg
            m = p.center[s] + t / p.ihalf[s]
            d = np.maximum(0.0, 1.0 - np.polyval(p.coef[:, s], t))
            total += 2.0 * float(np.sum(wg * d * m)) * 0.5 * (t1 - t0) / p.ihalf[s]  # 2 D mu dmu
        return total * (1.0 + 1e-12) + p.mlo ** 2 + 1e-300, sorted(k for k in kinks if 0 < k < 1)

    def _parts(self) -> tuple:
        """([(piece, t0, t1)], kinks): the smooth parts of the product table's polynomial pieces in t = (m - centre) /
        half (each piece from t = -1 to its end, the last one to m = 1), cut where U = 1 (D's kinks, also returned in
        m), for Gauss-Legendre (:meth:`_integral`, :meth:`deficit_moment`).
        """
        p = self.product
        hi = np.concatenate([p.lo[1:-1], [1.0]])
        parts, kinks = [], []
        for s in range(len(p.lo) - 1):
            coef = p.coef[:, s]  # highest power first, in t = (m - centre) / half
            a, b = -1.0, (min(hi[s], 1.0) - p.center[s]) * p.ihalf[s]
            r = np.roots(np.concatenate([coef[:-1], [coef[-1] - 1.0]])) if len(coef) > 1 else np.array([])
            r = np.sort(r[np.abs(r.imag) <= 1e-8 * (1.0 + np.abs(r.real))].real)
            cuts = np.concatenate([[a], r[(r > a) & (r < b)], [b]])
            parts += [(s, t0, t1) for t0, t1 in zip(cuts[:-1], cuts[1:])]
            kinks += [float(p.center[s] + x / p.ihalf[s]) for x in cuts[1:-1]]
        return parts, kinks

    def deficit_moment(self) -> tuple | None:
        """(I, its error): I = 2 integral_0^1 D(m) m dm of the kernels' own D (:func:`_deficits`), the Kulla-Conty
        lobe's albedo per unit D(mu_i), over pi (the lobe D(mu_i) D(mu_o) reflects D(mu_i) 2 pi integral D(t) t dt).
        Above the product table's mlo D is a polynomial of degree 5 in m on each part (:meth:`_parts`): Gauss-Legendre
        of 8 nodes is exact there, on D evaluated as the kernels evaluate it, so the error is the rounding of the values
        (32 eps U per node, summed with the weights); below mlo, 0 <= D <= 1 adds between 0 and mlo^2 (half of it is
        counted, the other half is error).  (:meth:`_integral`'s I_hi is an upper bound of the same I.)  Cached; None
        without a product table.
        """
        got = getattr(self, "_moment", None)
        if got is not None or self.product is None:
            return got
        p = self.product
        xg, wg = np.polynomial.legendre.leggauss(8)
        parts, _ = self._parts()
        s, t0, t1 = (np.array(c) for c in zip(*parts))
        t = 0.5 * (t0 + t1)[:, None] + 0.5 * (t1 - t0)[:, None] * xg[None, :]
        m = (p.center[s][:, None] + t / p.ihalf[s][:, None]).ravel()
        w = (wg[None, :] * (0.5 * (t1 - t0) / p.ihalf[s])[:, None]).ravel()
        d = _deficits(m, *self.args)
        value = float(np.sum(2.0 * w * d * m)) + 0.5 * p.mlo ** 2
        err = 32.0 * np.finfo(float).eps * float(np.sum(2.0 * w * m * np.maximum(1.0, 1.0 - d))) + 0.5 * p.mlo ** 2
        self._moment = (value, err)
        return self._moment


@njit(cache=True, nogil=True)
def _uppers(m, pmlo, pcbase, pcell, plo, prow, logx, coef, v0, slope0, margin_lo, margin, cap):  # pragma: no cover
    """U(m) at every m (``m`` > 0) by :func:`scale_bound`: the kernels' own look-up, value for value."""
    out = np.empty(m.shape[0])
    for i in range(m.shape[0]):
        out[i] = scale_bound(m[i], pmlo, pcbase, pcell, plo, prow, logx, coef, v0, slope0, margin_lo, margin, cap)
    return out


def _deficits(m, *args) -> np.ndarray:
    """D(m) = max(0, 1 - U(m)) at every m (a 1-D array), as the Kulla-Conty kernel forms it from :func:`_uppers`."""
    return np.maximum(0.0, 1.0 - _uppers(m, *args))


def _bounds(white: BRDF) -> _Bound:
    t = compensation_table(white)
    b = getattr(t, "_bound", None)
    if b is None:
        b = t._bound = _Bound(t)
    return b


def fresnel_average(base: BRDF, nodes: int = 64) -> float:
    """F_avg = 2 integral_0^1 F(mu) mu dmu of a microfacet model's Fresnel factor (KC, "Fresnel").

    1 for a model without ``ior`` or ``eta``.  Gauss-Legendre on ``nodes`` points (F is smooth
    in mu on [0, 1]; 64 and 128 nodes agree to 1e-15 for ior 1.5 and gold).
    """
    p = base.p
    if p.get("eta") is None and p.get("ior") is None:
        return 1.0
    x, w = np.polynomial.legendre.leggauss(nodes)
    mu = 0.5 * (x + 1.0)
    if p.get("eta") is not None:
        from ..physics.fresnel import fresnel_conductor as fresnel

        fr = fresnel(mu, p["eta"], p.get("k") or 0.0)
    else:
        from ..physics.fresnel import fresnel_dielectric as fresnel

        fr = fresnel(mu, p["ior"])
    return float(np.clip(np.sum(w * 0.5 * 2.0 * fr * mu), 0.0, 1.0))


class _Compensated(BRDF):
    """Shared machinery of :class:`KullaConty` and :class:`Scaled`."""

    constant = None
    #: pairs per pass of the kernel (as Pumped.BLOCK)
    BLOCK = 8192

    def __init__(self, **kwargs):
        super().__init__(**kwargs)
        base = self.p["base"]
        white = self.p.get("white") or base
        if np.ndim(base._eval(np.array([0.0, 0.0, 1.0]), np.array([0.0, 0.0, 1.0]))) != 0:
            raise SpecError(f"{self.type}: the base must have one channel (a spectral or RGB base is not supported)")
        for name, f in (("base", base), ("white", white)):
            if f.azimuth_range() is not None:  # E(mu) would depend on the azimuth of the light
                raise SpecError(f"{self.type}: the {name} {f.type!r} is anisotropic; its albedo depends on the azimuth "
                                "of the light, and this compensation needs E(mu) alone (use pump(..., g='g1'|'g2'), "
                                "which bounds the supremum over azimuths)")
        self._white = white
        self.reciprocal = self._check_reciprocal(self.type, self._why) and type(self).reciprocal
        self._precheck()
        self.bound = _bounds(white)

    _why = ""

    def _precheck(self) -> None:
        """Checks before the table is built (override)."""

    @property
    def base(self) -> BRDF:
        return self.p["base"]

    @property
    def white(self) -> BRDF:
        """The Fresnel-1 BRDF whose albedo is E (the base unless ``white`` is given)."""
        return self._white

    def table(self):
        """The albedo table E of :attr:`white`."""
        return self.bound.table

    def _check_reciprocal(self, model: str, why: str) -> bool:
        """True if the base (and white) are reciprocal (measured); else a SpecError unless ``force``."""
        ok = True
        for name, f in (("base", self.base), ("white", self.white)):
            if name == "white" and f is self.base:
                continue
            r = check_reciprocity(f, n_mu=16, n_phi=16)
            if not (r.reciprocal and f.reciprocal):
                if not self.p["force"]:
                    raise SpecError(f"{model}: the {name} {f.type!r} is not reciprocal ({r}); {why}. "
                                    "Pass force=True (--force on the command line) to compensate it anyway.")
                ok = False
        return ok

    def _run(self, kernel, first, wi, wo):
        shape = np.broadcast_shapes(wi.shape[:-1], wo.shape[:-1])
        n = math.prod(shape)
        if n > 2 * self.BLOCK and wi.shape == wo.shape:
            a, b = wi.reshape(-1, 3), wo.reshape(-1, 3)
            out = np.empty(n)
            for s in range(0, n, self.BLOCK):
                out[s:s + self.BLOCK] = self._run(kernel, first, a[s:s + self.BLOCK], b[s:s + self.BLOCK])
            return out.reshape(shape)
        f = self.base._eval(wi, wo)
        own = (isinstance(f, np.ndarray) and f.dtype == np.float64 and f.flags.owndata and f.flags.c_contiguous
               and f.flags.writeable and getattr(self.base, "fn", None) is None)
        if not own or f.shape != shape:
            f = np.array(np.broadcast_to(f, shape), dtype=np.float64)
        if wi.shape[:-1] != shape or wo.shape[:-1] != shape:
            wi, wo = np.broadcast_to(wi, shape + (3,)), np.broadcast_to(wo, shape + (3,))
        kernel(f.reshape(-1), wi.reshape(-1, 3), wo.reshape(-1, 3), first, *self.bound.args)
        return f


@register("kulla_conty")
class KullaConty(_Compensated):
    """The Kulla-Conty energy compensation f + F_ms f_ms [1/sr] (KC eq. 1-2; see the module docstring).

    f_ms(wi, wo) = D(mu_i) D(mu_o) / (pi I), D = 1 - E (from the upper bound of E's table),
    I = 1 - E_avg = 2 integral D mu dmu (an upper bound of it), F_ms = F_avg^2 E_avg /
    (1 - F_avg (1 - E_avg)).

    Parameters
    ----------
    base : spec
        The BRDF to compensate; reciprocal (checked) unless ``force``; its albedo (or that of
        ``white``) must not exceed 1 beyond its error.
    white : spec, optional
        The Fresnel-1 BRDF whose albedo is E (default: ``base``).  For a coloured lobe
        f = F f_1 give f_1 here (:func:`compensate` does it for ``ggx``/``beckmann`` with
        ``ior`` or ``eta``).
    f_avg : float, in [0, 1], default 1
        The hemispherical average of the Fresnel factor, F_avg = 2 integral F mu dmu; 1 gives
        F_ms = 1.
    force : bool
        Accept a non-reciprocal base.

    Notes
    -----
    Reciprocal to rounding when the base is (D(mu_i) D(mu_o) is formed in the same order both
    ways).  The albedo is 1 within about 2e-7 for a base with Fresnel 1 (module docstring).
    Sampling: the base's strategy and a cosine lobe, mixed in the ratio of their albedos at
    the conditioning direction, E : F_ms (1 - E) (the albedo deficit).

    Examples
    --------
    >>> import pumpup
    >>> f = pumpup.load({"type": "kulla_conty", "base": {"type": "lambert", "albedo": 0.5}})
    >>> round(float(pumpup.albedo(f, 0.7)), 6)
    1.0
    """

    params = {
        "base": Param(kind="spec", doc="the BRDF to compensate"),
        "white": Param(None, kind="spec", doc="the Fresnel-1 BRDF whose albedo is E (default: base)"),
        "f_avg": Param(1.0, lo=0.0, hi=1.0, doc="hemispherical average of the Fresnel factor"),
        "force": Param(False, kind="bool", doc="accept a base that is not reciprocal"),
    }
    examples = [{"base": {"type": "phong", "n": 5}}, {"base": {"type": "lambert", "albedo": 0.5}, "f_avg": 0.8}]
    _why = "the Kulla-Conty lobe compensates a symmetric BRDF"

    #: where :meth:`_precheck` looks for an albedo above 1 before the table is built
    PROBE_MU = (1.0, 0.5, 0.1, 1e-2, 1e-4, 1e-6, 1e-8)

    def _precheck(self) -> None:
        from ..engine.cubature import albedo

        a, e = albedo(self.white, np.array(self.PROBE_MU), return_error=True, rtol=1e-6, atol=1e-12)
        self._refuse_above_one(np.array(self.PROBE_MU), a, e)

    def _refuse_above_one(self, mu, value, error) -> None:
        over = value - error
        if float(np.max(over)) > 1.0:
            i = int(np.argmax(over))
            raise SpecError(
                f"kulla_conty: the albedo of the base {self.white.type!r} exceeds 1 (E = {value[i]:.9g} +- "
                f"{error[i]:.2g} at mu = {mu[i]:.3g}, theta = {math.degrees(math.acos(mu[i])):.4f} deg), "
                "so 1 - E < 0 would make the lobe f_ms negative; use method 'g1' or 'g2' (pumping), "
                "which handles such a base")

    def __init__(self, **kwargs):
        super().__init__(**kwargs)
        t = self.table()
        self._refuse_above_one(t.mu, t.value, t.error)
        i_hi = self.bound.deficit_integral
        self.e_avg = 1.0 - i_hi  # a lower bound of the E_avg of the table's bound
        fa = self.p["f_avg"]
        den = 1.0 - fa * (1.0 - self.e_avg)
        self.f_ms = 0.0 if den <= 0 else min(1.0, fa * fa * self.e_avg / den)  # KC Fresnel slide: F_ms <= 1
        #: the constant of the lobe, F_ms / (pi I_hi) (0 when E = 1 everywhere)
        self.scale = self.f_ms / (math.pi * i_hi) if i_hi > 1e-250 else 0.0

    @property
    def spec(self) -> dict:
        """The model as a plain-JSON dict: the base, and ``white``, ``f_avg`` and ``force`` where they are not the
        defaults.
        """
        out = {"type": "kulla_conty", "base": self.base.spec}
        if self.p["white"] is not None:
            out["white"] = self.p["white"].spec
        if self.p["f_avg"] != 1.0:
            out["f_avg"] = self.p["f_avg"]
        if self.p["force"]:
            out["force"] = True
        return out

    def _eval(self, wi, wo):
        out = self.base.eval_plus_lobe(wi, wo, self.scale, self.bound.args)  # one pass, where the base has one
        return out if out is not None else self._run(_kc_kernel, self.scale, wi, wo)

    def _eval_two_passes(self, wi, wo):
        """:meth:`_eval` as the base's kernel, then :func:`_kc_kernel`: the reference of the fused pass and the
        baseline of scripts/bench/bench_eval.py.
        """
        return self._run(_kc_kernel, self.scale, wi, wo)

    def reference(self, wi, wo):
        """The plain numpy f_r: the base's reference plus F_ms D(mu_i) D(mu_o) (KC eq. 1), 0 below the horizon."""
        wi = np.asarray(wi, dtype=np.float64)
        wo = np.asarray(wo, dtype=np.float64)
        f = np.asarray(self.base.reference(wi, wo), dtype=np.float64)
        mi, mo = np.broadcast_arrays(wi[..., 2], wo[..., 2])
        up = (mi > 0) & (mo > 0)
        d = self.bound.deficit
        ms = self.scale * (d(np.where(up, mi, 1.0)) * d(np.where(up, mo, 1.0)))  # KC eq. 1
        return np.where(up, f + ms, 0.0)

    # --- hints: the base's terms and the lobe as its own term -----------------------------
    def _ms_term(self):
        if not hasattr(self, "_ms"):
            self._ms = _MsLobe(self) if self.scale > 0 else None
        return self._ms

    def albedo_terms(self):
        """The base's terms, plus the Kulla-Conty lobe D(mu_i) D(mu_o) weighted F_ms where that is positive."""
        terms = list(self.base.albedo_terms())
        ms = self._ms_term()
        return terms + ([(self.scale, ms)] if ms is not None else [])

    def sampling_terms(self, mu: float):
        """Terms weighted by their albedo at the conditioning direction: the base's terms share
        U(mu) >= E(mu), the lobe gets F_ms D(mu) (the deficit), for the sampling mixture.
        """
        terms = self.base.albedo_terms()
        w = np.array([abs(x) for x, _ in terms], dtype=float)
        w = w / w.sum() if w.sum() > 0 else np.full(len(terms), 1.0 / len(terms))
        e = float(min(1.0, self.bound.upper(np.array([mu]))[0]))
        out = [(float(x) * e, t) for x, (_, t) in zip(w, terms)]
        ms = self._ms_term()
        if ms is not None:
            out.append((self.f_ms * float(self.bound.deficit(np.array([mu]))[0]), ms))
        return out

    def lobe(self, mu: float) -> Lobe:
        """The base's Lobe hint with the kinks of D (where U reaches 1, and the table's breaks) as levels."""
        return self.base.lobe(mu).with_levels(self.bound.kinks)

    def sampling_lobe(self, mu: float) -> Lobe:
        """The base's sampling hint."""
        return self.base.sampling_lobe(mu)

    def report(self) -> str:
        """One paragraph for ``pumpup check``: E_avg, F_ms, the table and the bound on the furnace."""
        t = self.table()
        return (f"kulla_conty: E_avg = {self.e_avg:.10g} (lower bound), F_avg = {self.p['f_avg']:.6g}, "
                f"F_ms = {self.f_ms:.10g}; E table of {self.white.type!r}: {len(t.mu)} nodes, margin {t.margin:.2g}; "
                f"albedo <= 1 and >= 1 - {2 * t.margin_below:.2g} where E <= 1 (F_avg = 1)")


class _MsLobe(BRDF):
    """D(mu_i) D(mu_o): the shape of the Kulla-Conty lobe (its weight is KullaConty.scale)."""

    type = "kulla_conty-lobe"
    params = {}

    def __init__(self, kc: KullaConty):
        self.p = {}
        self.kc = kc
        self.reciprocal = True

    @property
    def spec(self):
        return {"type": "kulla_conty-lobe", "of": self.kc.spec}

    def _eval(self, wi, wo):
        shape = np.broadcast_shapes(wi.shape[:-1], wo.shape[:-1])
        f = np.zeros(shape)
        if wi.shape[:-1] != shape or wo.shape[:-1] != shape:
            wi, wo = np.broadcast_to(wi, shape + (3,)), np.broadcast_to(wo, shape + (3,))
        _kc_kernel(f.reshape(-1), wi.reshape(-1, 3), wo.reshape(-1, 3), 1.0, *self.kc.bound.args)
        return f

    def lobe(self, mu):
        return Lobe(axis="normal", radial="cosine", levels=tuple(sorted(set(self.kc.bound.kinks) | set(TABLE_DECADES))),
                    symmetric=True)

    def azimuth_hint(self):
        """The lobe's albedo in closed form (:class:`~pumpup.core.hints.ClosedForm`): D(mu) 2 pi integral_0^1 D(t) t
        dt = D(mu) pi I, D the kernels' own (:func:`_deficits`), I by :meth:`_Bound.deficit_moment` (exact on the
        product table's polynomial pieces); the relative error I's, plus 8 ulps for D(mu) pi I itself.  Without
        it the nested engine integrates the lobe (80 ms for 257 mu, GGX alpha = 0.3).
        """
        from ..core.hints import AzimuthHint, ClosedForm

        got = self.kc.bound.deficit_moment()
        if got is None:  # pragma: no cover
            return None
        i, e = got
        args = self.kc.bound.args
        rel = e / i if i > 0.0 else 0.0
        return AzimuthHint(ClosedForm(ulps=8.0 + rel / np.finfo(float).eps),
                           scale=lambda mu: math.pi * i * _deficits(np.asarray(mu, dtype=np.float64).reshape(-1),
                                                                    *args).reshape(np.shape(mu)))


def _scaled_lobe(b: Lobe, bound) -> Lobe:
    """The hint of a scaled lobe: the base's (``b``), with U's kinks and, about the normal, the levels of
    :func:`pumpup.operators.pumping.table_decades`.
    """
    return b.with_levels(bound.kinks, table_decades(b))


@register("scaled")
class Scaled(_Compensated):
    """The 1/E scaling f (1 + F0 (1 / E(mu_o) - 1)) [1/sr] (Turquin 2019 eq. 6; Cycles, Filament, Unity).

    With F0 = 1 it is f / E(mu_o): the white furnace toward the viewer is 1 (to within the
    table's margin).  Not reciprocal: the factor depends on wo alone (declared:
    ``reciprocal = False``; :func:`pumpup.check_reciprocity` measures it).

    Parameters
    ----------
    base : spec
        The lobe to scale; reciprocal (checked, else E of the table is not the albedo toward wo)
        unless ``force``.
    white : spec, optional
        The Fresnel-1 BRDF whose albedo is E (default: ``base``).
    f0 : float, in [0, 1], default 1
        The Fresnel reflectance at normal incidence (Turquin's F0).
    force : bool
        Scale a non-reciprocal base with its albedo table anyway.

    Examples
    --------
    >>> import pumpup
    >>> f = pumpup.load({"type": "scaled", "base": {"type": "lambert", "albedo": 0.5}})
    >>> round(float(pumpup.albedo(f, 0.7)), 6)
    1.0
    """

    params = {
        "base": Param(kind="spec", doc="the BRDF to scale"),
        "white": Param(None, kind="spec", doc="the Fresnel-1 BRDF whose albedo is E (default: base)"),
        "f0": Param(1.0, lo=0.0, hi=1.0, doc="Fresnel reflectance at normal incidence"),
        "force": Param(False, kind="bool", doc="accept a base that is not reciprocal"),
    }
    reciprocal = False
    examples = [{"base": {"type": "phong", "n": 5}}, {"base": {"type": "phong", "n": 5}, "f0": 0.5}]
    _why = "its albedo table is then not the albedo toward wo that 1/E(mu_o) needs"

    def __init__(self, **kwargs):
        super().__init__(**kwargs)

    @property
    def spec(self) -> dict:
        """The model as a plain-JSON dict: the base, ``f0``, and ``white`` and ``force`` where they are not the
        defaults.
        """
        out = {"type": "scaled", "base": self.base.spec, "f0": self.p["f0"]}
        if self.p["white"] is not None:
            out["white"] = self.p["white"].spec
        if self.p["force"]:
            out["force"] = True
        return out

    def _eval(self, wi, wo):
        return self._run(_scale_kernel, self.p["f0"], wi, wo)

    def kernel_factor(self, mu_o) -> np.ndarray:
        """1 + F0 (1 / U(mu_o) - 1) with U from the kernels' own look-up (:func:`_uppers`; ``factor`` is its numpy
        reference), for the furnace toward the viewer's closed form (:meth:`_Transposed.polar`).
        """
        m = np.asarray(mu_o, dtype=np.float64)
        u = _uppers(np.clip(m, 1e-300, 1.0).reshape(-1), *self.bound.args).reshape(m.shape)
        f0 = self.p["f0"]
        return 1.0 / u if f0 == 1.0 else 1.0 + f0 * (1.0 / u - 1.0)

    def factor(self, mu_o) -> np.ndarray:
        """1 + F0 (1 / U(mu_o) - 1) in plain numpy (Turquin eq. 6)."""
        u = self.bound.upper(mu_o)
        f0 = self.p["f0"]
        return 1.0 / u if f0 == 1.0 else 1.0 + f0 * (1.0 / u - 1.0)

    def reference(self, wi, wo):
        """The plain numpy f_r: the base's reference times 1 + F0 (1 / U(mu_o) - 1) (Turquin eq. 6), 0 below the
        horizon.
        """
        wi = np.asarray(wi, dtype=np.float64)
        wo = np.asarray(wo, dtype=np.float64)
        f = np.asarray(self.base.reference(wi, wo), dtype=np.float64)
        mi, mo = np.broadcast_arrays(wi[..., 2], wo[..., 2])
        up = (mi > 0) & (mo > 0)
        return np.where(up, f * self.factor(np.where(up, mo, 1.0)), 0.0)

    def albedo_terms(self):
        """Itself for a base of one term, else each of the base's terms scaled by the same factor of mu_o."""
        terms = self.base.albedo_terms()
        if len(terms) == 1 and terms[0][1] is self.base:
            return [(1.0, self)]
        return [(w, _ScaledTerm(t, self)) for w, t in terms]

    def lobe(self, mu: float) -> Lobe:
        """The base's Lobe hint with U's kinks and, about the normal, the table's decades as levels."""
        return _scaled_lobe(self.base.lobe(mu), self.bound)

    def azimuth_hint(self):
        """The base's hint times 1 + F0 (1 / U(N.wo) - 1) (Turquin eq. 6;
        :class:`~pumpup.core.hints.InverseAlbedoFactor`), a function of N.wo alone, with U's kinks as its levels; None
        where the base has no hint, or where U is not smooth between its kinks: the white model must be a Smith lobe
        with F = 1, the exact G1 and alpha <= 1, or Schlick's, with no factors of its own.
        """
        from ..core.hints import InverseAlbedoFactor, SchlickLobe, SmithLobe

        hint = self.base.azimuth_hint()
        white = hint if self.white is self.base else self.white.azimuth_hint()
        if hint is None or white is None or white.factors:
            return None
        f = white.family
        if not (isinstance(f, SchlickLobe) or isinstance(f, SmithLobe) and f.fresnel is None and f.alpha <= 1.0
                and f.g1 == "exact"):
            # Walter's G1, whose albedo jumps at the switch level (pumpup.models.microfacet.walter_level): the table's
            # spline rings across the jump among hundreds of knots (614 nodes, margin 1.1e-4, for Beckmann alpha 0.19),
            # which the 1-D route's pieces did not see: F0 0.11 at mu = 0.9999 was 2.9e-12 off with an estimate of
            # 3.1e-14 (94 x), alpha 0.035 at mu = 0.074 28 x
            return None
        # U's kinks, and where its look-up turns from the spline to the product table (:func:`scale_bound`): a level, so
        # that the cuts are graded in N.wo down to a quarter of it (``chain_cuts``; U(N.wo) is a spline in log N.wo
        # and not analytic at 0: with the grading only down to a quarter of mu, as g's needs, Schlick r = 0.2 at mu =
        # 0.985 was 1.0e-11 off on the piece N.wo < 0.172 with an estimate of 2.7e-12)
        kinks = tuple(self.bound.kinks) + (float(self.bound.args[0]),)
        return hint.times(InverseAlbedoFactor(f0=float(self.p["f0"]), bound=tuple(self.bound.args),
                                              levels=lambda mu: tuple(sorted({float(mu), *kinks}))))

    def sampling_lobe(self, mu: float) -> Lobe:
        """The base's sampling hint."""
        return self.base.sampling_lobe(mu)

    def report(self) -> str:
        """One paragraph for ``pumpup check``: the formula, F0, the E table's size and margin, and the furnace bound."""
        t = self.table()
        return (f"scaled: f (1 + F0 (1/E(mu_o) - 1)), F0 = {self.p['f0']:.6g}; not reciprocal by construction; "
                f"E table of {self.white.type!r}: {len(t.mu)} nodes, margin {t.margin:.2g}; the furnace toward wo is "
                "E/U <= 1 (F0 = 1)")


class _ScaledTerm(BRDF):
    """One linear term of a scaled sum, f_k (1 + F0 (1 / U(mu_o) - 1))."""

    type = "scaled-term"
    params = {}

    def __init__(self, term: BRDF, scaled: Scaled):
        self.p = {}
        self.term, self.scaled = term, scaled
        self.reciprocal = False

    @property
    def spec(self):
        return {"type": "scaled-term", "term": self.term.spec, "of": self.scaled.spec}

    def _eval(self, wi, wo):
        f = np.asarray(self.term._eval(wi, wo), dtype=np.float64)
        return f * self.scaled.factor(np.clip(np.broadcast_to(wo[..., 2], f.shape), 1e-300, 1.0))

    def lobe(self, mu):
        return _scaled_lobe(self.term.lobe(mu), self.scaled.bound)

    def sampling_lobe(self, mu):
        return self.term.sampling_lobe(mu)


# --- the white furnace toward the viewer ------------------------------------------------------


class _Transposed(BRDF):
    """f(wo, wi): its albedo at mu is the white furnace toward a viewer at cos(theta_o) = mu,
    integral f(wi, wo) cos(theta_i) d omega_i.  The hint is the inner one, which is right when f
    is a reciprocal BRDF times a function of one direction (the scaled BRDF).
    """

    type = "transposed"
    params = {}

    def __init__(self, inner: BRDF):
        self.p = {}
        self.inner = inner
        self.reciprocal = inner.reciprocal

    @property
    def spec(self):
        return {"type": "transposed", "of": self.inner.spec}

    def _eval(self, wi, wo):
        return self.inner._eval(wo, wi)

    def lobe(self, mu):
        return self.inner.lobe(mu)

    def albedo_terms(self):
        terms = self.inner.albedo_terms()
        if len(terms) == 1 and terms[0][1] is self.inner:
            return [(1.0, self)]
        return [(w, _Transposed(t)) for w, t in terms]

    def azimuth_hint(self):
        """The 1-D path of the furnace toward the viewer of a scaled model, or of one term of a scaled sum: f(wi, wo) =
        f_r(wi, wo) s(N.wo) with f_r reciprocal, so f(wo, wi) = s(N.wi) f_r(wi, wo) and its albedo at mu is s(mu) times
        f_r's (000 eq. 2; s = 1 + F0 (1 / U - 1), Turquin eq. 6): f_r's own hint with its scale times s (as the kernel
        forms it, :meth:`Scaled.kernel_factor`).  None for anything else (the nested engine), or a base forced in
        without reciprocity.
        """
        import dataclasses

        if isinstance(self.inner, Scaled):
            base, scaled = self.inner.base, self.inner
        elif isinstance(self.inner, _ScaledTerm):
            base, scaled = self.inner.term, self.inner.scaled
        else:
            return None
        hint = base.azimuth_hint() if base.reciprocal else None
        if hint is None:
            return None
        inner_scale = hint.scale
        return dataclasses.replace(hint, scale=lambda mu: inner_scale(mu) * scaled.kernel_factor(mu))


@functools.singledispatch
def furnace(f: BRDF, mu: ArrayLike, return_error: bool = False,
            **kw: Any) -> np.ndarray | tuple[np.ndarray, np.ndarray]:
    """The white furnace toward a viewer at cos(theta_o) = mu: integral f(wi, wo) cos(theta_i) d omega_i.

    For a reciprocal BRDF this is its albedo a(mu) (000 eq. 2); for ``scaled`` it is the
    quantity the scaling makes 1.  Keywords go to :func:`pumpup.albedo`.
    """
    from ..engine.cubature import albedo

    g = f if f.reciprocal else _Transposed(f)
    return albedo(g, mu, return_error=return_error, **kw)


# --- the operator ---------------------------------------------------------------------------


def compensate(f: BRDF | dict, method: str = "kulla_conty", *, f0: float | None = None, f_avg: float | None = None,
               white: BRDF | dict | None = None, force: bool = False, max_seconds: float | None = None) -> BRDF:
    """Energy compensation of a BRDF: the Kulla-Conty lobe, the 1/E scaling, or pumping.

    Parameters
    ----------
    f : BRDF or spec
        Any BRDF the engine can tabulate (one channel), or a spectral model or spec: each
        wavelength compensated on its own (:class:`pumpup.spectral.ops.SpectralCompensated`).
    method : {"kulla_conty", "scale", "g1", "g2"}
        "kulla_conty": f + F_ms f_ms (:class:`KullaConty`); "scale": f (1 + F0 (1/E(mu_o) - 1))
        (:class:`Scaled`, not reciprocal); "g1", "g2": one level of pumping (001 eq. 20, 21;
        :func:`pumpup.pump`).
    f0 : float, in [0, 1], optional
        "scale": Turquin's F0 (default 1).  "kulla_conty": F_avg from Schlick's Fresnel,
        (20 F0 + 1) / 21 = 2 integral (F0 + (1 - F0)(1 - mu)^5) mu dmu.
    f_avg : float, in [0, 1], optional
        "kulla_conty": the Fresnel average directly.  Default: from ``f0``, else from the base's
        own Fresnel factor (``ior`` or ``eta``, ``k`` of ``ggx``/``beckmann``, whose E is then
        that of the Fresnel-1 lobe), else 1.
    white : BRDF or spec, optional
        The Fresnel-1 BRDF whose albedo is E (default: f without its Fresnel factor, or f).
    force : bool
        Accept a non-reciprocal base for the methods that need a reciprocal one.
    max_seconds : float, optional
        A time budget: the tables are computed now (by default, on first use), and past the budget the work stops
        with :class:`pumpup.core.budget.BudgetExceeded` (a TimeoutError) instead of running on.

    Returns
    -------
    BRDF
        A registered, nested spec: ``{"type": "kulla_conty", "base": ...}``, ``{"type":
        "scaled", "base": ..., "f0": ...}`` or ``{"type": "pumped", ...}``.

    Examples
    --------
    >>> import pumpup
    >>> c = pumpup.compensate({"type": "lambert", "albedo": 0.5}, method="scale")
    >>> c.spec
    {'type': 'scaled', 'base': {'type': 'lambert', 'albedo': 0.5}, 'f0': 1.0}
    """
    if method not in METHODS:
        raise SpecError(f"compensate: method must be one of {', '.join(map(repr, METHODS))}; got {method!r}")
    for name, v in (("f0", f0), ("f_avg", f_avg)):
        if v is not None and (isinstance(v, bool) or not isinstance(v, (int, float, np.integer, np.floating))
                              or not 0.0 <= v <= 1.0):  # (v itself: float() of 10**400 overflows)
            raise SpecError(f"compensate: {name} must be a number in [0, 1], got {reprlib.repr(v)}")
    if not isinstance(force, (bool, np.bool_)):
        raise SpecError(f"compensate: force must be true or false, got {force!r}")
    check_max_seconds("compensate", max_seconds)
    with time_budget("compensate", max_seconds):
        out = compensate_model(load(f), method, f0=f0, f_avg=f_avg, white=white, force=force)
        if max_seconds is not None:
            prepare(out)
    return out


@functools.singledispatch
def compensate_model(base: BRDF, method: str, *, f0, f_avg, white, force) -> BRDF:
    """:func:`compensate` of a loaded model, its arguments checked.  Other kinds of model register their own
    (:mod:`pumpup.spectral`: every wavelength compensated on its own).
    """
    if method in ("g1", "g2"):
        if f0 is not None or f_avg is not None or white is not None:
            raise SpecError(f"compensate: method {method!r} (pumping) takes no f0, f_avg or white")
        return Pumped(base=base, g=method, force=bool(force))
    f0 = None if f0 is None else float(f0)  # (checked by compensate: a number in [0, 1])
    w = load(white) if white is not None else base.fresnel_one()
    spec: dict = {"base": base}
    if w is not None:
        spec["white"] = w
    if force:
        spec["force"] = True
    if method == "scale":
        if f_avg is not None:
            raise SpecError("compensate: f_avg belongs to method 'kulla_conty'; method 'scale' takes f0")
        return Scaled(**spec, f0=1.0 if f0 is None else f0)
    if f_avg is None:
        f_avg = (20.0 * f0 + 1.0) / 21.0 if f0 is not None else fresnel_average(base)
    return KullaConty(**spec, f_avg=f_avg)


# --- saving and loading: the spec and every table it needs, one netCDF file -----------------


def _needed_tables(f: BRDF, out: list) -> list:
    """(cache name, BRDF whose table it is) for every compensated or pumped node under f."""
    if isinstance(f, _Compensated):
        out.append(("compensate", f.white))
    elif isinstance(f, Pumped):
        out.append(("pump", f.base))
    for v in f.p.values():
        if isinstance(v, BRDF):
            _needed_tables(v, out)
    return out


def save_compensated(f: BRDF, path: str | os.PathLike[str]) -> str:
    """Write a compensated (or pumped, or any nesting of them) BRDF and all its tables to one netCDF file.

    Groups ``table1``, ``table2``, ... hold the tables (attribute ``cache``: "compensate" for
    an E table, "pump" for a pumping table); the root attributes hold the spec.  Written
    atomically; :func:`load_compensated` reads it back without recomputing anything.
    """
    import xarray as xr

    from .._version import __version__
    from ..tables import write_groups
    from .pumping import base_table

    if not isinstance(f, BRDF):
        raise TypeError(f"save_compensated needs a pumpup BRDF, got {type(f).__name__}")
    need = _needed_tables(f, [])
    if not need:
        raise TypeError(f"save_compensated needs a compensated or pumped BRDF, got {f.type!r} (no tables to save)")
    seen, groups = set(), []
    for kind, g in need:
        k = (kind, _key(g))
        if k in seen:
            continue
        seen.add(k)
        if kind == "compensate":
            ds = compensation_table(g).dataset
        else:
            ds = base_table(g).dataset
        groups.append(ds.assign_attrs(cache=kind))
    root = xr.Dataset(attrs={"pumpup_kind": "pumpup compensated BRDF", "spec": json.dumps(f.spec, sort_keys=True),
                             "tables": len(groups), "pumpup_version": __version__})
    # checksums and digests as every file pumpup writes (open_table checks them on load)
    return write_groups(path, root, [(f"table{i}", ds) for i, ds in enumerate(groups, start=1)])


def load_compensated(path: str | os.PathLike[str]) -> BRDF:
    """Load a BRDF saved by :func:`save_compensated`, without recomputing its tables.

    Every group is read from one file (:func:`pumpup.tables.snapshot`), whatever a concurrent save puts at ``path``
    meanwhile.
    """
    from ..tables import snapshot

    with snapshot(path) as copy:
        return _load_compensated(copy, os.fspath(path))


def _load_compensated(path: str, where: str) -> BRDF:
    """:func:`load_compensated` of the file at ``path`` (a snapshot), named ``where`` in messages."""
    from ..tables import AlbedoTable, open_table

    root = open_table(path, _container=True, _name=where)  # (the saved BRDF's root)
    if root.attrs.get("pumpup_kind") != "pumpup compensated BRDF":
        raise ValueError(f"{where!r} is a pumpup file but not a saved compensated BRDF "
                         f"(pumpup_kind {root.attrs.get('pumpup_kind')!r})")
    try:
        n = int(root.attrs["tables"])
        spec = json.loads(root.attrs["spec"])
    except (KeyError, ValueError) as exc:
        raise ValueError(f"{where!r}: damaged compensated-BRDF file ({exc})") from None
    tables = {}
    # innermost first (the groups were saved outermost first): a group's spec is validated by
    # building it, which needs the tables of the BRDFs nested in it, taken from this file
    with file_tables(tables):
        for i in range(n, 0, -1):
            ds = open_table(path, group=f"table{i}", _name=where)
            kind = ds.attrs.get("cache")
            if kind not in ("compensate", "pump") or "albedo" not in ds or "albedo_error" not in ds:
                raise ValueError(f"{where!r}: group table{i} is not a compensation or pumping table")
            t = AlbedoTable.from_dataset(ds)
            ds = ds.copy()
            del ds.attrs["cache"]
            t.dataset = ds
            key = json.dumps(json.loads(ds.attrs["spec"]), sort_keys=True)  # = _key of its BRDF, without building it
            tables[(kind, key)] = t
    # the file's tables serve only the objects built from it: never the session's caches (issue 13 item 5)
    with file_tables(tables):
        f = load(spec)
        for node in _nodes(f):
            if isinstance(node, Pumped):
                t = tables.get(("pump", _key(node.base)))
                if t is None:
                    raise ValueError(f"{where!r}: no table for the pumped level of {node.base.spec}")
                node._own_table = t
                node.lookup()  # built now, from the file's table
    return f


def _nodes(f: BRDF):
    """The BRDF f and every BRDF nested in its parameters."""
    yield f
    for v in f.p.values():
        if isinstance(v, BRDF):
            yield from _nodes(v)
