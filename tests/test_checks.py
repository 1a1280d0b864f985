"""The compiled direction checks of as_directions (pumpup/_checks.py) against their numpy twin,
and the messages of BRDF.eval for bad directions."""

import numpy as np
import pytest

import pumpup
from pumpup import _checks
from pumpup.core import UNIT_TOL


def _unit(rng, n):
    v = rng.normal(size=(n, 3))
    return v / np.linalg.norm(v, axis=-1, keepdims=True)


def test_kernel_matches_numpy_reference(rng):
    for trial in range(200):
        v = _unit(rng, 50)
        for _ in range(rng.integers(0, 3)):
            i, k = rng.integers(0, 50), rng.integers(0, 3)
            v[i, k] = rng.choice([np.nan, np.inf, -np.inf, 1e200, v[i, k] * (1 + rng.choice([-1, 1]) * 10 ** rng.uniform(-8, -3))])
        assert _checks.first_bad(v, UNIT_TOL) == _checks.first_bad_reference(v, UNIT_TOL), v
    # the edge of the tolerance, both sides
    v = np.array([[0.0, 0.0, 1.0 + 0.999 * UNIT_TOL], [0.0, 0.0, 1.0 - 0.999 * UNIT_TOL], [0.0, 0.0, 1.0 + 1.001 * UNIT_TOL]])
    assert _checks.first_bad(v, UNIT_TOL) == (-1, 2) == _checks.first_bad_reference(v, UNIT_TOL)


def test_eval_messages(rng):
    f = pumpup.load({"type": "phong", "n": 20})
    good = _unit(rng, 6).reshape(2, 3, 3)
    good[..., 2] = np.abs(good[..., 2])
    bad = good.copy()
    bad[1, 2, 0] = np.nan
    bad[0, 1] *= 1.1  # a non-unit row before the NaN: the NaN is reported (as before)
    with pytest.raises(ValueError, match=r"^wi contains non-finite values \(first at index \(1, 2\)\)$"):
        f.eval(bad, good)
    bad[1, 2, 0] = 0.5
    with pytest.raises(ValueError, match=r"^wo must be unit vectors \(\|w\| = 1 within 1e-06\); \|wo\[0, 1\]\| = 1\.1$"):
        f.eval(good, bad)
    with pytest.raises(ValueError, match=r"\|wi\[\]\| = 2$"):
        f.eval([0.0, 0.0, 2.0], [0.0, 0.0, 1.0])
    np.testing.assert_array_equal(f.eval(good, good[:, ::-1]), f._eval(good, good[:, ::-1]))
    # a non-contiguous view is checked as well
    with pytest.raises(ValueError, match="non-finite"):
        f.eval(np.concatenate([bad, np.full((2, 3, 3), np.inf)], axis=-1)[..., 3:], good)
