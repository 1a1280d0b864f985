"""Input checks of directions in one compiled pass (used by :func:`pumpup.core.as_directions`).

The plain numpy version, :func:`first_bad_reference`, is the readable twin of the kernel; the
tests check that the two find the same rows.

A model may also check while it evaluates (``BRDF.rows_kernel``, issue 14 item 6): its compiled
loop calls :func:`off_unit` on every row of both arguments in the same pass as the formula and
returns the first row of each that fails; ``BRDF.eval`` then runs :func:`first_bad` on a failing
argument for the message, so the errors are word for word those of ``as_directions``.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit


@njit(cache=True, nogil=True)
def _first_bad(a, tol):  # pragma: no cover - compiled; see first_bad_reference
    """(row of the first non-finite component or -1, row of the first |w| off 1 by more than tol or
    -1; -1 when a row is not finite) of an (N, 3) array, in one pass.
    """
    bad_norm = -1
    lo2 = (1.0 - tol) * (1.0 - tol)  # |w| in [1 - tol, 1 + tol]  <=>  |w|^2 in [lo2, hi2]
    hi2 = (1.0 + tol) * (1.0 + tol)
    for i in range(a.shape[0]):
        x, y, z = a[i, 0], a[i, 1], a[i, 2]
        n2 = x * x + y * y + z * z
        if not (lo2 <= n2 <= hi2):  # also every row with a NaN or an infinity
            if not (math.isfinite(x) and math.isfinite(y) and math.isfinite(z)):
                return i, -1
            if bad_norm < 0:
                bad_norm = i
    return -1, bad_norm


@njit(cache=True, nogil=True, inline="always")
def off_unit(x, y, z, lo2, hi2):  # pragma: no cover - compiled; see off_unit_reference
    """True where |(x, y, z)|^2 is outside [lo2, hi2] (|w| off 1 by more than the tolerance), and
    for every row with a NaN or an infinity (the comparisons fail).
    """
    n2 = x * x + y * y + z * z
    return not ((lo2 <= n2) & (n2 <= hi2))  # `&`, not `and`: no branch, the calling loops stay vectorized


def unit_bounds(tol: float) -> tuple[float, float]:
    """(lo2, hi2): |w| in [1 - tol, 1 + tol]  <=>  |w|^2 in [lo2, hi2] (the bounds of :func:`off_unit`)."""
    return (1.0 - tol) * (1.0 - tol), (1.0 + tol) * (1.0 + tol)


def off_unit_reference(a: np.ndarray, tol: float) -> np.ndarray:
    """:func:`off_unit` in numpy, on the rows of ``a`` (..., 3): non-finite or |w| off 1 by more than tol."""
    lo2, hi2 = unit_bounds(tol)
    with np.errstate(over="ignore", invalid="ignore"):
        n2 = a[..., 0] * a[..., 0] + a[..., 1] * a[..., 1] + a[..., 2] * a[..., 2]  # the kernel's order
        return ~((lo2 <= n2) & (n2 <= hi2))


def first_bad_reference(a: np.ndarray, tol: float) -> tuple[int, int]:
    """The same as the kernel, in numpy: (first non-finite row or -1, first non-unit row or -1)."""
    fin = np.all(np.isfinite(a), axis=-1)
    if not fin.all():
        return int(np.argmin(fin)), -1
    bad = np.abs(np.sqrt(np.einsum("...k,...k->...", a, a)) - 1.0) > tol
    return -1, (int(np.argmax(bad)) if bad.any() else -1)


def first_bad(a: np.ndarray, tol: float) -> tuple[int, int]:
    """(first non-finite row, first non-unit row), -1 where none, of the rows of ``a`` (..., 3),
    counted in C order over the leading axes.
    """
    flat = a.reshape(-1, 3)
    if not flat.flags.c_contiguous:
        flat = np.ascontiguousarray(flat)
    i, j = _first_bad(flat, tol)
    return int(i), int(j)
