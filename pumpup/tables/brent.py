"""Brent's bounded minimisation of a scalar function, without importing ``scipy.optimize``.

:func:`bounded_minimum` takes the same steps, in the same floating-point operations, as
``scipy.optimize.minimize_scalar(fun, bounds=(lo, hi), method="bounded", options={"xatol": xatol})`` (scipy's
``_minimize_scalar_bounded``, Brent's ``fminbound``: golden-section steps and parabolic interpolation), so it returns
the same point bit for bit.  Importing ``scipy.optimize`` takes a few hundred milliseconds (it loads most of scipy);
:func:`pumpup.tables.max_albedo` is on the path of every ``pumpup.max_constant`` call, and of the explorer's first
answer, so it uses this one.
"""

from __future__ import annotations

import math
from collections.abc import Callable

__all__ = ["bounded_minimum"]

#: scipy's sqrt(2.2e-16) and (3 - sqrt(5)) / 2
_SQRT_EPS = math.sqrt(2.2e-16)
_GOLDEN = 0.5 * (3.0 - math.sqrt(5.0))


def _sign(x: float) -> float:
    """The sign as numpy gives it: -1, 0 or 1 (NaN for NaN)."""
    if x != x:
        return x
    return float(x > 0) - float(x < 0)


def bounded_minimum(fun: Callable[[float], float], lo: float, hi: float, xatol: float = 1e-5,
                    maxiter: int = 500) -> tuple[float, float, int]:
    """The minimum of ``fun`` on [lo, hi] by Brent's bounded method: (x, fun(x), number of calls).

    Parameters
    ----------
    fun : callable
        float -> float.
    lo, hi : float
        The bounds, finite, lo <= hi.
    xatol : float
        Absolute tolerance in x.
    maxiter : int
        The most calls of ``fun``.

    Examples
    --------
    >>> x, fx, n = bounded_minimum(lambda x: (x - 0.3) ** 2, 0.0, 1.0, xatol=1e-9)
    >>> round(x, 6), n
    (0.3, 6)
    """
    if not (math.isfinite(lo) and math.isfinite(hi)):
        raise ValueError(f"bounded_minimum: the bounds must be finite, got ({lo!r}, {hi!r})")
    if lo > hi:
        raise ValueError(f"bounded_minimum: the lower bound {lo!r} exceeds the upper bound {hi!r}")
    a, b = float(lo), float(hi)
    fulc = a + _GOLDEN * (b - a)
    nfc, xf = fulc, fulc
    rat = e = 0.0
    x = xf
    fx = fun(x)
    num = 1
    fu = math.inf
    ffulc = fnfc = fx
    xm = 0.5 * (a + b)
    tol1 = _SQRT_EPS * abs(xf) + xatol / 3.0
    tol2 = 2.0 * tol1
    while abs(xf - xm) > (tol2 - 0.5 * (b - a)):
        golden = True
        if abs(e) > tol1:  # a parabola through the three best points
            golden = False
            r = (xf - nfc) * (fx - ffulc)
            q = (xf - fulc) * (fx - fnfc)
            p = (xf - fulc) * q - (xf - nfc) * r
            q = 2.0 * (q - r)
            if q > 0.0:
                p = -p
            q = abs(q)
            r = e
            e = rat
            if abs(p) < abs(0.5 * q * r) and p > q * (a - xf) and p < q * (b - xf):  # its minimum is acceptable
                rat = (p + 0.0) / q
                x = xf + rat
                if (x - a) < tol2 or (b - x) < tol2:
                    rat = tol1 * (_sign(xm - xf) + ((xm - xf) == 0))
            else:
                golden = True
        if golden:  # a golden-section step into the larger part
            e = (a - xf) if xf >= xm else (b - xf)
            rat = _GOLDEN * e
        si = _sign(rat) + (rat == 0)
        x = xf + si * max(abs(rat), tol1)
        fu = fun(x)
        num += 1
        if fu <= fx:
            if x >= xf:
                a = xf
            else:
                b = xf
            fulc, ffulc = nfc, fnfc
            nfc, fnfc = xf, fx
            xf, fx = x, fu
        else:
            if x < xf:
                a = x
            else:
                b = x
            if fu <= fnfc or nfc == xf:
                fulc, ffulc = nfc, fnfc
                nfc, fnfc = x, fu
            elif fu <= ffulc or fulc == xf or fulc == nfc:
                fulc, ffulc = x, fu
        xm = 0.5 * (a + b)
        tol1 = _SQRT_EPS * abs(xf) + xatol / 3.0
        tol2 = 2.0 * tol1
        if num >= maxiter:
            break
    return xf, fx, num
