"""Lewis's energy-conserving Phong shader (002 eq. 22) and its normalisation H_s.

H_s(S) = integral over the hemisphere of F_s(S, V') (N.V') d omega' with
F_s = (R_l.V)_+^n (002 eq. 5, sec. 4.1) is the directional albedo of reciprocal Phong
with c = 1 at mu = N.S.  :func:`phong_hs` computes it to about 1e-15 relative (see its
Notes), exactly per call: nothing is tabulated or interpolated.
"""

from __future__ import annotations

import math

import numpy as np
from numba import vectorize

from ..core import BRDF, MAX_EXPONENT, Lobe, Param, load, register

__all__ = ["LewisPhong", "phong_hs"]

# tanh-sinh (double exponential) nodes on [0, pi/2]: step 1/64, |t| <= 4.5
_DE_H = 1.0 / 64.0
_DE_T = 4.5
_DE_CACHE: dict = {}


def _de_nodes():
    """Nodes of tanh-sinh quadrature on [0, L], L = pi/2, as distances from both ends, and weights."""
    if not _DE_CACHE:
        L = 0.5 * math.pi
        t = np.arange(-_DE_T, _DE_T + 0.5 * _DE_H, _DE_H)
        z = 0.5 * math.pi * np.sinh(t)
        with np.errstate(over="ignore"):
            left = L / (1.0 + np.exp(-2.0 * z))  # phi
            right = L / (1.0 + np.exp(2.0 * z))  # pi/2 - phi, without cancellation
            w = _DE_H * 0.5 * L * (0.5 * math.pi * np.cosh(t)) / np.cosh(z) ** 2
        _DE_CACHE.update(left=left, right=right, w=w)
    return _DE_CACHE["left"], _DE_CACHE["right"], _DE_CACHE["w"]


def phong_hs(mu, n: float) -> np.ndarray:
    """H_s(mu) = integral_hemisphere (R.V)_+^n (N.V) d omega_V (002 sec. 4.1, F_s of 002 eq. 5).

    The directional albedo of reciprocal Phong with c = 1; H_s(1) = 2 pi / (n + 2).

    Parameters
    ----------
    mu : array_like, in [0, 1]
        cos(theta_i) = N.S.
    n : float, >= 0
        Phong exponent.

    Returns
    -------
    ndarray
        H_s, same shape as ``mu`` [sr].

    Notes
    -----
    In the frame of the mirror direction R (N.R = mu, s = sqrt(1 - mu^2)), with
    V = u R + sqrt(1 - u^2) (e1 cos(beta) + e2 sin(beta)) and N = mu R + s e1,
    N.V = mu u + s sqrt(1 - u^2) cos(beta).  For u >= s the whole circle is visible; for
    u < s the visible arc is |beta| < beta0 with sin(beta0) sqrt(1 - u^2) s = sqrt(s^2 - u^2)
    and beta0 = pi/2 + atan(mu u / sqrt(s^2 - u^2)).  Integrating beta in closed form and
    substituting u = s sin(phi) gives::

        H_s = pi mu (2 - s^(n+2)) / (n + 2)
              + s^(n+2) [B((n+1)/2, 3/2) + 2 mu K],
        K = integral_0^(pi/2) sin^(n+1)(phi) cos(phi) atan(mu tan(phi)) d phi,

    with B the beta function, B((n+1)/2, 3/2) = 2 integral_0^(pi/2) sin^n cos^2 d phi
    (scipy.special.beta loses up to 1e-10 relative for n ~ 1e5, so this integral is
    computed alongside K).  Both integrands are smooth inside (0, pi/2) and tanh-sinh
    quadrature (577 fixed nodes) integrates them, including the endpoint behaviour phi^(n+2) at 0
    and sharp peaks at pi/2 for large n, to about 1e-15 relative; the tests check H_s
    against adaptive quadrature of the original u-integral to 1e-12.

    Examples
    --------
    >>> import math
    >>> round(float(phong_hs(1.0, 20)) * 22 / (2 * math.pi), 12)
    1.0
    """
    mu = np.clip(np.asarray(mu, dtype=np.float64), 0.0, 1.0)
    n = float(n)
    with np.errstate(divide="ignore"):
        sn2 = np.exp(0.5 * (n + 2.0) * np.log1p(-mu * mu))  # s^(n+2), s = sqrt(1 - mu^2)
    left, right, w = _de_nodes()
    sin_phi = np.where(left < 0.75, np.sin(left), np.cos(right))
    cos_phi = np.where(left < 0.75, np.cos(left), np.sin(right))
    # sin^n = exp(n log sin), with log sin = log1p(-2 sin^2((pi/2 - phi)/2)) near pi/2: cos(eps)^n
    # would lose n * 1e-16 relative for large n
    log_sin = np.where(left < 0.75, np.log(np.sin(left)), np.log1p(-2.0 * np.sin(0.5 * right) ** 2))
    sin_n = np.exp(n * log_sin) if n > 0 else np.ones_like(log_sin)
    base = w * sin_n * sin_phi * cos_phi  # weights times sin^(n+1) cos
    b_fn = 2.0 * float(np.sum(w * sin_n * cos_phi * cos_phi))  # B((n+1)/2, 3/2) = 2 int sin^n cos^2
    flat = mu.reshape(-1)
    k = np.empty_like(flat)
    chunk = max(1, 2**20 // base.size)
    for i in range(0, flat.size, chunk):
        m = flat[i : i + chunk, None]
        k[i : i + chunk] = np.arctan2(m * sin_phi, cos_phi) @ base  # atan(mu tan(phi))
    k = k.reshape(mu.shape)
    return np.pi * mu * (2.0 - sn2) / (n + 2.0) + sn2 * (b_fn + 2.0 * mu * k)


def _hs_at(mu: np.ndarray, n: float) -> np.ndarray:
    """H_s at each mu > 0 of an array (1 elsewhere), evaluated once per distinct value."""
    h = np.ones(mu.shape)
    up = mu > 0
    if np.any(up):
        vals, inv = np.unique(mu[up], return_inverse=True)
        h[up] = phong_hs(vals, n)[inv.reshape(-1)]
    return h


@vectorize(cache=True)
def _kernel(lx, ly, lz, vx, vy, vz, n, k_rho, k_sigma, hs):  # pragma: no cover - compiled
    if lz <= 0.0 or vz <= 0.0:
        return 0.0
    rv = 2.0 * lz * vz - (lx * vx + ly * vy + lz * vz)  # (R_l.V), 000 eq. 9
    fs = rv**n if rv > 0.0 else 0.0  # 002 eq. 5
    return k_rho * ((1.0 - k_sigma) / math.pi + k_sigma * fs / hs)  # 002 eq. 22


def _reference(wi, wo, n, k_rho, k_sigma):
    up = (wi[..., 2] > 0) & (wo[..., 2] > 0)
    lv = wi[..., 0] * wo[..., 0] + wi[..., 1] * wo[..., 1] + wi[..., 2] * wo[..., 2]
    rv = 2.0 * wi[..., 2] * wo[..., 2] - lv  # (R_l.V), 000 eq. 9
    fs = np.where(rv > 0, np.maximum(rv, 0.0) ** n, 0.0)  # 002 eq. 5
    hs = _hs_at(wi[..., 2], n) if k_sigma > 0 else 1.0
    f = k_rho * ((1.0 - k_sigma) / np.pi + k_sigma * fs / hs)  # 002 eq. 22
    return np.where(up, f, 0.0)


@register("lewis_phong")
class LewisPhong(BRDF):
    """Lewis's energy-conserving Phong shader, f_r = k_rho [(1 - k_sigma)/pi + k_sigma F_s / H_s(S)] [1/sr].

    002 eq. 22, with F_s(S, V) = (R_l.V)_+^n (002 eq. 5) and
    H_s(S) = integral over the hemisphere of F_s(S, V') (N.V') d omega' (002 sec. 4.1;
    :func:`phong_hs`).  Its directional albedo is exactly k_rho at every incidence
    angle, but it is **not reciprocal**: H_s depends on S only (002 sec. 5.1).

    Parameters
    ----------
    n : float, >= 0
        Phong exponent of F_s.
    k_rho : float, in [0, 1], default 1
        Directional-hemispherical reflectance (002 eq. 15).
    k_sigma : float, in [0, 1], default 1
        Specular fraction of the reflected power (002 eq. 20).

    Examples
    --------
    >>> import math, pumpup
    >>> f = pumpup.load({"type": "lewis_phong", "n": 20})
    >>> round(float(f.eval([0, 0, 1], [0, 0, 1])) / (22 / (2 * math.pi)), 12)  # 1 / H_s(1)
    1.0
    """

    params = {
        "n": Param(lo=0.0, hi=MAX_EXPONENT, doc="exponent"),
        "k_rho": Param(1.0, lo=0.0, hi=1.0, doc="directional-hemispherical reflectance"),
        "k_sigma": Param(1.0, lo=0.0, hi=1.0, doc="specular fraction"),
    }
    reciprocal = False
    constant = "k_rho"
    examples = [{"n": 20}, {"n": 0}, {"n": 1, "k_rho": 0.8, "k_sigma": 0.5}, {"n": 500, "k_sigma": 0.9}, {"n": 3.5}]
    reference_fn = staticmethod(_reference)

    def hs(self, mu) -> np.ndarray:
        """H_s(mu) of this model's exponent (:func:`phong_hs`)."""
        return phong_hs(mu, self.p["n"])

    def _eval(self, wi: np.ndarray, wo: np.ndarray) -> np.ndarray:
        q = self.p
        mu = np.asarray(wi[..., 2])
        hs = _hs_at(mu, q["n"]) if q["k_sigma"] > 0 else np.ones(mu.shape)
        return _kernel(wi[..., 0], wi[..., 1], wi[..., 2], wo[..., 0], wo[..., 1], wo[..., 2],
                       q["n"], q["k_rho"], q["k_sigma"], hs)

    def albedo_terms(self):
        """The specular term with k_rho = k_sigma = 1, weighted k_rho k_sigma, and a white Lambertian weighted k_rho (1
        - k_sigma); either alone where the other vanishes.
        """
        q = self.p
        if q["k_sigma"] == 1:
            return [(1.0, self)]
        lambert = load({"type": "lambert", "albedo": 1.0})
        if q["k_sigma"] == 0:
            return [(q["k_rho"], lambert)]
        return [(q["k_rho"] * q["k_sigma"], self.with_params(k_rho=1.0, k_sigma=1.0)),
                (q["k_rho"] * (1.0 - q["k_sigma"]), lambert)]

    def azimuth_hint(self):
        """k_rho / H_s(mu) times reciprocal Phong with c = 1 (002 eq. 22), when k_sigma = 1; the
        H_s is the one :meth:`_eval` divides by (:func:`_hs_at`).
        """
        from ..core.hints import AzimuthHint, PowerLobe

        q = self.p
        if q["k_sigma"] != 1:
            return None  # albedo_terms splits off the diffuse part
        return AzimuthHint(PowerLobe(n=q["n"], p=0.0), scale=lambda mu: q["k_rho"] / _hs_at(np.asarray(mu), q["n"]))

    def lobe(self, mu):
        """The Lobe hint: a power lobe of exponent n about the mirror direction for the pure specular term, else no
        knowledge.
        """
        if self.p["k_sigma"] == 1:
            return Lobe(axis="mirror", radial="power", sharpness=self.p["n"])
        return super().lobe(mu)
