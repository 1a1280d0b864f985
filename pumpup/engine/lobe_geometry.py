"""What the 2-D cubature and the nested quadrature share about a model's Lobe hint: the 7/15 Gauss-Kronrod rule on
[0, 1], the radial maps of a lobe and their inverses, the smoothing substitution, the codes of axes and radial maps, the
rotation of wi out of the xz-plane, the accumulation of f cos(theta_o), and the rounding of a lobe's values;
:mod:`pumpup.engine.cubature` describes the method.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from ..core import Lobe

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


def power_split(k: float) -> tuple[float, float]:
    """(u_s, y_s) of the two-piece power map: the tail cos(alpha) in [0, u_s = 1/2] is
    integrated in cos(alpha) itself, the peak y = cos^(n+1)(alpha) in [y_s, 1].
    """
    return 0.5, 0.5 ** (k + 1.0)


def radial_map(kind: str, k: float, x: np.ndarray, xc: np.ndarray):
    """(cos(alpha), sin(alpha), jac) of the radial map ``kind`` of sharpness ``k`` (:class:`pumpup.core.Lobe`) at ``x``,
    given ``xc`` = 1 - x for precision near x = 1: the polar angle about the lobe's axis, and jac = sin(alpha) d alpha /
    dx, so that d omega = jac dx d beta.
    """
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
        us, ys = power_split(k)
        tail = x < 0.5
        with np.errstate(divide="ignore", invalid="ignore"):
            y = 1.0 - 2.0 * (1.0 - ys) * xc  # = ys + (1 - ys)(2 x - 1), kept exact near y = 1
            ly = np.log1p(-2.0 * (1.0 - ys) * xc) / (k + 1.0)
            ca_peak = np.exp(ly)
            sa_peak = np.sqrt(-np.expm1(ly) * (1.0 + ca_peak))
            jac_peak = 2.0 * (1.0 - ys) * ca_peak / ((k + 1.0) * y)
        # at x = 1/2 itself 1 - (1 - ys) rounds ys off beyond n = 52 (y = 0): alpha is the split's, cos(alpha) = u_s,
        # not 90 deg (the kink scan samples tau = 1/2 and saw the wrong side there), with the weight 0 the point had
        # before (it only ends intervals one double wide)
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


AXES = ("normal", "mirror", "retro", "half")


def smooth(tau):
    """The values x = tau^2 (3 - 2 tau), 1 - x and dx/dtau."""
    x = tau * tau * (3.0 - 2.0 * tau)
    xc = (1.0 - tau) ** 2 * (1.0 + 2.0 * tau)
    return x, xc, 6.0 * tau * (1.0 - tau)


AXIS_CODE = {"normal": 0, "mirror": 1, "retro": 2, "half": 3}
RADIAL_CODE = {"cosine": 0, "power": 1, "beckmann": 2, "ggx": 3, "gaussian": 4}


def kink_coefficients(lobe: Lobe, mu: np.ndarray, x: np.ndarray, xc: np.ndarray):
    """(a, b) arrays of shape (N, K) of the model's own kinks a + b cos(beta) = 0."""
    s = np.sqrt((1.0 - mu) * (1.0 + mu))
    ca, sa, _ = radial_map(lobe.radial, lobe.sharpness, x, xc)
    pairs = list(lobe.kinks(mu, s, ca, sa))
    a = np.stack([np.broadcast_to(np.asarray(p[0], float), mu.shape) for p in pairs], axis=-1)
    b = np.stack([np.broadcast_to(np.asarray(p[1], float), mu.shape) for p in pairs], axis=-1)
    return np.ascontiguousarray(a), np.ascontiguousarray(b)


@njit(cache=True, nogil=True)
def radial_map_scalar(kind, k, x, xc):  # pragma: no cover - compiled; see radial_map
    """Compiled scalar twin of :func:`radial_map`, the map given by its code ``kind`` (:data:`RADIAL_CODE`)."""
    if kind == 0:
        ca = math.sqrt(xc)
        return ca, math.sqrt(x), (0.5 / ca if ca > 0 else math.inf)
    if kind == 1:
        us = 0.5  # as in power_split
        ys = us ** (k + 1.0)
        if x < 0.5:
            c = 2.0 * us * x
            return c, math.sqrt((1.0 - c) * (1.0 + c)), 2.0 * us
        y = 1.0 - 2.0 * (1.0 - ys) * xc
        if y <= 0.0:  # x = 1/2 with ys rounded off: the split's alpha, weight 0 (as in radial_map)
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
    ln_y = (math.log(y) if y > 0.0 else 0.0) if x < 0.5 else math.log1p(-(1.0 - y0) * xc)  # as in radial_map
    a = min(math.sqrt(max(-ln_y, 0.0)) / k, 0.5 * math.pi) if y > 0.0 else 0.5 * math.pi
    sinc = math.sin(a) / a if a > 0 else 1.0
    return math.cos(a), math.sin(a), ((1.0 - y0) * sinc / (2.0 * k * k * y) if y > 0.0 else math.inf)


def rotate_wi(w, c, s):
    """The direction w rotated about N = (0, 0, 1) by the angle with cosine c and sine s (arrays (n,))."""
    out = np.empty_like(w)
    out[:, 0] = c * w[:, 0] - s * w[:, 1]
    out[:, 1] = s * w[:, 0] + c * w[:, 1]
    out[:, 2] = w[:, 2]
    return out


@njit(cache=True, nogil=True)
def accumulate(f, cos_o, weight, total):  # pragma: no cover - compiled
    """Compute total += f cos(theta_o) weight where all are positive; the index of the first value of f
    that is negative or not finite (or -1).
    """
    for i in range(f.shape[0]):
        v = f[i]
        if not (v >= 0.0 and v < math.inf):
            return i
        if v > 0.0 and cos_o[i] > 0.0 and weight[i] > 0.0:
            total[i] += v * cos_o[i] * weight[i]
    return -1


def radial_map_inverse(kind: str, k: float, alpha: float) -> tuple[float, float]:
    """The map variable x of the polar angle alpha, and 1 - x, both to full precision
    (inverse of :func:`radial_map`).
    """
    ta = math.tan(alpha)
    if kind == "cosine":
        return math.sin(alpha) ** 2, math.cos(alpha) ** 2
    if kind == "power":
        us, ys = power_split(k)
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


def smooth_inverse(x: float, xc: float) -> float:
    """The tau with tau^2 (3 - 2 tau) = x, precise at both ends (the map is symmetric about 1/2)."""
    small = min(x, xc)
    if small < 1e-4:
        # the series tau = t0 (1 + t0 / 3 + ...), t0 = sqrt(small / 3): the closed form below rounds 1 - 2 small, and
        # for small below about 1e-16 it started Newton at tau = 0 or 5.6e-17, whence three steps did not come back
        # (xc = 9.2e-18 gave 1 - tau = 6.8e-3 for 1.7e-9: GGX alpha = 1e-4's horizon break at mu = 6.05e-5, 6.8e-9
        # off with an estimate of 2.8e-10)
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


def lobe_rounding(lobe: Lobe) -> float:
    """Relative rounding error of the integrand values.

    A lobe cos^n(alpha) computed from directions that carry a relative rounding error of
    a few eps has a relative error of about n eps (measured: 3 n eps for n = 1e4 at
    grazing incidence), so the term grows with the exponent.
    """
    eps = np.finfo(float).eps
    n = lobe.sharpness if lobe.radial == "power" else 0.0
    return 16.0 * eps * (4.0 + n)
