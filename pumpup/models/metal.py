"""Metal and plastic BRDFs of Neumann, Neumann and Szirmay-Kalos (000 sec. 5, eq. 27-30).

Both use the stretched Phong lobe cos^n(alpha) / cos(Theta_min) with
cos(alpha) = (R.V)_+ (000 eq. 8, 9) and cos(Theta_min) = max(N.L, N.V), times the
Fresnel reflectance F evaluated at Theta_min (000 eq. 28), a symmetric function of L and
V, so both models are reciprocal.

The models take one scalar refractive index (one wavelength or one colour channel);
:func:`per_channel` builds one BRDF per channel from lists.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np
from numba import vectorize

from ..core import BRDF, MAX_EXPONENT, MAX_INDEX, MIN_INDEX, Lobe, Param, SpecError, load, register
from ..physics.fresnel import FRESNEL_LEVEL_Y0, fresnel_levels  # noqa: F401  (re-exported for the models)
from ..physics.fresnel import conductor_scalar as _fresnel_real
from ..physics.fresnel import fresnel_conductor as fresnel

__all__ = ["Metal", "Plastic", "fresnel", "per_channel"]


# --- Fresnel reflectance -----------------------------------------------------------------


def _phong_c(q):
    return (q["n"] + 2.0) / (2.0 * math.pi)  # 000 eq. 6


def _cos_alpha(wi, wo):
    # 000 eq. 9, summed in the kernel's order
    lv = wi[..., 0] * wo[..., 0] + wi[..., 1] * wo[..., 1] + wi[..., 2] * wo[..., 2]
    return 2.0 * wi[..., 2] * wo[..., 2] - lv


def _up(wi, wo):
    return (wi[..., 2] > 0) & (wo[..., 2] > 0)


# --- metal ----------------------------------------------------------------------------------


@vectorize(cache=True)
def _metal_kernel(lx, ly, lz, vx, vy, vz, n, eta, k, c):  # pragma: no cover - compiled
    if lz <= 0.0 or vz <= 0.0:
        return 0.0
    rv = 2.0 * lz * vz - (lx * vx + ly * vy + lz * vz)  # cos(alpha), 000 eq. 9
    if rv <= 0.0:
        return 0.0
    mx = max(lz, vz)  # cos(Theta_min)
    return c * rv**n / mx * _fresnel_real(mx, eta, k)  # 000 eq. 28


def _metal_reference(wi, wo, n, eta, k, c):
    rv = np.maximum(_cos_alpha(wi, wo), 0.0)
    mx = np.maximum(wi[..., 2], wo[..., 2])
    with np.errstate(divide="ignore", invalid="ignore"):
        f = c * rv**n / mx * fresnel(mx, eta, k)  # 000 eq. 28
    return np.where(_up(wi, wo) & (rv > 0), f, 0.0)


@register("metal")
class Metal(BRDF):
    """Metallic BRDF, f_r = c cos^n(alpha) / cos(Theta_min) F(eta + i k, Theta_min) [1/sr].

    000 eq. 28 (eq. 27 with Theta = Theta_min): cos(alpha) = (R.V)_+,
    cos(Theta_min) = max(N.L, N.V), F the exact unpolarised Fresnel reflectance of
    a conductor (:func:`fresnel`).  Reciprocal.  One wavelength or colour channel per
    model; see :func:`per_channel`.

    Parameters
    ----------
    n : float, >= 0
        Phong exponent.
    eta : float, > 0
        Real part of the complex refractive index at this wavelength.
    k : float, >= 0, default 0
        Extinction coefficient (imaginary part of the index).
    c : float, >= 0, default (n + 2) / (2 pi)
        Scale [1/sr] (000 eq. 6, 28).

    Examples
    --------
    >>> import math, pumpup
    >>> f = pumpup.load({"type": "metal", "n": 100, "eta": 0.2, "k": 3.0})
    >>> F0 = ((0.2 - 1) ** 2 + 9) / ((0.2 + 1) ** 2 + 9)  # Fresnel at normal incidence
    >>> round(float(f.eval([0, 0, 1], [0, 0, 1])) / (102 / (2 * math.pi) * F0), 12)
    1.0
    """

    params = {
        "n": Param(lo=0.0, hi=MAX_EXPONENT, doc="exponent"),
        "eta": Param(lo=MIN_INDEX, hi=MAX_INDEX, doc="refractive index, real part"),
        "k": Param(0.0, lo=0.0, hi=MAX_INDEX, doc="extinction coefficient"),
        "c": Param(_phong_c, lo=0.0, doc="scale [1/sr]"),
    }
    examples = [
        {"n": 20, "eta": 0.2, "k": 3.0},
        {"n": 1, "eta": 1.5},
        {"n": 500, "eta": 1.1, "k": 6.0},
        {"n": 7.5, "eta": 0.6, "k": 0.3, "c": 0.5},
    ]
    kernel = staticmethod(_metal_kernel)
    reference_fn = staticmethod(_metal_reference)

    def lobe(self, mu):
        """The Lobe hint: a power lobe of exponent n about the mirror direction, with the levels N.wo = mu
        and F's kink.
        """
        return Lobe(axis="mirror", radial="power", sharpness=self.p["n"],
                    levels=tuple(sorted({float(mu), *fresnel_levels(self.p["eta"], self.p["k"])})))

    def albedo_breaks(self):
        """F's kink or near-kink, where F(max(mu, N.wo)) turns (:func:`fresnel_levels`)."""
        return fresnel_levels(self.p["eta"], self.p["k"])  # F(max(mu, N.wo)) turns at mu = x0 too

    def fresnel_one(self):
        """000 eq. 28 with F = 1: the stretched Phong lobe with p = 1 (000 eq. 12), or None without an index."""
        if self.p["eta"] is None:
            return None
        return load({"type": "stretched_phong", "n": self.p["n"], "p": 1.0, "c": self.p["c"]})

    def azimuth_hint(self):
        """The azimuth hint: a power lobe with p = 1 times the factor F(max(N.wi, N.wo)) (000 eq. 28)."""
        return _fresnel_hint(self.p["n"], self.p["c"], self.p["eta"], self.p["k"])


def _fresnel_hint(n, c, eta, k):
    """The azimuth hint of c u^n F(eta + i k, Theta_min) / max(N.L, N.V) (000 eq. 28): a power lobe with p = 1 times
    the factor F(max(N.wi, N.wo)).
    """
    from ..core.hints import AzimuthHint, FresnelAtMax, PowerLobe

    return AzimuthHint(PowerLobe(n=n, p=1.0), scale=lambda mu: np.full(np.shape(mu), c),
                       factors=(FresnelAtMax(eta, k),))


# --- plastic --------------------------------------------------------------------------------


@vectorize(cache=True)
def _plastic_kernel(lx, ly, lz, vx, vy, vz, n, ad, a_s, eta):  # pragma: no cover - compiled
    if lz <= 0.0 or vz <= 0.0:
        return 0.0
    f = ad / math.pi
    rv = 2.0 * lz * vz - (lx * vx + ly * vy + lz * vz)  # cos(alpha), 000 eq. 9
    if rv > 0.0:
        mx = max(lz, vz)  # cos(Theta_min)
        fr = _fresnel_real(mx, eta, 0.0) if eta > 0.0 else 1.0  # eta <= 0 stands for "no Fresnel", 000 eq. 30
        f += a_s * (n + 2.0) / (2.0 * math.pi) * rv**n / mx * fr  # 000 eq. 29
    return f


def _plastic_reference(wi, wo, n, ad, a_s, eta):
    rv = np.maximum(_cos_alpha(wi, wo), 0.0)
    mx = np.maximum(wi[..., 2], wo[..., 2])
    fr = fresnel(mx, eta) if eta is not None and eta > 0 else 1.0
    with np.errstate(divide="ignore", invalid="ignore"):
        spec = np.where(rv > 0, a_s * (n + 2.0) / (2.0 * np.pi) * rv**n / mx * fr, 0.0)  # 000 eq. 29, 30
    return np.where(_up(wi, wo), ad / np.pi + spec, 0.0)


#: the largest albedo of plastic's specular lobe with a_s = 1 and F = 1, over all n >= 0 and mu
#: (at n = 0, theta = 45 degrees: 1.0857906, rounded up; see Plastic._validate)
PLASTIC_MAX_S = 1.0858


_MAX_S_CACHE: dict = {}


def _plastic_max_s(n: float, eta) -> float:
    """The max over mu of the albedo of plastic's specular lobe with a_s = 1 (plus its error estimate):
    ``metal`` with k = 0 (the same kernel, 000 eq. 28-29) or stretched Phong without Fresnel.
    """
    key = (float(n), eta)
    if key not in _MAX_S_CACHE:
        from ..core import service

        max_albedo = service("max_albedo")  # pumpup.tables.max_albedo

        lobe = load({"type": "stretched_phong", "n": n, "p": 1.0}) if eta is None else \
            load({"type": "metal", "n": n, "eta": eta, "k": 0.0})
        m = max_albedo(lobe, rtol=1e-9, mu_min=1e-8)
        c = (n + 2.0) / (2.0 * math.pi)  # max_albedo sets the constant to 1
        _MAX_S_CACHE[key] = c * (m.albedo + m.error)
    return _MAX_S_CACHE[key]


@register("plastic")
class Plastic(BRDF):
    """Plastic / ceramic BRDF, a Lambertian base plus the metallic lobe [1/sr].

    f_r = ad / pi + a_s (n + 2) / (2 pi) cos^n(alpha) / cos(Theta_min) F(eta, Theta_min)
    (000 eq. 29), with a real (dielectric) index eta; without eta, F = 1 (000 eq. 30).
    Reciprocal.

    Parameters
    ----------
    n : float, >= 0
        Phong exponent.
    ad : float, in [0, 1], default 0.5
        Albedo of the diffuse component (one channel).
    a_s : float, in [0, 1], default 0.5
        Weight of the specular component; ad + a_s <= 1 (000 sec. 5.2) and ad + a_s max S <= 1,
        S the albedo of the specular lobe with a_s = 1, so that the model conserves energy
        (both checked; the second matters for n < 2, where max S exceeds 1: 1.0858 at n = 0).
    eta : float, > 0, optional
        Real refractive index of the dielectric; omitted means F = 1 (000 eq. 30).

    Examples
    --------
    >>> import math, pumpup
    >>> f = pumpup.load({"type": "plastic", "n": 50, "ad": 0.3, "a_s": 0.6, "eta": 1.5})
    >>> value = 0.3 / math.pi + 0.6 * 52 / (2 * math.pi) * 0.04  # at wi = wo = N
    >>> round(float(f.eval([0, 0, 1], [0, 0, 1])) / value, 12)
    1.0
    """

    params = {
        "n": Param(lo=0.0, hi=MAX_EXPONENT, doc="exponent"),
        "ad": Param(0.5, lo=0.0, hi=1.0, doc="diffuse albedo"),
        "a_s": Param(0.5, lo=0.0, hi=1.0, doc="specular weight"),
        "eta": Param(None, lo=MIN_INDEX, hi=MAX_INDEX, doc="refractive index (omitted: F = 1)"),
    }
    constant = None  # f is not a constant times a fixed shape
    examples = [
        {"n": 20},
        {"n": 100, "ad": 0.3, "a_s": 0.6, "eta": 1.5},
        {"n": 2, "ad": 0.0, "a_s": 1.0, "eta": 1.33},
        {"n": 1000, "ad": 0.8, "a_s": 0.2},
    ]
    kernel = staticmethod(_plastic_kernel)
    reference_fn = staticmethod(_plastic_reference)

    def _validate(self) -> None:
        # energy conservation: the albedo is ad + a_s S(mu), S the albedo of the specular lobe
        # with a_s = 1, so the condition is ad + a_s max_mu S <= 1.  000 sec. 5.2's a_s + ad <= 1
        # is it only where max S = 1: the stretched lobe (n + 2)/(2 pi) cos^n / cos(Theta_min)
        # reflects more than 1 for small n (max S = 1.0858 at n = 0, 45 degrees; 1.0104 at
        # n = 0.5, 1.00028 at n = 1) and exactly 1 at normal incidence for n >= 2 (measured with
        # pumpup.max_albedo, and max S falls with n; tests/models/test_energy_claims.py); F <= 1 only lowers S.
        ad, a_s, n = self.p["ad"], self.p["a_s"], self.p["n"]
        if a_s + ad > 1.0 + 1e-12:  # the model's own constraint (000 sec. 5.2), necessary where F = 1
            raise SpecError(
                f"{self.type}: parameters 'a_s' + 'ad' must not exceed 1 (energy conservation, 000 sec. 5.2); "
                f"got a_s = {a_s:g}, ad = {ad:g}"
            )
        bound = 1.0 if n >= 2.0 else PLASTIC_MAX_S
        if ad + a_s * bound <= 1.0 + 1e-12:
            return
        s_max = _plastic_max_s(n, self.p["eta"])  # the bound fails: compute max S itself (cached)
        if ad + a_s * s_max > 1.0 + 1e-9:
            limit = (1.0 - ad) / s_max
            scale = 10.0 ** (5 - math.floor(math.log10(limit))) if limit > 0.0 else 1.0
            limit = math.floor(limit * scale) / scale  # (6 digits, rounded down: the advice must be followable)
            raise SpecError(
                f"{self.type}: ad + a_s * max S must not exceed 1 (energy conservation; S, the specular lobe's "
                f"albedo, reaches {s_max:.6f} for n = {n:g}): with ad = {ad:g}, 'a_s' must be at most {limit:.6g}; "
                f"got a_s = {a_s:g}"
            )

    def kernel_args(self) -> tuple:
        """(n, ad, a_s, eta) for the compiled kernel, eta 0 without a Fresnel factor."""
        q = self.p
        return (q["n"], q["ad"], q["a_s"], 0.0 if q["eta"] is None else q["eta"])

    def reference(self, wi, wo) -> np.ndarray:
        """The plain numpy f_r of 000 eq. 29-30."""
        q = self.p
        wi = np.asarray(wi, dtype=np.float64)
        wo = np.asarray(wo, dtype=np.float64)
        return _plastic_reference(wi, wo, q["n"], q["ad"], q["a_s"], q["eta"])

    def albedo_terms(self):
        """The specular lobe alone, plus the diffuse base ad times a white Lambertian where ad > 0."""
        if self.p["ad"] == 0:
            return [(1.0, self)]
        return [(1.0, self.with_params(ad=0.0)), (self.p["ad"], load({"type": "lambert", "albedo": 1.0}))]

    def lobe(self, mu):
        """The Lobe hint: a power lobe of exponent n about the mirror direction, with the levels N.wo = mu
        and F's kink.
        """
        return Lobe(axis="mirror", radial="power", sharpness=self.p["n"],
                    levels=tuple(sorted({float(mu), *self.albedo_breaks()})))

    def albedo_breaks(self):
        """The dielectric's kink of F where ``eta`` is given, else none."""
        return () if self.p["eta"] is None else fresnel_levels(self.p["eta"], 0.0)

    def fresnel_one(self):
        """The same plastic with F = 1 (no eta), or None without an index."""
        return None if self.p["eta"] is None else self.with_params(eta=None)

    def azimuth_hint(self):
        """The azimuth hint of the specular lobe (000 eq. 29-30: with F(Theta_min) where ``eta`` is given), or None
        where ad > 0 (the terms are integrated apart).
        """
        q = self.p
        if q["ad"] != 0:
            return None  # the diffuse part is split off by albedo_terms
        from ..core.hints import AzimuthHint, PowerLobe

        c = q["a_s"] * (q["n"] + 2.0) / (2.0 * math.pi)  # 000 eq. 30: stretched Phong's lobe (p = 1) times a_s
        if q["eta"] is not None:
            return _fresnel_hint(q["n"], c, q["eta"], 0.0)  # 000 eq. 29: F(Theta_min) by frame 5's rule on the arc
        return AzimuthHint(PowerLobe(n=q["n"], p=1.0), scale=lambda mu: np.full(np.shape(mu), c))


# --- one model per channel -------------------------------------------------------------------


def per_channel(kind: str, n: Any, eta: Any, k: Any = None, **kw: Any) -> list[BRDF]:
    """One metal or plastic BRDF per wavelength or colour channel.

    Parameters
    ----------
    kind : {"metal", "plastic"}
    n, eta, k : float or list of float
        Exponent, real index and extinction coefficient; a list gives one value per
        channel, a scalar is shared by all channels.  ``k`` must be omitted (or 0) for
        "plastic", whose index is real; ``eta`` may be None for "plastic" (F = 1).
    **kw : float or list of float
        Further parameters of the model (``c`` for metal; ``ad``, ``a_s`` for plastic),
        scalars or per-channel lists.

    Returns
    -------
    list of BRDF
        One model per channel, in order.

    Examples
    --------
    Gold-like RGB values (illustrative round numbers near published data for about
    650, 550 and 450 nm, not measured data):

    >>> from pumpup.models.metal import per_channel
    >>> gold = per_channel("metal", n=200, eta=[0.18, 0.42, 1.37], k=[3.42, 2.35, 1.77])
    >>> [f.p["eta"] for f in gold]
    [0.18, 0.42, 1.37]
    >>> [round(float(fresnel(1.0, f.p["eta"], f.p["k"])), 3) for f in gold]  # F at normal incidence
    [0.945, 0.777, 0.374]
    """
    if kind not in ("metal", "plastic"):
        raise SpecError(f"per_channel: 'kind' must be 'metal' or 'plastic', got {kind!r}")
    args = {"n": n, "eta": eta, **kw}
    if kind == "metal":
        args["k"] = 0.0 if k is None else k
    elif k is not None and np.any(np.asarray(k, dtype=float) != 0):
        raise SpecError("per_channel: parameter 'k' must be omitted or 0 for 'plastic' (a dielectric has a real index)")
    lengths = {name: len(v) for name, v in args.items() if isinstance(v, (list, tuple, np.ndarray))}
    if len(set(lengths.values())) > 1:
        text = ", ".join(f"{name!r} has {m}" for name, m in lengths.items())
        raise SpecError(f"per_channel: the per-channel lists must have equal length; {text}")
    m = next(iter(lengths.values()), 1)
    if m == 0:
        raise SpecError(f"per_channel: empty per-channel list(s) {', '.join(map(repr, lengths))}")
    out = []
    for i in range(m):
        spec: dict[str, Any] = {"type": kind}
        for name, v in args.items():
            val = v[i] if name in lengths else v
            spec[name] = val.item() if isinstance(val, np.generic) else val
        out.append(load(spec))
    return out
