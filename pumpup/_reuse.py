"""Reuse within a cell: the mean albedo and the albedo maximum of a BRDF that was just tabulated.

:func:`pumpup.tabulate` leaves its values on the BRDF object (:func:`remember`);
:func:`pumpup.mean_albedo` and :func:`pumpup.max_albedo` then start from them instead of computing
about 220 and 97 fresh values:

* the mean albedo 2 integral_0^1 a(mu) mu dmu (000 eq. 33) = integral_0^(pi/2) a sin(2 theta) d theta
  over the table's range [theta(1) = 0, theta(mu_min)] is the integral of the quintic interpolating
  spline in theta of a sin(2 theta) through the table's nodes.  Its error is measured: the
  difference to the cubic spline's integral (the interpolation error of the quintic is far below
  that of the cubic where both resolve the albedo, and where they do not the difference is large),
  plus the table's quadrature errors through the absolute weights of the rule.  The part below the
  table's smallest mu is integrated afresh (adaptive Gauss-Kronrod in mu).  If the total error
  estimate does not meet the requested tolerance, the caller computes the mean afresh as before.
* the maximum: the table's nodes take the place of the scan (with fresh values at the scan points
  below the table's smallest mu), scaled to the unit constant when the model is measured to be
  proportional to it; the bracket is refined and the final value computed afresh as before.
"""

from __future__ import annotations

import math

import numpy as np

_KEY = "_pumpup_albedo_table"


def remember(brdf, mu, value, error, rtol) -> None:
    """Keep the values of a table just computed on the BRDF object (they die with it)."""
    try:
        brdf.__dict__[_KEY] = (np.array(mu, dtype=np.float64), np.array(value, dtype=np.float64),
                               np.array(error, dtype=np.float64), float(rtol))
    except AttributeError:  # an object without a __dict__: nothing is reused
        pass


def recall(brdf):
    """(mu, albedo, error, rtol) of the last table of ``brdf``, increasing mu, or None."""
    t = getattr(brdf, "__dict__", {}).get(_KEY)
    if t is None:
        return None
    mu, a, e, rtol = t
    order = np.argsort(mu)
    return mu[order], a[order], e[order], rtol


def _spline_weights(theta: np.ndarray, k: int, hi: float) -> np.ndarray:
    """w with integral_0^hi S(theta) = w . values for the interpolating spline S of degree k
    (not-a-knot) through the nodes theta (increasing, theta[0] = 0, theta[-1] = hi)."""
    key = (theta.tobytes(), k, hi)
    w = _WEIGHTS.get(key)
    if w is None:
        from scipy.interpolate import make_interp_spline

        w = make_interp_spline(theta, np.eye(len(theta)), k=k).integrate(0.0, hi)
        if len(_WEIGHTS) > 16:  # a sweep uses one grid; keep a few
            _WEIGHTS.clear()
        _WEIGHTS[key] = w
    return w


#: the rules' weights by grid (one grid serves every cell of a sweep)
_WEIGHTS: dict = {}


def mean_from_table(brdf, rtol: float, fresh_part):
    """(mean, error) from the last table of ``brdf``, or None (no table, too few nodes, no node at
    mu = 1, or an error estimate above ``rtol`` x mean).

    ``fresh_part(mu_min, scale)`` returns (value, error) of 2 integral_0^mu_min a(mu) mu dmu computed
    afresh, to an absolute error that is a small fraction of rtol x scale.
    """
    t = recall(brdf)
    if t is None:
        return None
    mu, a, e, _ = t
    if len(mu) < 12 or mu[-1] != 1.0 or not (np.all(np.isfinite(a)) and np.all(np.isfinite(e))):
        return None
    s = np.sqrt((1.0 - mu) * (1.0 + mu))
    theta = np.arctan2(s, mu)[::-1]  # increasing from 0
    g = (2.0 * mu * s * a)[::-1]  # a sin(2 theta)
    ge = (2.0 * mu * s * e)[::-1]
    hi = float(theta[-1])
    w5 = _spline_weights(theta, 5, hi)
    w3 = _spline_weights(theta, 3, hi)
    i5 = float(w5 @ g)
    i3 = float(w3 @ g)
    propagated = float(np.abs(w5) @ ge)
    low, low_err = fresh_part(float(mu[0]), abs(i5))
    total = i5 + low
    err = abs(i5 - i3) + propagated + low_err + 50 * np.finfo(float).eps * abs(total)
    if not err <= rtol * abs(total):
        return None
    return total, err


def proportional_factor(brdf, unit, rng_seed: int = 7) -> float | None:
    """k with unit = k * brdf, measured on random pairs of directions (relative 1e-13), or None."""
    if unit is brdf:
        return 1.0
    rng = np.random.default_rng(rng_seed)
    v = rng.normal(size=(2, 400, 3))
    v /= np.linalg.norm(v, axis=-1, keepdims=True)
    v[..., 2] = np.abs(v[..., 2]) + 1e-3
    v /= np.linalg.norm(v, axis=-1, keepdims=True)
    wi, wo = v[0], v[1]
    wo[:100] = wi[:100] * np.array([-1.0, -1.0, 1.0])  # mirror pairs: the peak of most lobes
    f = np.asarray(brdf._eval(wi, wo), dtype=np.float64)
    u = np.asarray(unit._eval(wi, wo), dtype=np.float64)
    big = f > 1e-300
    if f.shape != u.shape or not big.any() or not np.all(np.isfinite(f)) or not np.all(np.isfinite(u)):
        return None
    k = float(np.median(u[big] / f[big]))
    if not (k > 0 and math.isfinite(k)) or np.max(np.abs(u - k * f)) > 1e-13 * np.max(np.abs(u)):
        return None
    return k


def scan_from_table(brdf, unit, scan_mu: np.ndarray, mu_min: float, fresh):
    """(mu, albedo, error) to stand for max_albedo's scan of ``unit`` (the model with its constant
    set to 1): the table nodes of ``brdf`` in [mu_min, 1] scaled by the measured factor, and
    ``fresh(mu)`` at the scan points below the table; or None."""
    t = recall(brdf)
    if t is None:
        return None
    mu, a, e, _ = t
    if len(mu) < 12 or mu[-1] != 1.0:
        return None
    k = proportional_factor(brdf, unit)
    if k is None:
        return None
    keep = mu >= mu_min
    below = scan_mu[scan_mu < mu[0]]
    fa, fe = fresh(below) if len(below) else (np.zeros(0), np.zeros(0))
    m = np.concatenate([below, mu[keep]])
    v = np.concatenate([np.asarray(fa, float), k * a[keep]])
    er = np.concatenate([np.asarray(fe, float), k * e[keep]])
    order = np.argsort(m)
    return m[order], v[order], er[order]


def fresh_low(brdf, mu_min: float, abs_tol: float, rtol: float, max_intervals: int = 64):
    """(value, error) of 2 integral_0^mu_min a(mu) mu dmu by adaptive 7/15 Gauss-Kronrod in tau,
    mu = mu_min tau^2 (3 - 2 tau), every a(mu) from :func:`pumpup.albedo` at ``rtol`` or to an absolute
    error abs_tol / (4 mu_min^2), whichever is looser; the error adds |K - G| and the propagated albedo
    errors (as :func:`pumpup.mean_albedo` does).

    The propagated part is sum 2 e(mu) mu w <= 2 max(e) mu_min integral w = 2 max(e) mu_min^2, so the
    absolute tolerance keeps it below abs_tol / 2 however small a(mu) is relative to the mean: near
    grazing incidence, where the values cost most, a cell's mean asks them for about 1e-6 instead of
    rtol / 10 (the p-model's cell: issue 14)."""
    from .albedo import NODES, WG, WK, albedo

    atol = max(1e-15, abs_tol / (4.0 * mu_min * mu_min))

    def rule(lo, hi):
        tau = lo[:, None] + (hi - lo)[:, None] * NODES[None, :]
        mu = mu_min * tau * tau * (3 - 2 * tau)
        w = mu_min * 6 * tau * (1 - tau) * (hi - lo)[:, None]
        v, e = albedo(brdf, np.maximum(mu, 1e-300), return_error=True, rtol=rtol, atol=atol)
        fv = 2 * v * mu * w
        k = fv @ WK
        return k, np.abs(k - fv @ WG), (2 * e * mu * w) @ WK

    lo, hi = np.array([0.0]), np.array([1.0])  # one interval to start (two cost a p-model cell 2.5 ms)
    k, qe, pe = rule(lo, hi)
    while qe.sum() > abs_tol and len(lo) < max_intervals:
        j = int(np.argmax(qe))
        m = 0.5 * (lo[j] + hi[j])
        nk, nqe, npe = rule(np.array([lo[j], m]), np.array([m, hi[j]]))
        lo = np.concatenate([np.delete(lo, j), [lo[j], m]])
        hi = np.concatenate([np.delete(hi, j), [m, hi[j]]])
        k = np.concatenate([np.delete(k, j), nk])
        qe = np.concatenate([np.delete(qe, j), nqe])
        pe = np.concatenate([np.delete(pe, j), npe])
    return float(k.sum()), float(qe.sum() + pe.sum())
