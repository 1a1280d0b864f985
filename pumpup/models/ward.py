"""The Ward family: isotropic Ward, anisotropic Ward, and the modified Ward model.

delta is the angle between N and the halfway vector H = (L + V) / |L + V|.  With the
unnormalised S = L + V (S_z > 0 above the horizon), tan^2 delta = (S_x / S_z)^2 + (S_y / S_z)^2,
and the anisotropic terms are tan^2 delta cos^2 phi_h = (h_x / h_z)^2 = (S_x / S_z)^2 (likewise
for y); this avoids the cancellation in 1 - (N.H)^2 near the highlight.  sqrt(N.L) sqrt(N.V)
stands for sqrt((N.L)(N.V)) so that the product cannot underflow.
"""

from __future__ import annotations

import math

import numpy as np
from numba import vectorize

from ..core import BRDF, MAX_WIDTH, MIN_WIDTH, Lobe, Param, SpecError, register
from ._half import tan2_half


def _tan2_delta(wi, wo):
    """tan^2 delta = (S_x / S_z)^2 + (S_y / S_z)^2 with S = L + V."""
    s = wi + wo
    qx = s[..., 0] / s[..., 2]
    qy = s[..., 1] / s[..., 2]
    return qx * qx + qy * qy


def _up(wi, wo):
    return (wi[..., 2] > 0) & (wo[..., 2] > 0)


# --- isotropic Ward -------------------------------------------------------------------------


@vectorize(cache=True)
def _ward_kernel(lx, ly, lz, vx, vy, vz, m, c):  # pragma: no cover - compiled
    if lz <= 0.0 or vz <= 0.0:
        return 0.0
    t2 = tan2_half(lx, ly, lz, vx, vy, vz)  # tan^2 delta
    den = 4.0 * math.pi * m * m * (math.sqrt(lz) * math.sqrt(vz))
    return c * math.exp(-t2 / (m * m)) / den  # 000 eq. 34, 001 eq. 8


def _ward_reference(wi, wo, m, c):
    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
        t2 = _tan2_delta(wi, wo)
        den = 4.0 * np.pi * m * m * (np.sqrt(wi[..., 2]) * np.sqrt(wo[..., 2]))
        f = c * np.exp(-t2 / (m * m)) / den  # 000 eq. 34, 001 eq. 8
    return np.where(_up(wi, wo), f, 0.0)


@register("ward")
class Ward(BRDF):
    """Isotropic Ward, f_r = c exp(-tan^2 delta / m^2) / (4 pi m^2 sqrt((N.L)(N.V))) [1/sr].

    000 eq. 34 (with C_max = c) and 001 eq. 8; delta = arccos(N.H).  Its albedo
    diverges at grazing incidence (001 sec. 2.1), so it is not physically plausible.

    Parameters
    ----------
    m : float, in (0, inf)
        RMS surface slope (dimensionless).
    c : float, >= 0, default 1
        Scale (dimensionless); Ward's value is 1, energy conserving below 89 degrees
        for m < 0.2 (000 sec. 6.2).

    Examples
    --------
    >>> import math, pumpup
    >>> f = pumpup.load({"type": "ward", "m": 0.1})
    >>> round(float(f.eval([0, 0, 1], [0, 0, 1])) * 4 * math.pi * 0.1**2, 12)
    1.0
    """

    params = {
        "m": Param(lo=MIN_WIDTH, hi=MAX_WIDTH, doc="RMS slope"),
        "c": Param(1.0, lo=0.0, doc="scale"),
    }
    examples = [{"m": 0.1}, {"m": 0.2}, {"m": 0.02}, {"m": 0.4, "c": 0.6}]
    kernel = staticmethod(_ward_kernel)
    reference_fn = staticmethod(_ward_reference)

    def lobe(self, mu):
        """The Lobe hint: a Beckmann lobe of slope m about the half vector."""
        return Lobe(axis="half", radial="beckmann", sharpness=self.p["m"])

    def azimuth_hint(self):
        """The azimuth hint: Ward's lobe, the half vector's azimuth by complete elliptic integrals (000 eq. 34)."""
        from ..core.hints import AzimuthHint, WardLobe

        m, c = self.p["m"], self.p["c"]
        # 000 eq. 34: c / (4 pi m^2 sqrt(mu)) times exp(-tan^2(alpha) / m^2) / sqrt(N.wo); the half vector's azimuth
        # by complete elliptic integrals (pumpup.engine.half_frames._k_ward), the Beckmann weight in
        # t = tan^2(alpha) / m^2
        return AzimuthHint(WardLobe(m=m), scale=lambda mu: c / (4.0 * math.pi * m * m * np.sqrt(mu)))


# --- anisotropic Ward -----------------------------------------------------------------------


@vectorize(cache=True)
def _aniso_kernel(lx, ly, lz, vx, vy, vz, ax, ay, c):  # pragma: no cover - compiled
    if lz <= 0.0 or vz <= 0.0:
        return 0.0
    sz = lz + vz
    qx = (lx + vx) / sz  # h_x / h_z: tan^2 delta cos^2 phi_h = qx^2
    qy = (ly + vy) / sz  # h_y / h_z: tan^2 delta sin^2 phi_h = qy^2
    e = (qx / ax) ** 2 + (qy / ay) ** 2
    den = 4.0 * math.pi * ax * ay * (math.sqrt(lz) * math.sqrt(vz))
    return c * math.exp(-e) / den  # Ward 1992 anisotropic (isotropic case: 000 eq. 34)


def _aniso_reference(wi, wo, ax, ay, c):
    s = wi + wo
    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
        qx = s[..., 0] / s[..., 2]
        qy = s[..., 1] / s[..., 2]
        e = (qx / ax) ** 2 + (qy / ay) ** 2
        den = 4.0 * np.pi * ax * ay * (np.sqrt(wi[..., 2]) * np.sqrt(wo[..., 2]))
        f = c * np.exp(-e) / den  # Ward 1992 anisotropic (isotropic case: 000 eq. 34)
    return np.where(_up(wi, wo), f, 0.0)


def _y_axis(mu, s, cos_a, sin_a):
    """The half-vector azimuth beta = pi/2 (the tangent y axis) as a breakpoint: 0 + 1 cos(beta) = 0."""
    return [(0.0, 1.0)]


@register("ward_aniso")
class WardAniso(BRDF):
    """Anisotropic Ward [1/sr] (Ward 1992; the isotropic case is 000 eq. 34).

    f_r = c exp(-tan^2 delta (cos^2 phi_h / a_x^2 + sin^2 phi_h / a_y^2))
    / (4 pi a_x a_y sqrt((N.L)(N.V))), with phi_h the azimuth of H measured from the
    tangent x axis; tan^2 delta cos^2 phi_h = (h_x / h_z)^2 and
    tan^2 delta sin^2 phi_h = (h_y / h_z)^2.  ax = ay = m gives ``ward``.

    Parameters
    ----------
    ax, ay : float, in (0, inf)
        RMS slopes along the tangent x and y axes (dimensionless).
    c : float, >= 0, default 1
        Scale (dimensionless).

    Examples
    --------
    >>> import math, pumpup
    >>> f = pumpup.load({"type": "ward_aniso", "ax": 0.1, "ay": 0.3})
    >>> round(float(f.eval([0, 0, 1], [0, 0, 1])) * 4 * math.pi * 0.1 * 0.3, 12)
    1.0
    """

    params = {
        "ax": Param(lo=MIN_WIDTH, hi=MAX_WIDTH, doc="RMS slope along x"),
        "ay": Param(lo=MIN_WIDTH, hi=MAX_WIDTH, doc="RMS slope along y"),
        "c": Param(1.0, lo=0.0, doc="scale"),
    }
    examples = [{"ax": 0.1, "ay": 0.3}, {"ax": 0.05, "ay": 0.05}, {"ax": 0.4, "ay": 0.02, "c": 0.8}]
    kernel = staticmethod(_aniso_kernel)
    reference_fn = staticmethod(_aniso_reference)

    #: the largest ratio max(ax, ay) / min(ax, ay) where the albedo is accurate: at 1e3 the values at
    #: mu = 1 agree over every azimuth of wi to 3e-13; at 1e4 (ax = 1e-6, ay = 1e-2) they differed by
    #: 6e-5 with error estimates of 5e-11 (the narrow ridge is unresolved across its width)
    MAX_RATIO = 1e3

    def _validate(self) -> None:
        ax, ay = self.p["ax"], self.p["ay"]
        if max(ax, ay) > self.MAX_RATIO * min(ax, ay):
            wide, narrow = ("ax", "ay") if ax > ay else ("ay", "ax")
            raise SpecError(
                f"{self.type}: parameters {wide!r} / {narrow!r} = {max(ax, ay) / min(ax, ay):g} exceeds "
                f"{self.MAX_RATIO:g}, the anisotropy where pumpup's albedo is accurate; "
                f"keep {wide!r} in [{min(ax, ay):g}, {self.MAX_RATIO * min(ax, ay):g}]"
            )

    def lobe(self, mu):
        """The Lobe hint: a Beckmann lobe about the half vector with the wider slope max(ax, ay), the y axis cut when
        anisotropic.
        """
        # the wider of the two slopes: in x = exp(-tan^2 delta / m^2) the integrand behaves as
        # x^(p - 1), p = m^2 (cos^2 phi_h / ax^2 + sin^2 phi_h / ay^2), times a bounded factor;
        # m = max(ax, ay) makes p >= 1 in every azimuth, so it is bounded.  The narrower slope
        # (the old hint) gave p < 1 across the wide axis: a singularity at x = 0 that the
        # cubature could not see (ax = 0.05, ay = 0.5 at mu = 0.9 came out 6.7e-4 low with
        # an error estimate of 6e-11) or could not integrate at all (ax = 0.4, ay = 0.02: inf)
        # The azimuth beta of h is cut at the y axis (beta = pi/2; the x axis is at the ends 0, pi): a
        # lobe narrow across x is a ridge along y (ax = 1e-6, ay = 1e-3 gave 0.617 +- 2e-11 instead
        # of 0.99999850 at mu = 1 without the cut)
        return Lobe(axis="half", radial="beckmann", sharpness=max(self.p["ax"], self.p["ay"]), symmetric=True,
                    kinks=None if self.p["ax"] == self.p["ay"] else _y_axis)

    def azimuth_range(self):
        """None when isotropic (ax = ay), else pi / 2 (the albedo is even in x and in y)."""
        # f is even in the x and y components of L + V: a(phi) = a(-phi) = a(pi - phi)
        return None if self.p["ax"] == self.p["ay"] else math.pi / 2

    def slope_hint(self):
        """(a_x, a_y, c) for the albedo in slope space (:mod:`pumpup.engine.slope`: one ray integral per direction)."""
        return self.p["ax"], self.p["ay"], self.p["c"]

    def sampling_lobe(self, mu):
        """The sampling hint: a Beckmann lobe with the wider slope, so that the weights f cos / p stay bounded."""
        # the wider of the two slopes: a Beckmann density with the narrower one falls off faster
        # than f across the wide axis, and the weights f cos / p would be unbounded
        return Lobe(axis="half", radial="beckmann", sharpness=max(self.p["ax"], self.p["ay"]), symmetric=True)


# --- modified Ward --------------------------------------------------------------------------


@vectorize(cache=True)
def _modified_kernel(lx, ly, lz, vx, vy, vz, m, c):  # pragma: no cover - compiled
    if lz <= 0.0 or vz <= 0.0:
        return 0.0
    t2 = tan2_half(lx, ly, lz, vx, vy, vz)  # tan^2 delta
    return c * math.exp(-t2 / (m * m)) / (4.0 * math.pi * m * m * max(lz, vz))  # 000 eq. 35


def _modified_reference(wi, wo, m, c):
    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
        t2 = _tan2_delta(wi, wo)
        mx = np.maximum(wi[..., 2], wo[..., 2])
        f = c * np.exp(-t2 / (m * m)) / (4.0 * np.pi * m * m * mx)  # 000 eq. 35
    return np.where(_up(wi, wo), f, 0.0)


@register("modified_ward")
class ModifiedWard(BRDF):
    """Modified Ward, f_r = c exp(-tan^2 delta / m^2) / (4 pi m^2 max(N.L, N.V)) [1/sr].

    000 eq. 35: the isotropic Ward model with max(N.L, N.V) in place of
    sqrt((N.L)(N.V)), which bounds its albedo at grazing angles.

    Parameters
    ----------
    m : float, in (0, inf)
        RMS surface slope (dimensionless).
    c : float, >= 0, default 1
        Scale (dimensionless); 000 Table 4 gives the largest energy-conserving values
        (1.63 for m = 0.4, 1.04 for m = 0.1, about 1 for m < 0.05).

    Examples
    --------
    >>> import math, pumpup
    >>> f = pumpup.load({"type": "modified_ward", "m": 0.1})
    >>> mu = 0.5  # mirror direction at 60 degrees: H = N, f = c / (4 pi m^2 mu)
    >>> wi = [3**0.5 / 2, 0, mu]; wo = [-3**0.5 / 2, 0, mu]
    >>> round(float(f.eval(wi, wo)) * 4 * math.pi * 0.1**2 * mu, 12)
    1.0
    """

    params = {
        "m": Param(lo=MIN_WIDTH, hi=MAX_WIDTH, doc="RMS slope"),
        "c": Param(1.0, lo=0.0, doc="scale"),
    }
    examples = [{"m": 0.1}, {"m": 0.2, "c": 1.16}, {"m": 0.02}, {"m": 0.4, "c": 1.63}]
    kernel = staticmethod(_modified_kernel)
    reference_fn = staticmethod(_modified_reference)

    def lobe(self, mu):
        """The Lobe hint: a Beckmann lobe of slope m about the half vector, with max(N.L, N.V)'s kink at N.wo = mu."""
        return Lobe(axis="half", radial="beckmann", sharpness=self.p["m"], levels=(mu,))

    def azimuth_hint(self):
        """The azimuth hint: a Beckmann half-vector lobe divided by max(N.L, N.V), closed-form in the azimuth (000 eq.
        35).
        """
        from ..core.hints import AzimuthHint, HalfVectorLobe

        m, c = self.p["m"], self.p["c"]
        # 000 eq. 35: c / (4 pi m^2) times exp(-tan^2(alpha) / m^2) / max(N.L, N.V), the half vector's azimuth
        # in closed form (stretched Blinn's, p = 1) and the Beckmann weight in t = tan^2(alpha) / m^2
        return AzimuthHint(HalfVectorLobe(n=m, p=1.0, radial="beckmann"),
                           scale=lambda mu: np.full(np.shape(mu), c / (4.0 * math.pi * m * m)))
