"""The compiled direction checks of as_directions (pumpup/core/checks.py) against their numpy twin,
and the messages of BRDF.eval for bad directions."""

import numpy as np
import pytest

import pumpup
from pumpup.core import UNIT_TOL
from pumpup.core import checks as _checks


def _unit(rng, n):
    v = rng.normal(size=(n, 3))
    return v / np.linalg.norm(v, axis=-1, keepdims=True)


def test_kernel_matches_numpy_reference(rng):
    for trial in range(200):
        v = _unit(rng, 50)
        for _ in range(rng.integers(0, 3)):
            i, k = rng.integers(0, 50), rng.integers(0, 3)
            v[i, k] = rng.choice([np.nan, np.inf, -np.inf, 1e200,
                                  v[i, k] * (1 + rng.choice([-1, 1]) * 10 ** rng.uniform(-8, -3))])
        assert _checks.first_bad(v, UNIT_TOL) == _checks.first_bad_reference(v, UNIT_TOL), v
    # the edge of the tolerance, both sides
    v = np.array([[0.0, 0.0, 1.0 + 0.999 * UNIT_TOL], [0.0, 0.0, 1.0 - 0.999 * UNIT_TOL],
                  [0.0, 0.0, 1.0 + 1.001 * UNIT_TOL]])
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
    with pytest.raises(ValueError,
                       match=r"^wo must be unit vectors \(\|w\| = 1 within 1e-06\); \|wo\[0, 1\]\| = 1\.1$"):
        f.eval(good, bad)
    with pytest.raises(ValueError, match=r"\|wi\[\]\| = 2$"):
        f.eval([0.0, 0.0, 2.0], [0.0, 0.0, 1.0])
    np.testing.assert_array_equal(f.eval(good, good[:, ::-1]), f._eval(good, good[:, ::-1]))
    # a non-contiguous view is checked as well
    with pytest.raises(ValueError, match="non-finite"):
        f.eval(np.concatenate([bad, np.full((2, 3, 3), np.inf)], axis=-1)[..., 3:], good)


def test_off_unit_matches_numpy_reference(rng):
    """The branch-free row check that models call inside their evaluation loops (BRDF.rows_kernel)."""
    lo2, hi2 = _checks.unit_bounds(UNIT_TOL)
    v = _unit(rng, 400)
    v[::7] *= 1 + rng.choice([-1, 1], size=(len(v[::7]), 1)) * 10 ** rng.uniform(-8, -4, size=(len(v[::7]), 1))
    v[3, 1], v[11, 0], v[19, 2], v[23, 0] = np.nan, np.inf, -np.inf, 1e200
    v = np.vstack([v, [[0.0, 0.0, 1.0 + 0.999 * UNIT_TOL], [0.0, 0.0, 1.0 - 0.999 * UNIT_TOL],
                       [0.0, 0.0, 1.0 + 1.001 * UNIT_TOL]]])
    got = np.array([_checks.off_unit(x, y, z, lo2, hi2) for x, y, z in v])
    ref = _checks.off_unit_reference(v, UNIT_TOL)
    np.testing.assert_array_equal(got, ref)
    assert ref[[3, 11, 19, 23]].all() and list(ref[-3:]) == [False, False, True]
    # the same rows as first_bad: a row fails off_unit exactly when first_bad would report it
    with np.errstate(over="ignore", invalid="ignore"):
        for k in range(len(v)):
            assert bool(ref[k]) == (_checks.first_bad(v[k : k + 1], UNIT_TOL) != (-1, -1))


def _pairs(rng, shape):
    wi, wo = _unit(rng, int(np.prod(shape))), _unit(rng, int(np.prod(shape)))
    wi[:, 2] = np.abs(wi[:, 2])
    return wi.reshape(*shape, 3), wo.reshape(*shape, 3)


@pytest.mark.parametrize("n_rows", [4000, 255, 256, 257])
def test_eval_messages_checked_in_the_evaluation_pass(rng, n_rows):
    """Phong's eval checks while it evaluates (rows_kernel): the same messages as as_directions, for a
    bad row in any block, wi before wo, a non-finite value before an earlier non-unit row."""
    f = pumpup.load({"type": "phong", "n": 20})
    assert type(f).rows_kernel is not None
    wi, wo = _pairs(rng, (n_rows,))
    last = n_rows - 1
    for arg, name in [(0, "wi"), (1, "wo")]:
        bad = [wi.copy(), wo.copy()]
        bad[arg][last // 2] *= 1.5
        with pytest.raises(ValueError, match=rf"^{name} must be unit vectors .*\|{name}\[{last // 2}\]\| = 1\.5$"):
            f.eval(*bad)
        bad[arg][last, 1] = np.nan
        with pytest.raises(ValueError, match=rf"^{name} contains non-finite values \(first at index \({last},\)\)$"):
            f.eval(*bad)
    bad_i, bad_o = wi.copy(), wo.copy()
    bad_i[last] *= 2.0
    bad_o[0, 0] = np.inf
    with pytest.raises(ValueError, match=r"^wi must be unit"):
        f.eval(bad_i, bad_o)  # wi first, as before, though wo's bad row comes earlier


def test_eval_error_order_unchanged(rng):
    """A bad wi is reported before a wrong shape of wo and before shapes that do not broadcast."""
    f = pumpup.load({"type": "phong", "n": 20})
    wi, wo = _pairs(rng, (5,))
    bad = wi.copy()
    bad[2, 0] = np.nan
    with pytest.raises(ValueError, match=r"^wi contains non-finite"):
        f.eval(bad, wo[:, :2])
    with pytest.raises(ValueError, match=r"^wi contains non-finite"):
        f.eval(bad, wo[:4])
    with pytest.raises(ValueError, match=r"^wo must have 3 components"):
        f.eval(wi, wo[:, :2])
    with pytest.raises(ValueError, match=r"^wi and wo must broadcast"):
        f.eval(wi, wo[:4])


def test_eval_paths_agree(rng):
    """The checked rows pass, the unchecked one (_eval) and the broadcasting kernel give the same
    values bit for bit, on every shape eval takes."""
    f = pumpup.load({"type": "phong", "n": 20})
    wi, wo = _pairs(rng, (3, 70))

    def ufunc(a, b):
        return f.kernel(a[..., 0], a[..., 1], a[..., 2], b[..., 0], b[..., 1], b[..., 2], *f.kernel_args())

    ref = ufunc(wi, wo)
    for a, b in [(wi, wo), (wi.tolist(), wo), (wi.astype(np.float32).astype(np.float64), wo)]:
        got = f.eval(a, b)
        assert got.shape == (3, 70)
        np.testing.assert_array_equal(got, ufunc(np.asarray(a, dtype=np.float64), wo))
    np.testing.assert_array_equal(f._eval(wi, wo), ref)
    np.testing.assert_array_equal(f.eval(wi[:, ::2], wo[:, ::2]), ref[:, ::2])  # not contiguous
    np.testing.assert_array_equal(f.eval(wi[:1], wo), ufunc(wi[:1], wo))  # broadcast
    np.testing.assert_array_equal(f.eval(wi[0, 0], wo[0]), ufunc(wi[0, 0], wo[0]))
    assert f.eval(np.empty((0, 3)), np.empty((0, 3))).shape == (0,)
    assert np.ndim(f.eval(wi[0, 0], wo[0, 0])) == 0
