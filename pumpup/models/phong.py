"""The Phong family: reciprocal Phong, stretched Phong / p-model, retro-reflective, and
Phong's original (non-reciprocal) shader as a BRDF.

All lobes are powers of cos(alpha) = (R.V)_+ (or (L.V)_+ for the retro-reflective model),
with R = 2 (N.L) N - L the mirror direction of L (000 eq. 8) and, by 000 eq. 9,
R.V = 2 (N.L)(N.V) - L.V.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit, vectorize

from ..core import BRDF, MAX_EXPONENT, Lobe, Param, dot, register
from ..core.checks import off_unit
from ..physics.lookups import g_levels_call, g_pair, g_product, g_split


def _phong_c(p):
    return (p["n"] + 2.0) / (2.0 * math.pi)  # 000 eq. 6, the largest energy-conserving c


def _cos_alpha(wi, wo):
    """(R.V) = 2 (N.L)(N.V) - (L.V), 000 eq. 9."""
    return 2.0 * wi[..., 2] * wo[..., 2] - dot(wi, wo)


def _up(wi, wo):
    return (wi[..., 2] > 0) & (wo[..., 2] > 0)


# --- reciprocal Phong ---------------------------------------------------------------------


@vectorize(cache=True)
def _phong_kernel(lx, ly, lz, vx, vy, vz, n, c):  # pragma: no cover - compiled
    if lz <= 0.0 or vz <= 0.0:
        return 0.0
    rv = 2.0 * lz * vz - (lx * vx + ly * vy + lz * vz)  # 000 eq. 9
    if rv <= 0.0:
        return 0.0
    return c * rv**n  # 000 eq. 5


#: rows per block of _phong_rows: a (B, 3) block of each argument and the scratch stay in the L1 cache
_BLOCK = 256


@njit(cache=True, nogil=True, inline="always")
def _lit_cos(lx, ly, lz, vx, vy, vz):  # pragma: no cover - compiled
    """R.V where the pair is lit (both above the horizon and R.V > 0, the kernel's tests, which a
    NaN passes), else 0.
    """
    rv = 2.0 * lz * vz - (lx * vx + ly * vy + lz * vz)  # 000 eq. 9
    return 0.0 if (lz <= 0.0) | (vz <= 0.0) | (rv <= 0.0) else rv


@njit(cache=True, nogil=True)
def _phong_rows(wi, wo, out, check, lo2, hi2, n, c):  # pragma: no cover - compiled; see _phong_reference
    """The kernel over the rows of C-contiguous (N, 3) arrays into ``out`` (N,) (``BRDF.rows_kernel``),
    with the input check in the same pass when ``check``.  Returns the first row of wi and of wo
    that is off the unit sphere (|w|^2 outside [lo2, hi2]) or not finite, -1 where none.

    Blocks of _BLOCK rows.  The first loop has no branch or call, so the compiler vectorizes it:
    R.V (0 where not lit) and, when ``check``, the check, which costs little there.  Then the lit rows are gathered
    without branches (a third of the pairs are dark, at random: an ``if`` mispredicts) and pow runs
    on them only.  The values are those of ``_phong_kernel`` bit for bit (the same operations,
    c * pow(R.V, n); a NaN gives what it gives there).  Loops index block views from 0: an index
    s + r kept LLVM from vectorizing them.
    """
    N = out.shape[0]
    x = np.empty(_BLOCK)  # R.V where lit, else 0
    lit = np.empty(_BLOCK, dtype=np.int64)  # the lit rows of the block
    bad_i = -1
    bad_o = -1
    for s in range(0, N, _BLOCK):
        m = min(N - s, _BLOCK)
        a = wi[s : s + m]
        b = wo[s : s + m]
        f = out[s : s + m]
        bad = False
        if check:
            for r in range(m):
                lx, ly, lz = a[r, 0], a[r, 1], a[r, 2]
                vx, vy, vz = b[r, 0], b[r, 1], b[r, 2]
                bad |= off_unit(lx, ly, lz, lo2, hi2) | off_unit(vx, vy, vz, lo2, hi2)
                x[r] = _lit_cos(lx, ly, lz, vx, vy, vz)
                f[r] = 0.0
        else:
            for r in range(m):
                x[r] = _lit_cos(a[r, 0], a[r, 1], a[r, 2], b[r, 0], b[r, 1], b[r, 2])
                f[r] = 0.0
        if bad:  # rare: the first failing rows of this block
            for r in range(m):
                if bad_i < 0 and off_unit(a[r, 0], a[r, 1], a[r, 2], lo2, hi2):
                    bad_i = s + r
                if bad_o < 0 and off_unit(b[r, 0], b[r, 1], b[r, 2], lo2, hi2):
                    bad_o = s + r
        q = 0
        for r in range(m):
            lit[q] = r
            q += (x[r] > 0.0) | (x[r] != x[r])
        for j in range(q):
            r = lit[j]
            f[r] = c * x[r] ** n  # 000 eq. 5
    return bad_i, bad_o


@njit(cache=True, nogil=True)
def _divide_rows(f, a, b, rows, count, offsets, logx, coef, v0, slope0, margin_lo, cap, controlled, increasing, mu0,
                 index, index_lo, index_h_inv, pmlo, pcbase, pcell, plo, prow, pinv, qmlo, qshift, qcbase, qcell, qlo,
                 qrow, rcells, rpattern, rfid, rhid, rshift, rcbase, rcell, rlo, rcoef):  # pragma: no cover - compiled
    """f[r] / (g_1 ... g_k) in place for the rows r = ``rows[:count]`` of a block (``a``, ``b`` its rows of wi and wo),
    the path of each chosen as ``pumpup.operators.pumping._chain_kernel`` chooses it; rows with a cosine <= 0 are left
    as they are.  Called once per block by :func:`_phong_divided` and :func:`_phong_divided_lit` (a call per row
    would cost more than the look-up: ``pumpup.physics.lookups.g_levels_call``).
    """
    for j in range(count):  # (a loop without pow's call)
        r = rows[j]
        lz, vz = a[r, 2], b[r, 2]
        if lz <= 0.0 or vz <= 0.0:
            continue
        mmax, mmin = max(lz, vz), min(lz, vz)
        if mmin > pmlo:  # (pumpup.physics.lookups.g_levels_call says why the paths are written out)
            f[r] = f[r] * g_product(mmax, pcbase, pcell, plo, pinv)  # 001 eq. 16, all levels (times 1 / G)
        elif mmin > qmlo:
            g = 0.0
            if rcells > 0:  # the split table: one product F(mmin) H(mmax), 0 where the cell has no pattern
                g = g_split(mmin, mmax, rcells, rpattern, rfid, rhid, rshift, rcbase, rcell, rlo, rcoef)
            if g == 0.0:
                g = g_pair(lz, vz, controlled, qshift, qcbase, qcell, qlo, qrow)
            f[r] = f[r] / g  # 001 eq. 16, all levels
        elif f[r] != 0.0:
            f[r] = f[r] / g_levels_call(mmax, mmin, offsets, logx, coef, v0, slope0, margin_lo, cap, controlled,
                                        increasing, mu0, index, index_lo, index_h_inv)


#: rows per block of _phong_divided and _phong_divided_lit (measured on 3-level g2 pumped Phong n = 20, when the kernel
#: still divided by G: 1.40 x Phong with blocks of 4096 rows, 1.51 x with 256, 1.43 x with 2048; 1 level: 1.37, 1.51
#: and 1.38 x)
_DIVIDED_BLOCK = 4096


@njit(cache=True, nogil=True)
def _phong_divided(wi, wo, out, n, c, offsets, logx, coef, v0, slope0, margin_lo, cap, controlled, increasing, mu0,
                   index, index_lo, index_h_inv, pmlo, pcbase, pcell, plo, prow, pinv, qmlo, qshift, qcbase, qcell, qlo,
                   qrow, rcells, rpattern, rfid, rhid, rshift, rcbase, rcell, rlo,
                   rcoef):  # pragma: no cover - compiled
    """f_r / (g_1 ... g_k) (001 eq. 16) over the rows of C-contiguous (N, 3) arrays into ``out`` in one pass, the path
    of each row chosen as ``pumpup.operators.pumping._chain_kernel`` chooses it (``BRDF.eval_divided``): the same
    operations, the same values (:func:`_phong_divided_lit`, tested bit for bit).

    Blocks of _DIVIDED_BLOCK rows.  A first loop without branches: R.V (0 where dark, :func:`_lit_cos`), max(N.wi,
    N.wo) and the number of rows with a cosine at or below the product table's ``mlo`` (or NaN).  In a block that has
    some (a direction below the horizon counts), the lit rows among them that the table does not serve are set aside
    for the row-by-row paths of :func:`_divide_rows`.  The other lit rows (a third of random pairs are dark) are then
    gathered without branches into contiguous arrays of R.V and max cosine; the product table's look-ups run over them
    in a loop of their own (1 / G, the table's inverse rows: a product costs less than a division), then pow and the
    product, each value written to its row.  A chain without a product table takes :func:`_phong_divided_lit`
    (:meth:`Phong.eval_divided`).
    """
    N = out.shape[0]
    x = np.empty(_DIVIDED_BLOCK)  # R.V where lit and the product table serves the row, else 0
    mm = np.empty(_DIVIDED_BLOCK)  # max(N.wi, N.wo)
    rows = np.empty(_DIVIDED_BLOCK, dtype=np.int64)  # the lit rows the product table serves
    y = np.empty(_DIVIDED_BLOCK)  # their R.V
    mc = np.empty(_DIVIDED_BLOCK)  # their max(N.wi, N.wo)
    hk = np.empty(_DIVIDED_BLOCK)  # their 1 / (g_1 ... g_k)
    rest = np.empty(_DIVIDED_BLOCK, dtype=np.int64)  # the other lit rows
    y_rest = np.empty(_DIVIDED_BLOCK)  # their R.V
    for s in range(0, N, _DIVIDED_BLOCK):
        m = min(N - s, _DIVIDED_BLOCK)
        a = wi[s : s + m]
        b = wo[s : s + m]
        f = out[s : s + m]
        low = 0  # rows with a cosine at or below the table's mlo (or NaN)
        for r in range(m):
            lz, vz = a[r, 2], b[r, 2]
            x[r] = _lit_cos(a[r, 0], a[r, 1], lz, b[r, 0], b[r, 1], vz)
            mm[r] = max(lz, vz)
            low += not (min(lz, vz) > pmlo)
            f[r] = 0.0
        k = 0
        if low > 0:  # (most blocks of directions above the horizon have none: the test per row would cost 0.03 x)
            for r in range(m):  # the lit rows the table does not serve leave x for rest
                lz, vz = a[r, 2], b[r, 2]
                xr = x[r]
                rest[k] = r
                y_rest[k] = xr
                other = ((xr > 0.0) | (xr != xr)) & (not ((lz > 0.0) & (vz > 0.0) & (min(lz, vz) > pmlo)))
                k += other
                x[r] = 0.0 if other else xr
        q = 0
        for r in range(m):
            rows[q] = r
            y[q] = x[r]
            mc[q] = mm[r]
            q += (x[r] > 0.0) | (x[r] != x[r])  # lit (a NaN too, as _phong_rows)
        for j in range(q):  # the look-ups first, in a loop without pow's call
            hk[j] = g_product(mc[j], pcbase, pcell, plo, pinv)
        for j in range(q):
            fr = c * y[j] ** n  # 000 eq. 5
            f[rows[j]] = fr * hk[j]  # 001 eq. 16, all levels (times 1 / G)
        for j in range(k):  # the other lit rows, as _phong_divided_lit
            f[rest[j]] = c * y_rest[j] ** n  # 000 eq. 5
        if k > 0:
            _divide_rows(f, a, b, rest, k, offsets, logx, coef, v0, slope0, margin_lo, cap, controlled, increasing,
                         mu0, index, index_lo, index_h_inv, pmlo, pcbase, pcell, plo, prow, pinv, qmlo, qshift, qcbase,
                         qcell, qlo, qrow, rcells, rpattern, rfid, rhid, rshift, rcbase, rcell, rlo, rcoef)


@njit(cache=True, nogil=True)
def _phong_divided_lit(wi, wo, out, n, c, offsets, logx, coef, v0, slope0, margin_lo, cap, controlled, increasing,
                       mu0, index, index_lo, index_h_inv, pmlo, pcbase, pcell, plo, prow, pinv, qmlo, qshift, qcbase,
                       qcell, qlo, qrow, rcells, rpattern, rfid, rhid, rshift, rcbase, rcell, rlo,
                       rcoef):  # pragma: no cover - compiled
    """:func:`_phong_divided` in blocks of _DIVIDED_BLOCK rows, every lit row divided in place through its row index
    (:func:`_divide_rows`, the path chosen row by row as ``pumpup.operators.pumping._chain_kernel`` chooses it): the
    same operations, the same values.  The baseline :meth:`Phong._eval_divided_lit` runs, for the tests of
    :func:`_phong_divided` and scripts/bench/bench_eval.py.
    """
    N = out.shape[0]
    x = np.empty(_DIVIDED_BLOCK)
    lit = np.empty(_DIVIDED_BLOCK, dtype=np.int64)
    for s in range(0, N, _DIVIDED_BLOCK):
        m = min(N - s, _DIVIDED_BLOCK)
        a = wi[s : s + m]
        b = wo[s : s + m]
        f = out[s : s + m]
        for r in range(m):
            x[r] = _lit_cos(a[r, 0], a[r, 1], a[r, 2], b[r, 0], b[r, 1], b[r, 2])
            f[r] = 0.0
        q = 0
        for r in range(m):
            lit[q] = r
            q += (x[r] > 0.0) | (x[r] != x[r])
        for j in range(q):
            r = lit[j]
            f[r] = c * x[r] ** n  # 000 eq. 5
        # only the lit rows (a dark row's value is 0 / g = 0 already)
        _divide_rows(f, a, b, lit, q, offsets, logx, coef, v0, slope0, margin_lo, cap, controlled, increasing,
                     mu0, index, index_lo, index_h_inv, pmlo, pcbase, pcell, plo, prow, pinv, qmlo, qshift, qcbase,
                     qcell, qlo, qrow, rcells, rpattern, rfid, rhid, rshift, rcbase, rcell, rlo, rcoef)


def _phong_reference(wi, wo, n, c):
    rv = np.maximum(_cos_alpha(wi, wo), 0.0)
    return np.where(_up(wi, wo) & (rv > 0), c * rv**n, 0.0)  # 000 eq. 5


@register("phong")
class Phong(BRDF):
    """Reciprocal Phong, f_r = c (R.V)_+^n [1/sr] (000 eq. 5; Lewis 002 removes 1/(N.L)).

    Parameters
    ----------
    n : float, >= 0
        Phong exponent.
    c : float, >= 0, default (n + 2) / (2 pi)
        Scale; (n + 2) / (2 pi) is the largest that conserves energy (000 eq. 6), and
        gives albedo exactly 1 at normal incidence.

    Examples
    --------
    >>> import pumpup
    >>> f = pumpup.load({"type": "phong", "n": 20})
    >>> float(f.eval([0, 0, 1], [0, 0, 1])) == 22 / (2 * 3.141592653589793)
    True
    """

    params = {
        "n": Param(lo=0.0, hi=MAX_EXPONENT, doc="exponent"),
        "c": Param(_phong_c, lo=0.0, doc="scale [1/sr]"),
    }
    examples = [{"n": 0}, {"n": 1}, {"n": 20}, {"n": 5000}, {"n": 10.5, "c": 1.0}]
    kernel = staticmethod(_phong_kernel)

    def eval_divided(self, wi, wo, chain):
        """f_r / (g_1 ... g_k) of a pumped chain in one pass (:func:`_phong_divided`; ``BRDF.eval_divided``)."""
        if self._rows(wi, wo) is None:
            return None
        out = np.empty(wi.shape[:-1])
        # a chain without a product table (pmlo = inf): the row-by-row kernel, which suits the split and level tables'
        # paths (5-level g2 pumped Phong n = 20: 1.90-1.94 x Phong, 2.06-2.11 x by _phong_divided)
        kernel = _phong_divided if chain.product_mlo < math.inf else _phong_divided_lit
        kernel(wi.reshape(-1, 3), wo.reshape(-1, 3), out.reshape(-1), *self.kernel_args(), *chain)
        return out

    def _eval_divided_lit(self, wi, wo, chain):
        """:meth:`eval_divided` by :func:`_phong_divided_lit`, the baseline of :func:`_phong_divided` (its tests and
        scripts/bench/bench_eval.py).
        """
        if self._rows(wi, wo) is None:
            return None
        out = np.empty(wi.shape[:-1])
        _phong_divided_lit(wi.reshape(-1, 3), wo.reshape(-1, 3), out.reshape(-1), *self.kernel_args(), *chain)
        return out

    rows_kernel = staticmethod(_phong_rows)
    reference_fn = staticmethod(_phong_reference)

    def lobe(self, mu):
        """The Lobe hint: a power lobe of exponent n about the mirror direction."""
        return Lobe(axis="mirror", radial="power", sharpness=self.p["n"])

    def azimuth_hint(self):
        """The azimuth hint: the mirror direction's power lobe c (R.V)_+^n, closed-form in the azimuth."""
        return _polar_hint(self.p["n"], 0.0, self.p["c"])


def _polar_hint(n, p, c, per_mu=None):
    """The closed-form-azimuth hint (pumpup.engine.polar) of a lobe c u^n / max(N.L, N.V)^p, p in [0, 1]
    (closed form for p in {0, 1}, an inner rule on one arc between them); ``per_mu(mu)`` multiplies
    c (Phong's shader: 1 / mu).
    """
    from ..core.hints import AzimuthHint, PowerLobe

    if per_mu is None:
        return AzimuthHint(PowerLobe(n=n, p=float(p)), scale=lambda mu: np.full(np.shape(mu), c))
    return AzimuthHint(PowerLobe(n=n, p=float(p)), scale=lambda mu: c * per_mu(mu))


# --- stretched Phong / p-model ------------------------------------------------------------


@vectorize(cache=True)
def _stretched_kernel(lx, ly, lz, vx, vy, vz, n, p, c):  # pragma: no cover - compiled
    if lz <= 0.0 or vz <= 0.0:
        return 0.0
    rv = 2.0 * lz * vz - (lx * vx + ly * vy + lz * vz)  # 000 eq. 9
    if rv <= 0.0:
        return 0.0
    mx = max(lz, vz)
    den = mx if p == 1.0 else (1.0 if p == 0.0 else mx**p)  # pow only for a true p-model
    return c * rv**n / den  # 000 eq. 10, 12


def _stretched_reference(wi, wo, n, p, c):
    rv = np.maximum(_cos_alpha(wi, wo), 0.0)
    mx = np.maximum(wi[..., 2], wo[..., 2])
    with np.errstate(divide="ignore", invalid="ignore"):
        f = c * rv**n / mx**p  # 000 eq. 10, 12
    return np.where(_up(wi, wo) & (rv > 0), f, 0.0)


@register("stretched_phong")
class StretchedPhong(BRDF):
    """Stretched Phong and the p-model, f_r = c (R.V)_+^n / max(N.L, N.V)^p [1/sr].

    000 eq. 7 and 10 (p = 1, the metallic "stretched" model) and eq. 12 (the p-model,
    a transition from reciprocal Phong at p = 0).

    Parameters
    ----------
    n : float, >= 0
        Phong exponent.
    p : float, in [0, 1], default 1
        Stretch power.
    c : float, >= 0, default (n + 2) / (2 pi)
        Scale (000 eq. 6 holds for n >= 1 and any p, 000 sec. 2.3).

    Examples
    --------
    >>> import pumpup
    >>> f = pumpup.load({"type": "stretched_phong", "n": 20})
    >>> mu = 0.5  # mirror direction at 60 degrees: f = c / mu
    >>> wi = [3**0.5 / 2, 0, mu]; wo = [-3**0.5 / 2, 0, mu]
    >>> round(float(f.eval(wi, wo)) * mu / (22 / (2 * 3.141592653589793)), 12)
    1.0
    """

    params = {
        "n": Param(lo=0.0, hi=MAX_EXPONENT, doc="exponent"),
        "p": Param(1.0, lo=0.0, hi=1.0, doc="stretch power"),
        "c": Param(_phong_c, lo=0.0, doc="scale [1/sr]"),
    }
    examples = [{"n": 1}, {"n": 20}, {"n": 5000}, {"n": 8, "p": 0.5}, {"n": 3, "p": 0.0}]
    kernel = staticmethod(_stretched_kernel)
    reference_fn = staticmethod(_stretched_reference)

    def lobe(self, mu):
        """The Lobe hint: a power lobe of exponent n about the mirror direction, with a kink at N.wo = mu
        where p > 0.
        """
        levels = (mu,) if self.p["p"] > 0 else ()
        return Lobe(axis="mirror", radial="power", sharpness=self.p["n"], levels=levels)

    def azimuth_hint(self):
        """The azimuth hint: the mirror direction's power lobe divided by max(N.L, N.V)^p (000 eq. 7, 12)."""
        return _polar_hint(self.p["n"], self.p["p"], self.p["c"])  # 000 eq. 7, 12


# --- retro-reflective ---------------------------------------------------------------------


@vectorize(cache=True)
def _retro_kernel(lx, ly, lz, vx, vy, vz, n, p, c):  # pragma: no cover - compiled
    if lz <= 0.0 or vz <= 0.0:
        return 0.0
    lv = lx * vx + ly * vy + lz * vz
    if lv <= 0.0:
        return 0.0
    return c * lv**n / max(lz, vz) ** p  # 000 eq. 13


def _retro_reference(wi, wo, n, p, c):
    lv = np.maximum(dot(wi, wo), 0.0)
    mx = np.maximum(wi[..., 2], wo[..., 2])
    with np.errstate(divide="ignore", invalid="ignore"):
        f = c * lv**n / mx**p  # 000 eq. 13
    return np.where(_up(wi, wo) & (lv > 0), f, 0.0)


@register("retro")
class Retro(BRDF):
    """Retro-reflective stretched Phong, f_r = c (L.V)_+^n / max(N.L, N.V)^p [1/sr] (000 eq. 13).

    The mirror direction R of the stretched model is replaced by L itself, so the lobe
    peaks back towards the light.

    Parameters
    ----------
    n : float, >= 0
    p : float, in [0, 1], default 1 (000 eq. 13 has p = 1)
    c : float, >= 0, default (n + 2) / (2 pi) (000 sec. 3.1)
    """

    params = {
        "n": Param(lo=0.0, hi=MAX_EXPONENT, doc="exponent"),
        "p": Param(1.0, lo=0.0, hi=1.0, doc="stretch power"),
        "c": Param(_phong_c, lo=0.0, doc="scale [1/sr]"),
    }
    examples = [{"n": 10}, {"n": 100, "p": 0.5}]
    kernel = staticmethod(_retro_kernel)
    reference_fn = staticmethod(_retro_reference)

    def lobe(self, mu):
        """The Lobe hint: a power lobe of exponent n about wi (the retro direction), with a kink at N.wo = mu where p >
        0.
        """
        levels = (mu,) if self.p["p"] > 0 else ()
        return Lobe(axis="retro", radial="power", sharpness=self.p["n"], levels=levels)

    def azimuth_hint(self):
        """The azimuth hint: stretched Phong's, as the lobe about wi integrates as the one about R (000 eq. 13)."""
        # around wi, N.wo = mu u + s sqrt(1 - u^2) cos(beta) as around R: the same 1-D integral
        return _polar_hint(self.p["n"], self.p["p"], self.p["c"])  # 000 eq. 13


# --- Phong's original shader as a BRDF (not reciprocal) ------------------------------------


@vectorize(cache=True)
def _shader_kernel(lx, ly, lz, vx, vy, vz, n, ks, kd):  # pragma: no cover - compiled
    if lz <= 0.0 or vz <= 0.0:
        return 0.0
    rv = 2.0 * lz * vz - (lx * vx + ly * vy + lz * vz)
    spec = ks * rv**n / lz if rv > 0.0 else 0.0  # 002 eq. 5, 8
    return kd + spec


def _shader_reference(wi, wo, n, ks, kd):
    rv = np.maximum(_cos_alpha(wi, wo), 0.0)
    with np.errstate(divide="ignore", invalid="ignore"):
        spec = np.where(rv > 0, ks * rv**n / wi[..., 2], 0.0)  # 002 eq. 5, 8
    return np.where(_up(wi, wo), kd + spec, 0.0)


@register("phong_shader")
class PhongShader(BRDF):
    """Phong's original shader as a BRDF, f_r = k_d + k_s (R.V)_+^n / (N.L) [1/sr].

    002 eq. 8 with F_s of 002 eq. 5.  Not reciprocal (002 sec. 5.1) and its albedo
    diverges at grazing incidence (002 sec. 4.1).

    Parameters
    ----------
    n : float, >= 0
    ks : float, >= 0, default (n + 2) / (2 pi)
        Specular coefficient [1/sr].
    kd : float, in [0, 1/pi], default 0
        Diffuse coefficient [1/sr] (k_d of 002 eq. 8 is already divided by pi).
    """

    params = {
        "n": Param(lo=0.0, hi=MAX_EXPONENT, doc="exponent"),
        "ks": Param(_phong_c, lo=0.0, doc="specular coefficient [1/sr]"),
        "kd": Param(0.0, lo=0.0, hi=1.0 / math.pi, doc="diffuse coefficient [1/sr]"),
    }
    reciprocal = False
    constant = "ks"
    examples = [{"n": 20}, {"n": 5, "kd": 0.1}]
    kernel = staticmethod(_shader_kernel)
    reference_fn = staticmethod(_shader_reference)

    def albedo_terms(self):
        """The specular lobe alone, plus the diffuse term pi k_d times a white Lambertian where k_d > 0."""
        if self.p["kd"] == 0:
            return [(1.0, self)]
        return [(1.0, self.with_params(kd=0.0)), (math.pi * self.p["kd"], load_lambert())]

    def lobe(self, mu):
        """The Lobe hint: a power lobe of exponent n about the mirror direction."""
        return Lobe(axis="mirror", radial="power", sharpness=self.p["n"])

    def azimuth_hint(self):
        """The azimuth hint of the specular lobe k_s (R.V)_+^n / mu (002 eq. 5, 8), or None where k_d > 0 (the terms are
        integrated apart).
        """
        if self.p["kd"] != 0:
            return None  # albedo_terms splits off the diffuse part
        return _polar_hint(self.p["n"], 0.0, self.p["ks"], per_mu=lambda mu: 1.0 / mu)  # 002 eq. 5, 8


def load_lambert():
    """A white Lambertian (albedo 1), the diffuse term of :class:`PhongShader`'s albedo."""
    from ..core import load

    return load({"type": "lambert", "albedo": 1.0})
