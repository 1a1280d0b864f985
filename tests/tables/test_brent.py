"""pumpup.tables.brent.bounded_minimum takes scipy's bounded-Brent steps: the same point, value and calls."""

from __future__ import annotations

import math
import subprocess
import sys

import numpy as np
import pytest

from pumpup.tables.brent import bounded_minimum


def _scipy(fun, lo, hi, xatol, maxiter=500):
    from scipy.optimize import minimize_scalar

    calls = []

    def counted(x):
        calls.append(x)
        return fun(x)

    res = minimize_scalar(counted, bounds=(lo, hi), method="bounded", options={"xatol": xatol, "maxiter": maxiter})
    return float(res.x), float(res.fun), int(res.nfev), calls


def _cases():
    rng = np.random.default_rng(7)
    out = [
        (lambda x: (x - 0.3) ** 2, 0.0, 1.0),  # parabolic steps
        (lambda x: abs(x - 0.71), 0.0, 1.0),  # a kink: golden steps
        (lambda x: -math.cos(3 * x), -2.0, 2.0),
        (lambda x: x, 0.2, 0.9),  # the minimum at the lower bound
        (lambda x: -x, 0.2, 0.9),  # at the upper bound
        (lambda x: 1.0, 0.0, 1.0),  # flat
        (lambda x: math.exp(-x) * math.sin(5 * x), 0.0, 3.0),  # several minima
        (lambda x: (x - 0.5) ** 4, 0.499, 0.501),  # a narrow bracket
        (lambda x: -((1 - x * x) ** 0.5) * x ** 3, 0.0, 1.0),
    ]
    for _ in range(20):
        c, w, p = rng.uniform(0, 1), rng.uniform(0.01, 2), rng.choice([2, 4, 6])
        lo, hi = sorted(rng.uniform(-1, 2, 2))
        out.append((lambda x, c=c, w=w, p=p: -math.exp(-((x - c) / w) ** p) + 0.1 * math.sin(9 * x), lo, hi))
    return out


@pytest.mark.parametrize("k", range(len(_cases())))
@pytest.mark.parametrize("xatol", [1e-5, 1e-9])
def test_same_steps_as_scipy(k, xatol):
    fun, lo, hi = _cases()[k]
    calls = []

    def counted(x):
        calls.append(x)
        return fun(x)

    x, fx, n = bounded_minimum(counted, lo, hi, xatol=xatol * max(abs(hi), 1.0))
    sx, sfx, sn, scalls = _scipy(fun, lo, hi, xatol * max(abs(hi), 1.0))
    assert calls == scalls  # every point tried, in order
    assert (x, fx, n) == (sx, sfx, sn)


def test_maxiter_stops_like_scipy():
    fun = lambda x: math.sin(40 * x) + x  # noqa: E731
    x, fx, n = bounded_minimum(fun, 0.0, 3.0, xatol=1e-15, maxiter=7)
    sx, sfx, sn, _ = _scipy(fun, 0.0, 3.0, 1e-15, maxiter=7)
    assert n == sn == 7 and (x, fx) == (sx, sfx)


@pytest.mark.parametrize("lo, hi, match", [(0.0, math.inf, "finite"), (1.0, 0.0, "exceeds")])
def test_bad_bounds(lo, hi, match):
    with pytest.raises(ValueError, match=match):
        bounded_minimum(lambda x: x, lo, hi)


def test_max_constant_imports_no_scipy_optimize():
    """pumpup.max_constant (the explorer's first answer) does not load scipy.optimize."""
    code = ("import sys, pumpup; pumpup.max_constant(pumpup.load('phong:n=20')); "
            "print('scipy.optimize' in sys.modules)")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.strip() == "False"
