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

:func:`calibrated` is the compiled version (callable from any numba kernel: ``pumpup._polar``,
``pumpup.albedo``'s tensor rule through :func:`calibrated_array`, and the nested engine);
:func:`calibrated_reference` is its plain-Python twin and the tests compare the two.

What was measured
-----------------
``scripts/error_calibration.py`` prints, for the 1-D path (``pumpup._polar``) and the 2-D
engine, the distribution of true error / estimate over every independent reference in
``tests/`` (``tests/data/independent_reference.json``, ``independent_anisotropic.json``, the
30-digit mpmath Phong values, the closed forms) at rtol 1e-6 .. 1e-12, with the raw and the
calibrated estimate; ``tests/test_error_calibration.py`` asserts that the calibrated estimate
still bounds the true error on all of them.  The module docstrings of ``pumpup._polar`` and
``pumpup.albedo`` state the measured ratios.

:data:`MODE` selects the estimate: ``"quadpack"`` (the default), ``"raw"`` (|K - G|, the
engines before issue 14) or ``"min"`` (the smaller of the two: measured honest too, 2-D
true error / estimate at most 0.23, but only 5-20 % fewer evaluations than the raw estimate,
so not the default).  :func:`raw_estimate` switches to the raw one within a block, for the
calibration script and the harness's "before" column.

Measured (``PYTHONPATH=.:scripts:tests python scripts/error_calibration.py --worst``, 168
references x 4 tolerances): 1-D path, true error / estimate at most 0.015 (raw 0.03); 2-D
engine at most 0.12 (raw 0.18), median 4.3e-4 (raw 1.3e-3); no case above 1 with any of the
three.  The cost (``--cost``): the 1-D path's evaluations are set by its first intervals
(unchanged); the 2-D engine's change by -13 % .. +14 % (Cook-Torrance m = 0.3: +14 %), since
the refinement is spent where rectangles are poorly resolved, and there QUADPACK's estimate is
the larger one.
"""

from __future__ import annotations

import contextlib

import numpy as np
from numba import njit

__all__ = ["MODE", "calibrated", "calibrated_array", "calibrated_reference", "mode_code", "raw_estimate"]

#: "quadpack" (the calibrated estimate) or "raw" (|K - G|, as before issue 14)
MODE = "quadpack"

#: QUADPACK's rounding floor: never below FLOOR * eps * integral of |f|
FLOOR = 50.0
EPS = float(np.finfo(float).eps)


def mode_code() -> int:
    """1 for the calibrated estimate, 0 for the raw |K - G| (an argument of the compiled kernels)."""
    if MODE not in ("quadpack", "raw", "min"):
        raise ValueError(f"pumpup._errors.MODE must be 'quadpack', 'min' or 'raw', got {MODE!r}")
    return {"raw": 0, "quadpack": 1, "min": 2}[MODE]


@contextlib.contextmanager
def raw_estimate():
    """Within the block the engines report the raw |K - G| (the estimate before issue 14).
    Not meant for concurrent toggling."""
    global MODE
    old = MODE
    MODE = "raw"
    try:
        yield
    finally:
        MODE = old


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
    ``wk`` and Gauss weights ``wg`` (summing to 1: multiply by the length)."""
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
