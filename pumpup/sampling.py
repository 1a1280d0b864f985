"""Importance sampling of BRDFs and Monte Carlo estimators (000 sec. 4).

Every BRDF can be sampled.  The strategy comes from the model's :class:`~pumpup.core.Lobe`
hint, the same one the albedo engine uses, so a pumped BRDF, a sum of lobes or a user's
model samples like its base with no special case:

==================  ==================================================================
hint                sampled density of wi given wo [1/sr]
==================  ==================================================================
mirror, power(n)    the Phong lobe of 000 eq. 19-22: R drawn around wo with density
                    (n+1)/(2 pi) cos^n alpha (eq. 19-20), then wi = mirror image of R;
                    wi below the horizon is rejected (eq. 23-25)
retro, power(n)     the same lobe, wi = R (000 eq. 13)
half, power(n)      h around N with density (n+1)/(2 pi) (N.h)^n (Blinn), wi = 2 (wo.h) h - wo,
                    p(wi) = p(h) / (4 wo.h)
half, beckmann(m)   h with density D(h) (N.h), D Beckmann of RMS slope m (Ward, Cook-Torrance;
                    Walter et al. 2007 eq. 28)
half, ggx(r)        h with density D(h) (N.h), D = r / (pi cos^4 (r + tan^2)^2), r = alpha^2
                    (Schlick, GGX; Walter et al. 2007 eq. 35-36)
half, gaussian(c)   the Beckmann density with m = 1 / c (close to exp(-(c alpha)^2) for small alpha)
anything else       the cosine-weighted hemisphere, p = N.wi / pi (the fallback that covers
                    every BRDF: user functions, diffuse models)
==================  ==================================================================

The hint is :meth:`BRDF.sampling_lobe`, which is the quadrature hint unless a model says
otherwise (anisotropic Ward samples the Beckmann lobe of the wider slope).

A BRDF that is a sum of terms (:meth:`BRDF.albedo_terms`, e.g. the plastic model or a
multi-lobe Lafortune model) is sampled from the mixture of its terms' strategies with
probabilities proportional to the terms' weights; the pdf is the mixture pdf.

Rejected samples (a lobe direction below the horizon) are real draws that produce no
direction: :func:`sample` returns them with ``wi = (0, 0, 0)`` and ``pdf = 0``, and the
estimators count them as samples of weight 0, which keeps them unbiased (000 after eq. 22:
"these samples would get zero weight").

Note: 000 prints the mirroring after eq. 22 as L = (N.R) N - R; the mirror image of R
about N is L = 2 (N.R) N - R, which is what is implemented (it keeps R.V = cos alpha).
"""

from __future__ import annotations

import math
import os
import reprlib
from collections.abc import Callable
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np
from numba import njit, vectorize

from .core import BRDF, Lobe, as_directions
from .engine.cubature import check_mu

if TYPE_CHECKING:
    from numpy.typing import ArrayLike

__all__ = ["Strategy", "acceptance", "efficiency_dataset", "mc_albedo", "mc_radiance", "pdf", "plot_efficiency",
           "sample", "second_moment", "strategy"]

# component kinds (ints for the compiled kernels)
COSINE, MIRROR, RETRO, HALF_POWER, HALF_BECKMANN, HALF_GGX = range(6)
KIND_NAMES = {COSINE: "cosine", MIRROR: "phong lobe (mirror)", RETRO: "phong lobe (retro)",
              HALF_POWER: "blinn half vector", HALF_BECKMANN: "beckmann half vector", HALF_GGX: "ggx half vector"}

_INV_2PI = 0.5 / math.pi


# ----------------------------------------------------------------------------------------
# compiled kernels
# ----------------------------------------------------------------------------------------


@njit(cache=True)
def _frame(ax, ay, az):  # pragma: no cover - compiled
    """An orthonormal basis (e1, e2) perpendicular to the unit vector a (Duff et al. 2017)."""
    sign = 1.0 if az >= 0.0 else -1.0
    a = -1.0 / (sign + az)
    b = ax * ay * a
    return (1.0 + sign * ax * ax * a, sign * b, -sign * ax), (b, sign + ay * ay * a, -ay)


@njit(cache=True)
def _power_direction(k, u1, u2):  # pragma: no cover - compiled
    """(cos alpha, sin alpha, cos beta, sin beta) of a cos^k lobe: cos alpha = u1^(1/(k+1)) (000 eq. 20)."""
    if u1 <= 0.0:
        return 0.0, 1.0, 1.0, 0.0
    t = math.log(u1) / (k + 1.0)
    ca = math.exp(t)
    sa = math.sqrt(-math.expm1(t) * (1.0 + ca))  # (1 - c)(1 + c) without cancellation
    phi = 2.0 * math.pi * u2
    return ca, sa, math.cos(phi), math.sin(phi)


@njit(cache=True)
def _sample_kernel(kind, k, wo, u1, u2, wi, p):  # pragma: no cover - compiled
    """Fill wi (n, 3) and p (n,) from the uniforms u1, u2; rejected samples get wi = 0, p = 0."""
    ox, oy, oz = wo[0], wo[1], wo[2]
    if kind == MIRROR or kind == RETRO:
        e1, e2 = _frame(ox, oy, oz)
    for j in range(u1.shape[0]):
        wi[j, 0] = 0.0
        wi[j, 1] = 0.0
        wi[j, 2] = 0.0
        p[j] = 0.0
        if kind == COSINE:
            r = math.sqrt(u1[j])
            phi = 2.0 * math.pi * u2[j]
            z = math.sqrt(1.0 - u1[j])
            if z > 0.0:
                wi[j, 0] = r * math.cos(phi)
                wi[j, 1] = r * math.sin(phi)
                wi[j, 2] = z
                p[j] = z / math.pi
        elif kind == MIRROR or kind == RETRO:
            ca, sa, cb, sb = _power_direction(k, u1[j], u2[j])
            rx = ca * ox + sa * (cb * e1[0] + sb * e2[0])  # 000 eq. 22: R around V
            ry = ca * oy + sa * (cb * e1[1] + sb * e2[1])
            rz = ca * oz + sa * (cb * e1[2] + sb * e2[2])
            if rz > 0.0:
                if kind == MIRROR:
                    rx, ry = -rx, -ry  # L = 2 (N.R) N - R (000 after eq. 22)
                wi[j, 0] = rx
                wi[j, 1] = ry
                wi[j, 2] = rz
                p[j] = (k + 1.0) * _INV_2PI * math.exp(k * math.log(u1[j]) / (k + 1.0))  # 000 eq. 19: cos^n alpha
        else:
            if kind == HALF_POWER:
                ch, sh, cb, sb = _power_direction(k, u1[j], u2[j])
                ph = (k + 1.0) * _INV_2PI * math.exp(k * math.log(u1[j]) / (k + 1.0))  # (N.h)^n
            else:
                if kind == HALF_BECKMANN:
                    t2 = -k * k * math.log1p(-u1[j])  # tan^2 theta_h = -m^2 ln(1 - u)
                else:
                    t2 = k * u1[j] / (1.0 - u1[j])  # tan^2 theta_h = r u / (1 - u)
                ch = 1.0 / math.sqrt(1.0 + t2)
                sh = math.sqrt(t2) * ch
                phi = 2.0 * math.pi * u2[j]
                cb, sb = math.cos(phi), math.sin(phi)
                if kind == HALF_BECKMANN:
                    ph = (1.0 - u1[j]) / (math.pi * k * k * ch * ch * ch)  # D(h) N.h, Walter eq. 28
                else:
                    q = k + t2
                    ph = k / (math.pi * ch * ch * ch * q * q)  # D(h) N.h, Walter eq. 35
            hx, hy, hz = sh * cb, sh * sb, ch
            d = ox * hx + oy * hy + oz * hz
            if d > 0.0:
                lx, ly, lz = 2.0 * d * hx - ox, 2.0 * d * hy - oy, 2.0 * d * hz - oz
                if lz > 0.0:
                    wi[j, 0] = lx
                    wi[j, 1] = ly
                    wi[j, 2] = lz
                    p[j] = ph / (4.0 * d)  # Jacobian of the reflection, Walter eq. 14


@vectorize(cache=True)
def _pdf_kernel(kind, k, ix, iy, iz, ox, oy, oz):  # pragma: no cover - compiled
    """Density [1/sr] of wi = (ix, iy, iz) given wo = (ox, oy, oz) for one component."""
    if iz <= 0.0 or oz <= 0.0:
        return 0.0
    if kind == COSINE:
        return iz / math.pi
    if kind == MIRROR or kind == RETRO:
        rx, ry = (-ix, -iy) if kind == MIRROR else (ix, iy)
        dx, dy, dz = rx - ox, ry - oy, iz - oz
        h = 0.5 * (dx * dx + dy * dy + dz * dz)  # 1 - R.V, without cancellation
        if h >= 1.0:
            return 0.0
        return (k + 1.0) * _INV_2PI * math.exp(k * math.log1p(-h))  # 000 eq. 19
    sx, sy, sz = ix + ox, iy + oy, iz + oz
    s = math.sqrt(sx * sx + sy * sy + sz * sz)  # |wi + wo| = 2 wo.h
    if s <= 0.0:
        return 0.0
    t2 = (sx * sx + sy * sy) / (sz * sz)  # tan^2 theta_h
    ch = sz / s
    if kind == HALF_POWER:
        ph = (k + 1.0) * _INV_2PI * math.exp(k * math.log(ch))
    elif kind == HALF_BECKMANN:
        ph = math.exp(-t2 / (k * k)) / (math.pi * k * k * ch * ch * ch)
    else:
        q = k + t2
        ph = k / (math.pi * ch * ch * ch * q * q)
    return ph / (2.0 * s)  # p(h) / (4 wo.h)


# ----------------------------------------------------------------------------------------
# plain numpy references (readable; tested against the kernels)
# ----------------------------------------------------------------------------------------


def _frame_reference(a):
    sign = 1.0 if a[2] >= 0 else -1.0
    c = -1.0 / (sign + a[2])
    b = a[0] * a[1] * c
    return np.array([1.0 + sign * a[0] ** 2 * c, sign * b, -sign * a[0]]), np.array([b, sign + a[1] ** 2 * c, -a[1]])


def sample_reference(kind, k, wo, u1, u2):
    """Numpy version of the compiled sampler (same uniforms give the same directions)."""
    wo = np.asarray(wo, dtype=np.float64)
    u1 = np.asarray(u1, dtype=np.float64)
    u2 = np.asarray(u2, dtype=np.float64)
    phi = 2 * np.pi * u2
    with np.errstate(divide="ignore", invalid="ignore"):
        if kind == COSINE:
            z = np.sqrt(1 - u1)
            d = np.stack([np.sqrt(u1) * np.cos(phi), np.sqrt(u1) * np.sin(phi), z], -1)
            p = z / np.pi
            ok = z > 0
        elif kind in (MIRROR, RETRO):
            t = np.log(u1) / (k + 1)
            ca = np.exp(t)  # 000 eq. 20
            sa = np.sqrt(-np.expm1(t) * (1 + ca))
            e1, e2 = _frame_reference(wo)
            d = (ca[:, None] * wo + sa[:, None] * (np.cos(phi)[:, None] * e1 + np.sin(phi)[:, None] * e2))  # eq. 22
            ok = d[:, 2] > 0
            if kind == MIRROR:
                d = d * np.array([-1.0, -1.0, 1.0])  # L = 2 (N.R) N - R
            p = (k + 1) / (2 * np.pi) * np.exp(k * t)  # 000 eq. 19: cos^n alpha
        else:
            if kind == HALF_POWER:
                t = np.log(u1) / (k + 1)
                ch = np.exp(t)
                sh = np.sqrt(-np.expm1(t) * (1 + ch))
                ph = (k + 1) / (2 * np.pi) * np.exp(k * t)
            else:
                t2 = -k * k * np.log1p(-u1) if kind == HALF_BECKMANN else k * u1 / (1 - u1)
                ch = 1 / np.sqrt(1 + t2)
                sh = np.sqrt(t2) * ch
                ph = ((1 - u1) / (np.pi * k * k * ch**3) if kind == HALF_BECKMANN
                      else k / (np.pi * ch**3 * (k + t2) ** 2))
            h = np.stack([sh * np.cos(phi), sh * np.sin(phi), ch], -1)
            dh = h @ wo
            d = 2 * dh[:, None] * h - wo
            ok = (dh > 0) & (d[:, 2] > 0)
            p = ph / (4 * dh)
    return np.where(ok[:, None], d, 0.0), np.where(ok, p, 0.0)


def pdf_reference(kind, k, wi, wo):
    """Numpy version of the compiled component density [1/sr]."""
    wi = np.asarray(wi, dtype=np.float64)
    wo = np.asarray(wo, dtype=np.float64)
    up = (wi[..., 2] > 0) & (wo[..., 2] > 0)
    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
        if kind == COSINE:
            p = wi[..., 2] / np.pi
        elif kind in (MIRROR, RETRO):
            r = wi * np.array([-1.0, -1.0, 1.0]) if kind == MIRROR else wi
            h = 0.5 * np.sum((r - wo) ** 2, axis=-1)  # 1 - R.V
            p = np.where(h < 1, (k + 1) / (2 * np.pi) * np.exp(k * np.log1p(-np.minimum(h, 1))), 0.0)  # eq. 19
        else:
            s = wi + wo
            n = np.linalg.norm(s, axis=-1)
            t2 = (s[..., 0] ** 2 + s[..., 1] ** 2) / s[..., 2] ** 2
            ch = s[..., 2] / n
            if kind == HALF_POWER:
                ph = (k + 1) / (2 * np.pi) * ch**k
            elif kind == HALF_BECKMANN:
                ph = np.exp(-t2 / k**2) / (np.pi * k**2 * ch**3)
            else:
                ph = k / (np.pi * ch**3 * (k + t2) ** 2)
            p = ph / (2 * n)
    return np.where(up, p, 0.0)


# ----------------------------------------------------------------------------------------
# strategies
# ----------------------------------------------------------------------------------------


def _component(lobe: Lobe) -> tuple[int, float]:
    """(kind, parameter) of the sampling component for a Lobe hint."""
    s = float(lobe.sharpness)
    if lobe.radial == "power" and lobe.axis in ("mirror", "retro", "half"):
        return {"mirror": MIRROR, "retro": RETRO, "half": HALF_POWER}[lobe.axis], s
    if lobe.axis == "half" and lobe.radial == "beckmann" and s > 0:
        return HALF_BECKMANN, s
    if lobe.axis == "half" and lobe.radial == "gaussian" and s > 0:
        return HALF_BECKMANN, 1.0 / s
    if lobe.axis == "half" and lobe.radial == "ggx" and s > 0:
        return HALF_GGX, s
    return COSINE, 0.0


@dataclass(frozen=True)
class Strategy:
    """A sampling density for wi given wo: a mixture of components (kind, parameter).

    Attributes
    ----------
    components : tuple of (probability, kind, parameter)
        The probabilities sum to 1.
    """

    components: tuple

    @property
    def names(self) -> list[str]:
        """The components' names with their parameters, e.g. ``phong lobe (mirror)(20)``, and ``cosine``."""
        return [f"{KIND_NAMES[k]}({s:g})" if k != COSINE else "cosine" for _, k, s in self.components]

    def __str__(self) -> str:
        return " + ".join(f"{w:g} x {n}" for (w, _, _), n in zip(self.components, self.names))

    def sample(self, wo: np.ndarray, n: int, rng: np.random.Generator) -> tuple[np.ndarray, np.ndarray]:
        """The n draws of wi given one wo (shape (3,)): (wi (n, 3), pdf (n,)); rejected draws are 0, 0."""
        wi = np.empty((n, 3))
        p = np.empty(n)
        if len(self.components) == 1:
            _, kind, k = self.components[0]
            u = rng.random((2, n))
            _sample_kernel(kind, k, wo, u[0], u[1], wi, p)
            return wi, p
        probs = np.array([w for w, _, _ in self.components])
        which = rng.choice(len(probs), size=n, p=probs)
        u = rng.random((2, n))
        for c, (_, kind, k) in enumerate(self.components):
            sel = np.nonzero(which == c)[0]
            wc, pc = np.empty((len(sel), 3)), np.empty(len(sel))
            _sample_kernel(kind, k, wo, u[0, sel], u[1, sel], wc, pc)
            wi[sel], p[sel] = wc, pc
        ok = p > 0
        p[ok] = self.pdf(wi[ok], wo)  # the mixture density
        return wi, p

    def pdf(self, wi: np.ndarray, wo: np.ndarray) -> np.ndarray:
        """Density [1/sr] of wi given wo, broadcast over the leading axes."""
        wi = np.asarray(wi, dtype=np.float64)
        wo = np.asarray(wo, dtype=np.float64)
        out = 0.0
        for w, kind, k in self.components:
            out = out + w * _pdf_kernel(kind, k, wi[..., 0], wi[..., 1], wi[..., 2], wo[..., 0], wo[..., 1], wo[..., 2])
        return np.asarray(out, dtype=np.float64)


@dataclass(frozen=True)
class OwnSampling:
    """The sampling density of a model that draws its own directions (:attr:`pumpup.core.BRDF.own_sampler`), with
    :class:`Strategy`'s interface.
    """

    brdf: BRDF

    @property
    def names(self) -> list[str]:
        return [f"{self.brdf.type}'s own"]

    def __str__(self) -> str:
        return f"1 x {self.names[0]}"

    def sample(self, wo: np.ndarray, n: int, rng: np.random.Generator) -> tuple[np.ndarray, np.ndarray]:
        """The n draws of wi given one wo (shape (3,)): (wi (n, 3), pdf (n,)); rejected draws are 0, 0."""
        u = rng.random((2, n))
        wi, p = self.brdf.sample_wi(wo, u[0], u[1])
        return np.asarray(wi, dtype=np.float64), np.asarray(p, dtype=np.float64)

    def pdf(self, wi: np.ndarray, wo: np.ndarray) -> np.ndarray:
        """Density [1/sr] of wi given wo, broadcast over the leading axes."""
        return np.asarray(self.brdf.pdf_wi(np.asarray(wi, dtype=np.float64), np.asarray(wo, dtype=np.float64)),
                          dtype=np.float64)


def strategy(brdf: BRDF, mu: float = 1.0, kind: str = "lobe") -> Strategy | OwnSampling:
    """The sampling strategy of ``brdf`` for a conditioning direction with cos(theta) = mu.

    Parameters
    ----------
    brdf : BRDF
    mu : float
        cos(theta) of the direction the samples are drawn around (the hints may depend on it).
    kind : {"lobe", "cosine"}
        "lobe": from the Lobe hints of the BRDF's terms (see the module docstring);
        "cosine": the cosine-weighted hemisphere for every BRDF.

    Examples
    --------
    >>> import pumpup
    >>> print(pumpup.sampling.strategy(pumpup.load({"type": "phong", "n": 20})))
    1 x phong lobe (mirror)(20)
    >>> print(pumpup.sampling.strategy(pumpup.load({"type": "ward", "m": 0.2})))
    1 x beckmann half vector(0.2)
    """
    if kind == "cosine":
        return Strategy(((1.0, COSINE, 0.0),))
    if kind != "lobe":
        raise ValueError(f"sampling strategy must be 'lobe' or 'cosine', got {kind!r}")
    if brdf.own_sampler:  # the model's own importance sampling (BRDF.sample_wi)
        return OwnSampling(brdf)
    terms = brdf.sampling_terms(float(mu))  # the terms weighted for this mu (the Kulla-Conty mixture's)
    weights = np.array([abs(w) for w, _ in terms], dtype=np.float64)
    if not np.all(np.isfinite(weights)) or weights.sum() <= 0:
        weights = np.ones(len(terms))
    merged: dict = {}
    for w, (_, term) in zip(weights / weights.sum(), terms):
        key = _component(term.sampling_lobe(float(mu)))
        merged[key] = merged.get(key, 0.0) + float(w)
    return Strategy(tuple((w, kind_, k) for (kind_, k), w in merged.items() if w > 0))


# ----------------------------------------------------------------------------------------
# public functions
# ----------------------------------------------------------------------------------------


def _check_wo(wo) -> np.ndarray:
    w = as_directions(wo, "wo")
    if w.shape != (3,):
        raise ValueError(f"wo must be one direction of shape (3,), got shape {w.shape}")
    if not w[2] > 0:
        raise ValueError(f"wo must point above the surface (wo_z > 0), got wo_z = {w[2]!r}")
    return w


#: the most samples :func:`sample` and :func:`mc_albedo` draw at once (their arrays: about 24 bytes per sample each)
MAX_SAMPLES = 10**8


def _check_n(n) -> int:
    if isinstance(n, bool) or not isinstance(n, (int, np.integer)) or not 1 <= n <= MAX_SAMPLES:
        raise ValueError(f"the number of samples n must be an integer in [1, {MAX_SAMPLES:.0e}], got {reprlib.repr(n)}")
    return int(n)


def _check_rng(rng) -> np.random.Generator:
    if isinstance(rng, np.random.Generator):
        return rng
    if rng is None or isinstance(rng, (int, np.integer)):
        return np.random.default_rng(rng)
    raise TypeError(f"rng must be a numpy.random.Generator or an integer seed, got {type(rng).__name__}")


def _check_brdf(brdf) -> BRDF:
    if not isinstance(brdf, BRDF):
        raise TypeError(f"need a pumpup BRDF, got {type(brdf).__name__}; wrap functions with pumpup.from_function")
    return brdf


def sample(brdf: BRDF, wo: ArrayLike, n: int, rng: np.random.Generator | int | None = None, *,
           kind: str = "lobe") -> tuple[np.ndarray, np.ndarray]:
    """Draw n incidence directions wi for the view direction wo, with their density.

    Parameters
    ----------
    brdf : BRDF
    wo : array_like, shape (3,)
        Unit vector towards the viewer, above the surface.
    n : int
        Number of draws.
    rng : numpy.random.Generator or int or None
        The random generator (or a seed for one).
    kind : {"lobe", "cosine"}
        The strategy (see :func:`strategy`).

    Returns
    -------
    wi : ndarray, shape (n, 3)
        Sampled unit directions; (0, 0, 0) for a rejected draw (a lobe direction below the
        horizon, 000 after eq. 22).
    pdf : ndarray, shape (n,)
        Their density in solid-angle measure [1/sr]; 0 for a rejected draw.

    Examples
    --------
    >>> import numpy as np, pumpup
    >>> f = pumpup.load({"type": "phong", "n": 20})
    >>> wi, p = pumpup.sample(f, [0.0, 0.0, 1.0], 4, np.random.default_rng(1))
    >>> wi.shape, p.shape, bool(np.all(p > 0))
    ((4, 3), (4,), True)
    """
    f = _check_brdf(brdf)
    w = _check_wo(wo)
    return strategy(f, float(w[2]), kind).sample(w, _check_n(n), _check_rng(rng))


def pdf(brdf: BRDF, wi, wo, *, kind: str = "lobe") -> np.ndarray:
    """The density [1/sr] with which :func:`sample` draws wi given wo (wo of shape (3,)).

    ``wi`` may hold the zero vectors of rejected draws (their density is 0), so
    ``pdf(f, sample(f, wo, n, rng)[0], wo)`` equals the second output of :func:`sample`.
    """
    f = _check_brdf(brdf)
    w = _check_wo(wo)
    a = np.asarray(wi, dtype=np.float64)
    rejected = np.all(a == 0.0, axis=-1, keepdims=True)
    a = as_directions(np.where(rejected, np.array([0.0, 0.0, -1.0]), a), "wi")  # below the horizon: p = 0
    return strategy(f, float(w[2]), kind).pdf(a, w)


def _weights(f: BRDF, strat: Strategy, w: np.ndarray, n: int, rng, radiance=None, chunk: int = 1 << 20):
    """Mean and standard error of the weights f(wi, w) cos(wi) L(wi) / p(wi) over n draws
    (rejected draws count as 0), accumulated in chunks with Chan's pairwise update.
    """
    count, mean, m2 = 0, 0.0, 0.0
    while count < n:
        m = min(chunk, n - count)
        wi, p = strat.sample(w, m, rng)
        ok = p > 0
        x = np.zeros(m)
        if ok.any():
            v = f._eval(wi[ok], w) * wi[ok, 2] / p[ok]  # 000 eq. 18: f cos / p
            if radiance is not None:
                v = v * np.asarray(radiance(wi[ok]), dtype=np.float64)
            x[ok] = v
        mb = float(x.mean())
        m2b = float(np.sum((x - mb) ** 2))
        delta = mb - mean
        tot = count + m
        mean += delta * m / tot
        m2 += m2b + delta * delta * count * m / tot
        count = tot
    var = m2 / (n - 1) if n > 1 else math.inf
    return mean, math.sqrt(var / n)


def mc_radiance(brdf: BRDF, wo: ArrayLike, n: int, rng: np.random.Generator | int | None = None,
                radiance: Callable[[np.ndarray], ArrayLike] | None = None, *,
                kind: str = "lobe") -> tuple[float, float]:
    """Monte Carlo estimate of the reflected radiance towards wo (000 eq. 17-18, 23-25).

    L_out(wo) = integral of L_in(wi) f_r(wi, wo) cos(theta_i) d omega_i, estimated with n
    draws of :func:`sample`; rejected draws count as zero-weight samples.

    Parameters
    ----------
    brdf : BRDF
    wo : array_like, shape (3,)
        Unit vector towards the viewer.
    n : int
    rng : numpy.random.Generator or int or None
    radiance : callable or None
        L_in(wi) for an array of directions (n, 3) -> (n,), in the unit of the result;
        None: L_in = 1, and the result is the albedo at wo (for a reciprocal BRDF).
    kind : {"lobe", "cosine"}

    Returns
    -------
    (estimate, standard error)
    """
    f = _check_brdf(brdf)
    w = _check_wo(wo)
    return _weights(f, strategy(f, float(w[2]), kind), w, _check_n(n), _check_rng(rng), radiance)


def mc_albedo(brdf: BRDF, mu: ArrayLike, n: int, rng: np.random.Generator | int | None = None, *,
              kind: str = "lobe") -> tuple[float, float] | tuple[np.ndarray, np.ndarray]:
    """Monte Carlo estimate of the directional albedo a(mu) and its standard error.

    a(mu) = integral of f_r(wi, wo) cos(theta_o) d omega_o with wi = (sqrt(1 - mu^2), 0, mu)
    (000 eq. 2), estimated with wo drawn by :func:`sample` around wi; no reciprocity is
    assumed.  With L_in = 1 this is the estimator of 000 eq. 24-25 (sec. 4.2: "the
    importance sampling can also be used to ... calculate and tabulate the values of the
    albedo function").

    Parameters
    ----------
    brdf : BRDF
    mu : float or array_like
        cos(theta_i) in (0, 1].
    n : int
        Samples per value of mu.
    rng : numpy.random.Generator or int or None
    kind : {"lobe", "cosine"}

    Returns
    -------
    (estimate, standard error)
        Floats for scalar mu, else arrays of the shape of mu.

    Examples
    --------
    >>> import numpy as np, pumpup
    >>> a, se = pumpup.mc_albedo(pumpup.load({"type": "phong", "n": 20}), 1.0, 100_000, np.random.default_rng(0))
    >>> abs(a - 1.0) < 4 * se
    True
    """
    f = _check_brdf(brdf)
    m = check_mu(mu)
    n = _check_n(n)
    g = _check_rng(rng)
    flat = m.ravel()
    est, se = np.empty_like(flat), np.empty_like(flat)
    t = _SwappedRoles(f)
    for i, x in enumerate(flat):
        w = np.array([math.sqrt((1.0 - x) * (1.0 + x)), 0.0, x])
        est[i], se[i] = _weights(t, strategy(f, x, kind), w, n, g)
    delta = f.delta_albedo
    if delta is not None:
        est += delta(flat)  # a delta lobe (he_torrance's specular part): exact, no variance
    if m.ndim == 0:
        return float(est[0]), float(se[0])
    return est.reshape(m.shape), se.reshape(m.shape)


class _SwappedRoles:
    """f with its arguments swapped, so that sampling around wi integrates over wo."""

    def __init__(self, f: BRDF):
        self.f = f

    def _eval(self, a, b):
        return self.f._eval(b, a)


# ----------------------------------------------------------------------------------------
# exact moments of the estimator (by the albedo engine)
# ----------------------------------------------------------------------------------------


class _MomentIntegrand(BRDF):
    """An integrand h(c, x) whose albedo at c (the engine integrates h cos(theta_x) over x) is a
    moment of the sampling of x around c (x drawn with density p(x | c) of ``strategy``), chosen by ``what``.

    * ``what = "second"``: h = f(c, x)^2 cos(theta_x) / p(x | c), albedo E[w^2] of mc_albedo;
    * ``what = "density"``: h = p(x | c) / cos(theta_x), albedo the acceptance probability.
    """

    type = "sampling-moment"
    params = {}
    constant = None

    def __init__(self, f: BRDF, kind: str, what: str):
        self.p = {}
        self.f, self.kind, self.what = f, kind, what
        self.reciprocal = False

    @property
    def spec(self):  # not a user model: never saved
        return {"type": self.type, "of": self.f.spec, "kind": self.kind, "what": self.what}

    def _eval(self, c, x):
        c, x = np.broadcast_arrays(c, x)
        shape = c.shape[:-1]
        a, b = c.reshape(-1, 3), x.reshape(-1, 3)
        out = np.zeros(a.shape[0])
        fv = self.f._eval(a, b) if self.what == "second" else None
        for m in np.unique(a[:, 2]):  # the engine integrates a few incidence directions at a time
            sel = a[:, 2] == m
            p = strategy(self.f, float(m), self.kind).pdf(b[sel], a[sel])
            z = b[sel, 2]
            with np.errstate(divide="ignore", invalid="ignore"):
                if self.what == "second":
                    out[sel] = np.where(fv[sel] > 0, fv[sel] ** 2 * np.maximum(z, 0) / p, 0.0)
                else:
                    out[sel] = np.where(z > 0, p / np.where(z > 0, z, 1.0), 0.0)
        return out.reshape(shape)

    def lobe(self, mu):
        return self.f.lobe(mu)


def second_moment(brdf: BRDF, mu, *, kind: str = "lobe", rtol: float = 1e-9, return_error: bool = False):
    """E[w^2] of one sample of :func:`mc_albedo`, w = f cos / p, computed by the albedo engine.

    The variance per sample is ``second_moment(f, mu) - albedo(f, mu)**2``; it is infinite
    (returned as inf) where the strategy's density is 0 and f is not.

    Examples
    --------
    >>> import pumpup
    >>> f = pumpup.load({"type": "phong", "n": 10})
    >>> m2 = pumpup.sampling.second_moment(f, 1.0)   # w = (n+2)/(n+1) cos(theta) (000 eq. 24)
    >>> bool(0 < m2 - pumpup.albedo(f, 1.0)**2 < 0.1)
    True
    """
    from .engine.cubature import albedo

    f = _check_brdf(brdf)
    return albedo(_MomentIntegrand(f, kind, "second"), mu, return_error=return_error, rtol=rtol)


def acceptance(brdf: BRDF, mu, *, kind: str = "lobe", rtol: float = 1e-9, return_error: bool = False):
    """Probability that a draw of :func:`sample` around a direction with cos(theta) = mu is
    accepted (not below the horizon): the integral of the density over the hemisphere,
    computed by the albedo engine.

    Examples
    --------
    >>> import pumpup
    >>> f = pumpup.load({"type": "phong", "n": 20})
    >>> round(float(pumpup.sampling.acceptance(f, 1e-9)), 6)   # half the lobe is below the horizon
    0.5
    """
    from .engine.cubature import albedo

    f = _check_brdf(brdf)
    return albedo(_MomentIntegrand(f, kind, "density"), mu, return_error=return_error, rtol=rtol)


# ----------------------------------------------------------------------------------------
# the efficiency study of 000 sec. 4.2
# ----------------------------------------------------------------------------------------

#: the exponents and viewing angles of the stored study (tables/sampling_efficiency.nc)
EFFICIENCY_N = (1.0, 5.0, 20.0, 100.0, 1000.0)
EFFICIENCY_THETA = (0.0, 10.0, 20.0, 30.0, 40.0, 50.0, 60.0, 70.0, 75.0, 80.0, 85.0, 88.0, 89.0, 89.9, 89.99)


def efficiency_dataset(ns=EFFICIENCY_N, theta_deg=EFFICIENCY_THETA, mu_grazing: float = 1e-8, rtol: float = 1e-9):
    """Variance per sample of the Phong-lobe estimator (000 eq. 23-25) for reciprocal Phong and
    stretched Phong, against the viewing angle (000 sec. 4.2), as an xarray.Dataset.

    For each model, exponent n and viewing direction V (cos(theta_V) = mu): the albedo a (the
    estimator's mean, L_in = 1), the second moment E[w^2] of one weight w = f cos / p and the
    acceptance probability, all three by the albedo engine (no sampling); the variance per
    sample E[w^2] - a^2 and the relative variance (variance / a^2: the number of samples
    needed for a relative standard error of 1 is this number).  The last angle is
    mu = ``mu_grazing``, where 000 eq. 26 gives a = (n+2)/(2(n+1)) for the stretched model.
    """
    import xarray as xr

    from ._version import __version__
    from .core import load
    from .engine.cubature import albedo

    mu = np.concatenate([np.cos(np.radians(np.asarray(theta_deg, dtype=np.float64))), [mu_grazing]])
    models = ("phong", "stretched_phong")
    shape = (len(models), len(ns), len(mu))
    out = {k: np.empty(shape) for k in ("albedo", "albedo_error", "second_moment", "second_moment_error",
                                        "acceptance", "acceptance_error")}
    for i, model in enumerate(models):
        for j, n in enumerate(ns):
            f = load({"type": model, "n": float(n)})
            out["albedo"][i, j], out["albedo_error"][i, j] = albedo(f, mu, return_error=True, rtol=rtol)
            out["second_moment"][i, j], out["second_moment_error"][i, j] = second_moment(f, mu, return_error=True,
                                                                                      rtol=rtol)
            out["acceptance"][i, j], out["acceptance_error"][i, j] = acceptance(f, mu, return_error=True, rtol=rtol)
    var = out["second_moment"] - out["albedo"] ** 2
    var_err = out["second_moment_error"] + 2 * out["albedo"] * out["albedo_error"]
    theta = np.degrees(np.arccos(mu))
    dims = ("model", "n", "mu")
    coords = {"model": list(models), "n": ("n", np.asarray(ns, dtype=np.float64), {"long_name": "Phong exponent"}),
              "mu": ("mu", mu, {"long_name": "cos(theta_V), the viewing direction", "units": "1"}),
              "theta": ("mu", theta, {"long_name": "viewing angle theta_V", "units": "degree"})}
    ds = xr.Dataset(
        {
            "albedo": (dims, out["albedo"], {"long_name": "albedo a(V), the estimator's mean (L_in = 1)",
                                             "units": "1"}),
            "albedo_error": (dims, out["albedo_error"], {"long_name": "quadrature error estimate of albedo"}),
            "second_moment": (dims, out["second_moment"], {"long_name": "E[w^2], w = f cos(theta_L) / p(L)"}),
            "second_moment_error": (dims, out["second_moment_error"], {"long_name": "quadrature error of E[w^2]"}),
            "variance": (dims, var, {"long_name": "variance per sample, E[w^2] - a^2"}),
            "variance_error": (dims, var_err, {"long_name": "error bound of variance"}),
            "relative_variance": (dims, var / out["albedo"] ** 2,
                                  {"long_name": "variance / a^2 (samples per unit relative standard error squared)"}),
            "acceptance": (dims, out["acceptance"], {"long_name": "probability that a draw is above the horizon"}),
            "acceptance_error": (dims, out["acceptance_error"], {"long_name": "quadrature error of acceptance"}),
        },
        coords=coords,
        attrs={"pumpup_kind": "pumpup sampling efficiency",
               "title": "Importance sampling efficiency of the Phong lobe (000 sec. 4.2)",
               "method": "pumpup albedo engine on E[w], E[w^2] and the density (no Monte Carlo)", "rtol": rtol,
               "sampler": "000 eq. 19-22: R around V with density (n+1)/(2 pi) cos^n, L = mirror of R",
               "pumpup_version": __version__},
    )
    return ds


def plot_efficiency(ds, path):
    """Relative variance per sample against the viewing angle (000 sec. 4.2), both models."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, (ax, bx) = plt.subplots(1, 2, figsize=(11, 4.5), constrained_layout=True)
    colors = plt.get_cmap("viridis")(np.linspace(0, 0.9, ds.sizes["n"]))
    theta = ds.theta.values
    for j, n in enumerate(ds.n.values):
        for model, style in (("phong", "--"), ("stretched_phong", "-")):
            rv = ds.relative_variance.sel(model=model).values[j]
            ax.semilogy(theta, rv, style, color=colors[j], label=f"{model} n={n:g}")
        ratio = (ds.relative_variance.sel(model="phong").values[j]
                 / ds.relative_variance.sel(model="stretched_phong").values[j])
        bx.plot(theta, ratio, "-o", ms=3, color=colors[j], label=f"n={n:g}")
    ax.set(xlabel="viewing angle theta_V [deg]", ylabel="variance per sample / albedo^2",
           title="Phong-lobe sampling, dashed: Phong, solid: stretched")
    bx.set(xlabel="viewing angle theta_V [deg]", ylabel="relative variance, Phong / stretched Phong",
           title="Phong samples needed per stretched-Phong sample")
    for a in (ax, bx):
        a.grid(alpha=0.3, which="both")
    ax.legend(fontsize=7, ncol=2)
    bx.legend(fontsize=7)
    from .tables import atomic_path

    with atomic_path(path) as tmp:  # (atomically, with the user's permissions)
        fig.savefig(tmp, dpi=90, format=os.path.splitext(os.fspath(path))[1][1:] or "png")
    plt.close(fig)
    return path
