"""The albedo engine: directional albedo a(mu) of any BRDF, with an error estimate.

Method
------
a(mu) = integral over the hemisphere of f_r(wi, wo) cos(theta_o) d omega_o (000 eq. 2) is
computed by globally adaptive two-dimensional Gauss-Kronrod cubature (a 15 x 15 tensor
Kronrod rule with the embedded 7 x 7 Gauss rule on every rectangle; the error of a
rectangle is |K - G|; the rectangle is bisected along the axis whose one-dimensional
error is larger), in coordinates chosen from the BRDF's :class:`~pumpup.core.Lobe` hint:

* directions d = A cos(alpha) + sin(alpha) (e1 cos(beta) + e2 sin(beta)) around an axis A:
  the normal N, the mirror direction R of wi, wi itself, or (half-vector parametrisation)
  the half vector h around N with wo = 2 (wi.h) h - wi and d omega_o = 4 (wo.h) d omega_h;
* a radial map x -> alpha that absorbs the lobe peak (cos(alpha) = x^(1/(n+1)) for a cos^n
  lobe, tan^2(alpha) = -m^2 ln x for a Beckmann lobe, ...), so the integrand is smooth in x;
* for every x, the visible arc of beta (where N.wo > 0) in closed form, since N.wo is
  a + b cos(beta) in all four frames, and the kinks of the integrand (max(N.L, N.V), the
  levels of a pumped BRDF's g, the Cook-Torrance geometry factor) as breakpoints in beta,
  so every piece is smooth;
* breakpoints in x where a kink enters or leaves the arc (also where it only touches it: two
  roots in one cell of the scan), and, since the pieces are the cuts in sorted order, where two
  cuts cross or a cut meets the horizon end of the arc (``kink_breaks``): inside a rectangle,
  such a kink in x can make the Kronrod and Gauss rules agree while both are wrong;
* in beta, the first rectangles of a piece that ends at the cut of a small level N.wo = u graded
  towards that end (``_level_end_scales``): continued past the cut, N.wo reaches 0 within
  sqrt(u / (3 dn w)) in tau_t, the branch point of a p-model's N.wo^(1 - p), which both rules miss
  near grazing incidence (u = mu);
* a smoothing substitution x = tau^2 (3 - 2 tau) on both axes, which removes the
  square-root behaviour at the ends of every piece.

A BRDF without a hint (for example one from :func:`pumpup.from_function`) is integrated
around N over the full circle of beta, with x = sin^2(theta_o) (exact for Lambert); the
adaptive cubature then finds its lobes and kinks by itself, more slowly.

The reported error is the sum of |K - G| over all rectangles plus a rounding term: it is
pessimistic on smooth integrands by design (true error / estimate at most 0.18, median 1.3e-3
over every independent reference of ``tests/`` at rtol 1e-6 .. 1e-12,
``scripts/calibration/error_calibration.py``), and the tests check it against closed forms and against
independent quadratures.  QUADPACK's calibrated estimate (:mod:`pumpup.physics.quadrature`, used by the
1-D path) is not used here by default: the integrand of a pumped or compensated BRDF has kinks
at the knots of its albedo table that no hint marks, and there the calibrated estimate was
measured below the true error (``pumpup.physics.quadrature.MODE_2D`` switches it on for measurements).
"""

from __future__ import annotations

import math
import reprlib
import warnings
from dataclasses import dataclass, replace
from typing import TYPE_CHECKING

import numpy as np
from numba import njit

from ..core import BRDF, Lobe, budget
from .arc_breaks import graded, horizon_breaks, kink_breaks
from .lobe_geometry import (
    AXES,
    AXIS_CODE,
    NODES,
    RADIAL_CODE,
    WG,
    WK,
    accumulate,
    kink_coefficients,
    lobe_rounding,
    radial_map,
    radial_map_scalar,
    rotate_wi,
    smooth,
)

if TYPE_CHECKING:
    from numpy.typing import ArrayLike

__all__ = ["albedo", "check_mu", "check_phi", "AlbedoWarning"]

DEFAULT_RTOL = 1e-10
DEFAULT_ATOL = 1e-14
#: the largest ``max_regions`` accepted (each rectangle costs 225 evaluations and about 100 bytes)
MAX_REGIONS_LIMIT = 10**7
NX_INIT = 8  # initial subdivisions of the radial variable
NT_INIT = 2  # initial subdivisions of each piece of the azimuth


class AlbedoWarning(UserWarning):
    """The cubature stopped before it met the tolerance; the error estimate says by how much."""


def check_mu(mu) -> np.ndarray:
    """``mu`` as a float64 array, or a ValueError that says which value is outside (0, 1]."""
    raw = None if isinstance(mu, (str, bytes)) else np.asarray(mu)
    if raw is None or raw.dtype.kind not in "fiu":  # (a string, True, None, a nested list of mixed kinds)
        raise ValueError(f"mu must be a number or an array of numbers in (0, 1], got {reprlib.repr(mu)}")
    m = raw.astype(np.float64)
    if ((m > 0) & (m <= 1)).all():  # (NaN fails both comparisons, inf the second: one pass where all is well)
        return m
    bad = ~np.isfinite(m) | (m <= 0) | (m > 1)
    if np.any(bad):
        i = tuple(int(k) for k in np.argwhere(bad)[0]) if m.ndim else ()
        where = f"mu[{', '.join(map(str, i))}]" if i else "mu"
        raise ValueError(f"mu = cos(theta_i) must be in (0, 1]; {where} = {float(m[i])!r}")
    return m


def check_phi(phi) -> np.ndarray:
    """``phi`` (the azimuth of wi, radians) as a float64 array, or a ValueError naming it."""
    if type(phi) is float and math.isfinite(phi):  # (the default, 0.0: no numpy check needed)
        return np.asarray(phi)
    if isinstance(phi, (str, bytes)) or phi is None:
        raise ValueError(f"phi (the azimuth of wi, in radians) must be a finite number, got {phi!r}")
    if isinstance(phi, (bool, np.bool_)) or np.asarray(phi).dtype.kind not in "fiu":
        raise ValueError(f"phi (the azimuth of wi, in radians) must be a finite number or an array of them, "
                         f"got {reprlib.repr(phi)}")
    try:
        p = np.asarray(phi, dtype=np.float64)
    except (TypeError, ValueError, OverflowError):
        raise ValueError(f"phi (the azimuth of wi, in radians) must be a finite number or an array of them, "
                         f"got {phi!r}") from None
    if not np.all(np.isfinite(p)):
        raise ValueError(f"phi (the azimuth of wi, in radians) must be finite, got {phi!r}")
    return p


@dataclass
class _Group:
    """Problems (values of mu) that share one hint structure."""

    lobe: Lobe
    mu: np.ndarray  # (P,)
    levels: np.ndarray  # (P, L)
    phi: np.ndarray | None = None  # (P,) azimuths of wi, or None: wi in the xz-plane


def _geometry_reference(lobe: Lobe, mu, levels, ka, kb, piece, tx, tt):
    """Plain numpy geometry: (wi, wo, weight) of every point (tau_x, tau_t) of a piece.

    ``weight`` is d omega_o per d tau_x d tau_t (with the half-vector Jacobian and the
    width of the beta piece), for one sign of beta; ``levels`` (N, L) and ``ka``, ``kb``
    (N, K) give the kinks.  The compiled :func:`_geometry_kernel` does the same.
    """
    s = np.sqrt((1.0 - mu) * (1.0 + mu))
    x, xc, dx = smooth(tx)
    t, _, dt = smooth(tt)
    ca, sa, jac = radial_map(lobe.radial, lobe.sharpness, x, xc)
    axis = lobe.axis
    if axis == "normal":
        a0, b0 = ca, np.zeros_like(ca)
    elif axis in ("mirror", "retro"):
        a0, b0 = mu * ca, s * sa
    else:  # half: N.wo = mu cos(2 alpha) + s sin(2 alpha) cos(beta)
        a0, b0 = mu * (ca * ca - sa * sa), 2.0 * s * sa * ca
    with np.errstate(divide="ignore", invalid="ignore"):
        beta0 = np.where(b0 > 0, np.arccos(np.clip(-a0 / b0, -1.0, 1.0)), np.where(a0 > 0, np.pi, 0.0))
        cuts = [np.where(b0 > 0, np.arccos(np.clip((levels[:, j] - a0) / b0, -1.0, 1.0)), 0.0)
                for j in range(levels.shape[1])]
        cuts += [np.where(np.abs(kb[:, j]) > 0, np.arccos(np.clip(-ka[:, j] / kb[:, j], -1.0, 1.0)), 0.0)
                 for j in range(ka.shape[1])]
    if cuts:
        edges = np.sort(np.minimum(np.stack(cuts, axis=-1), beta0[:, None]), axis=-1)
        edges = np.concatenate([np.zeros_like(beta0)[:, None], edges, beta0[:, None]], axis=-1)
        lo = np.take_along_axis(edges, piece[:, None], axis=-1)[:, 0]
        hi = np.take_along_axis(edges, piece[:, None] + 1, axis=-1)[:, 0]
    else:
        lo, hi = np.zeros_like(beta0), beta0
    width = hi - lo
    beta = lo + t * width
    cb, sb = np.cos(beta), np.sin(beta)
    wi = np.stack([s, np.zeros_like(s), mu], axis=-1)
    # d = A cos(alpha) + sin(alpha) (e1 cos(beta) + e2 sin(beta))
    if axis in ("normal", "half"):
        d = np.stack([sa * cb, sa * sb, ca], axis=-1)
    elif axis == "mirror":  # A = R = (-s, 0, mu), e1 = (mu, 0, s)
        d = np.stack([-s * ca + mu * sa * cb, sa * sb, mu * ca + s * sa * cb], axis=-1)
    else:  # retro: A = wi = (s, 0, mu), e1 = (-mu, 0, s)
        d = np.stack([s * ca - mu * sa * cb, sa * sb, mu * ca + s * sa * cb], axis=-1)
    if axis == "half":
        ih = s * d[:, 0] + mu * d[:, 2]
        wo = 2.0 * ih[:, None] * d - wi
        extra = 4.0 * ih  # d omega_o = 4 (wo.h) d omega_h
    else:
        wo = d
        extra = 1.0
    return wi, wo, jac * extra * width * dx * dt


@njit(cache=True, nogil=True, inline="always")
def _sort_interior(x, n):  # pragma: no cover - compiled
    """Insertion sort of x[1:n - 1] in place (the cuts between an arc's two ends x[0] and x[n - 1]: a
    few, already nearly sorted; no allocation).
    """
    for a in range(2, n - 1):
        val = x[a]
        b = a - 1
        while b >= 1 and x[b] > val:
            x[b + 1] = x[b]
            b -= 1
        x[b + 1] = val


@njit(cache=True, nogil=True)
def _geometry_kernel(axis, radial, k, mu_p, levels_p, prob, ka, kb, piece, tx, tt, wi, wo, weight):  # pragma: no cover
    """Compiled twin of :func:`_geometry_reference`; fills ``wi``, ``wo`` (N, 3) and ``weight`` (N).

    Point i belongs to problem prob[i], with mu = mu_p[prob[i]] and levels levels_p[prob[i]].
    """
    L = levels_p.shape[1]
    K = ka.shape[1]
    edges = np.empty(L + K + 2)
    # the points come as 15 values of tau_t per value of tau_x: everything that depends on x
    # (the radial map, the visible arc, the cuts) is computed once per x and reused
    prev_tx, prev_mu, prev_piece = -1.0, -1.0, -1
    m = s = ca = sa = jac = dx = lo = width = 0.0
    for i in range(tx.shape[0]):
        p = prob[i]
        if tx[i] != prev_tx or mu_p[p] != prev_mu or piece[i] != prev_piece:
            prev_tx, prev_mu, prev_piece = tx[i], mu_p[p], piece[i]
            m = mu_p[p]
            s = math.sqrt((1.0 - m) * (1.0 + m))
            # smoothing substitution x = tau^2 (3 - 2 tau)
            u = tx[i]
            x = u * u * (3.0 - 2.0 * u)
            xc = (1.0 - u) ** 2 * (1.0 + 2.0 * u)
            dx = 6.0 * u * (1.0 - u)
            ca, sa, jac = radial_map_scalar(radial, k, x, xc)
            if axis == 0:
                a0, b0 = ca, 0.0
            elif axis == 3:
                a0, b0 = m * (ca * ca - sa * sa), 2.0 * s * sa * ca
            else:
                a0, b0 = m * ca, s * sa
            if b0 > 0:
                beta0 = math.acos(min(1.0, max(-1.0, -a0 / b0)))
            else:
                beta0 = math.pi if a0 > 0 else 0.0
            n = 0
            edges[n] = 0.0
            n += 1
            for j in range(L):
                c = math.acos(min(1.0, max(-1.0, (levels_p[p, j] - a0) / b0))) if b0 > 0 else 0.0
                edges[n] = min(c, beta0)
                n += 1
            for j in range(K):
                c = math.acos(min(1.0, max(-1.0, -ka[i, j] / kb[i, j]))) if kb[i, j] != 0 else 0.0
                edges[n] = min(c, beta0)
                n += 1
            edges[n] = beta0
            n += 1
            _sort_interior(edges, n)
            lo = edges[piece[i]]
            width = edges[piece[i] + 1] - lo
        wi[i, 0] = s
        wi[i, 1] = 0.0
        wi[i, 2] = m
        v = tt[i]
        t = v * v * (3.0 - 2.0 * v)
        dt = 6.0 * v * (1.0 - v)
        beta = lo + t * width
        cb, sb = math.cos(beta), math.sin(beta)
        if axis == 0 or axis == 3:
            d0, d1, d2 = sa * cb, sa * sb, ca
        elif axis == 1:
            d0, d1, d2 = -s * ca + m * sa * cb, sa * sb, m * ca + s * sa * cb
        else:
            d0, d1, d2 = s * ca - m * sa * cb, sa * sb, m * ca + s * sa * cb
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
        w = jac * extra * width * dx * dt
        weight[i] = w if width > 0 else 0.0


def _integrand(brdf: BRDF, g: _Group, prob: np.ndarray, piece: np.ndarray, tx: np.ndarray, tt: np.ndarray):
    """Integrand values at points (tau_x, tau_t) of piece ``piece`` of problem ``prob``."""
    lobe = g.lobe
    n = len(tx)
    if lobe.kinks is not None:
        x, xc, _ = smooth(tx)
        ka, kb = kink_coefficients(lobe, g.mu[prob], x, xc)
    else:
        ka = kb = np.zeros((n, 0))
    wi = np.empty((n, 3))
    wo = np.empty((n, 3))
    weight = np.empty(n)
    _geometry_kernel(AXIS_CODE[lobe.axis], RADIAL_CODE[lobe.radial], float(lobe.sharpness), g.mu, g.levels, prob,
                     ka, kb, piece, tx, tt, wi, wo, weight)
    total = np.zeros(n)
    if g.phi is not None:  # rotate the whole configuration by phi about N: wi gets azimuth phi
        cp, sp = np.cos(g.phi[prob]), np.sin(g.phi[prob])
        wi_c, wo_c = wi, wo
    for sign in (1.0,) if lobe.symmetric else (1.0, -1.0):
        if sign < 0:
            wo[:, 1] *= -1.0  # beta -> -beta flips wo_y in every frame (wi_y = 0)
        if g.phi is not None:
            wi, wo = rotate_wi(wi_c, cp, sp), rotate_wi(wo_c, cp, sp)  # N.wi, N.wo and wi.wo unchanged
        f = np.ascontiguousarray(brdf._eval(wi, wo), dtype=np.float64)
        i = accumulate(f, wo[:, 2], weight, total)
        if g.phi is not None:
            wo = wo_c
        if i >= 0:
            raise ValueError(
                f"{brdf!r} returned {f[i]!r} at wi={wi[i].tolist()}, wo={wo[i].tolist()}: "
                "a BRDF must be finite and non-negative above the horizon"
            )
    return 2.0 * total if lobe.symmetric else total


def _rule(brdf, g, prob, piece, x0, x1, t0, t1, chunk=1_500_000):
    """Apply the 15 x 15 Gauss-Kronrod tensor rule to rectangles; return (K, err, ex, et).

    err is the error estimate of the rectangle, |K - G| (or, when ``pumpup.physics.quadrature.MODE_2D``
    asks for it, QUADPACK's calibration of it: not the default, see the module docstring);
    ex and et, the same for the Gauss rule in x only and in t only, choose the split direction.
    """
    from ..physics.quadrature import calibrated_array, mode_code

    mode = mode_code(smooth=False)  # raw |K - G| unless pumpup.physics.quadrature.MODE_2D says otherwise
    R = len(prob)
    out = np.empty((R, 4))
    per = max(1, chunk // 225)
    for a in range(0, R, per):
        budget.check("the 2-D cubature refined its rectangles")  # (a time budget: pumpup.core.budget)
        sl = slice(a, min(R, a + per))
        n = sl.stop - sl.start
        hx = (x1[sl] - x0[sl])[:, None, None]
        ht = (t1[sl] - t0[sl])[:, None, None]
        X = x0[sl][:, None, None] + hx * NODES[None, :, None]
        T = t0[sl][:, None, None] + ht * NODES[None, None, :]
        X, T = np.broadcast_arrays(X, T)
        P = np.broadcast_to(prob[sl][:, None, None], X.shape)
        K = np.broadcast_to(piece[sl][:, None, None], X.shape)
        v = _integrand(brdf, g, np.ascontiguousarray(P.ravel()), np.ascontiguousarray(K.ravel()),
                       np.ascontiguousarray(X.ravel()), np.ascontiguousarray(T.ravel())).reshape(n, 15, 15)
        area = (hx * ht)[:, 0, 0]
        kk = np.einsum("rij,i,j->r", v, WK, WK) * area
        gg = np.einsum("rij,i,j->r", v, WG, WG) * area
        gk = np.einsum("rij,i,j->r", v, WG, WK) * area  # Gauss in x: measures the x error
        kg = np.einsum("rij,i,j->r", v, WK, WG) * area
        out[sl, 0] = kk
        if mode == 0:  # the raw |K - G| (pumpup.physics.quadrature.raw_estimate)
            out[sl, 1] = np.abs(kk - gg)
            out[sl, 2] = np.abs(kk - gk)
            out[sl, 3] = np.abs(kk - kg)
            continue
        # QUADPACK's calibration (pumpup.physics.quadrature) with the tensor Kronrod rule's resasc (the
        # integral of |f - mean f|) and resabs; per axis the same resasc, so ex >= et (the split
        # direction) is the comparison of the raw per-axis differences, as before
        mean = (kk / area)[:, None, None]
        resasc = np.einsum("rij,i,j->r", np.abs(v - mean), WK, WK) * area
        resabs = np.einsum("rij,i,j->r", np.abs(v), WK, WK) * area
        out[sl, 1] = calibrated_array(np.abs(kk - gg), resasc, resabs, mode)
        out[sl, 2] = calibrated_array(np.abs(kk - gk), resasc, resabs, mode)
        out[sl, 3] = calibrated_array(np.abs(kk - kg), resasc, resabs, mode)
    return out.T

#: a piece end at the cut of a small level is graded where the integrand's scale there, in tau_t, is
#: below this (as ``pumpup.engine.nested.D_GRADE``)
D_GRADE = 0.05
#: at most this many graded breaks towards one end (steps d 4^k, k < K_GRADE)
K_GRADE = 16
#: the points of each first column of tau_x where the scale of :func:`_level_end_scales` is sampled
_SCALE_NODES = np.concatenate([[0.0], NODES, [1.0]])


def _level_end_scales(lobe: Lobe, mu: float, levels: np.ndarray, gx: np.ndarray, n_pieces: int) -> np.ndarray:
    """(C, n_pieces): for each first column [gx[i], gx[i + 1]] of tau_x and each piece of beta, the
    scale in tau_t on which the integrand varies at the piece's upper end when that end is the cut
    of a small level u > 0 (inf elsewhere), the smallest over the column.

    N.wo = a + b cos(beta) falls along the arc, so the piece below the cut of a level u (its upper end,
    t = 1) lies where N.wo > u, and there N.wo - u = dn w (1 - t), dn = b sin(cut) = |d N.wo / d beta|,
    w the piece's width.  Continued past the cut, N.wo reaches the horizon N.wo = 0 at the distance
    u / (dn w) in t, sqrt(u / (3 dn w)) in tau_t (1 - t ~ 3 (1 - tau_t)^2): there the integrand of a
    p-model, c (R.V)^n N.wo^(1 - p) (000 eq. 12, times the cosine), has its branch point.  Near
    grazing incidence (u = mu) that is far inside the rule's outermost node: with p = 1/2, where the
    limit u -> 0 of the integrand is analytic at the end (N.wo^(1/2) ~ (1 - tau_t) sqrt(3 dn w)), the
    15 x 15 and 7 x 7 rules agree on the limit and both miss the O(u^(3/2)) difference (stretched Phong
    n = 1, p = 1/2, mu = 1e-7: 0.4576559181133117, |K - G| 7.1e-12, true error 1.7e-11).  The piece
    above the cut (N.wo < u) has no such point near its end: N.wo grows past it.  The engine does not
    know p (nor what a pumped model does at N.wo -> 0), so every level's cut is treated alike.
    """
    C = len(gx) - 1
    lev = np.asarray(levels, dtype=np.float64)
    if not len(lev) or not np.any(lev > 0) or lobe.axis == "normal":  # around N, no level cuts the arc
        return np.full((C, n_pieces), np.inf)
    from .nested import _nodes_reference

    tx = (gx[:-1, None] + np.diff(gx)[:, None] * _SCALE_NODES[None, :]).ravel()
    N = len(tx)
    m = np.full(N, float(mu))
    if lobe.kinks is not None:
        x, xc, _ = smooth(tx)
        ka, kb = kink_coefficients(lobe, m, x, xc)
    else:
        ka = kb = np.zeros((N, 0))
    _, _, _, _, edges, lab, dn = _nodes_reference(lobe.axis, lobe.radial, float(lobe.sharpness), m,
                                                  np.ascontiguousarray(np.broadcast_to(lev, (N, len(lev)))), ka, kb, tx)
    up = lab[:, 1:]  # the level whose cut is the upper end of each piece (-1: none)
    u = np.where(up >= 0, lev[np.maximum(up, 0)], 0.0)
    width = np.diff(edges, axis=1)
    with np.errstate(divide="ignore", invalid="ignore"):
        d = np.sqrt(u / (3.0 * dn[:, 1:] * width))
    d = np.where((up >= 0) & (u > 0) & (width > 0) & (dn[:, 1:] > 0) & (d == d), d, np.inf)
    return d.reshape(C, len(_SCALE_NODES), n_pieces).min(axis=1)


def _first_rectangles_t(d: np.ndarray, gt: np.ndarray):
    """The first intervals of tau_t of pieces whose upper end has the scale ``d`` (any shape S, see
    :func:`_level_end_scales`): the grid ``gt`` and, where d < D_GRADE, breaks 1 - d 4^k graded
    towards the end.  Returns (index into S.ravel(), t0, t1).
    """
    d = d.ravel()
    kk = 4.0 ** np.arange(K_GRADE)
    need = d < D_GRADE
    off = np.maximum(d, 0.25 / kk[-1])[:, None] * kk[None, :]
    pts = np.where(need[:, None] & (off < 0.25), 1.0 - off, np.nan)
    allp = np.sort(np.concatenate([np.broadcast_to(gt, (len(d), len(gt))), pts], axis=1), axis=1)  # NaN last
    a, b = allp[:, :-1], allp[:, 1:]
    row, col = np.nonzero(np.isfinite(a) & np.isfinite(b) & (b > a))
    return row, a[row, col], b[row, col]

#: the second first grid of the generic path (nx, nt), besides (8, 8)
GENERIC_GRID2 = (7, 11)


def _integrate_group(brdf: BRDF, g: _Group, rtol: float, atol: float, max_regions: int, grid=None,
                     generic_check: bool = True):
    """(value, error, converged) per problem of the group by the adaptive cubature.

    A BRDF without a hint (the generic path: axis "normal", radial "cosine", not symmetric) may have kinks no
    hint marks, and a first rectangle that straddles one is refined only if its |K - G| shows it, which a kink
    does not (the slow test test_every_example_engine_and_generic_path_agree failed on 26 of the 107 registry
    examples at mu = 0.01 since it was written, by up to 5000 x the estimate: e.g. stretched Phong n = 1,
    1.9e-7 off with an estimate of 3.8e-11 at every rtol).  So the generic path (``generic_check``) cuts at
    N.wo = mu, the kink of every max(N.L, N.V) (that alone mended 22 of the 28 examples), and integrates on
    two first grids, (8, 8) and ``GENERIC_GRID2``: the value is the second's, the error the larger estimate
    plus the difference of the two (a kink missed by one grid and not by the other shows there: stretched
    Phong n = 1 at mu = 0.01 gave 1.9e-7 and 7e-12 off on the two grids), and it is converged only if both
    are and their difference meets the tolerance.  This costs the generic path about twice the evaluations.
    """
    if g.lobe.generic and generic_check and grid is None:
        lev = np.concatenate([g.levels, g.mu[:, None]], axis=1)
        g2 = _Group(lobe=g.lobe, mu=g.mu, levels=lev, phi=g.phi)
        v1, e1, c1 = _integrate_group(brdf, g2, rtol, atol, max_regions, grid=(8, 8))
        v2, e2, c2 = _integrate_group(brdf, g2, rtol, atol, max_regions, grid=GENERIC_GRID2)
        diff = np.abs(v1 - v2)
        return v2, np.maximum(e1, e2) + diff, c1 & c2 & (diff <= np.maximum(rtol * np.abs(v2), atol))
    P = len(g.mu)
    n_pieces = 1 + g.levels.shape[1] + (
        len(g.lobe.kinks(np.array([0.5]), np.array([0.5]), np.array([0.5]), np.array([0.5]))) if g.lobe.kinks else 0)
    nx = NX_INIT if not g.lobe.generic else (8 if grid is None else grid[0])
    nt = NT_INIT if not g.lobe.generic else (8 if grid is None else grid[1])
    # initial rectangles: nx x nt per piece per problem, with the x grid also split where
    # the horizon starts to cut the lobe and where it hides it completely
    gt = np.linspace(0, 1, nt + 1)
    from .nested import _alpha_grading  # _nested imports this module

    cols = []
    arc_kinks = kink_breaks(g.lobe, g.mu, g.levels)
    for p_ in range(P):
        # the arc changes on the scale of the distance from a break to the nearer end (near
        # grazing incidence the horizon break sits within 1e-5 of an end): the grid is graded
        # geometrically towards every break, so that no first rectangle straddles it unseen
        breaks = np.concatenate([horizon_breaks(g.lobe, float(g.mu[p_])),
                                 arc_kinks[p_]])
        # and, near normal incidence on a microfacet lobe, towards both horizon breaks on the roughness's scale
        # (``pumpup.engine.nested._alpha_grading``: G1(wo) falls to 0 within alpha of the horizon; GGX alpha = 2.7e-4 at
        # mu = 1 was 2.6e-11 off with an estimate of 4.1e-13, 62 x, before)
        gx = np.unique(np.concatenate([np.linspace(0, 1, nx + 1), graded(breaks),
                                       _alpha_grading(g.lobe, float(g.mu[p_]))]))
        # and the pieces that end at the cut of a small level graded towards it in tau_t
        # (_level_end_scales: the near-singularity there is invisible to both rules)
        d = _level_end_scales(g.lobe, float(g.mu[p_]), g.levels[p_], gx, n_pieces)
        row, T0, T1 = _first_rectangles_t(d, gt)
        col, k = np.divmod(row, n_pieces)
        cols.append((np.full(len(row), p_), k, gx[col], gx[col + 1], T0, T1))
    prob, piece, x0, x1, t0, t1 = (np.concatenate(c) for c in zip(*cols))
    val, err, ex, et = _rule(brdf, g, prob, piece, x0, x1, t0, t1)
    # the budget counts the rectangles added by refinement: a lobe with many kink levels (a
    # pumped Cook-Torrance with g2, 3 levels: 42 near mu = 1) starts with more than max_regions
    budget = max_regions + np.bincount(prob, minlength=P)
    rounding = lobe_rounding(g.lobe)
    converged = np.zeros(P, bool)
    while True:
        total = np.bincount(prob, val, minlength=P)
        E = np.bincount(prob, err, minlength=P)
        A = np.bincount(prob, np.abs(val), minlength=P)
        R = rounding * A
        tol = np.maximum(rtol * np.abs(total), atol)
        # done when the cubature error meets the tolerance, or is already below the rounding
        # error of the integrand (refining further cannot help); the reported error is both
        converged = E <= np.maximum(tol, R)
        E = E + R
        count = np.bincount(prob, minlength=P)
        active = ~converged & (count < budget)
        if not active.any():
            break
        # split every rectangle of an unconverged problem whose error exceeds its share
        share = tol / count
        pick = active[prob] & (err > 0.5 * share[prob])
        # always include the worst rectangle of each active problem
        order = np.lexsort((-err, prob))
        first = order[np.r_[True, prob[order][1:] != prob[order][:-1]]]
        pick[first[active[prob[first]]]] = True
        idx = np.nonzero(pick)[0]
        keep = ~pick
        splitx = ex[idx] >= et[idx]
        xm = 0.5 * (x0[idx] + x1[idx])
        tm = 0.5 * (t0[idx] + t1[idx])
        # child A: lower half, child B: upper half
        ax0, ax1 = x0[idx], np.where(splitx, xm, x1[idx])
        at0, at1 = t0[idx], np.where(splitx, t1[idx], tm)
        bx0, bx1 = np.where(splitx, xm, x0[idx]), x1[idx]
        bt0, bt1 = np.where(splitx, t0[idx], tm), t1[idx]
        cprob = np.concatenate([prob[idx], prob[idx]])
        cpiece = np.concatenate([piece[idx], piece[idx]])
        cx0, cx1 = np.concatenate([ax0, bx0]), np.concatenate([ax1, bx1])
        ct0, ct1 = np.concatenate([at0, bt0]), np.concatenate([at1, bt1])
        cv, ce, cex, cet = _rule(brdf, g, cprob, cpiece, cx0, cx1, ct0, ct1)
        prob = np.concatenate([prob[keep], cprob])
        piece = np.concatenate([piece[keep], cpiece])
        x0, x1 = np.concatenate([x0[keep], cx0]), np.concatenate([x1[keep], cx1])
        t0, t1 = np.concatenate([t0[keep], ct0]), np.concatenate([t1[keep], ct1])
        val, err = np.concatenate([val[keep], cv]), np.concatenate([err[keep], ce])
        ex, et = np.concatenate([ex[keep], cex]), np.concatenate([et[keep], cet])
    return total, E, converged


_TURNED: dict = {}


def _turned_lobe(brdf: BRDF, lobe: Lobe, phi: float) -> Lobe:
    """The hint for wi at azimuth phi: not even in beta, and, where beta is the azimuth about N
    (the "normal" and "half" frames) and the model's anisotropy is aligned with the tangent axes
    (``azimuth_range() == pi / 2``), the model's x and y axes as breakpoints of beta: a lobe that is
    narrow across one axis is a ridge along it, which at phi = 0 lies on the ends of the beta range
    and otherwise would fall inside a piece unseen (ward_aniso ax = 1000, ay = 1e-6 gave 0 at mu = 1).
    """
    lobe = replace(lobe, symmetric=False)
    rng = brdf.azimuth_range()
    if lobe.axis not in ("normal", "half") or rng is None or abs(rng - math.pi / 2) > 1e-15:
        return lobe
    key = (lobe.kinks, phi)
    if key not in _TURNED:
        # the model's axes at azimuths 0, pi/2, pi, 3 pi/2 are, in the engine's frame (turned by phi),
        # at beta = -phi + k pi/2; the engine integrates |beta| in [0, pi] (both signs), so the cuts
        # are the folded angles, as kinks a + b cos(beta) = 0 with a = -cos(angle), b = 1
        angles = sorted({abs(math.remainder(-phi + k * math.pi / 2, 2 * math.pi)) for k in range(4)})
        cuts = [c for c in angles if 1e-12 < c < math.pi - 1e-12]
        base = lobe.kinks

        def kinks(mu, s, ca, sa, base=base, cuts=tuple(cuts)):
            out = list(base(mu, s, ca, sa)) if base is not None else []
            return out + [(-math.cos(c), 1.0) for c in cuts]
        _TURNED[key] = kinks
    return replace(lobe, kinks=_TURNED[key])


def _groups(brdf: BRDF, mu: np.ndarray, phi: np.ndarray | None = None):
    """Group the values of mu by the structure of their Lobe hint (and whether wi leaves the
    xz-plane: ``phi`` != 0, where the hint's symmetry in beta no longer holds).
    """
    by_key: dict = {}
    for i, m in enumerate(mu):
        lobe = brdf.lobe(float(m))
        if lobe.axis not in AXES:
            raise ValueError(f"{brdf!r}: Lobe axis must be one of {AXES}, got {lobe.axis!r}")
        turned = phi is not None and phi[i] != 0.0
        if turned:
            lobe = _turned_lobe(brdf, lobe, float(phi[i]))
        key = (lobe.axis, lobe.radial, lobe.sharpness, lobe.kinks, lobe.symmetric, len(lobe.levels), turned,
               float(phi[i]) if turned else 0.0)
        by_key.setdefault(key, (lobe, [], [], turned))
        by_key[key][1].append(i)
        by_key[key][2].append(lobe.levels)
    for lobe, idx, levels, turned in by_key.values():
        idx = np.array(idx)
        lev = np.array(levels, dtype=np.float64).reshape(len(idx), -1)
        if turned:
            # the hint's "even in beta" holds for wi in the xz-plane (Lobe.symmetric); an anisotropic
            # BRDF seen from wi at azimuth phi is not even in beta: both halves (_turned_lobe)
            yield idx, _Group(lobe=lobe, mu=mu[idx], levels=lev, phi=phi[idx])
        else:
            yield idx, _Group(lobe=lobe, mu=mu[idx], levels=lev)


def albedo(brdf: BRDF, mu: ArrayLike, return_error: bool = False, rtol: float = DEFAULT_RTOL,
           atol: float = DEFAULT_ATOL, max_regions: int = 20000, phi: ArrayLike = 0.0,
           engine: str | None = None,
           max_seconds: float | None = None) -> np.ndarray | tuple[np.ndarray, np.ndarray]:
    """Directional albedo a(mu) of ``brdf`` (000 eq. 2; Lewis's k_rho, 002 eq. 15).

    a(mu, phi) = integral over the hemisphere of f_r(wi, wo) cos(theta_o) d omega_o, with
    wi = (sqrt(1 - mu^2) cos(phi), sqrt(1 - mu^2) sin(phi), mu).  Dimensionless.

    Parameters
    ----------
    brdf : BRDF
        Any BRDF: a built-in model (which guides the cubature with its Lobe hint) or
        one from :func:`pumpup.from_function` (generic adaptive cubature).  A spectral
        model (:mod:`pumpup.spectral`) gives one albedo per wavelength on a trailing axis.
    mu : float or array_like
        cos(theta_i), each in (0, 1].  Work in mu near grazing: 89.9995 degrees is
        mu = 8.7e-6.
    return_error : bool
        Also return the error estimate.
    rtol, atol : float
        The cubature refines until its error estimate is below max(rtol * a, atol): rtol in (0, 1], atol >= 0
        (0: the relative tolerance alone).
    max_regions : int
        Rectangles that refinement may add per value of mu (beyond the first grid, which
        grows with the lobe's kinks); if the tolerance is not met by then, an
        :class:`AlbedoWarning` is issued and the (larger) error estimate is returned.
    phi : float or array_like, default 0
        Azimuth of wi in radians, measured from the tangent x axis towards y; broadcast
        against ``mu``.  An anisotropic BRDF's albedo depends on it (``ward_aniso``,
        ``lafortune`` with cx != cy, a user function); for a model whose
        :meth:`~pumpup.core.BRDF.azimuth_range` is None (isotropic) it is ignored.
    engine : {"auto", "1d", "nested", "2d"}, optional
        Which routes may integrate (:mod:`pumpup.engine.routes`): every route ("auto", the default); the 1-D routes
        only ("1d": an error for a model or a value of mu none of them takes); the nested quadrature where it applies,
        else the 2-D cubature ("nested"); the 2-D cubature alone ("2d", the reference the others are tested against).
        None: the choice in force (:func:`pumpup.engine.routes.using`, by default "auto").
    max_seconds : float, optional
        A time budget (:mod:`pumpup.core.budget`): past it the work stops with a ``BudgetExceeded`` (a TimeoutError)
        instead of running on.  None: no bound of its own.

    Returns
    -------
    ndarray, or (ndarray, ndarray)
        The albedo with the broadcast shape of ``mu`` and ``phi`` (and the estimated
        absolute error).

    Notes
    -----
    The method is described in the module docstring of ``pumpup.albedo``: adaptive
    15 x 15 Gauss-Kronrod cubature in a lobe-adapted frame, the visible arc in closed
    form, the kinks as breakpoints.  The error estimate is the sum of |Kronrod - Gauss|
    over the rectangles, plus rounding.

    Examples
    --------
    >>> import pumpup
    >>> a, err = pumpup.albedo(pumpup.load({"type": "phong", "n": 20}), 1.0, return_error=True)
    >>> abs(float(a) - 1.0) < 1e-10 and float(err) < 1e-9
    True
    """
    if max_seconds is not None:
        with budget.time_budget("albedo", max_seconds):
            return albedo(brdf, mu, return_error, rtol, atol, max_regions, phi, engine)
    if not isinstance(brdf, BRDF):
        if getattr(brdf, "is_spectral", False):  # pumpup.spectral: one albedo per wavelength, on a trailing axis
            return brdf.albedo(mu, return_error=return_error, rtol=rtol, atol=atol, max_regions=max_regions, phi=phi)
        raise TypeError(f"albedo needs a pumpup BRDF, got {type(brdf).__name__}; wrap functions with "
                        "pumpup.from_function")
    from ..core import check_count, check_tolerance

    rtol = check_tolerance("albedo", "rtol", rtol)
    atol = check_tolerance("albedo", "atol", atol, hi=math.inf, zero=True)  # 0: relative only
    max_regions = check_count("albedo", "max_regions", max_regions, 0, MAX_REGIONS_LIMIT)  # 0: the first grid
    m = check_mu(mu)
    ph = check_phi(phi)
    if ph.ndim:
        try:
            m, ph = np.broadcast_arrays(m, ph)
        except ValueError:
            raise ValueError(f"phi (shape {ph.shape}) does not broadcast against mu (shape {m.shape})") from None
    flat = np.array(m, dtype=np.float64).ravel()
    phflat = np.array(ph, dtype=np.float64).ravel() if ph.ndim else np.full(flat.shape, float(ph))
    value = np.zeros_like(flat)
    error = np.zeros_like(flat)
    ok = np.ones(flat.shape, bool)
    from . import nested, polar, slope
    from .routes import check_engine, current, plan, using

    choice = current()
    if engine is not None and check_engine("albedo", engine) != choice.engine:
        with using(engine=engine):
            return albedo(brdf, mu, return_error=return_error, rtol=rtol, atol=atol, max_regions=max_regions, phi=phi)
    turn = phflat if (float(ph) != 0.0 if not ph.ndim else bool((phflat != 0.0).any())) else None
    for w, term in brdf.albedo_terms():
        for route, idx, payload in plan(term, flat, turn, choice):
            if route == "slope":  # anisotropic Ward, at every azimuth of wi (pumpup.engine.slope)
                v, e, conv, _ = slope.slope_albedo(term, flat[idx], phflat[idx], rtol, atol, max_regions)
            elif route == "lobe_axis":  # a power lobe about its own axis (Lafortune's, p = 0), at every azimuth of wi
                n, nu, scale = payload
                v, e, conv, _ = polar.axis_albedo(n, np.broadcast_to(nu, flat.shape)[idx],
                                                  np.broadcast_to(scale, flat.shape)[idx], rtol, atol, max_regions,
                                                  choice.decay_estimate)
            elif route == "nested":
                v, e, conv = nested.integrate(term, payload, rtol, atol, max_regions)
            elif route == "cubature":
                v, e, conv = _integrate_group(term, payload, rtol, atol, max_regions,
                                              generic_check=choice.generic_check)
            else:  # the 1-D routes of the model's azimuth hint (pumpup.engine.polar)
                v, e, conv, _ = polar.run(route, payload, flat[idx], rtol, atol, max_regions, choice.lobe_fresnel_gauss,
                                          choice.decay_estimate)
            value[idx] += w * v
            error[idx] += abs(w) * e
            ok[idx] &= conv
    # a model's delta lobe (he_torrance's specular part) is added analytically; a model whose eval
    # is exact to a relative eval_rtol (a truncated series) has that share added to the error
    error += brdf.eval_rtol * value
    delta = brdf.delta_albedo
    if delta is not None:
        w = np.asarray(delta(flat), dtype=np.float64)
        value, error = value + w, error + 1e-15 * w
    if not ok.all():
        i = int(np.argmin(ok))
        warnings.warn(
            f"albedo of {brdf!r}: tolerance rtol={rtol:g} not met at {np.count_nonzero(~ok)} value(s) of mu "
            f"(e.g. mu={flat[i]:.6g}: a={value[i]:.10g} +- {error[i]:.2g}); raise max_regions or rtol",
            AlbedoWarning,
            stacklevel=2,
        )
    value = value.reshape(m.shape)
    error = error.reshape(m.shape)
    if return_error:
        return value, error
    return value
