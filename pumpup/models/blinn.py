"""The Blinn family: reciprocal Blinn, stretched Blinn, and Lewis's reciprocal Phong-Blinn.

All lobes are powers of cos(delta) = (N.H), with H = (L + V) / |L + V| the halfway
vector.  With S = L + V (unnormalised; S_z > 0 when both directions are above the
horizon), tan^2 delta = (S_x / S_z)^2 + (S_y / S_z)^2 and (N.H)^n = (1 + tan^2 delta)^(-n/2);
this stays finite (no 0/0) down to the smallest representable N.L and N.V.
"""

from __future__ import annotations

import math

import numpy as np
from numba import vectorize

from ..core import BRDF, MAX_EXPONENT, Lobe, Param, load, register
from ._half import tan2_half


def _cos2_delta(wi, wo):
    """(N.H)^2 = 1 / (1 + tan^2 delta), tan^2 delta = (S_x / S_z)^2 + (S_y / S_z)^2, S = L + V."""
    s = wi + wo
    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
        qx = s[..., 0] / s[..., 2]
        qy = s[..., 1] / s[..., 2]
        return 1.0 / (1.0 + (qx * qx + qy * qy))


def _up(wi, wo):
    return (wi[..., 2] > 0) & (wo[..., 2] > 0)


# --- reciprocal Blinn -----------------------------------------------------------------------


@vectorize(cache=True)
def _blinn_kernel(lx, ly, lz, vx, vy, vz, n, c):  # pragma: no cover - compiled
    if lz <= 0.0 or vz <= 0.0:
        return 0.0
    cos2 = 1.0 / (1.0 + tan2_half(lx, ly, lz, vx, vy, vz))  # (N.H)^2 = 1 / (1 + tan^2 delta)
    return c * cos2 ** (0.5 * n)  # 000 eq. 31: c (N.H)^n


def _blinn_reference(wi, wo, n, c):
    with np.errstate(divide="ignore", invalid="ignore"):
        f = c * _cos2_delta(wi, wo) ** (0.5 * n)  # 000 eq. 31
    return np.where(_up(wi, wo), f, 0.0)


@register("blinn")
class Blinn(BRDF):
    """Reciprocal Blinn, f_r = c (N.H)^n [1/sr] (000 eq. 31; 001 eq. 6).

    Blinn's specular term without the division by (N.L) that made it non-reciprocal
    (Lewis 002).  H = (L + V) / |L + V| is the halfway vector.

    Parameters
    ----------
    n : float, >= 0
        Blinn exponent (dimensionless).
    c : float, >= 0, default 1
        Scale [1/sr].  000 Table 2 lists the largest energy-conserving value C_n
        (0.350 for n = 1, 0.895 for n = 16, 20.6 for n = 512).

    Examples
    --------
    >>> import pumpup
    >>> f = pumpup.load({"type": "blinn", "n": 20, "c": 0.9})
    >>> float(f.eval([0, 0, 1], [0, 0, 1]))  # N.H = 1 at wi = wo = N
    0.9
    """

    params = {
        "n": Param(lo=0.0, hi=MAX_EXPONENT, doc="exponent"),
        "c": Param(1.0, lo=0.0, doc="scale [1/sr]"),
    }
    examples = [{"n": 0}, {"n": 1}, {"n": 20}, {"n": 512, "c": 20.6}, {"n": 10.5, "c": 0.7}]
    kernel = staticmethod(_blinn_kernel)
    reference_fn = staticmethod(_blinn_reference)

    def lobe(self, mu):
        """The Lobe hint: a power lobe of exponent n about the half vector."""
        return Lobe(axis="half", radial="power", sharpness=self.p["n"])

    def azimuth_hint(self):
        """The azimuth hint: the half vector's power lobe c (N.H)^n, closed-form in the azimuth (000 eq. 31)."""
        return _half_hint(self.p["n"], 0.0, self.p["c"])  # 000 eq. 31


def _half_hint(n, p, c):
    """The azimuth hint of a lobe c (N.H)^n / max(N.L, N.V)^p, p in {0, 1} (000 eq. 31, 32): the half vector's
    azimuth about N integrates in closed form.
    """
    from ..core.hints import AzimuthHint, HalfVectorLobe

    return AzimuthHint(HalfVectorLobe(n=n, p=float(p)), scale=lambda mu: np.full(np.shape(mu), c))


# --- stretched Blinn ------------------------------------------------------------------------


@vectorize(cache=True)
def _stretched_kernel(lx, ly, lz, vx, vy, vz, n, c):  # pragma: no cover - compiled
    if lz <= 0.0 or vz <= 0.0:
        return 0.0
    cos2 = 1.0 / (1.0 + tan2_half(lx, ly, lz, vx, vy, vz))  # (N.H)^2 = 1 / (1 + tan^2 delta)
    return c * cos2 ** (0.5 * n) / max(lz, vz)  # 000 eq. 32


def _stretched_reference(wi, wo, n, c):
    mx = np.maximum(wi[..., 2], wo[..., 2])
    with np.errstate(divide="ignore", invalid="ignore"):
        f = c * _cos2_delta(wi, wo) ** (0.5 * n) / mx  # 000 eq. 32
    return np.where(_up(wi, wo), f, 0.0)


@register("stretched_blinn")
class StretchedBlinn(BRDF):
    """Stretched Blinn, f_r = c (N.H)^n / max(N.L, N.V) [1/sr] (000 eq. 32).

    The Blinn model corrected like the stretched Phong model (000 sec. 6.1), so that
    it does not darken towards grazing angles as fast.

    Parameters
    ----------
    n : float, >= 0
        Blinn exponent (dimensionless).
    c : float, >= 0, default 1
        Scale [1/sr]; the largest energy-conserving values are in 000 Table 2
        (column "Blinn / cos Theta_min": 0.293 for n = 1, 0.895 for n = 16).

    Examples
    --------
    >>> import pumpup
    >>> f = pumpup.load({"type": "stretched_blinn", "n": 20})
    >>> mu = 0.5  # mirror direction at 60 degrees: H = N, f = c / mu
    >>> wi = [3**0.5 / 2, 0, mu]; wo = [-3**0.5 / 2, 0, mu]
    >>> round(float(f.eval(wi, wo)), 12)
    2.0
    """

    params = {
        "n": Param(lo=0.0, hi=MAX_EXPONENT, doc="exponent"),
        "c": Param(1.0, lo=0.0, doc="scale [1/sr]"),
    }
    examples = [{"n": 1, "c": 0.293}, {"n": 20}, {"n": 128, "c": 5.34}, {"n": 0}]
    kernel = staticmethod(_stretched_kernel)
    reference_fn = staticmethod(_stretched_reference)

    def lobe(self, mu):
        """The Lobe hint: a power lobe of exponent n about the half vector, with max(N.L, N.V)'s kink at N.wo = mu."""
        return Lobe(axis="half", radial="power", sharpness=self.p["n"], levels=(mu,))

    def azimuth_hint(self):
        """The azimuth hint: the half vector's power lobe divided by max(N.L, N.V), p = 1 (000 eq. 32)."""
        return _half_hint(self.p["n"], 1.0, self.p["c"])  # 000 eq. 32


# --- Lewis's reciprocal Phong-Blinn ----------------------------------------------------------


@vectorize(cache=True)
def _phong_blinn_kernel(lx, ly, lz, vx, vy, vz, n, ks, kd):  # pragma: no cover - compiled
    if lz <= 0.0 or vz <= 0.0:
        return 0.0
    cos2 = 1.0 / (1.0 + tan2_half(lx, ly, lz, vx, vy, vz))  # (N.H)^2 = 1 / (1 + tan^2 delta)
    return kd + ks * cos2 ** (0.5 * n)  # 002 eq. 24 with F_s^B of 002 eq. 6


def _phong_blinn_reference(wi, wo, n, ks, kd):
    with np.errstate(divide="ignore", invalid="ignore"):
        f = kd + ks * _cos2_delta(wi, wo) ** (0.5 * n)  # 002 eq. 24, 6
    return np.where(_up(wi, wo), f, 0.0)


@register("phong_blinn")
class PhongBlinn(BRDF):
    """Lewis's reciprocal Phong-Blinn shader, f_r = k_d + k_s (N.H)^n [1/sr] (002 eq. 24).

    Phong's shading formula (002 eq. 8) with Blinn's specular term F_s^B = (N.H)^n
    (002 eq. 6) and without the division by (N.S), which makes it reciprocal; its
    albedo is bounded, so k_s and k_d can be limited to conserve energy (002 sec. 6).

    Parameters
    ----------
    n : float, >= 0
        Blinn exponent (dimensionless).
    ks : float, >= 0, default 1
        Specular coefficient [1/sr].
    kd : float, in [0, 1/pi], default 0
        Diffuse coefficient [1/sr] (already divided by pi: the diffuse albedo is pi k_d).

    Examples
    --------
    >>> import pumpup
    >>> f = pumpup.load({"type": "phong_blinn", "n": 10, "ks": 0.5, "kd": 0.1})
    >>> round(float(f.eval([0, 0, 1], [0, 0, 1])), 12)
    0.6
    """

    params = {
        "n": Param(lo=0.0, hi=MAX_EXPONENT, doc="exponent"),
        "ks": Param(1.0, lo=0.0, doc="specular coefficient [1/sr]"),
        "kd": Param(0.0, lo=0.0, hi=1.0 / math.pi, doc="diffuse coefficient [1/sr]"),
    }
    constant = "ks"
    examples = [{"n": 20}, {"n": 5, "ks": 0.5, "kd": 0.1}, {"n": 0, "ks": 0.1, "kd": 0.2}]
    kernel = staticmethod(_phong_blinn_kernel)
    reference_fn = staticmethod(_phong_blinn_reference)

    def albedo_terms(self):
        """The specular lobe alone, plus the diffuse term pi k_d times a white Lambertian where k_d > 0."""
        if self.p["kd"] == 0:
            return [(1.0, self)]
        return [(1.0, self.with_params(kd=0.0)), (math.pi * self.p["kd"], load({"type": "lambert", "albedo": 1.0}))]

    def lobe(self, mu):
        """The Lobe hint: a power lobe of exponent n about the half vector."""
        return Lobe(axis="half", radial="power", sharpness=self.p["n"])

    def azimuth_hint(self):
        """The azimuth hint of the specular lobe k_s (N.H)^n (002 eq. 24), or None where k_d > 0 (the terms are
        integrated apart).
        """
        if self.p["kd"] != 0:
            return None  # albedo_terms splits off the diffuse part
        return _half_hint(self.p["n"], 0.0, self.p["ks"])  # 002 eq. 24
