"""The compiled kernels of reciprocal Phong (pumpup/models/phong.py) against each other and against
the numpy reference: the broadcasting kernel (_phong_kernel) and the blocked rows kernel that BRDF.eval
and _eval use for arguments of one shape (_phong_rows, issue 14 item 6)."""

import numpy as np
import pytest

import pumpup
from pumpup.core import UNIT_TOL
from pumpup.core import checks as _checks
from pumpup.models import phong

EXPONENTS = [0.0, 1.0, 2.0, 20.0, 10.5, 0.25, 5000.0, 65537.0, 1e6]


def _pairs(rng, n, below=True):
    v = rng.normal(size=(2, n, 3))
    v /= np.linalg.norm(v, axis=-1, keepdims=True)
    if not below:
        v[..., 2] = np.abs(v[..., 2])
    return np.ascontiguousarray(v[0]), np.ascontiguousarray(v[1])


def _ufunc(wi, wo, n, c):
    return phong._phong_kernel(wi[:, 0], wi[:, 1], wi[:, 2], wo[:, 0], wo[:, 1], wo[:, 2], n, c)


@pytest.mark.parametrize("n", EXPONENTS)
@pytest.mark.parametrize("rows", [0, 1, 255, 256, 257, 3001])
def test_rows_kernel_is_the_kernel_bit_for_bit(rng, n, rows):
    wi, wo = _pairs(rng, rows)
    wo[: rows // 3] = 2 * wi[: rows // 3, 2:3] * np.array([0.0, 0.0, 1.0]) - wi[: rows // 3]  # mirror pairs: lit
    c = (n + 2) / (2 * np.pi)
    ref = _ufunc(wi, wo, n, c)
    for check in (True, False):
        out = np.full(rows, -7.0)
        assert phong._phong_rows(wi, wo, out, check, *_checks.unit_bounds(UNIT_TOL), n, c) == (-1, -1)
        np.testing.assert_array_equal(out, ref)
    if rows > 100:  # both branches were taken
        assert (ref > 0).any() and (ref == 0).any()


@pytest.mark.parametrize("n", EXPONENTS)
def test_rows_kernel_matches_numpy_reference(rng, n):
    wi, wo = _pairs(rng, 2000)
    wo[:700] = 2 * wi[:700, 2:3] * np.array([0.0, 0.0, 1.0]) - wi[:700]  # the lobe's peak
    wo[:700] += 1e-3 * rng.normal(size=(700, 3))
    wo[:700] /= np.linalg.norm(wo[:700], axis=-1, keepdims=True)
    c = (n + 2) / (2 * np.pi)
    out = np.empty(2000)
    phong._phong_rows(wi, wo, out, True, *_checks.unit_bounds(UNIT_TOL), n, c)
    ref = phong._phong_reference(wi, wo, n, c)
    np.testing.assert_allclose(out, ref, rtol=1e-12, atol=0)  # as every model's kernel (test_models_common)


def test_rows_kernel_non_finite_like_the_kernel(rng):
    """Without the check (_eval), a NaN or an infinity gives what the broadcasting kernel gives."""
    wi, wo = _pairs(rng, 600, below=False)
    wi[5, 0], wi[300, 2], wo[7, 1], wo[400, 2], wo[401, 0] = np.nan, np.inf, np.nan, -np.inf, np.inf
    for n in [0.0, 3.0, 10.5]:
        out = np.empty(600)
        phong._phong_rows(wi, wo, out, False, 1.0, 1.0, n, 2.0)
        with np.errstate(invalid="ignore"):
            np.testing.assert_array_equal(out, _ufunc(wi, wo, n, 2.0))


def test_rows_kernel_reports_the_first_bad_rows(rng):
    lo2, hi2 = _checks.unit_bounds(UNIT_TOL)
    for _ in range(50):
        rows = int(rng.integers(1, 1200))
        wi, wo = _pairs(rng, rows)
        for w in (wi, wo):
            for _ in range(rng.integers(0, 3)):
                i, k = rng.integers(0, rows), rng.integers(0, 3)
                w[i, k] = rng.choice([np.nan, np.inf, 1e200,
                                      w[i, k] * (1 + rng.choice([-1, 1]) * 10 ** rng.uniform(-7, -3))])
        with np.errstate(over="ignore", invalid="ignore"):
            want = tuple(int(np.argmax(b)) if b.any() else -1
                         for b in (_checks.off_unit_reference(wi, UNIT_TOL), _checks.off_unit_reference(wo, UNIT_TOL)))
            out = np.empty(rows)
            assert phong._phong_rows(wi, wo, out, True, lo2, hi2, 20.0, 1.0) == want
            assert phong._phong_rows(wi, wo, out, False, lo2, hi2, 20.0, 1.0) == (-1, -1)


def test_eval_uses_the_rows_kernel(rng):
    f = pumpup.load({"type": "phong", "n": 20})
    wi, wo = _pairs(rng, 10, below=False)
    assert f._rows(wi, wo) is not None
    assert f._rows(wi[::2], wo[::2]) is None and f._rows(wi[:1], wo) is None and f._rows(wi[0], wo[0]) is None
    assert pumpup.load({"type": "stretched_phong", "n": 20})._rows(wi, wo) is None  # Phong only, so far


def test_subclass_that_overrides_eval_is_not_bypassed(rng):
    """A Phong subclass with its own _eval: eval goes through it, not through the rows kernel."""
    base = pumpup.load({"type": "phong", "n": 20})

    class Doubled(type(base)):
        def _eval(self, wi, wo):
            return 2.0 * super()._eval(wi, wo)

    f = Doubled(n=20)
    v = rng.normal(size=(100, 3))
    v /= np.linalg.norm(v, axis=-1, keepdims=True)
    v[:, 2] = np.abs(v[:, 2])
    w = v[::-1].copy()
    np.testing.assert_array_equal(f.eval(v, w), 2.0 * base.eval(v, w))
