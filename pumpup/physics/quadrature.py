"""The error estimate of one Gauss-Kronrod rule application, calibrated to the truth (issue 14 item 4).

What the estimate is
--------------------
A Gauss-Kronrod pair (K, the Kronrod rule, and G, its embedded Gauss rule) applied to f on an
interval of length h gives K, G, resabs = integral of |f| (by K) and
resasc = integral of |f - K / h| (by K, the spread of f about its mean).  The raw estimate
|K - G| is the error of the *Gauss* rule; the returned value K is far more accurate than that on
smooth integrands (8-1000x measured, issue 14).  QUADPACK (Piessens et al. 1983, routines
``qk15``/``qk21``) reports instead

    err = resasc * min(1, (200 |K - G| / resasc)^1.5)

which is *smaller* than |K - G| when the interval is well resolved (|K - G| < resasc / 8e6, ratio
2828 sqrt(|K - G| / resasc)) and *larger* when it is not, so a poorly resolved interval is never
called converged on the strength of a lucky Gauss value.  Below it lies a rounding floor,
``50 eps resabs`` (QUADPACK's own), and the engines add their integrand's rounding term on top.

:func:`calibrated` is the compiled version (callable from any numba kernel: ``pumpup.engine.polar``,
a nested engine; ``pumpup.albedo``'s tensor rule uses :func:`calibrated_array` when
:data:`MODE_2D` asks for it);
:func:`calibrated_reference` is its plain-Python twin and the tests compare the two.

What was measured
-----------------
``scripts/calibration/error_calibration.py`` prints, for the 1-D path (``pumpup.engine.polar``) and the 2-D
engine, the distribution of true error / estimate over every independent reference in
``tests/`` (``tests/data/independent_reference.json``, ``independent_anisotropic.json``, the
30-digit mpmath Phong values, the closed forms) at rtol 1e-6 .. 1e-12, with the raw and the
calibrated estimate; ``tests/physics/test_error_calibration.py`` asserts that the engines' estimates
still bound the true error on all of them.

:data:`MODE` selects the estimate of the 1-D path, :data:`MODE_2D` that of the 2-D engine:
``"quadpack"``, ``"raw"`` (|K - G|, the engines before issue 14) or ``"min"`` (the smaller of the
two); :func:`estimates` sets both within a block, :func:`raw_estimate` the raw one (the harness's
"before" column).

Where it is used, and why not everywhere
----------------------------------------
QUADPACK's scaling assumes the integrand is smooth on the interval (the Kronrod error then is
far below the Gauss error).  The 1-D path's pieces are smooth by construction (analytic between
breakpoints, the square-root ends removed by the smoothing substitution), so it uses it (MODE =
"quadpack").  The 2-D engine does not know every kink of its integrand: a pumped BRDF divides
by an interpolated albedo table, a Kulla-Conty lobe multiplies by one, a ``from_function`` has
whatever it has; there the calibrated estimate was measured *below the true error*: pumped
g1 Blinn n = 16 at mu = 1e-3, true error 1.12 x the estimate at rtol 1e-10 and 1.64 x at 1e-11
(the reference: the same engine at rtol 1e-13 with the raw estimate, its own error counted in
the engine's favour); the Kulla-Conty lobe of Phong n = 20 at rtol 1e-10, 0.89 x (0.09 x with
the raw estimate).  So the 2-D engine keeps the raw
|K - G| (MODE_2D = "raw"): honesty wins.

Measured (``PYTHONPATH=.:scripts:tests python scripts/calibration/error_calibration.py --worst``, 168
independent references x rtol 1e-6, 1e-8, 1e-10, 1e-12): 1-D path, true error / estimate at
most 0.015 calibrated (0.03 raw), never above 1.  The 2-D engine on the same (smooth, or with
every kink marked) references: at most 0.12 calibrated, 0.18 raw, 0.23 with "min"; but its
evaluations change by only -13 % .. +14 % (``--cost``; Cook-Torrance m = 0.3: +14 %), since the
refinement is spent where rectangles are poorly resolved, and there QUADPACK's estimate is the
larger one.  The 1-D path's evaluations are set by its first intervals: the gain there is
``pumpup.engine.lobe_frame.N_INIT`` = 1 (one first interval per piece, was 2), which the calibrated
estimate meets at rtol 1e-10 almost everywhere.
"""

from __future__ import annotations

import contextlib

import numpy as np
from numba import njit

__all__ = ["MODE", "MODE_2D", "calibrated", "calibrated_array", "calibrated_reference", "estimates", "mode_code",
           "raw_estimate"]

#: the estimate of the engines whose pieces are smooth by construction (the 1-D path of
#: ``pumpup.engine.polar``): "quadpack" (calibrated), "min" or "raw" (|K - G|, as before issue 14)
MODE = "quadpack"
#: the estimate of the 2-D engine, whose integrand may have kinks no hint marks (the knots of a
#: pumped BRDF's albedo table, a Kulla-Conty lobe's E(mu), a ``from_function``): "raw" (see
#: the module docstring: QUADPACK's scaling measured 1.64 x below the true error there)
MODE_2D = "raw"

#: QUADPACK's rounding floor: never below FLOOR * eps * integral of |f|
FLOOR = 50.0
EPS = float(np.finfo(float).eps)


def mode_code(smooth: bool = True) -> int:
    """The estimate as an argument of the compiled kernels: 0 raw |K - G|, 1 calibrated, 2 the
    smaller of the two; ``smooth`` selects :data:`MODE` (True) or :data:`MODE_2D` (False).
    """
    mode = MODE if smooth else MODE_2D
    if mode not in ("quadpack", "raw", "min"):
        raise ValueError(f"pumpup.physics.quadrature.MODE{'' if smooth else '_2D'} must be 'quadpack', 'min' or 'raw', "
                         f"got {mode!r}")
    return {"raw": 0, "quadpack": 1, "min": 2}[mode]


@contextlib.contextmanager
def estimates(mode: str, mode_2d: str | None = None):
    """Within the block the 1-D path reports ``mode`` and the 2-D engine ``mode_2d`` (default: the
    same).  For measurements; not meant for concurrent toggling.
    """
    global MODE, MODE_2D
    old = MODE, MODE_2D
    MODE, MODE_2D = mode, mode if mode_2d is None else mode_2d
    try:
        mode_code(True), mode_code(False)
    except ValueError:
        MODE, MODE_2D = old
        raise
    try:
        yield
    finally:
        MODE, MODE_2D = old


def raw_estimate():
    """Within the block every engine reports the raw |K - G| (the estimate before issue 14)."""
    return estimates("raw")


@njit(cache=True, nogil=True)
def calibrated(diff, resasc, resabs, mode):  # pragma: no cover - compiled; see calibrated_reference
    """Error estimate of one rule application (all arguments already multiplied by the length).

    Parameters
    ----------
    diff : float
        |K - G|, the raw estimate.
    resasc : float
        Integral of |f - mean(f)| by the Kronrod rule.
    resabs : float
        Integral of |f| by the Kronrod rule.
    mode : int
        1: QUADPACK's calibrated estimate with its rounding floor; 0: ``diff`` itself.
    """
    if mode == 0:
        return diff
    err = diff
    if resasc != 0.0 and diff != 0.0:
        err = resasc * min(1.0, (200.0 * diff / resasc) ** 1.5)  # QUADPACK qk21 / qk15
        if mode == 2:
            err = min(err, diff)
    return max(FLOOR * EPS * resabs, err)


def calibrated_reference(diff: float, resasc: float, resabs: float, mode: int = 1) -> float:
    """Plain-Python twin of :func:`calibrated` (the readable reference; the tests compare them)."""
    if mode == 0:
        return diff
    err = diff
    if resasc != 0.0 and diff != 0.0:
        err = resasc * min(1.0, (200.0 * diff / resasc) ** 1.5)
        if mode == 2:
            err = min(err, diff)
    return max(FLOOR * EPS * resabs, err)


def calibrated_array(diff: np.ndarray, resasc: np.ndarray, resabs: np.ndarray, mode: int | None = None) -> np.ndarray:
    """:func:`calibrated` elementwise on numpy arrays (the 2-D engine's rectangles)."""
    if mode is None:
        mode = mode_code()
    diff = np.asarray(diff, dtype=np.float64)
    if mode == 0:
        return diff
    resasc = np.asarray(resasc, dtype=np.float64)
    with np.errstate(divide="ignore", invalid="ignore"):
        scaled = resasc * np.minimum(1.0, (200.0 * diff / resasc) ** 1.5)
    if mode == 2:
        scaled = np.minimum(scaled, diff)
    err = np.where((resasc != 0.0) & (diff != 0.0), scaled, diff)
    return np.maximum(FLOOR * EPS * np.asarray(resabs, dtype=np.float64), err)


@njit(cache=True, nogil=True)
def rule_sums(f, wk, wg):  # pragma: no cover - compiled
    """(K, |K - G|, resasc, resabs) of values ``f`` at the nodes of a rule with Kronrod weights
    ``wk`` and Gauss weights ``wg`` (summing to 1: multiply by the length).
    """
    k = 0.0
    g = 0.0
    ab = 0.0
    for j in range(f.shape[0]):
        k += wk[j] * f[j]
        g += wg[j] * f[j]
        ab += wk[j] * abs(f[j])
    asc = 0.0
    for j in range(f.shape[0]):
        asc += wk[j] * abs(f[j] - k)
    return k, abs(k - g), asc, ab
