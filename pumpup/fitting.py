"""Perceptual fitting: fit a compact model to a target BRDF under point light and sky light (001 sec. 1.1).

001 sec. 1.1: under a point light of power 4 pi at distance 1 in direction L the observer
at V sees L_out(V) = f_r(L, V) cos(theta_L) (001 eq. 3); under uniform sky light of radiance
1 it sees L_out(V) = integral of f_r(L, V) cos(theta_L) d omega_L = a(V) (001 eq. 4, the
albedo of a reciprocal BRDF).  "In perceptual based fitting the albedo should also be
considered, and the maximal relative errors of both the weighted BRDF and of the albedo
should be minimized simultaneously."  :func:`fit` does that:

    minimise  E = max(w_f e_f, w_a e_a)
    e_f = max over (L, V) in D of |f(L, V) cos(theta_L) / f_t(L, V) cos(theta_L) - 1|
    e_a = max over mu in M of |a(mu) / a_t(mu) - 1|

where f_t is the target, D the lobe region of the target (below) and M a set of mu down
to ``mu_min``.  ``method="least_squares"`` instead minimises the classical L2 distance of
the point-light radiance alone (the "so far" of 001 sec. 1.1),

    sum over views V of integral over L of (f(L, V) - f_t(L, V))^2 cos^2(theta_L) d omega_L,

on the same direction grid (solid-angle weights), over all L with f_t > 0, not only the lobe.

The lobe region (default)
-------------------------
Relative error is meaningful only where the target is not negligible.  Views V lie in the
xz-plane with theta_V uniform in [0, arccos(mu_min)]; for each view, the lights L lie on a
log-polar grid around the mirror direction of V (polar offsets 0, 1e-3 ... pi rad
geometric, and a uniform set; azimuths uniform over the full circle), and D keeps the pairs where
f_t(L, V) cos(theta_L) >= ``lobe_fraction`` (default 0.1) times its maximum over L for that
view.  The fit uses a coarse grid.  The reported e_f is, for each view of a denser grid of the
same construction (``FitResult.eval_pairs`` pairs in the region), the grid maximum refined by
local maximisation over the light direction inside the region (the view's peak refined
too), since the worst point often lies on the region's boundary, between grid points; the
reported e_a is the maximum over ``mu`` refined the same way in theta.  ``worst_pair`` and
``worst_mu`` say where they are attained.  e_f is a maximum over the evaluation grid's views
(25, theta_V uniform): between them it can be larger (by 2e-5 relative on a 37-view grid in
the tests).

Scale
-----
If the family has a multiplicative constant (``BRDF.constant``, "c") among the free
parameters and nothing is pumped, it is not searched: the model is evaluated at c = 1 and
the optimal c within its bounds is exact (the min-max of four lines for the perceptual
objective, the clipped normal equation for least squares).

Cost
----
The albedo of each candidate is the cost.  During the search it is computed with
``search_rtol`` (default 1e-5) on ``n_mu_search`` values of mu; the errors reported in the
result are recomputed afterwards at ``final_rtol`` (default 1e-9) on ``n_mu`` values, with
the bound of that recomputation (``albedo_error_bound``).

This module is over 1,000 lines because the objective, its sampling of directions and the fits of each model family
share the same residual and its weights.
"""

from __future__ import annotations

import json
import math
import time
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

import numpy as np

from .core import BRDF, SpecError, load, registry

if TYPE_CHECKING:
    from numpy.typing import ArrayLike

__all__ = ["fit", "FitResult", "FitData", "FitError", "FitWarning", "lobe_grid", "relative_errors", "plot_fits",
           "DEFAULT_LOBE_FRACTION", "DEFAULT_MU_MIN"]

#: default lobe region: f_t cos(theta_L) at least this fraction of its maximum over L for the view
DEFAULT_LOBE_FRACTION = 0.1
#: default smallest mu = cos(theta) of the albedo set and of the views (theta = 87.13 degrees)
DEFAULT_MU_MIN = 0.05
#: smallest polar offset of the log-polar light grid around the mirror direction [rad]
ALPHA_MIN = 1e-3
#: (views, polar offsets, azimuths) of the search grid and of the denser evaluation grid
SEARCH_GRID = (12, 48, 32)
EVAL_GRID = (25, 90, 48)
METHODS = ("perceptual", "least_squares")


class FitError(SpecError):
    """Bad input to :func:`fit`; the message names the argument and its allowed range."""


class FitWarning(UserWarning):
    """A fit that is hardly better than the zero BRDF (:data:`NEAR_ZERO_FIT`)."""


#: a fit whose objective max(w_f e_f, w_a e_a) is at least this fraction of the zero BRDF's (e_f = e_a = 1: f = 0 is
#: 100 % off everywhere) is reported as no fit, with a :class:`FitWarning` and a note
NEAR_ZERO_FIT = 0.9


# ----------------------------------------------------------------------------------------
# Direction sets
# ----------------------------------------------------------------------------------------


def view_mus(n_views: int, mu_min: float) -> np.ndarray:
    """The mu of the views: theta uniform in [0, arccos(mu_min)], normal view first."""
    return np.cos(np.linspace(0.0, math.acos(mu_min), n_views))


def lobe_grid(n_views: int, n_alpha: int, n_beta: int, mu_min: float = DEFAULT_MU_MIN):
    """Light-view pairs on log-polar grids around the mirror direction of each view.

    Parameters
    ----------
    n_views : int
        Views V = (sin theta_V, 0, cos theta_V), theta_V uniform in [0, arccos(mu_min)].
    n_alpha : int
        Polar offsets from the mirror direction R_V: 0, ``n_alpha`` values geometric in
        [1e-3, pi] rad and ``n_alpha // 2`` uniform in (0, pi].
    n_beta : int
        Azimuths around R_V, uniform over [0, 2 pi).
    mu_min : float
        Smallest cos(theta_V).

    Returns
    -------
    wi, wo : ndarray, shape (n, 3)
        Light and view directions of the pairs with the light above the horizon.
    view : ndarray of int, shape (n,)
        Index of the view of each pair.
    weight : ndarray, shape (n,)
        Solid angle of each light direction's cell [sr] (for the least-squares integral).
    """
    # geometric offsets resolve sharp lobes; uniform ones (every pi / n_alpha * 2) keep broad ones resolved
    alpha = np.unique(np.concatenate([[0.0], np.geomspace(ALPHA_MIN, math.pi, n_alpha),
                                      np.linspace(0.0, math.pi, max(n_alpha // 2, 2) + 1)[1:]]))
    n_alpha = len(alpha) - 1
    # cell edges in alpha: midpoints, [0, a_1 / 2] for the centre
    edges = np.concatenate([[0.0], 0.5 * (alpha[1:] + alpha[:-1]), [math.pi]])
    band = 2.0 * math.pi * (np.cos(edges[:-1]) - np.cos(edges[1:]))  # solid angle of each ring
    beta = np.arange(n_beta) * (2.0 * math.pi / n_beta)
    a = np.concatenate([[0.0], np.repeat(alpha[1:], n_beta)])
    b = np.concatenate([[0.0], np.tile(beta, n_alpha)])
    w = np.concatenate([[band[0]], np.repeat(band[1:] / n_beta, n_beta)])
    wis, wos, views, weights = [], [], [], []
    for k, mv in enumerate(view_mus(n_views, mu_min)):
        sv = math.sqrt(max(0.0, (1.0 - mv) * (1.0 + mv)))
        v = np.array([sv, 0.0, mv])
        r = np.array([-sv, 0.0, mv])  # mirror of V about N
        e1 = np.array([mv, 0.0, sv])  # in the plane of incidence, perpendicular to R
        e2 = np.array([0.0, 1.0, 0.0])
        d = (np.cos(a)[:, None] * r + np.sin(a)[:, None] * (np.cos(b)[:, None] * e1 + np.sin(b)[:, None] * e2))
        d /= np.linalg.norm(d, axis=-1, keepdims=True)
        up = d[:, 2] > 1e-12
        wis.append(d[up])
        wos.append(np.broadcast_to(v, (int(up.sum()), 3)))
        views.append(np.full(int(up.sum()), k))
        weights.append(w[up])
    return np.concatenate(wis), np.concatenate(wos), np.concatenate(views), np.concatenate(weights)


@dataclass
class FitData:
    """What the objective compares: the target on a direction set and on a set of mu.

    ``region`` marks the pairs of the lobe region (used by the perceptual errors);
    ``t`` is f_t cos(theta_L) on all pairs, ``a_t`` the target albedo at ``mu``.
    """

    wi: np.ndarray
    wo: np.ndarray
    view: np.ndarray
    weight: np.ndarray
    cos_l: np.ndarray
    t: np.ndarray
    region: np.ndarray
    mu: np.ndarray
    a_t: np.ndarray
    a_t_err: np.ndarray
    lobe_fraction: float | None

    @classmethod
    def build(cls, target: BRDF, pairs, mu, lobe_fraction, rtol):
        """The data of a fit: the target's f_t cos(theta_L) on the direction pairs ``pairs`` (001 eq. 3), its lobe
        region (values at least ``lobe_fraction`` of each view's peak, or all positive ones) and its albedo at ``mu`` to
        ``rtol``; a FitError where the target cannot be fitted (not single-channel, not finite, zero on every pair, an
        albedo <= 0).
        """
        from .engine.cubature import albedo

        wi, wo, view, weight = pairs
        cos_l = wi[:, 2]
        t = np.asarray(target._eval(wi, wo), dtype=np.float64) * cos_l  # 001 eq. 3
        if t.ndim != 1:
            raise FitError(f"fit: the target must be a single-channel BRDF; its values have shape {t.shape}")
        if not np.all(np.isfinite(t)):
            raise FitError("fit: the target is not finite on the direction set")
        if lobe_fraction is None:
            region = t > 0
        else:
            peak = np.zeros(int(view.max()) + 1)
            np.maximum.at(peak, view, t)
            region = (t > 0) & (t >= lobe_fraction * peak[view])
        if not region.any():
            raise FitError("fit: the target is zero on every direction pair; nothing to fit")
        a_t, a_err = albedo(target, mu, return_error=True, rtol=rtol)
        if np.any(a_t <= 0):
            i = int(np.argmin(a_t))
            raise FitError(f"fit: the target's albedo is {a_t[i]:g} at mu = {mu[i]:g}; "
                           "relative albedo error needs a > 0")
        return cls(wi, wo, view, weight, cos_l, t, region, np.asarray(mu, float), a_t, a_err, lobe_fraction)

    def add_pairs(self, target: BRDF, wi: np.ndarray, wo: np.ndarray) -> None:
        """Append pairs to the lobe region (the exchange rounds of :func:`fit`; no least-squares weight)."""
        t = np.asarray(target._eval(wi, wo), dtype=np.float64) * wi[:, 2]
        ok = t > 0
        self.wi = np.concatenate([self.wi, wi[ok]])
        self.wo = np.concatenate([self.wo, wo[ok]])
        self.view = np.concatenate([self.view, np.zeros(int(ok.sum()), int)])
        self.weight = np.concatenate([self.weight, np.zeros(int(ok.sum()))])
        self.cos_l = np.concatenate([self.cos_l, wi[ok, 2]])
        self.t = np.concatenate([self.t, t[ok]])
        self.region = np.concatenate([self.region, np.ones(int(ok.sum()), bool)])


def relative_errors(brdf: BRDF, data: FitData, rtol: float, scale: float = 1.0, return_albedo: bool = False):
    """(e_f, e_a, bound of e_a from the albedo error estimates) of ``scale * brdf`` on ``data``.

    With ``return_albedo``, also the albedo of ``scale * brdf`` at ``data.mu``.
    """
    from .engine.cubature import albedo

    m = np.asarray(brdf._eval(data.wi[data.region], data.wo[data.region]), dtype=np.float64) * data.cos_l[data.region]
    e_f = float(np.max(np.abs(scale * m / data.t[data.region] - 1.0)))  # 001 eq. 3, relative
    a, a_err = albedo(brdf, data.mu, return_error=True, rtol=rtol)
    q = scale * a / data.a_t
    e_a = float(np.max(np.abs(q - 1.0)))  # 001 eq. 4, relative
    bound = float(np.max(scale * a_err / data.a_t + q * data.a_t_err / data.a_t))
    if return_albedo:
        return e_f, e_a, bound, scale * a
    return e_f, e_a, bound


def _frame(v):
    """Mirror direction R of each view V (K, 3) and the two axes e1, e2 perpendicular to it."""
    r = v * np.array([-1.0, -1.0, 1.0])
    e2 = np.broadcast_to(np.array([0.0, 1.0, 0.0]), v.shape)
    e1 = np.cross(e2, r)
    return r, e1, e2


def _around(v, a, b):
    """Light directions at polar offset a and azimuth b around the mirror of v (broadcast)."""
    r, e1, e2 = _frame(v)
    r, e1, e2 = r[:, None, :], e1[:, None, :], e2[:, None, :]
    d = np.cos(a)[..., None] * r + np.sin(a)[..., None] * (np.cos(b)[..., None] * e1 + np.sin(b)[..., None] * e2)
    return d / np.linalg.norm(d, axis=-1, keepdims=True)


def _zoom(value, v, a0, b0, rounds: int = 9, n: int = 21, shrink: float = 4.0):
    """Maximise value(wl (K, P, 3), v (K, 1, 3)) -> (K, P) by patches in (a, b) around each start,
    each round ``shrink`` times smaller around the best point so far.  Returns (best, wl*).
    """
    k = len(v)
    ha = 0.2 * a0 + 0.02  # [rad]: beyond the neighbouring cells of the log-polar grids
    hb = np.where(a0 < 0.05, math.pi, 0.3)  # near the mirror direction: every azimuth
    u = np.linspace(-1.0, 1.0, n)
    du, dv = (g.ravel() for g in np.meshgrid(u, u, indexing="ij"))
    best = np.full(k, -np.inf)
    best_w = np.zeros((k, 3))
    a, b = a0.copy(), b0.copy()
    vv = v[:, None, :]
    for _ in range(rounds):
        aa = np.abs(a[:, None] + ha[:, None] * du[None, :])
        bb = b[:, None] + hb[:, None] * dv[None, :]
        wl = _around(v, aa, bb)
        with np.errstate(all="ignore"):
            val = np.where(wl[..., 2] > 0, value(wl, vv), -np.inf)
        i = np.argmax(val, axis=1)
        rows = np.arange(k)
        better = val[rows, i] > best
        best = np.where(better, val[rows, i], best)
        best_w[better] = wl[rows, i][better]
        a = np.where(better, aa[rows, i], a)
        b = np.where(better, bb[rows, i], b)
        ha, hb = ha / shrink, hb / shrink
    return best, best_w


def _offsets(wi, wo):
    """(a, b) of light wi around the mirror of view wo: the inverse of :func:`_around`."""
    r, e1, e2 = _frame(wo)
    ca = np.clip(np.einsum("ij,ij->i", wi, r), -1.0, 1.0)
    return np.arccos(ca), np.arctan2(np.einsum("ij,ij->i", wi, e2), np.einsum("ij,ij->i", wi, e1))


def sup_brdf_error(target: BRDF, brdf: BRDF, data: FitData, n_start: int = 4, return_points: bool = False):
    """e_f refined: for each view, the grid maximum of |f cos / f_t cos - 1| over the lobe region,
    then local maximisation over the light direction (shrinking patches around the ``n_start``
    worst grid points), the view's peak refined the same way.  Returns (e_f, worst wi, worst wo).

    The grid maximum alone underestimates the supremum where the worst point lies on the
    region's boundary (common: the tails differ most).
    """
    m = np.asarray(brdf._eval(data.wi, data.wo), dtype=np.float64) * data.cos_l
    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):  # outside the region t may be tiny
        err = np.where(data.t > 0, np.abs(m / np.where(data.t > 0, data.t, 1.0) - 1.0), 0.0)
    nv = int(data.view.max()) + 1
    first = np.array([np.flatnonzero(data.view == k)[0] for k in range(nv)])
    views = data.wo[first]
    peak = np.zeros(nv)
    np.maximum.at(peak, data.view, data.t)
    if data.lobe_fraction is None:
        inside = data.t > 0
        j = int(np.argmax(np.where(inside, err, -1.0)))
        if return_points:
            return float(err[j]), data.wi[j], data.wo[j], data.wi[j:j + 1], data.wo[j:j + 1], err[j:j + 1]
        return float(err[j]), data.wi[j], data.wo[j]

    def tval(wl, vv):
        return target._eval(wl, vv) * wl[..., 2]  # 001 eq. 3

    jp = np.array([np.flatnonzero(data.view == k)[np.argmax(data.t[data.view == k])] for k in range(nv)])
    a0, b0 = _offsets(data.wi[jp], views)
    p_ref, _ = _zoom(tval, views, a0, b0)
    peak = np.maximum(peak, p_ref)
    thr = data.lobe_fraction * peak
    inside = (data.t > 0) & (data.t >= thr[data.view])
    starts = []
    for k in range(nv):
        s = np.flatnonzero(inside & (data.view == k))
        starts.extend(s[np.argsort(err[s])[::-1][:n_start]])
    starts = np.array(starts)
    j = starts[np.argmax(err[starts])]
    best = (float(err[j]), data.wi[j], data.wo[j])
    sv = data.wo[starts]
    st = thr[data.view[starts]][:, None]

    def eval_err(wl, vv):
        t = target._eval(wl, vv) * wl[..., 2]
        f = brdf._eval(wl, vv) * wl[..., 2]
        return np.where((t > 0) & (t >= st), np.abs(f / np.where(t > 0, t, 1.0) - 1.0), -np.inf)

    a0, b0 = _offsets(data.wi[starts], sv)
    val, wl = _zoom(eval_err, sv, a0, b0)
    i = int(np.argmax(val))
    if val[i] > best[0]:
        best = (float(val[i]), wl[i], sv[i])
    if return_points:
        return best + (wl, sv, val)
    return best


def sup_albedo_error(target: BRDF, brdf: BRDF, mu: np.ndarray, a_t: np.ndarray, a: np.ndarray, rtol: float):
    """e_a refined: the grid maximum of |a / a_t - 1| over ``mu``, then bounded Brent
    maximisation in theta between the neighbours of the worst grid point (when the worst grid
    point is an end of the range and the midpoint towards its neighbour is lower, the end is
    taken as the maximum).  Returns (e_a, mu*).
    """
    from scipy.optimize import minimize_scalar

    from .engine.cubature import albedo

    q = np.abs(a / a_t - 1.0)
    i = int(np.argmax(q))
    best = (float(q[i]), float(mu[i]))
    order = np.argsort(mu)
    pos = int(np.flatnonzero(order == i)[0])
    lo = mu[order[max(pos - 1, 0)]]
    hi = mu[order[min(pos + 1, len(mu) - 1)]]
    if lo == hi:
        return best

    def neg(th):
        m = math.cos(th)
        return -abs(float(albedo(brdf, m, rtol=rtol)) / float(albedo(target, m, rtol=rtol)) - 1.0)

    if i in (order[0], order[-1]):  # the worst grid point is an end of [mu_min, 1]: is the maximum there?
        mid = 0.5 * (math.acos(lo) + math.acos(hi))
        if -neg(mid) <= best[0]:
            return best
    r = minimize_scalar(neg, bounds=(math.acos(hi), math.acos(lo)), method="bounded",
                        options={"xatol": 1e-6, "maxiter": 30})
    if -r.fun > best[0]:
        best = (float(-r.fun), math.cos(r.x))
    return best


# ----------------------------------------------------------------------------------------
# The result
# ----------------------------------------------------------------------------------------


@dataclass
class FitResult:
    """The outcome of :func:`fit`.

    Attributes
    ----------
    spec : dict
        The fitted model; ``pumpup.load(spec)`` (``brdf``) rebuilds it.
    brdf : BRDF
    params : dict
        The fitted values of the free parameters (for a pumped family: of its base).
    brdf_error : float
        e_f, max relative error of f cos(theta_L) over the lobe region (the evaluation grid's
        views; the light direction refined locally, see the module docstring), attained at
        ``worst_pair`` = (wi, wo).
    albedo_error : float
        e_a, max relative error of the albedo over [mu_min, 1] (the ``mu`` grid refined
        locally; albedo at ``final_rtol``), attained at ``worst_mu``.
    albedo_error_bound : float
        How far ``albedo_error`` may be off because of the albedo quadrature (both albedos'
        error estimates).
    objective : float
        max(w_f e_f, w_a e_a) at the result.
    lsq : float
        Root of the least-squares objective (the L2 distance of f cos theta_L, summed over
        the views) on the search grid.
    """

    target: dict
    target_brdf: BRDF
    family: str
    method: str
    spec: dict
    brdf: BRDF
    params: dict
    bounds: dict
    brdf_error: float
    albedo_error: float
    albedo_error_bound: float
    worst_pair: tuple
    worst_mu: float
    objective: float
    search_objective: float
    exchanges: int
    plausible: bool
    directions_given: bool
    view_mu_min: float
    weights: tuple
    lsq: float
    mu: np.ndarray
    lobe_fraction: float | None
    eval_pairs: int
    eval_views: int
    max_albedo: float
    evaluations: int
    albedo_evaluations: int
    n_mu_search: int
    seconds: float
    final_rtol: float
    search_rtol: float
    notes: list = field(default_factory=list)

    @property
    def mu_min(self) -> float:
        """The smallest mu at which the final albedo error was measured."""
        return float(np.min(self.mu))

    def __repr__(self) -> str:
        free = ", ".join(f"{k} = {v:.6g} in [{self.bounds[k][0]:g}, {self.bounds[k][1]:g}]"
                         for k, v in self.params.items())
        if self.directions_given:
            where = f"over the {self.eval_pairs} given pairs where f_t > 0"
        else:
            region = (f"f_t cos >= {self.lobe_fraction:g} x its peak per view" if self.lobe_fraction is not None
                      else "f_t > 0")
            where = (f"({self.eval_pairs} pairs of the lobe region: {region}; {self.eval_views} views, "
                     f"mu_V >= {self.view_mu_min:g})")
        lines = [
            f"FitResult({self.method}{', albedo <= 1' if self.plausible else ''}: {self.family} fitted to "
            f"{json.dumps(self.target)})",
            f"  fitted spec    {json.dumps(self.spec)}",
            f"  free params    {free or 'none'}",
            f"  point light    max rel. error of f cos(theta_L) = {self.brdf_error:.4g} {where}",
            f"  sky light      max rel. error of albedo         = {self.albedo_error:.4g} "
            f"(+- {self.albedo_error_bound:.1g}; {self.mu.size} mu in [{self.mu_min:g}, 1], rtol {self.final_rtol:g})",
            f"  objective      max({self.weights[0]:g} e_f, {self.weights[1]:g} e_a) = {self.objective:.4g}; "
            f"L2 distance {self.lsq:.4g}" + (f"; on the search set {self.search_objective:.4g} "
                                                f"({self.exchanges} exchange rounds)"
                                                if self.method == "perceptual" else ""),
            f"  max albedo     {self.max_albedo:.9g} on those mu"
            + ("  (> 1: not energy conserving)" if self.max_albedo > 1 + 10 * self.final_rtol else ""),
            f"  cost           {self.evaluations} evaluations, {self.albedo_evaluations} with the albedo "
            f"(rtol {self.search_rtol:g}, {self.n_mu_search} mu), {self.seconds:.2f} s",
        ]
        lines += [f"  note           {n}" for n in self.notes]
        return "\n".join(lines)

    __str__ = __repr__

    def summary(self) -> dict:
        """The result as plain JSON-able values."""
        return {
            "target": self.target, "family": self.family, "method": self.method, "spec": self.spec,
            "params": self.params, "brdf_error": self.brdf_error, "albedo_error": self.albedo_error,
            "albedo_error_bound": self.albedo_error_bound, "objective": self.objective, "lsq": self.lsq,
            "search_objective": self.search_objective, "plausible": self.plausible, "notes": list(self.notes),
            "max_albedo": self.max_albedo, "seconds": self.seconds, "evaluations": self.evaluations,
            "mu_min": self.mu_min, "lobe_fraction": self.lobe_fraction,
        }


# ----------------------------------------------------------------------------------------
# Checking the input (all before any optimisation)
# ----------------------------------------------------------------------------------------


def _load_target(target: Any) -> BRDF:
    if isinstance(target, BRDF):
        return target
    if isinstance(target, str):
        from .core import parse_spec

        try:
            target = parse_spec(target)
        except SpecError as exc:
            raise FitError(f"fit: target {target!r} does not load: {exc}") from None
    if not isinstance(target, dict):
        raise TypeError(f"fit: target must be a pumpup BRDF, a spec dict or a spec string, got {type(target).__name__}")
    try:
        return load(target)
    except SpecError as exc:
        raise FitError(f"fit: target does not load: {exc}") from None


def _check_pump(pump: Any):
    if pump is None:
        return None
    if not isinstance(pump, dict) or set(pump) - {"g", "levels"} or "g" not in pump:
        raise FitError(f"fit: pump must be None or a dict {{'g': 'g1' or 'g2', 'levels': k >= 1}}, got {pump!r}")
    g = pump["g"]
    levels = pump.get("levels", 1)
    if g not in ("g1", "g2"):
        raise FitError(f"fit: pump['g'] must be 'g1' or 'g2', got {g!r}")
    if isinstance(levels, bool) or not isinstance(levels, (int, np.integer)) or levels < 1:
        raise FitError(f"fit: pump['levels'] must be an integer >= 1, got {levels!r}")
    return {"g": g, "levels": int(levels)}


def _check_params(cls, family: str, params: Any, fixed: dict, ties: dict):
    if not isinstance(params, dict) or not params:
        raise FitError(f"fit: params must be a non-empty dict name -> (lo, hi); {family} has {', '.join(cls.params)}")
    out = {}
    for name, rng in params.items():
        if name not in cls.params:
            raise FitError(f"fit: {family} has no parameter {name!r}; its parameters are {', '.join(cls.params)}")
        p = cls.params[name]
        if p.kind not in ("float", "int"):
            raise FitError(f"fit: parameter {name!r} of {family} is of kind {p.kind!r}; only numbers can be fitted")
        if name in fixed:
            raise FitError(f"fit: parameter {name!r} is both free (params) and fixed")
        if name in ties:
            raise FitError(f"fit: parameter {name!r} is both free (params) and tied to {ties[name]!r}")
        try:
            lo, hi = (float(v) for v in rng)
        except (TypeError, ValueError):
            raise FitError(f"fit: params[{name!r}] must be a range (lo, hi) of two numbers, got {rng!r}") from None
        if not (math.isfinite(lo) and math.isfinite(hi)):
            raise FitError(f"fit: params[{name!r}] = ({lo:g}, {hi:g}) must be finite")
        if not lo < hi:
            raise FitError(f"fit: params[{name!r}] = ({lo:g}, {hi:g}) is an empty or inverted range; need lo < hi")
        for v in (lo, hi):
            try:
                p.check_number(family, name, v)
            except SpecError as exc:
                raise FitError(f"fit: params[{name!r}] = ({lo:g}, {hi:g}): {exc}") from None
        out[name] = (lo, hi)
    return out


def _check_weights(weights: Any):
    try:
        w = tuple(float(x) for x in weights)
    except (TypeError, ValueError):
        raise FitError(f"fit: weights must be two numbers (w_brdf, w_albedo) >= 0, got {weights!r}") from None
    if len(w) != 2 or not all(math.isfinite(x) and x >= 0 for x in w) or w == (0.0, 0.0):
        raise FitError(f"fit: weights must be two finite numbers (w_brdf, w_albedo) >= 0, not both 0; got {weights!r}")
    return w


def _log_scaled(lo: float, hi: float) -> bool:
    return lo > 0 and hi / lo >= 10.0


# ----------------------------------------------------------------------------------------
# The fit
# ----------------------------------------------------------------------------------------


def _best_scale(pairs_q, lo, hi):
    """The argmin over c in [lo, hi] of max_k w_k max_i |c q_ki - 1|, exact (a max of lines).

    ``pairs_q`` is a list of (w_k, q_min_k, q_max_k); each term is
    w max(c q_max - 1, 1 - c q_min), so the maximum of 2K lines, convex in c.
    """
    ups = [(w * qmax, -w) for w, qmin, qmax in pairs_q if w > 0]  # slope, intercept: w (c qmax - 1)
    downs = [(-w * qmin, w) for w, qmin, qmax in pairs_q if w > 0]  # w (1 - c qmin)
    lines = ups + downs

    def value(c):
        return max(s * c + b for s, b in lines)

    cands = [lo, hi]
    for s1, b1 in ups:
        for s2, b2 in downs:
            if s1 != s2:
                c = (b2 - b1) / (s1 - s2)
                if lo <= c <= hi:
                    cands.append(c)
    best = min(cands, key=value)
    return best, value(best)


class _Problem:
    def __init__(self, target, family, cls, bounds, fixed, ties, pump, method, weights, data, search_rtol,
                 plausible=False):
        self.plausible = plausible
        self.target, self.family, self.cls = target, family, cls
        self.bounds, self.fixed, self.ties, self.pump = bounds, fixed, ties, pump
        self.method, self.weights, self.data, self.search_rtol = method, weights, data, search_rtol
        const = cls.constant
        self.profile = const if (const in bounds and pump is None) else None
        self.names = [k for k in bounds if k != self.profile]
        self.logs = [_log_scaled(*bounds[k]) for k in self.names]
        self.cache: dict = {}
        self.pruned: dict = {}
        self.best = math.inf
        self.evaluations = 0
        self.albedo_evaluations = 0

    def reset(self) -> None:
        """Forget the cached values (after the data changed)."""
        self.cache.clear()
        self.pruned.clear()
        self.best = math.inf

    # transformed coordinates x <-> parameter values
    def to_x(self, values):
        return np.array([math.log(values[k]) if lg else values[k] for k, lg in zip(self.names, self.logs)])

    def from_x(self, x):
        out = {}
        for k, lg, xi in zip(self.names, self.logs, x):
            lo, hi = self.bounds[k]
            v = math.exp(xi) if lg else float(xi)
            out[k] = min(max(v, lo), hi)
        return out

    def x_bounds(self):
        return [(math.log(self.bounds[k][0]), math.log(self.bounds[k][1])) if lg else self.bounds[k]
                for k, lg in zip(self.names, self.logs)]

    def spec(self, values, scale=None):
        s = {"type": self.family, **self.fixed, **values}
        if self.profile is not None:
            s[self.profile] = 1.0 if scale is None else scale
        for k, src in self.ties.items():
            s[k] = s[src]
        if self.pump is not None:
            return {"type": "pumped", "base": s, "g": self.pump["g"], "levels": self.pump["levels"]}
        return s

    def build(self, values, scale=None) -> BRDF:
        from .operators.pumping import pump

        s = self.spec(values, scale)
        if self.pump is not None:
            return pump(s["base"], g=self.pump["g"], levels=self.pump["levels"])
        return load(s)

    def evaluate(self, values, exact: bool = False):
        """(objective, scale) at these values of the searched parameters.

        During the search (``exact`` false) a candidate whose albedo-free lower bound of
        the objective already exceeds the best value found so far returns that bound
        without computing its albedo (it cannot become the best).
        """
        key = tuple(values[k] for k in self.names)
        if key in self.cache:
            return self.cache[key]
        if not exact and key in self.pruned:
            return self.pruned[key]
        self.evaluations += 1
        d = self.data
        try:
            f = self.build(values)
        except SpecError:
            self.cache[key] = (math.inf, None)
            return self.cache[key]
        with np.errstate(all="ignore"):
            m = np.asarray(f._eval(d.wi, d.wo), dtype=np.float64) * d.cos_l
        if not np.all(np.isfinite(m)):
            self.cache[key] = (math.inf, None)
            return self.cache[key]
        if self.method == "least_squares":
            res = self._lsq(m, f)
        else:
            if not exact:
                lb = self._lower_bound(m)
                if lb > self.best:
                    self.pruned[key] = (lb, None)
                    return self.pruned[key]
            res = self._minmax(f, m)
        self.best = min(self.best, res[0])
        self.cache[key] = res
        return res

    def _lower_bound(self, m):
        """A lower bound of the perceptual objective from the BRDF term alone (no albedo)."""
        d = self.data
        wf = self.weights[0]
        qf = m[d.region] / d.t[d.region]
        if self.profile is not None:
            lo, hi = self.bounds[self.profile]
            return _best_scale([(wf, qf.min(), qf.max())], lo, hi)[1]
        return wf * float(np.max(np.abs(qf - 1.0)))

    def _search_albedo(self, f):
        """The albedo of f on the search mu (at the search tolerance), or None if not finite."""
        import warnings

        from .engine.cubature import AlbedoWarning, albedo

        self.albedo_evaluations += 1
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", AlbedoWarning)
            a = albedo(f, self.data.mu, rtol=self.search_rtol)
        return a if np.all(np.isfinite(a)) else None

    def _scale_range(self, a):
        """The range of the profiled scale; with ``plausible``, capped so that c a <= 1 on the search mu
        (a: the albedo at c = 1).  None if empty.
        """
        lo, hi = self.bounds[self.profile]
        if self.plausible and a is not None and np.max(a) > 0:
            hi = min(hi, 1.0 / float(np.max(a)))  # energy conservation, 000 eq. 2-3
        return (lo, hi) if lo <= hi else None

    def _lsq(self, m, f=None):
        d = self.data
        w = d.weight
        scale = None
        a = None
        if self.plausible and f is not None:
            a = self._search_albedo(f)
            if a is None:
                return math.inf, None
            if self.profile is None and np.max(a) > 1.0 + 10 * self.search_rtol:
                return math.inf, None
        with np.errstate(over="ignore", invalid="ignore"):
            if self.profile is not None:
                rng = self._scale_range(a)
                if rng is None:
                    return math.inf, None
                lo, hi = rng
                den = float(np.sum(w * m * m))
                c = float(np.sum(w * m * d.t)) / den if den > 0 else hi
                if not math.isfinite(c):
                    return math.inf, None
                scale = min(max(c, lo), hi)  # a convex quadratic in c: clipping is exact
                m = scale * m
            val = float(np.sum(w * (m - d.t) ** 2))
        return (val if math.isfinite(val) else math.inf), scale

    def _minmax(self, f, m):
        d = self.data
        wf, wa = self.weights
        qf = m[d.region] / d.t[d.region]
        a = None
        if wa > 0 or self.plausible:
            a = self._search_albedo(f)
            if a is None:
                return math.inf, None
        qa = a / d.a_t if wa > 0 else np.ones(1)
        if self.profile is not None:
            rng = self._scale_range(a)
            if rng is None:
                return math.inf, None
            c, val = _best_scale([(wf, qf.min(), qf.max()), (wa, qa.min(), qa.max())], *rng)
            return val, c
        if self.plausible and np.max(a) > 1.0 + 10 * self.search_rtol:
            return math.inf, None
        val = max(wf * float(np.max(np.abs(qf - 1.0))), wa * float(np.max(np.abs(qa - 1.0))))
        return val, None

    def objective(self, x):
        return self.evaluate(self.from_x(x))[0]


def _local(prob: _Problem, x, width: float, xtol: float):
    """Local min-max refinement from x: bounded Brent on [x - width, x + width] (one parameter) or
    Nelder-Mead on the max, restarted once from its own result (several).
    """
    from scipy.optimize import minimize, minimize_scalar

    xb = prob.x_bounds()
    x = np.asarray(x, dtype=np.float64)
    f0 = prob.objective(x)
    if len(x) == 1:
        a, b = max(xb[0][0], x[0] - width), min(xb[0][1], x[0] + width)
        r = minimize_scalar(lambda y: prob.objective([y]), bounds=(a, b), method="bounded",
                            options={"xatol": xtol * max(1.0, abs(x[0])), "maxiter": 200})
        return np.array([r.x]) if r.fun <= f0 else x
    best = (f0, x)
    for _ in range(2):
        loc = minimize(prob.objective, best[1], method="Nelder-Mead", bounds=xb,
                       options={"xatol": xtol, "fatol": 1e-12, "maxfev": 100 * len(xb), "adaptive": True})
        if loc.fun <= best[0]:
            best = (loc.fun, loc.x)
    return np.asarray(best[1])


def _search(prob: _Problem, n_scan: int, seed: int, maxiter: int, xtol: float):
    """Bounded global search (a scan for one parameter, differential evolution for more), then
    :func:`_local`.  Returns (x, the width of the scan's step).
    """
    from scipy.optimize import differential_evolution

    xb = prob.x_bounds()
    if not prob.names:
        return np.zeros(0), 0.0
    if len(prob.names) == 1:
        lo, hi = xb[0]
        grid = np.linspace(lo, hi, n_scan)
        vals = np.array([prob.objective([x]) for x in grid])
        i = int(np.argmin(vals))
        step = grid[1] - grid[0]
        return _local(prob, [grid[i]], step, xtol), step
    r = differential_evolution(prob.objective, xb, seed=seed, popsize=6, maxiter=maxiter, tol=1e-6,
                               polish=False, init="sobol")
    return _local(prob, r.x, 0.0, xtol), 0.0


def fit(target: BRDF | dict | str, family: str, params: dict | None = None, fixed: dict | None = None,
        pump: dict | None = None, directions: tuple[ArrayLike, ArrayLike] | None = None, mu: ArrayLike | None = None,
        weights: tuple[float, float] = (1.0, 1.0), method: str = "perceptual", *, ties: dict | None = None,
        lobe_fraction: float | None = DEFAULT_LOBE_FRACTION, mu_min: float = DEFAULT_MU_MIN,
        n_mu: int = 33, n_mu_search: int = 9, search_rtol: float = 1e-5, final_rtol: float = 1e-9,
        n_scan: int = 16, seed: int = 0, maxiter: int = 20, xtol: float = 1e-9,
        exchange_rounds: int = 3, grid: tuple = SEARCH_GRID, eval_grid: tuple = EVAL_GRID,
        plausible: bool = False) -> FitResult:
    """Fit a compact model to ``target`` under point light and sky light (001 sec. 1.1).

    Parameters
    ----------
    target : BRDF, spec dict or spec string
        Any single-channel BRDF: a built-in model, a :func:`pumpup.from_function`, a
        Mitsuba BSDF through ``pumpup.mitsuba.from_mitsuba``; or its spec
        (``{"type": "ggx", "alpha": 0.1}`` or ``"ggx:alpha=0.1"``).
    family : str
        A registered model type (``pumpup.registry()``), e.g. ``"stretched_phong"``.
    params : dict name -> (lo, hi)
        The free parameters and their search ranges (inside each parameter's allowed
        range).  A range with lo > 0 and hi / lo >= 10 is searched in log scale.  With a
        pump, the names are the base's parameters.  Default ``{"n": (1, 1e4)}``.
    fixed : dict, optional
        Further parameters of the family held at given values (the rest take defaults).
    pump : None or dict
        ``{"g": "g1" or "g2", "levels": k}``: fit the family pumped up k times
        (:func:`pumpup.pump`, 001 eq. 16-21).  Every candidate builds its own albedo
        tables: seconds per candidate.
    directions : None or (wi, wo)
        Light and view directions (arrays of shape (n, 3)) on which f cos(theta_L) is
        compared; default the lobe region of the module docstring (``lobe_fraction``).
        Given pairs are used as they are (pairs where the target is 0 dropped), for the
        search and for the reported error.
    mu : array_like, optional
        cos(theta) values of the albedo comparison, in (0, 1].  Default ``n_mu_search``
        values (search) and ``n_mu`` values (reported error), theta uniform in
        [0, arccos(mu_min)].
    weights : (w_f, w_a)
        The objective is max(w_f e_f, w_a e_a); (1, 0) ignores the albedo.
    method : {"perceptual", "least_squares"}
        The min-max relative-error fit of 001 sec. 1.1, or the L2 fit of f cos(theta_L)
        alone (see the module docstring).  Both report both errors.
    ties : dict, optional
        ``{"cy": "cx"}``: a parameter that takes another's value (an isotropic Lafortune lobe).
    lobe_fraction : float in (0, 1) or None
        The lobe region: pairs with f_t cos(theta_L) >= this fraction of the maximum over L
        for the same view (None: every pair where f_t > 0).
    mu_min : float in (0, 1)
        Smallest mu of the default albedo set and of the views.
    search_rtol, final_rtol : float
        Albedo tolerance during the search and for the reported errors.
    n_scan, seed, maxiter : int
        Points of the scan (one searched parameter), seed and generations of the
        differential evolution (two or more).
    plausible : bool
        Energy conservation as a constraint: the profiled scale is capped so that the albedo
        is at most 1 on the search mu (and mu = 1 if it is among them); a family without a
        free scale rejects candidates whose albedo exceeds 1 there.  Pumped families conserve
        energy by construction.  ``FitResult.max_albedo`` reports the albedo maximum on the
        final mu set.
    grid, eval_grid : (int, int, int)
        Views, polar offsets and azimuths of the lobe grids (:func:`lobe_grid`) of the search
        and of the reported errors; default ``SEARCH_GRID`` = (12, 48, 32) and
        ``EVAL_GRID`` = (25, 90, 48).
    exchange_rounds : int
        Perceptual fits: at most this many rounds in which the worst points of the dense grid
        (refined) join the search set and the local search is repeated (Remez's exchange).
    xtol : float
        Tolerance of the local refinement in the search coordinates (log of a log-scaled
        parameter, i.e. relative): Brent's ``xatol``, Nelder-Mead's ``xatol``.

    Returns
    -------
    FitResult
        The fitted spec and BRDF, both maximal relative errors (recomputed on the denser
        evaluation grid and at ``final_rtol``), the cost.

    Notes
    -----
    Search: one parameter, a scan of ``n_scan`` points (log-spaced where the range is)
    and bounded Brent minimisation around the best; two or more, scipy's
    differential_evolution then Nelder-Mead on the max.  The scale c is profiled out
    exactly when it is free (module docstring).
    """
    t0 = time.perf_counter()
    if method not in METHODS:
        raise FitError(f"fit: method must be one of {', '.join(METHODS)}, got {method!r}")
    tgt = _load_target(target)
    reg = registry()
    if not isinstance(family, str) or family not in reg or family in ("pumped", "function"):
        raise FitError(f"fit: family must be a registered model type (not 'pumped' or 'function'; use pump=); "
                       f"got {family!r}; known: {', '.join(k for k in reg if k not in ('pumped', 'function'))}")
    cls = reg[family]
    fixed = dict(fixed or {})
    ties = dict(ties or {})
    for k in list(fixed) + list(ties) + list(ties.values()):
        if k not in cls.params:
            raise FitError(f"fit: {family} has no parameter {k!r}; its parameters are {', '.join(cls.params)}")
    bounds = _check_params(cls, family, {"n": (1.0, 1e4)} if params is None else params, fixed, ties)
    for k, src in ties.items():
        if k in fixed:
            raise FitError(f"fit: parameter {k!r} is both fixed and tied to {src!r}")
    pump = _check_pump(pump)
    weights = _check_weights(weights)
    if lobe_fraction is not None and not (isinstance(lobe_fraction, (int, float)) and 0 < lobe_fraction < 1):
        raise FitError(f"fit: lobe_fraction must be in (0, 1) or None, got {lobe_fraction!r}")
    if not (isinstance(mu_min, (int, float)) and 0 < mu_min < 1):
        raise FitError(f"fit: mu_min must be in (0, 1), got {mu_min!r}")
    for name, v, lo in (("search_rtol", search_rtol, 1e-13), ("final_rtol", final_rtol, 1e-13), ("xtol", xtol, 1e-15)):
        if not (isinstance(v, (int, float)) and lo <= v < 1):
            raise FitError(f"fit: {name} must be in [{lo:g}, 1), got {v!r}")
    for name, v, lo in (("n_mu", n_mu, 2), ("n_mu_search", n_mu_search, 2), ("n_scan", n_scan, 3),
                         ("maxiter", maxiter, 1), ("exchange_rounds", exchange_rounds, 0)):
        if isinstance(v, bool) or not isinstance(v, (int, np.integer)) or v < lo:
            raise FitError(f"fit: {name} must be an integer >= {lo}, got {v!r}")

    if mu is None:
        mu_search = np.cos(np.linspace(0.0, math.acos(mu_min), n_mu_search))
        mu_final = np.cos(np.linspace(0.0, math.acos(mu_min), n_mu))
    else:
        from .engine.cubature import check_mu

        try:
            mu_search = mu_final = np.unique(check_mu(mu).ravel())[::-1]
        except ValueError as exc:
            raise FitError(f"fit: {exc}") from None
        if mu_search.size == 0:
            raise FitError("fit: mu must hold at least one value in (0, 1], got an empty array")
    if directions is None:
        for name, g in (("grid", grid), ("eval_grid", eval_grid)):
            if (not isinstance(g, (tuple, list)) or len(g) != 3
                    or not all(isinstance(v, (int, np.integer)) and not isinstance(v, bool) and v >= 2 for v in g)):
                raise FitError(f"fit: {name} must be three integers >= 2 (views, polar offsets, azimuths), got {g!r}")
        pairs_search = lobe_grid(*grid, mu_min=mu_min)
        pairs_final = lobe_grid(*eval_grid, mu_min=mu_min)
    else:
        from .core import as_directions

        try:
            wi, wo = directions
        except (TypeError, ValueError):
            raise FitError("fit: directions must be a pair (wi, wo) of arrays of shape (n, 3)") from None
        try:
            wi = as_directions(wi, "directions[0] (wi)").reshape(-1, 3)
            wo = as_directions(wo, "directions[1] (wo)").reshape(-1, 3)
        except ValueError as exc:
            raise FitError(f"fit: {exc}") from None
        if wi.shape != wo.shape:
            raise FitError(f"fit: directions: wi and wo must have the same shape, got {wi.shape} and {wo.shape}")
        view = np.zeros(len(wi), int)
        pairs_search = pairs_final = (wi, wo, view, np.full(len(wi), 4 * math.pi / len(wi)))
        lobe_fraction = None

    # a candidate at the middle of the ranges must load (names, fixed values, ties, pump)
    mid = {k: (math.sqrt(lo * hi) if _log_scaled(lo, hi) else 0.5 * (lo + hi)) for k, (lo, hi) in bounds.items()}
    trial = {"type": family, **fixed, **mid}
    for k, src in ties.items():
        trial[k] = trial[src]
    try:
        trial_brdf = load(trial)
    except SpecError as exc:
        raise FitError(f"fit: the family with these fixed values does not load: {exc}") from None
    if pump is not None and not trial_brdf.reciprocal:
        raise FitError(f"fit: pump needs a reciprocal family; {family} is not")

    data = FitData.build(tgt, pairs_search, mu_search, lobe_fraction, final_rtol)
    prob = _Problem(tgt, family, cls, bounds, fixed, ties, pump, method, weights, data, search_rtol, bool(plausible))
    x, step = _search(prob, n_scan, seed, maxiter, xtol)
    values = prob.from_x(x) if prob.names else {}
    search_objective, scale = prob.evaluate(values, exact=True)
    final = FitData.build(tgt, pairs_final, mu_final, lobe_fraction, final_rtol)
    exchanges = 0
    last_sup = (None, None)
    if method == "perceptual" and directions is None and prob.names:
        # exchange rounds (as in Remez's algorithm): the worst points of the dense grid, refined,
        # join the search set and the local search is repeated, until the search set sees the maximum
        for _ in range(exchange_rounds):
            brdf = prob.build(values, scale)
            sup = sup_brdf_error(tgt, brdf, final, return_points=True)
            e_f, more_wi, more_wo, more_val = sup[0], sup[3], sup[4], sup[5]
            last_sup = (json.dumps(brdf.spec, sort_keys=True), sup[:3])
            if weights[0] * e_f <= search_objective * (1 + 1e-3):
                break
            keep = more_val >= 0.5 * e_f
            data.add_pairs(tgt, more_wi[keep], more_wo[keep])
            prob.reset()
            x = _local(prob, x, 2 * step, xtol)
            values = prob.from_x(x)
            search_objective, scale = prob.evaluate(values, exact=True)
            exchanges += 1
    brdf = prob.build(values, scale)
    m_fit = np.asarray(brdf._eval(data.wi, data.wo), dtype=np.float64) * data.cos_l
    lsq_search = float(np.sum(data.weight * (m_fit - data.t) ** 2))
    # the reported errors: the denser grid, the albedo at final_rtol
    _, _, bound, a_fit = relative_errors(brdf, final, final_rtol, return_albedo=True)
    if last_sup[0] == json.dumps(brdf.spec, sort_keys=True):  # the last exchange round measured this model
        e_f, worst_wi, worst_wo = last_sup[1]
    elif directions is None:
        e_f, worst_wi, worst_wo = sup_brdf_error(tgt, brdf, final)
    else:
        e_f, worst_wi, worst_wo = sup_brdf_error(tgt, brdf, final, n_start=1)
    e_a, worst_mu = sup_albedo_error(tgt, brdf, final.mu, final.a_t, a_fit, final_rtol)
    fitted = dict(values)
    if prob.profile is not None:
        fitted[prob.profile] = float(scale)
    notes = []
    for k, v in fitted.items():
        lo, hi = bounds[k]
        if v <= lo * (1 + 1e-9) + 1e-300 or v >= hi * (1 - 1e-9):
            notes.append(f"{k} = {v:g} is at the edge of its range [{lo:g}, {hi:g}]")
    objective = max(weights[0] * e_f, weights[1] * e_a)
    if objective >= NEAR_ZERO_FIT * max(weights):  # the zero BRDF scores max(w_f, w_a)
        import warnings

        why = (f"the fit's error max(w_f e_f, w_a e_a) = {objective:.3g} is within {1 - NEAR_ZERO_FIT:.0%} of the "
               f"zero BRDF's {max(weights):.3g}: {family} cannot follow this target's lobe on these directions")
        notes.append(why)
        warnings.warn(f"fit: {why}", FitWarning, stacklevel=2)
    return FitResult(
        target=tgt.spec, target_brdf=tgt, family=family, method=method, spec=brdf.spec, brdf=brdf, params=fitted,
        bounds=bounds, brdf_error=e_f, albedo_error=e_a, albedo_error_bound=bound, worst_pair=(worst_wi, worst_wo),
        worst_mu=worst_mu, search_objective=search_objective, exchanges=exchanges, plausible=bool(plausible),
        directions_given=directions is not None, view_mu_min=float(np.min(final.wo[:, 2])),
        albedo_evaluations=prob.albedo_evaluations, n_mu_search=len(mu_search),
        objective=objective, weights=weights, lsq=math.sqrt(lsq_search),
        mu=final.mu, lobe_fraction=lobe_fraction, eval_pairs=int(final.region.sum()),
        eval_views=int(final.view.max()) + 1, max_albedo=float(np.max(a_fit)), evaluations=prob.evaluations,
        seconds=time.perf_counter() - t0, final_rtol=final_rtol, search_rtol=search_rtol, notes=notes,
    )


# ----------------------------------------------------------------------------------------
# The comparison figure
# ----------------------------------------------------------------------------------------


def plot_fits(results, path, views_deg=(0.0, 45.0, 75.0), labels=None, title=None):
    """Write a PNG: point-light radiance and albedo curves of the target and the fits.

    Top row: f(L, V) cos(theta_L) (001 eq. 3) in the plane of incidence for the views
    ``views_deg``, against the signed light angle (positive on the mirror side), log
    scale.  Bottom: the albedo a(mu) (001 eq. 4) against theta = arccos(mu) down to the
    fits' mu_min, and its relative error.  All results must share one target.
    Written atomically; returns ``path``.
    """
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from .engine.cubature import albedo
    from .tables import atomic_path

    results = list(results)
    if not results:
        raise ValueError("plot_fits: no results to plot")
    tgt = results[0].target_brdf
    labels = labels or [f"{r.family}{'' if 'base' not in r.spec else ' pumped'} ({r.method}): "
                        f"e_f {r.brdf_error:.3g}, e_a {r.albedo_error:.3g}" for r in results]
    nv = len(views_deg)
    fig, axes = plt.subplots(2, max(nv, 2), figsize=(4.6 * max(nv, 2), 8), constrained_layout=True)
    th_l = np.linspace(-89.5, 89.5, 719)
    wl = np.stack([np.sin(np.radians(th_l)) * -1.0, np.zeros_like(th_l), np.cos(np.radians(th_l))], axis=-1)
    for j, tv in enumerate(views_deg):
        ax = axes[0, j]
        v = np.array([math.sin(math.radians(tv)), 0.0, math.cos(math.radians(tv))])
        ft = tgt.eval(wl, v) * wl[:, 2]  # 001 eq. 3
        ax.semilogy(th_l, ft, "k", lw=2.2, label="target")
        for r, lab in zip(results, labels):
            ax.semilogy(th_l, r.brdf.eval(wl, v) * wl[:, 2], lw=1.2, label=lab)
        peak = float(np.max(ft))
        ax.set(ylim=(peak * 1e-3, peak * 3), xlabel="light angle theta_L [deg] (+ = mirror side)",
               title=f"point light, view theta_V = {tv:g} deg")
        ax.grid(alpha=0.3)
    mu_min = min(r.mu_min for r in results)
    th = np.linspace(0.0, math.degrees(math.acos(mu_min)), 40)
    mu = np.cos(np.radians(th))
    a_t = albedo(tgt, mu, rtol=1e-6)  # a plot: 1e-6 is far below a line's width
    axes[1, 0].plot(th, a_t, "k", lw=2.2, label="target")
    for r, lab in zip(results, labels):
        a = albedo(r.brdf, mu, rtol=1e-6)
        axes[1, 0].plot(th, a, lw=1.2, label=lab)
        axes[1, 1].plot(th, a / a_t - 1.0, lw=1.2, label=lab)
    axes[1, 0].set(title="sky light: albedo a(theta)", xlabel="theta [deg]")
    axes[1, 1].set(title="relative albedo error a / a_t - 1", xlabel="theta [deg]")
    for ax in axes[1, :2]:
        ax.grid(alpha=0.3)
    if nv > 2:
        axes[1, 2].axis("off")
        axes[1, 2].legend(*axes[0, 0].get_legend_handles_labels(), fontsize=8, loc="center")
        for ax in axes[1, 3:]:
            ax.axis("off")
    else:
        axes[0, 0].legend(fontsize=7)
    fig.suptitle(title or f"fits to {json.dumps(results[0].target)}", fontsize=10)
    with atomic_path(path) as tmp:
        fig.savefig(tmp, dpi=90, format="png")
    plt.close(fig)
    return str(path)
