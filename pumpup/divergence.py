"""Divergence analysis of the albedo at grazing incidence (001 sec. 2.1, 000 sec. 6.2).

:func:`divergence` tabulates a(mu) from normal incidence down to mu = 1e-8 (logarithmic in
mu near grazing), fits the law a(mu) ~ K mu^(-k) on the grazing end and gives a verdict:
bounded (k consistent with 0) or diverging with exponent k.

:func:`ward_bound` and :func:`cook_torrance_bound` make the lower bounds of 001 eq. 11-15
concrete: for a cap of half-vectors delta <= delta0 around N, the constant kappa of eq. 11
and the region of viewing directions V whose half-vector lies in the cap (001 Fig. 2),
integrated in the half-vector parametrisation (d omega_V = 4 (V.H) d omega_H, with the
visible arc of the azimuth in closed form).
"""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass

import numpy as np

from .core import BRDF, load
from .engine.cubature import albedo

__all__ = ["divergence", "DivergenceResult", "ward_bound", "cook_torrance_bound", "analysis_dataset", "MODELS"]

#: the models of the analysis (issue: Ward and Cook-Torrance m = 0.05 ... 0.4, and for contrast
#: modified Ward, stretched Phong, stretched Blinn and Schlick)
MODELS = {
    **{f"ward m={m}": {"type": "ward", "m": m} for m in (0.05, 0.1, 0.2, 0.4)},
    **{f"cook_torrance m={m}": {"type": "cook_torrance", "m": m} for m in (0.05, 0.1, 0.2, 0.4)},
    "modified_ward m=0.1": {"type": "modified_ward", "m": 0.1},
    "stretched_phong n=20": {"type": "stretched_phong", "n": 20},
    "stretched_blinn n=20": {"type": "stretched_blinn", "n": 20},
    "schlick r=0.1": {"type": "schlick", "r": 0.1},
}


def grid(mu_min: float = 1e-8, per_decade: int = 4) -> np.ndarray:
    """Values of mu uniform in theta from 0 to 84 degrees, then logarithmic from 0.1 down to mu_min."""
    far = np.cos(np.radians(np.linspace(0.0, 84.0, 15)))
    near = np.logspace(-1, math.log10(mu_min), int(round(per_decade * math.log10(0.1 / mu_min))) + 1)
    return np.unique(np.concatenate([far, near]))[::-1]


@dataclass
class DivergenceResult:
    """The grazing-end fit a(mu) ~ K mu^(-k) of one BRDF."""

    k: float  #: the exponent (0 for a bounded albedo)
    k_error: float  #: its uncertainty (statistical and systematic: the spread between sub-windows)
    K: float
    verdict: str  #: "bounded" or "diverging"
    limit: float  #: for a bounded albedo, its value at the smallest mu (nan when diverging)
    mu: np.ndarray
    albedo: np.ndarray
    albedo_error: np.ndarray

    def __str__(self) -> str:
        if self.verdict == "bounded":
            return f"bounded: k = {self.k:.3g} +- {self.k_error:.2g}, a({self.mu[-1]:.1e}) = {self.limit:.8g}"
        return f"diverging: a ~ {self.K:.4g} mu^(-{self.k:.4f} +- {self.k_error:.2g})"


def fit_power_law(mu, a, err, window: tuple[float, float] = (1e-8, 1e-5)):
    """Least-squares fit of log a = log K - k log mu over ``window``; returns (k, k_error, K).

    The uncertainty is the larger of the fit's standard error (with the albedo errors as
    weights) and half the spread of k between the two halves of the window.
    """
    sel = (mu >= window[0] * (1 - 1e-12)) & (mu <= window[1] * (1 + 1e-12)) & (a > 0)
    x, y = np.log(mu[sel]), np.log(a[sel])
    if len(x) < 4:
        raise ValueError("the fit window needs at least 4 values of mu")
    A = np.stack([np.ones_like(x), x], axis=-1)
    coef, res, *_ = np.linalg.lstsq(A, y, rcond=None)
    resid = y - A @ coef
    dof = max(1, len(x) - 2)
    cov = np.linalg.inv(A.T @ A) * max(float(resid @ resid) / dof, (np.max(err[sel] / a[sel])) ** 2)
    half = len(x) // 2
    slopes = [np.polyfit(x[:half + 1], y[:half + 1], 1)[0], np.polyfit(x[half:], y[half:], 1)[0]]
    k = -coef[1]
    k_err = max(math.sqrt(cov[1, 1]), abs(slopes[0] - slopes[1]) / 2)
    return float(k), float(k_err), float(math.exp(coef[0]))


def divergence(brdf: BRDF | dict, mu_min: float = 1e-8, window: tuple[float, float] = (1e-8, 1e-5),
               threshold: float = 0.02) -> DivergenceResult:
    """Tabulate a(mu) down to ``mu_min`` and fit a ~ K mu^(-k) on the grazing end.

    Verdict: "diverging" when k exceeds both ``threshold`` and 3 times its uncertainty,
    else "bounded" (with the albedo at the smallest mu as the limit estimate).

    Examples
    --------
    >>> import pumpup
    >>> r = pumpup.divergence({"type": "ward", "m": 0.1})
    >>> r.verdict, round(r.k, 2)
    ('diverging', 0.5)
    """
    f = load(brdf)
    mu = grid(mu_min)
    a, e = albedo(f, mu, return_error=True, rtol=1e-9)
    k, k_err, K = fit_power_law(mu, a, e, window)
    diverging = k > threshold and k > 3 * k_err
    return DivergenceResult(k=k, k_error=k_err, K=K, verdict="diverging" if diverging else "bounded",
                            limit=float("nan") if diverging else float(a[-1]), mu=mu, albedo=a, albedo_error=e)


# --------------------------------------------------------------------------------------------
# The lower bounds of 001 eq. 11-15, made concrete
# --------------------------------------------------------------------------------------------


@functools.lru_cache(maxsize=8)
def _gauss_legendre(n: int) -> tuple[np.ndarray, np.ndarray]:
    """The n-point Gauss-Legendre rule of numpy on [-1, 1], built once per n (read-only arrays)."""
    x, w = np.polynomial.legendre.leggauss(n)
    x.flags.writeable = False
    w.flags.writeable = False
    return x, w


def _cap_integral(mu: float, delta0: float, weight, phi_limits, n: int = 96) -> float:
    """Integral over half-vectors H in the cap delta <= delta0 of weight(delta, cos phi) * 4 (L.H) d omega_H,
    over the arc of phi given by ``phi_limits(delta) -> (lo, hi)`` (in [0, pi], doubled by symmetry).

    Gauss-Legendre in delta and in phi (the integrand is smooth inside the limits).
    """
    s = math.sqrt((1 - mu) * (1 + mu))
    xd, wd = _gauss_legendre(n)
    d = 0.5 * delta0 * (xd + 1)
    wdd = 0.5 * delta0 * wd
    total = 0.0
    xp, wp = xd, wd
    for dk, wk in zip(d, wdd):
        lo, hi = phi_limits(dk)
        if hi <= lo:
            continue
        ph = lo + 0.5 * (hi - lo) * (xp + 1)
        wph = 0.5 * (hi - lo) * wp
        lh = s * math.sin(dk) * np.cos(ph) + mu * math.cos(dk)  # L.H
        total += 2 * wk * math.sin(dk) * float(np.sum(wph * 4 * lh * weight(dk, np.cos(ph))))
    return total


def _visible(mu: float, d: float) -> tuple[float, float]:
    """The phi range [0, phi0] where V = 2 (L.H) H - L is above the horizon: N.V = s sin 2d cos phi + mu cos 2d."""
    s = math.sqrt((1 - mu) * (1 + mu))
    b = s * math.sin(2 * d)
    a = mu * math.cos(2 * d)
    if b <= 0:
        return (0.0, math.pi if a > 0 else 0.0)
    return (0.0, math.acos(min(1.0, max(-1.0, -a / b))))


def ward_bound(m: float, mu: float, delta0: float | None = None) -> tuple[float, float]:
    """Lower bound of the Ward albedo (001 eq. 14), with kappa_Ward of eq. 11.

    a(L) >= kappa / sqrt(N.L) * integral over the critical region of sqrt(N.V) d omega_V,
    kappa = exp(-tan^2 delta0 / m^2) / (4 pi m^2), the region being all V whose half-vector
    lies in the cap delta <= delta0 (and V above the horizon).  ``delta0`` defaults to
    the value that maximises the bound.  Returns (bound, delta0).
    """
    def bound(d0):
        kappa = math.exp(-math.tan(d0) ** 2 / m**2) / (4 * math.pi * m * m)  # 001 eq. 11
        s = math.sqrt((1 - mu) * (1 + mu))

        def w(d, cph):
            nv = np.maximum(s * math.sin(2 * d) * cph + mu * math.cos(2 * d), 0.0)
            return np.sqrt(nv)

        return kappa / math.sqrt(mu) * _cap_integral(mu, d0, w, lambda d: _visible(mu, d))  # 001 eq. 14

    if delta0 is None:
        from scipy.optimize import minimize_scalar

        r = minimize_scalar(lambda d: -bound(d), bounds=(1e-4, min(1.2, 6 * m)), method="bounded",
                            options={"xatol": 1e-6})
        delta0 = float(r.x)
    return bound(delta0), delta0


def cook_torrance_bound(m: float, mu: float, delta0: float | None = None) -> tuple[float, float, float]:
    """The Cook-Torrance bound of 001 eq. 15 where its assumption holds.

    a(L) >= kappa_Cook / (N.L) * |region|, kappa_Cook the minimum of
    exp(-tan^2 d/m^2) / (4 pi m^2 cos^4 d) over the cap (001 eq. 11), the region being the V
    whose half-vector lies in the cap *and* where G = 1 (001 eq. 12): 2 (N.H)(N.V) >= V.H and
    2 (N.H)(N.L) >= V.H, both linear in cos(phi).  Returns (bound, delta0, |region|).
    """
    s = math.sqrt((1 - mu) * (1 + mu))

    def limits(d):
        lo, hi = _visible(mu, d)
        ch, sh = math.cos(d), math.sin(d)
        # L.H = s sh cos(phi) + mu ch (= V.H); N.V = s sin 2d cos(phi) + mu cos 2d
        # 2 ch N.V >= L.H  <=>  cos(phi) (2 ch s sin2d - s sh) >= mu ch - 2 ch mu cos2d
        # 2 ch mu  >= L.H  <=>  cos(phi) s sh <= 2 ch mu - mu ch = mu ch
        c_hi = mu * ch / (s * sh) if s * sh > 0 else math.inf  # cos(phi) <= c_hi
        bcoef = 2 * ch * s * math.sin(2 * d) - s * sh
        acoef = mu * ch - 2 * ch * mu * math.cos(2 * d)
        lo_c, hi_c = -1.0, min(1.0, c_hi)
        if bcoef > 0:
            lo_c = max(lo_c, acoef / bcoef)
        elif acoef > 0:
            return (0.0, 0.0)
        if hi_c < lo_c:
            return (0.0, 0.0)
        phi_lo = math.acos(min(1.0, max(-1.0, hi_c)))
        phi_hi = math.acos(min(1.0, max(-1.0, lo_c)))
        return (max(lo, phi_lo), min(hi, phi_hi))

    def bound(d0):
        dd = np.linspace(0, d0, 200)
        kappa = float(np.min(np.exp(-np.tan(dd) ** 2 / m**2) / (4 * math.pi * m * m * np.cos(dd) ** 4)))  # eq. 11
        area = _cap_integral(mu, d0, lambda d, c: np.ones_like(c), limits)
        return kappa * area / mu, area  # 001 eq. 15

    if delta0 is None:
        from scipy.optimize import minimize_scalar

        r = minimize_scalar(lambda d: -bound(d)[0], bounds=(1e-6, min(1.2, 6 * m)), method="bounded",
                            options={"xatol": 1e-8})
        delta0 = float(r.x)
    b, area = bound(delta0)
    return b, delta0, area


def analysis_dataset(mu_min: float = 1e-8, progress: bool | None = None):
    """The divergence analysis of :data:`MODELS` with the concrete bounds, as an xarray.Dataset."""
    import json

    import xarray as xr

    from ._version import __version__
    from .tables import _progress

    mu = grid(mu_min)
    names = list(MODELS)
    alb = np.zeros((len(names), len(mu)))
    err = np.zeros_like(alb)
    bound = np.full_like(alb, np.nan)
    k = np.zeros(len(names))
    k_err = np.zeros(len(names))
    K = np.zeros(len(names))
    verdict = []
    with _progress(len(names), "divergence", progress) as bar:
        bar.unit = "model"
        for i, name in enumerate(names):
            r = divergence(MODELS[name], mu_min=mu_min)
            alb[i], err[i] = r.albedo, r.albedo_error
            k[i], k_err[i], K[i] = r.k, r.k_error, r.K
            verdict.append(r.verdict)
            spec = MODELS[name]
            if spec["type"] == "ward":
                d0 = ward_bound(spec["m"], 1e-6)[1]
                bound[i] = [ward_bound(spec["m"], float(m), d0)[0] for m in mu]
            elif spec["type"] == "cook_torrance":
                bound[i] = [cook_torrance_bound(spec["m"], float(m))[0] for m in mu]
            bar.update(1)
    return xr.Dataset(
        {
            "albedo": (("model", "mu"), alb, {"long_name": "directional albedo", "units": "1"}),
            "albedo_error": (("model", "mu"), err, {"long_name": "estimated absolute error", "units": "1"}),
            "lower_bound": (("model", "mu"), bound,
                            {"long_name": "lower bound of 001 eq. 14 (Ward) or eq. 15 "
                                          "(Cook-Torrance, region where G = 1)"}),
            "k": ("model", k, {"long_name": "fitted exponent: a ~ K mu^(-k) for mu in [1e-8, 1e-5]"}),
            "k_error": ("model", k_err, {"long_name": "uncertainty of k"}),
            "K": ("model", K, {"long_name": "fitted prefactor"}),
            "verdict": ("model", np.array(verdict, dtype=object)),
        },
        coords={
            "model": np.array(names, dtype=object),
            "spec": ("model", np.array([json.dumps(MODELS[n]) for n in names], dtype=object)),
            "mu": ("mu", mu, {"long_name": "cosine of the incidence angle", "units": "1"}),
            "theta": ("mu", np.degrees(np.arccos(mu)), {"long_name": "incidence angle", "units": "degree"}),
        },
        attrs={"pumpup_kind": "pumpup divergence analysis", "title": "Albedo at grazing incidence (001 sec. 2.1)",
               "pumpup_version": __version__},
    )


def plot(ds, path):
    """Log-log plot of the albedo against mu, with the lower bounds dashed."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(9, 6), constrained_layout=True)
    colors = plt.get_cmap("tab20").colors[::2] + plt.get_cmap("tab20").colors[1::2]
    for i, name in enumerate(ds.model.values):
        line, = ax.loglog(ds.mu, ds.albedo[i], color=colors[i % len(colors)],
                          label=f"{name}: {ds.verdict.values[i]}, k = {abs(float(ds.k[i])):.3f}")
        if np.isfinite(ds.lower_bound[i]).any():
            ax.loglog(ds.mu, ds.lower_bound[i], "--", color=line.get_color(), lw=1)
    ax.set(xlabel="mu = cos(theta_i)", ylabel="albedo",
           title="Albedo near grazing incidence (dashed: 001 eq. 14/15 bounds)", ylim=(1e-3, 1e3))
    ax.invert_xaxis()
    ax.grid(alpha=0.3, which="both")
    ax.legend(fontsize=7)
    from .tables import atomic_path

    with atomic_path(path) as tmp:  # an interrupted write leaves no half PNG
        fig.savefig(tmp, dpi=90, format="png")
    plt.close(fig)
    return path
