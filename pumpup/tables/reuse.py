"""Reuse within a cell: the mean albedo and the albedo maximum of a BRDF that was just tabulated.

:func:`pumpup.tabulate` leaves its values on the BRDF object (:func:`remember`);
:func:`pumpup.mean_albedo` and :func:`pumpup.max_albedo` then start from them instead of computing
about 220 and 97 fresh values:

* the mean albedo 2 integral_0^1 a(mu) mu dmu (000 eq. 33) = integral_0^(pi/2) a sin(2 theta) d theta
  over the table's range [theta(1) = 0, theta(mu_min)] is the integral of the quintic interpolating
  spline in theta of a sin(2 theta) through the table's nodes.  Its error is measured: the larger
  of the differences to the cubic spline's integral and to the quintic spline's through every other
  node (the interpolation error of the quintic is far below that of the cubic where both resolve the
  albedo; where the grid barely resolves a feature both can be off alike, and the coarser grid then
  misses it by far more: Phong n = 20000 on the sweep's grid was 1.1e-9 off with a difference to the
  cubic's of 3.5e-10, to the coarser quintic's of 2.9e-9; ``scripts/calibration/reuse_calibration.py``), plus the
  table's quadrature errors through the absolute weights of the rule.  The part below the
  table's smallest mu is integrated afresh (adaptive Gauss-Kronrod in mu).  Where that estimate misses
  the requested tolerance because of a steep rise at grazing incidence that the grid does not resolve
  (Ward's and anisotropic Ward's, a narrow lobe's), the table is cut short: the spline is built again
  on the nodes above the first unresolved interval (less a margin), and the rest, below, is
  integrated afresh in the same way (:func:`mean_from_table`).  If the estimate still misses the
  tolerance, the caller computes the mean afresh as before.
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
    """The weights w with integral_0^hi S(theta) = w . values for the interpolating spline S of degree k
    (not-a-knot) through the nodes theta (increasing, theta[0] = 0, theta[-1] = hi).
    """
    key = (theta.tobytes(), k, hi)
    w = _WEIGHTS.get(key)
    if w is None:
        from scipy.interpolate import make_interp_spline

        w = make_interp_spline(theta, np.eye(len(theta)), k=k).integrate(0.0, hi)
        if len(_WEIGHTS) > _WEIGHTS_KEPT:  # a sweep uses one grid (and its cells' cut-short tables); keep a few
            _WEIGHTS.clear()
        _WEIGHTS[key] = w
    return w


#: the rules' weights by grid (one grid serves every cell of a sweep), at most _WEIGHTS_KEPT of them (a grid of 257
#: nodes has three vectors and, once a table is cut short, three 256 x 257 matrices of interval weights)
_WEIGHTS: dict = {}
_WEIGHTS_KEPT = 48


#: where the whole table misses the tolerance, it is cut TRUNCATE_MARGIN intervals before its first unresolved one
#: (:func:`_first_unresolved`): the quintic spline's error spreads a few nodes from where the grid misses a feature
#: (decaying by about 0.43 a node), and the margin keeps those nodes out of the shorter table
TRUNCATE_MARGIN = 4
#: ... but only where the rest, integrated afresh, lies at grazing incidence, mu <= TRUNCATE_MU_MAX: a wider rest costs
#: more than the mean afresh (metal eta 0.999, k 0.001, whose albedo rises from mu ~ 0.35: 160 ms against 107 ms)
TRUNCATE_MU_MAX = 0.2


def _coarse(n: int) -> np.ndarray:
    """The indices of every other node of n, the last one included."""
    idx = np.arange(0, n, 2)
    return idx if idx[-1] == n - 1 else np.append(idx, n - 1)


def _spline_part(mu, a, e):
    """(i5, error, propagated, theta, g, ge) of the table (increasing mu, mu[-1] = 1): the quintic spline's integral
    of g = a sin(2 theta) over [0, theta(mu[0])], its error (the larger difference to the cubic spline's and to the
    quintic's through every other node: the module docstring), the table's errors ge = e sin(2 theta) through the
    quintic's absolute weights, and the nodes theta (increasing from 0) with g and ge there.
    """
    s = np.sqrt((1.0 - mu) * (1.0 + mu))
    theta = np.arctan2(s, mu)[::-1]  # increasing from 0
    g = (2.0 * mu * s * a)[::-1]  # a sin(2 theta)
    ge = (2.0 * mu * s * e)[::-1]
    hi = float(theta[-1])
    w5 = _spline_weights(theta, 5, hi)
    i5 = float(w5 @ g)
    c = _coarse(len(theta))
    i3, i5c = float(_spline_weights(theta, 3, hi) @ g), float(_spline_weights(theta[c], 5, hi) @ g[c])
    return i5, max(abs(i5 - i3), abs(i5 - i5c)), float(np.abs(w5) @ ge), theta, g, ge


def _first_unresolved(theta: np.ndarray, g: np.ndarray, ge: np.ndarray, budget: float) -> int:
    """The index (in theta) of the first interval among those whose local estimates, the largest first, must leave
    the table for the rest to be within budget / 4: per interval, the larger difference of the quintic spline's
    integral to the cubic's and to the coarser quintic's (:func:`_spline_part`), plus the propagated table errors.
    """
    c = _coarse(len(theta))
    d5 = _interval_weights(theta, theta, 5)
    diff = np.maximum(np.abs((d5 - _interval_weights(theta, theta, 3)) @ g),
                      np.abs(d5 @ g - _interval_weights(theta[c], theta, 5) @ g[c]))
    local = diff + np.abs(d5) @ ge
    order = np.argsort(local)[::-1]
    rest = local.sum() - np.cumsum(local[order])
    n_bad = int(np.argmax(rest <= 0.25 * budget)) + 1
    return int(order[:n_bad].min())


def _interval_weights(nodes: np.ndarray, theta: np.ndarray, k: int) -> np.ndarray:
    """W with row i . values = the integral over [theta_i, theta_(i+1)] of the interpolating spline of degree k
    (not-a-knot) through ``nodes`` (increasing; the values at them).
    """
    key = (nodes.tobytes(), theta.tobytes(), k, "intervals")
    w = _WEIGHTS.get(key)
    if w is None:
        from scipy.interpolate import make_interp_spline

        w = np.diff(make_interp_spline(nodes, np.eye(len(nodes)), k=k).antiderivative()(theta), axis=0)
        if len(_WEIGHTS) > _WEIGHTS_KEPT:
            _WEIGHTS.clear()
        _WEIGHTS[key] = w
    return w


def mean_from_table(brdf, rtol: float, fresh_part):
    """(mean, error) from the last table of ``brdf``, or None (no table, too few nodes, no node at
    mu = 1, or an error estimate above ``rtol`` x mean, on the whole table and on the table cut short).

    ``fresh_part(mu_min, scale)`` returns (value, error) of 2 integral_0^mu_min a(mu) mu dmu computed
    afresh, to an absolute error that is a small fraction of rtol x scale.

    Where the whole table misses the tolerance, the intervals whose local estimates (:func:`_first_unresolved`)
    must go for the rest to be within a quarter of it mark the first unresolved
    one; the table is cut TRUNCATE_MARGIN nodes above it, the splines built again on the
    nodes left, and the part below afresh, where that part lies below TRUNCATE_MU_MAX.
    """
    t = recall(brdf)
    if t is None:
        return None
    mu, a, e, _ = t
    # nodes a few doubles apart in mu can share theta = arccos(mu) (an adaptive grid that bisected towards a jump of the
    # albedo down to the last bit: Beckmann alpha 0.0052 with Walter's G1, whose switch level is a jump, put 70 nodes at
    # mu = 0.00829462; the splines refused duplicate nodes, found by scripts/studies/fuzz_engines.py --mean): the last
    # of each
    theta = np.arctan2(np.sqrt((1.0 - mu) * (1.0 + mu)), mu)
    keep = np.r_[theta[:-1] != theta[1:], True]
    mu, a, e = mu[keep], a[keep], e[keep]
    if len(mu) < 12 or mu[-1] != 1.0 or not (np.all(np.isfinite(a)) and np.all(np.isfinite(e))):
        return None
    out, total, theta, g, ge = _mean_of(mu, a, e, rtol, fresh_part)
    if out is not None:
        return out
    k = _first_unresolved(theta, g, ge, rtol * abs(total)) - TRUNCATE_MARGIN  # the last node kept, in theta
    if k < 11 or math.cos(theta[k]) > TRUNCATE_MU_MAX:
        return None
    keep = len(mu) - 1 - k  # (mu increases: the nodes kept are mu[keep:])
    return _mean_of(mu[keep:], a[keep:], e[keep:], rtol, fresh_part)[0]


def _mean_of(mu, a, e, rtol, fresh_part):
    """((mean, error) or None, the mean, theta, g, ge) from the table (mu, a, e) and ``fresh_part`` below mu[0]
    (:func:`_spline_part`'s nodes and values).
    """
    i5, spline_err, propagated, theta, g, ge = _spline_part(mu, a, e)
    low, low_err = fresh_part(float(mu[0]), abs(i5))
    total = i5 + low
    err = spline_err + propagated + low_err + 50 * np.finfo(float).eps * abs(total)
    return ((total, err) if err <= rtol * abs(total) else None), total, theta, g, ge


def proportional_factor(brdf, unit, rng_seed: int = 7) -> float | None:
    """The factor k with unit = k * brdf, measured on random pairs of directions (relative 1e-13), or None."""
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
    ``fresh(mu)`` at the scan points below the table; or None.
    """
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
    rtol / 10 (the p-model's cell: issue 14).
    """
    from ..engine.cubature import NODES, WG, WK, albedo

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
