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
  cuts cross or a cut meets the horizon end of the arc (``_kink_breaks``): inside a rectangle,
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
import warnings
from dataclasses import dataclass, replace

import numpy as np
from numba import njit

from ..core import BRDF, Lobe

__all__ = ["albedo", "check_mu", "check_phi", "AlbedoWarning"]

DEFAULT_RTOL = 1e-10
DEFAULT_ATOL = 1e-14
#: the largest ``max_regions`` accepted (each rectangle costs 225 evaluations and about 100 bytes)
MAX_REGIONS_LIMIT = 10**7
NX_INIT = 8  # initial subdivisions of the radial variable
NT_INIT = 2  # initial subdivisions of each piece of the azimuth


class AlbedoWarning(UserWarning):
    """The cubature stopped before it met the tolerance; the error estimate says by how much."""


# --- Gauss-Kronrod 7/15 nodes and weights on [-1, 1] (QUADPACK qk15) -----------------------
_XGK = np.array(
    [
        0.991455371120812639206854697526329,
        0.949107912342758524526189684047851,
        0.864864423359769072789712788640926,
        0.741531185599394439863864773280788,
        0.586087235467691130294144845693013,
        0.405845151377397166906606412076961,
        0.207784955007898467600689403773245,
        0.0,
    ]
)
_WGK = np.array(
    [
        0.022935322010529224963732008058970,
        0.063092092629978553290700663189204,
        0.104790010322250183839876322541518,
        0.140653259715525918745189590510238,
        0.169004726639267902826583426598550,
        0.190350578064785409913256402421014,
        0.204432940075298892414161999234649,
        0.209482141084727828012999174891714,
    ]
)
_WG = np.array([0.129484966168869693270611432679082, 0.279705391489276667901467771423780,
                0.381830050505118944950369775488975, 0.417959183673469387755102040816327])
# full 15-point rule on [0, 1]
NODES = 0.5 * (1.0 + np.concatenate([-_XGK[:-1], _XGK[::-1]]))
WK = 0.5 * np.concatenate([_WGK[:-1], _WGK[::-1]])
WG = np.zeros(15)  # the embedded 7-point Gauss rule lives on the odd Kronrod nodes
WG[1::2] = 0.5 * np.concatenate([_WG[:-1], _WG[::-1]])


def check_mu(mu) -> np.ndarray:
    """``mu`` as a float64 array, or a ValueError that says which value is outside (0, 1]."""
    try:
        m = np.asarray(mu, dtype=np.float64)
    except (TypeError, ValueError):
        raise ValueError(f"mu must be a number or an array of numbers in (0, 1], got {mu!r}") from None
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
    try:
        p = np.asarray(phi, dtype=np.float64)
    except (TypeError, ValueError):
        raise ValueError(f"phi (the azimuth of wi, in radians) must be a finite number or an array of them, "
                         f"got {phi!r}") from None
    if not np.all(np.isfinite(p)):
        raise ValueError(f"phi (the azimuth of wi, in radians) must be finite, got {phi!r}")
    return p


# --- radial maps: x (with xc = 1 - x) -> cos(alpha), sin(alpha), J = |d cos(alpha) / dx| ------

def _power_split(k: float) -> tuple[float, float]:
    """(u_s, y_s) of the two-piece power map: the tail cos(alpha) in [0, u_s = 1/2] is
    integrated in cos(alpha) itself, the peak y = cos^(n+1)(alpha) in [y_s, 1]."""
    return 0.5, 0.5 ** (k + 1.0)


def _radial(kind: str, k: float, x: np.ndarray, xc: np.ndarray):
    if kind == "cosine":  # sin^2 alpha = x
        ca = np.sqrt(xc)
        sa = np.sqrt(x)
        with np.errstate(divide="ignore"):
            jac = 0.5 / ca
        return ca, sa, jac
    if kind == "power":
        # two pieces: for x < 1/2, cos(alpha) = 2 x u_s runs linearly over the tail [0, u_s];
        # for x >= 1/2, y = y_s + (1 - y_s)(2 x - 1) and cos(alpha) = y^(1/(n+1)) absorbs the
        # cos^n peak (000 eq. 20).  A single power map would be singular at alpha = 90 deg.
        us, ys = _power_split(k)
        tail = x < 0.5
        with np.errstate(divide="ignore", invalid="ignore"):
            y = 1.0 - 2.0 * (1.0 - ys) * xc  # = ys + (1 - ys)(2 x - 1), kept exact near y = 1
            ly = np.log1p(-2.0 * (1.0 - ys) * xc) / (k + 1.0)
            ca_peak = np.exp(ly)
            sa_peak = np.sqrt(-np.expm1(ly) * (1.0 + ca_peak))
            jac_peak = 2.0 * (1.0 - ys) * ca_peak / ((k + 1.0) * y)
        # at x = 1/2 itself 1 - (1 - ys) rounds ys off beyond n = 52 (y = 0): alpha is the split's, cos(alpha) = u_s, not
        # 90 deg (the kink scan samples tau = 1/2 and saw the wrong side there), with the weight 0 the point had before
        # (it only ends intervals one double wide)
        at_split = ~tail & (y <= 0.0)
        ca_tail = np.where(at_split, us, 2.0 * us * x)
        ca = np.where(tail | at_split, ca_tail, ca_peak)
        sa = np.where(tail | at_split, np.sqrt((1.0 - ca_tail) * (1.0 + ca_tail)), sa_peak)
        jac = np.where(tail, 2.0 * us, np.where(at_split, 0.0, jac_peak))
        return ca, sa, jac
    if kind == "beckmann":  # tan^2 alpha = -m^2 ln x
        with np.errstate(divide="ignore", invalid="ignore"):
            t2 = -(k * k) * np.where(x < 0.5, np.log(x), np.log1p(-xc))
            ca = 1.0 / np.sqrt(1.0 + t2)
            sa = np.where(np.isinf(t2), 1.0, np.sqrt(t2) * ca)
            jac = (k * k) * ca**3 / (2.0 * x)
        return ca, sa, jac
    if kind == "ggx":  # tan^2 alpha = r x / (1 - x)
        d = xc + k * x
        ca = np.sqrt(xc / d)
        sa = np.sqrt(k * x / d)
        with np.errstate(divide="ignore"):
            jac = k / (2.0 * ca * d * d)
        return ca, sa, jac
    if kind == "gaussian":  # alpha = sqrt(-ln y) / c, y in [y0, 1], y = y0 + (1 - y0) x
        y0 = math.exp(-((k * math.pi / 2) ** 2))
        y = y0 + (1.0 - y0) * x
        with np.errstate(divide="ignore", invalid="ignore"):
            # ln y: directly where y is small (1 - y0 may round to 1), via log1p near y = 1
            ln_y = np.where(x < 0.5, np.log(y), np.log1p(-(1.0 - y0) * xc))
            a = np.minimum(np.sqrt(np.maximum(-ln_y, 0.0)) / k, 0.5 * np.pi)  # y0 may underflow to 0
            ca = np.cos(a)
            sa = np.sin(a)
            sinc = np.where(a > 0, sa / np.where(a > 0, a, 1.0), 1.0)
            jac = (1.0 - y0) * sinc / (2.0 * k * k * y)
        return ca, sa, jac
    raise ValueError(f"unknown radial map {kind!r} in a Lobe hint")


_AXES = ("normal", "mirror", "retro", "half")


@dataclass
class _Group:
    """Problems (values of mu) that share one hint structure."""

    lobe: Lobe
    mu: np.ndarray  # (P,)
    levels: np.ndarray  # (P, L)
    phi: np.ndarray | None = None  # (P,) azimuths of wi, or None: wi in the xz-plane


def _smooth(tau):
    """x = tau^2 (3 - 2 tau), 1 - x, dx/dtau."""
    x = tau * tau * (3.0 - 2.0 * tau)
    xc = (1.0 - tau) ** 2 * (1.0 + 2.0 * tau)
    return x, xc, 6.0 * tau * (1.0 - tau)


_AXIS_CODE = {"normal": 0, "mirror": 1, "retro": 2, "half": 3}
_RADIAL_CODE = {"cosine": 0, "power": 1, "beckmann": 2, "ggx": 3, "gaussian": 4}


def _kink_coefficients(lobe: Lobe, mu: np.ndarray, x: np.ndarray, xc: np.ndarray):
    """(a, b) arrays of shape (N, K) of the model's own kinks a + b cos(beta) = 0."""
    s = np.sqrt((1.0 - mu) * (1.0 + mu))
    ca, sa, _ = _radial(lobe.radial, lobe.sharpness, x, xc)
    pairs = list(lobe.kinks(mu, s, ca, sa))
    a = np.stack([np.broadcast_to(np.asarray(p[0], float), mu.shape) for p in pairs], axis=-1)
    b = np.stack([np.broadcast_to(np.asarray(p[1], float), mu.shape) for p in pairs], axis=-1)
    return np.ascontiguousarray(a), np.ascontiguousarray(b)


def _geometry_reference(lobe: Lobe, mu, levels, ka, kb, piece, tx, tt):
    """Plain numpy geometry: (wi, wo, weight) of every point (tau_x, tau_t) of a piece.

    ``weight`` is d omega_o per d tau_x d tau_t (with the half-vector Jacobian and the
    width of the beta piece), for one sign of beta; ``levels`` (N, L) and ``ka``, ``kb``
    (N, K) give the kinks.  The compiled :func:`_geometry_kernel` does the same.
    """
    s = np.sqrt((1.0 - mu) * (1.0 + mu))
    x, xc, dx = _smooth(tx)
    t, _, dt = _smooth(tt)
    ca, sa, jac = _radial(lobe.radial, lobe.sharpness, x, xc)
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


@njit(cache=True, nogil=True)
def _radial_scalar(kind, k, x, xc):  # pragma: no cover - compiled; see _radial
    if kind == 0:
        ca = math.sqrt(xc)
        return ca, math.sqrt(x), (0.5 / ca if ca > 0 else math.inf)
    if kind == 1:
        us = 0.5  # as in _power_split
        ys = us ** (k + 1.0)
        if x < 0.5:
            c = 2.0 * us * x
            return c, math.sqrt((1.0 - c) * (1.0 + c)), 2.0 * us
        y = 1.0 - 2.0 * (1.0 - ys) * xc
        if y <= 0.0:  # x = 1/2 with ys rounded off: the split's alpha, weight 0 (as in _radial)
            return us, math.sqrt((1.0 - us) * (1.0 + us)), 0.0
        ly = math.log1p(-2.0 * (1.0 - ys) * xc) / (k + 1.0)
        c = math.exp(ly)
        sa = math.sqrt(-math.expm1(ly) * (1.0 + c))
        jac = 2.0 * (1.0 - ys) * c / ((k + 1.0) * y)
        return c, sa, jac
    if kind == 2:
        lg = math.log(x) if x < 0.5 else math.log1p(-xc)
        if x <= 0.0:
            return 0.0, 1.0, math.inf
        t2 = -(k * k) * lg
        c = 1.0 / math.sqrt(1.0 + t2)
        return c, math.sqrt(t2) * c, (k * k) * c * c * c / (2.0 * x)
    if kind == 3:
        d = xc + k * x
        c = math.sqrt(xc / d)
        return c, math.sqrt(k * x / d), (k / (2.0 * c * d * d) if c > 0 else math.inf)
    y0 = math.exp(-((k * math.pi / 2) ** 2))
    y = y0 + (1.0 - y0) * x
    ln_y = (math.log(y) if y > 0.0 else 0.0) if x < 0.5 else math.log1p(-(1.0 - y0) * xc)  # as in _radial
    a = min(math.sqrt(max(-ln_y, 0.0)) / k, 0.5 * math.pi) if y > 0.0 else 0.5 * math.pi
    sinc = math.sin(a) / a if a > 0 else 1.0
    return math.cos(a), math.sin(a), ((1.0 - y0) * sinc / (2.0 * k * k * y) if y > 0.0 else math.inf)


@njit(cache=True, nogil=True, inline="always")
def _sort_interior(x, n):  # pragma: no cover - compiled
    """Insertion sort of x[1:n - 1] in place (the cuts between an arc's two ends x[0] and x[n - 1]: a
    few, already nearly sorted; no allocation)."""
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
            ca, sa, jac = _radial_scalar(radial, k, x, xc)
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
        x, xc, _ = _smooth(tx)
        ka, kb = _kink_coefficients(lobe, g.mu[prob], x, xc)
    else:
        ka = kb = np.zeros((n, 0))
    wi = np.empty((n, 3))
    wo = np.empty((n, 3))
    weight = np.empty(n)
    _geometry_kernel(_AXIS_CODE[lobe.axis], _RADIAL_CODE[lobe.radial], float(lobe.sharpness), g.mu, g.levels, prob,
                     ka, kb, piece, tx, tt, wi, wo, weight)
    total = np.zeros(n)
    if g.phi is not None:  # rotate the whole configuration by phi about N: wi gets azimuth phi
        cp, sp = np.cos(g.phi[prob]), np.sin(g.phi[prob])
        wi_c, wo_c = wi, wo
    for sign in (1.0,) if lobe.symmetric else (1.0, -1.0):
        if sign < 0:
            wo[:, 1] *= -1.0  # beta -> -beta flips wo_y in every frame (wi_y = 0)
        if g.phi is not None:
            wi, wo = _rotate(wi_c, cp, sp), _rotate(wo_c, cp, sp)  # N.wi, N.wo and wi.wo unchanged
        f = np.ascontiguousarray(brdf._eval(wi, wo), dtype=np.float64)
        i = _accumulate(f, wo[:, 2], weight, total)
        if g.phi is not None:
            wo = wo_c
        if i >= 0:
            raise ValueError(
                f"{brdf!r} returned {f[i]!r} at wi={wi[i].tolist()}, wo={wo[i].tolist()}: "
                "a BRDF must be finite and non-negative above the horizon"
            )
    return 2.0 * total if lobe.symmetric else total


def _rotate(w, c, s):
    """w rotated about N = (0, 0, 1) by the angle with cosine c and sine s (arrays (n,))."""
    out = np.empty_like(w)
    out[:, 0] = c * w[:, 0] - s * w[:, 1]
    out[:, 1] = s * w[:, 0] + c * w[:, 1]
    out[:, 2] = w[:, 2]
    return out


@njit(cache=True, nogil=True)
def _accumulate(f, cos_o, weight, total):  # pragma: no cover - compiled
    """total += f cos(theta_o) weight where all are positive; the index of the first value of f
    that is negative or not finite (or -1)."""
    for i in range(f.shape[0]):
        v = f[i]
        if not (v >= 0.0 and v < math.inf):
            return i
        if v > 0.0 and cos_o[i] > 0.0 and weight[i] > 0.0:
            total[i] += v * cos_o[i] * weight[i]
    return -1


def _rule(brdf, g, prob, piece, x0, x1, t0, t1, chunk=1_500_000):
    """Apply the 15 x 15 Gauss-Kronrod tensor rule to rectangles; return (K, err, ex, et).

    err is the error estimate of the rectangle, |K - G| (or, when ``pumpup.physics.quadrature.MODE_2D``
    asks for it, QUADPACK's calibration of it: not the default, see the module docstring);
    ex and et, the same for the Gauss rule in x only and in t only, choose the split direction."""
    from ..physics.quadrature import calibrated_array, mode_code

    mode = mode_code(smooth=False)  # raw |K - G| unless pumpup.physics.quadrature.MODE_2D says otherwise
    R = len(prob)
    out = np.empty((R, 4))
    per = max(1, chunk // 225)
    for a in range(0, R, per):
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


def _radial_inverse(kind: str, k: float, alpha: float) -> tuple[float, float]:
    """The map variable x of the polar angle alpha, and 1 - x, both to full precision
    (inverse of :func:`_radial`)."""
    ta = math.tan(alpha)
    if kind == "cosine":
        return math.sin(alpha) ** 2, math.cos(alpha) ** 2
    if kind == "power":
        us, ys = _power_split(k)
        ca = math.cos(alpha)
        if ca < us:
            x = ca / (2 * us)
            return x, 1.0 - x
        one_minus_y = -math.expm1((k + 1.0) * math.log1p(-2.0 * math.sin(alpha / 2) ** 2))
        xc = one_minus_y / (2.0 * (1.0 - ys))
        return 1.0 - xc, xc
    if kind == "beckmann":
        q = ta * ta / (k * k)
        return math.exp(-q), -math.expm1(-q)
    if kind == "ggx":
        return ta * ta / (k + ta * ta), k / (k + ta * ta)
    if kind == "gaussian":
        y0 = math.exp(-((k * math.pi / 2) ** 2))
        q = (k * alpha) ** 2
        return (math.exp(-q) - y0) / (1.0 - y0), -math.expm1(-q) / (1.0 - y0)
    raise ValueError(kind)


def _smooth_inverse(x: float, xc: float) -> float:
    """tau with tau^2 (3 - 2 tau) = x, precise at both ends (the map is symmetric about 1/2)."""
    small = min(x, xc)
    if small < 1e-4:
        # the series tau = t0 (1 + t0 / 3 + ...), t0 = sqrt(small / 3): the closed form below rounds 1 - 2 small, and
        # for small below about 1e-16 it started Newton at tau = 0 or 5.6e-17, whence three steps did not come back
        # (xc = 9.2e-18 gave 1 - tau = 6.8e-3 for 1.7e-9: GGX alpha = 1e-4's horizon break at mu = 6.05e-5, 6.8e-9
        # off with an estimate of 2.8e-10, issue 14's twentieth session)
        t0 = math.sqrt(small / 3.0)
        tau = t0 * (1.0 + t0 / 3.0)
    else:
        tau = 0.5 - math.sin(math.asin(1.0 - 2.0 * small) / 3.0)
    for _ in range(3):  # Newton on the small side, where the residual keeps its digits
        d = 6.0 * tau * (1.0 - tau)
        if d <= 0:
            break  # small = 0: tau = 0
        tau -= (tau * tau * (3.0 - 2.0 * tau) - small) / d
    return tau if x <= xc else 1.0 - tau


#: horizon breaks whose map variable x or 1 - x is below this are the end itself (_horizon_breaks)
_BREAK_MIN = 1e-30


def _horizon_breaks(lobe: Lobe, mu: float) -> np.ndarray:
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
            tau = _tau_of_angle(lobe, a)
            if tau is not None:
                out.append(tau)
    return np.array(out)


def _tau_of_angle(lobe: Lobe, alpha: float) -> float | None:
    """tau_x of the polar angle ``alpha`` in the lobe's radial map, or None where the map variable x or 1 - x is below
    :data:`_BREAK_MIN`: x is the radial weight's measure, and a break there closes a region that weighs nothing (below x
    the integrand per unit x is at most about 1 / mu; beyond 1 - x, GGX's tail, about alpha / (mu sqrt(1 - x));
    Cook-Torrance m = 0.2 at mu = 0.359: x = 1.7e-315 put a break at tau_x = 2.4e-158, where the map's Jacobian
    k^2 cos^3 / (2 x) overflowed; a break at 3e-56 would cost the nested engine 46 graded intervals)."""
    x, xc = _radial_inverse(lobe.radial, lobe.sharpness, alpha)
    return _smooth_inverse(x, xc) if x > _BREAK_MIN and xc > _BREAK_MIN**2 else None


_TAU_SCAN = np.unique(np.concatenate([
    np.linspace(0.0, 1.0, 401),
    np.logspace(-13, math.log10(0.5), 120),
    1.0 - np.logspace(-13, math.log10(0.5), 120),
]))


#: kink breaks closer than this to an end of the radial range are the end itself (_kink_breaks)
_END_GAP = 1e-10
#: two cuts whose crossing function a_j b_k - a_k b_j stays within COINCIDENT eps S_j S_k at every node of the scan
#: (S a bound of the magnitudes a cut's coefficients are computed from: |a| + |b| of a model's kink, |a0 - u| + |b0| +
#: |u| of a level N.wo = u, |a0| + |b0| of the horizon) are one curve, computed twice: its "roots" are rounding noise.
#: A pumped Cook-Torrance has the level N.wo = mu of g2 and g1 (:meth:`pumpup.operators.pumping.Pumped.kink_levels`) and the
#: geometry factor's kink N.wo = mu (:func:`pumpup.models.cook_torrance._g_kinks`): 292 such breaks at mu = 0.5 gave
#: the nested engine 448 first intervals where the base model has 25, 40-60 x its evaluations (issue 14's
#: twenty-fourth session)
COINCIDENT = 64.0
_EPS = float(np.finfo(float).eps)


def _kink_breaks_reference(lobe: Lobe, mu: np.ndarray, levels: np.ndarray, crossings: bool = True) -> list[np.ndarray]:
    """Plain numpy reference of :func:`_kink_breaks`: the same breaks, bit for bit and in the same
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
        the model's kinks) and, last, of the horizon N.wo = 0, for problems p_sel at tau."""
        m, lev = mu[p_sel], levels[p_sel]
        with np.errstate(all="ignore"):
            s = np.sqrt((1.0 - m) * (1.0 + m))
            x, xc, _ = _smooth(tau)
            ca, sa, _ = _radial(lobe.radial, lobe.sharpness, x, xc)
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
        """the function of each row (function rows // P, problem rows % P) at tau"""
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
    around a local minimum of |h| (:func:`_touching_pairs_reference`), refined by bisection."""
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
    """Brackets of root pairs that the scan of :func:`_kink_breaks` shows no sign change for.

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


# --- the breaks of the radial variable: compiled scan and refinement (twin: _kink_breaks_reference) ---

#: points of the kink functions evaluated per round of :func:`_kink_breaks`'s searches: one evaluation
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
    :func:`_kink_breaks_reference`, the same operations in the same order)."""
    if axis == 0:  # normal
        return ca, 0.0
    if axis == 1 or axis == 2:  # mirror, retro
        return m * ca, s * sa
    return m * (ca * ca - sa * sa), 2.0 * s * sa * ca  # half


@njit(cache=True, nogil=True)
def _cut_ab(c, L, K, a0, b0, lev, KA, KB, i):  # pragma: no cover - compiled
    """(a, b) of cut c: a level N.wo = lev[c] (c < L), the model's kink c - L (its coefficients in
    column i of KA, KB), or the horizon (c = L + K)."""
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
    (the cuts of a crossing: j is a kink of the model, k a level, a kink or the horizon)."""
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
    (:data:`COINCIDENT`, the test of :func:`_kink_breaks_reference`)."""
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
    (kind 1: cuts j and k cross)."""
    if kind == 0:
        return aj - sign * bj
    return aj * bk - ak * bj


@njit(cache=True, nogil=True)
def _prepare_points(prob, tau, mu, s_p, radial, k, m, s, x, xc, ca, sa, rest):  # pragma: no cover
    """For the points (problem ``prob[i]``, tau[i]): m = mu and s = sqrt(1 - mu^2)
    of the problem, x and 1 - x of :func:`_smooth`, and cos(alpha), sin(alpha) of :func:`_radial`
    where the map is exact arithmetic and square roots (the cosine and GGX maps, the power map's
    tail x < 1/2: :func:`_radial_scalar` gives numpy's bits there); ``rest`` marks the others (logs
    and exponentials, left to numpy).  Returns how many those are."""
    n_rest = 0
    for i in range(prob.shape[0]):
        m[i] = mu[prob[i]]
        s[i] = s_p[prob[i]]
        t = tau[i]
        u = 1.0 - t
        x[i] = t * t * (3.0 - 2.0 * t)
        xc[i] = (u * u) * (1.0 + 2.0 * t)
        if radial == 0 or radial == 3 or (radial == 1 and x[i] < 0.5):
            c, sn, _ = _radial_scalar(radial, k, x[i], xc[i])
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
    :func:`_kink_breaks_reference`)."""
    for i in range(func.shape[0]):
        f = func[i]
        aj, bj, ak, bk = _cut_pair(f, prob[i], i, L, K, axis, m, s, ca, sa, KA, KB, levels, fj, fk)
        out[i] = _kink_h(kind[f], fj[f], fk[f], fs[f], aj, bj, ak, bk)


@njit(cache=True, nogil=True)
def _crossings_on_arc(func, prob, L, K, axis, m, s, ca, sa, KA, KB, levels, fj, fk, out):  # pragma: no cover
    """Whether both cuts of function ``func[i]`` of problem ``prob[i]`` are on the arc (|a| <= |b|)
    at point i."""
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
    counts (the arrays were too short where they exceed them)."""
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
    """pts (n, 2^d - 1): the midpoints of the next d bisection steps of every bracket [lo, hi] for
    either outcome of each step, as a heap (node q's children: 2 q + 1 where the root is above the
    midpoint, 2 q + 2 where below)."""
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
    and is set to 0 where a step changes nothing (lo and hi adjacent: so would every later step)."""
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
    """pts (n, 2 (2^d - 1)): the points x1, x2 of the next d steps of the golden-section search of
    every [a, b] for either outcome of each step (a heap as in :func:`_bisect_points`; child 2 q + 1
    keeps the left part [a, x2], child 2 q + 2 the right part [x1, b])."""
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
    steps left, is set to 0."""
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
    at the next round."""
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


def _kink_breaks(lobe: Lobe, mu: np.ndarray, levels: np.ndarray, crossings: bool = True) -> list[np.ndarray]:
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
    ``Lobe.kinks``, and ``_radial`` where it takes logs or exponentials: :func:`_prepare_points`), so
    the breaks are those of :func:`_kink_breaks_reference`, the plain numpy twin, bit for bit and in
    the same order (``tests/engine/test_cubature.py``).
    """
    P = len(mu)
    if not levels.shape[1] and lobe.kinks is None:
        return [np.array([]) for _ in range(P)]
    L = levels.shape[1]
    K = len(lobe.kinks(*(np.full(1, 0.5) for _ in range(4)))) if lobe.kinks is not None else 0
    n_cuts = L + K
    # the kink functions, one row each per problem (rows f P + p), as in _kink_breaks_reference
    funcs = [(0, j, j, sign) for j in range(n_cuts) for sign in (1.0, -1.0)]
    if crossings:
        funcs += [(1, j, k, 0.0) for j in range(L, n_cuts) for k in list(range(j)) + [n_cuts]]
    kind, fj, fk = (np.array([c[i] for c in funcs], np.int64) for i in range(3))
    fs = np.array([c[3] for c in funcs], np.float64)
    mu = np.ascontiguousarray(mu, dtype=np.float64)
    levels = np.ascontiguousarray(levels, dtype=np.float64)
    axis, radial, k = _AXIS_CODE[lobe.axis], _RADIAL_CODE[lobe.radial], float(lobe.sharpness)
    with np.errstate(all="ignore"):
        s_p = np.sqrt((1.0 - mu) * (1.0 + mu))

    def kink_coefficients(m, s, ca, sa, KA, KB):
        """the model's kinks at the points (numpy: ``Lobe.kinks`` is the model's) into KA, KB (K, n)"""
        if K:
            with np.errstate(all="ignore"):
                for q, (a, b) in enumerate(lobe.kinks(m, s, ca, sa)):
                    KA[q] = a
                    KB[q] = b

    # the scan: the radial map once at the G nodes, the model's kinks at every problem and node, in
    # chunks of problems (numpy's temporaries of _CHUNK points stay in malloc's heap, and are reused)
    G = len(_TAU_SCAN)
    with np.errstate(all="ignore"):
        x, xc, _ = _smooth(_TAU_SCAN)
        ca_g, sa_g, _ = _radial(lobe.radial, lobe.sharpness, x, xc)
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
        """(m, s, ca, sa, KA, KB) at the points (problem prob, tau); at most _CHUNK of them"""
        n = len(prob)
        m, s, x, xc, ca, sa = buf_v[:, :n]
        rest = buf_rest[:n]
        KA, KB = buf_k[:, :, :n]
        if _prepare_points(prob, tau, mu, s_p, radial, k, m, s, x, xc, ca, sa, rest):
            idx = np.flatnonzero(rest)
            with np.errstate(all="ignore"):
                ca[idx], sa[idx], _ = _radial(lobe.radial, lobe.sharpness, x[idx], xc[idx])
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
    # a root within 1e-10 of an end is the end itself (_kink_breaks_reference)
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


def _graded(points: np.ndarray) -> np.ndarray:
    """Breakpoints with a grid graded geometrically towards each (see _horizon_breaks)."""
    out = list(points)
    for t in points:
        d = min(t, 1.0 - t)
        for k in range(1, 30):
            step = d * 4.0**k
            if step > 0.25:
                break
            out.extend(v for v in (t - step, t + step) if 0 < v < 1)
    return np.array(out)


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
        x, xc, _ = _smooth(tx)
        ka, kb = _kink_coefficients(lobe, m, x, xc)
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
    towards the end.  Returns (index into S.ravel(), t0, t1)."""
    d = d.ravel()
    kk = 4.0 ** np.arange(K_GRADE)
    need = d < D_GRADE
    off = np.maximum(d, 0.25 / kk[-1])[:, None] * kk[None, :]
    pts = np.where(need[:, None] & (off < 0.25), 1.0 - off, np.nan)
    allp = np.sort(np.concatenate([np.broadcast_to(gt, (len(d), len(gt))), pts], axis=1), axis=1)  # NaN last
    a, b = allp[:, :-1], allp[:, 1:]
    row, col = np.nonzero(np.isfinite(a) & np.isfinite(b) & (b > a))
    return row, a[row, col], b[row, col]


def _rounding(lobe: Lobe) -> float:
    """Relative rounding error of the integrand values.

    A lobe cos^n(alpha) computed from directions that carry a relative rounding error of
    a few eps has a relative error of about n eps (measured: 3 n eps for n = 1e4 at
    grazing incidence), so the term grows with the exponent.
    """
    eps = np.finfo(float).eps
    n = lobe.sharpness if lobe.radial == "power" else 0.0
    return 16.0 * eps * (4.0 + n)


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
    n_pieces = 1 + g.levels.shape[1] + (len(g.lobe.kinks(np.array([0.5]), np.array([0.5]), np.array([0.5]), np.array([0.5]))) if g.lobe.kinks else 0)
    nx = NX_INIT if not g.lobe.generic else (8 if grid is None else grid[0])
    nt = NT_INIT if not g.lobe.generic else (8 if grid is None else grid[1])
    # initial rectangles: nx x nt per piece per problem, with the x grid also split where
    # the horizon starts to cut the lobe and where it hides it completely
    gt = np.linspace(0, 1, nt + 1)
    from .nested import _alpha_grading  # _nested imports this module

    cols = []
    kink_breaks = _kink_breaks(g.lobe, g.mu, g.levels)
    for p_ in range(P):
        # the arc changes on the scale of the distance from a break to the nearer end (near
        # grazing incidence the horizon break sits within 1e-5 of an end): the grid is graded
        # geometrically towards every break, so that no first rectangle straddles it unseen
        breaks = np.concatenate([_horizon_breaks(g.lobe, float(g.mu[p_])),
                                 kink_breaks[p_]])
        # and, near normal incidence on a microfacet lobe, towards both horizon breaks on the roughness's scale
        # (``pumpup.engine.nested._alpha_grading``: G1(wo) falls to 0 within alpha of the horizon; GGX alpha = 2.7e-4 at
        # mu = 1 was 2.6e-11 off with an estimate of 4.1e-13, 62 x, before)
        gx = np.unique(np.concatenate([np.linspace(0, 1, nx + 1), _graded(breaks), _alpha_grading(g.lobe, float(g.mu[p_]))]))
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
    rounding = _rounding(g.lobe)
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
    and otherwise would fall inside a piece unseen (ward_aniso ax = 1000, ay = 1e-6 gave 0 at mu = 1)."""
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
    xz-plane: ``phi`` != 0, where the hint's symmetry in beta no longer holds)."""
    by_key: dict = {}
    for i, m in enumerate(mu):
        lobe = brdf.lobe(float(m))
        if lobe.axis not in _AXES:
            raise ValueError(f"{brdf!r}: Lobe axis must be one of {_AXES}, got {lobe.axis!r}")
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


def albedo(brdf: BRDF, mu, return_error: bool = False, rtol: float = DEFAULT_RTOL, atol: float = DEFAULT_ATOL,
           max_regions: int = 20000, phi=0.0, engine: str | None = None):
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
        The cubature refines until its error estimate is below max(rtol * a, atol).
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
    if not isinstance(brdf, BRDF):
        if getattr(brdf, "is_spectral", False):  # pumpup.spectral: one albedo per wavelength, on a trailing axis
            return brdf.albedo(mu, return_error=return_error, rtol=rtol, atol=atol, max_regions=max_regions, phi=phi)
        raise TypeError(f"albedo needs a pumpup BRDF, got {type(brdf).__name__}; wrap functions with pumpup.from_function")
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
                                                  np.broadcast_to(scale, flat.shape)[idx], rtol, atol, max_regions)
            elif route == "nested":
                v, e, conv = nested.integrate(term, payload, rtol, atol, max_regions)
            elif route == "cubature":
                v, e, conv = _integrate_group(term, payload, rtol, atol, max_regions, generic_check=choice.generic_check)
            else:  # the 1-D routes of the model's azimuth hint (pumpup.engine.polar)
                v, e, conv, _ = polar.run(route, payload, flat[idx], rtol, atol, max_regions, choice.lobe_fresnel_gauss)
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
