"""The ``lobe`` route's sharper error estimate (pumpup/engine/outer_rule.py, ``DECAY_ROWS``): the closed forms' 21-point
rule estimates its error from the decay of its coefficients, never faster than the nearest singular point of K(u) lets
them decay.  Its compiled parts against their numpy twins, the estimate against the true error of test functions and of
the independent mpmath references, the saving on Phong n = 20's 257-point table, and a table that is the same whatever
the batch or the number of threads it was computed in."""

import math

import numpy as np
import pytest
from helpers import BareLobe, phong_albedo_1d

import pumpup
from pumpup.engine import outer_rule as _outer
from pumpup.engine import polar as _polar
from pumpup.physics.quadrature import calibrated_reference

TABLE_MU = np.sin(np.radians(90.0 - np.linspace(0.0, 89.99, 257)))  # (scripts/bench/bench_polar.py's table)


def _compiled_estimate(f):
    top, r = _outer._decay_ratio(np.ascontiguousarray(f, dtype=float), _outer.DECAY_ROWS, np.empty((2, 11)))
    return math.inf if r > _outer.DECAY_RCRIT else _outer.DECAY_SAFETY * top * r**_outer.DECAY_STEPS


def test_decay_ratio_matches_its_numpy_twin(rng):
    x = _outer.NODES21
    cases = [rng.standard_normal(21), np.exp(-14.6 * x), 1.0 / (1.3 - x), np.cos(20 * x), np.zeros(21),
             np.sqrt(x + 0.1), np.exp(-50 * (x - 0.5) ** 2)]
    finite = 0
    for f in cases:
        got, want = _compiled_estimate(f), _outer.decay_error_reference(f)
        if math.isinf(want):
            assert math.isinf(got)
        else:
            finite += 1
            assert got == pytest.approx(want, rel=1e-6, abs=1e-300)  # (r^6 carries the sums' rounding)
    assert finite >= 4  # (the smooth ones decay fast enough to be estimated)


def test_rows_are_the_orthonormal_polynomials_of_the_kronrod_rule():
    """Row k takes the values of the degree-(13 + k) orthonormal polynomial to 1 and every lower degree to 0."""
    x = 2.0 * _outer.NODES21 - 1.0
    for deg in range(21):
        c = _outer.DECAY_ROWS @ np.polynomial.legendre.legval(x, np.eye(21)[deg])
        if deg < _outer.DECAY_LOW:
            np.testing.assert_allclose(c, 0.0, atol=1e-12)
        else:
            assert abs(c[deg - _outer.DECAY_LOW]) > 0.1
            np.testing.assert_allclose(c[deg - _outer.DECAY_LOW + 1:], 0.0, atol=1e-12)


@pytest.mark.parametrize("kind,n", [(0, 20.0), (0, 2.5), (1, 0.0), (1, 20.0), (1, 5000.0)])
@pytest.mark.parametrize("p", [0.0, 1.0])
def test_singular_ratio_matches_its_twin(rng, kind, n, p):
    sing = np.empty((4, 6))
    for _ in range(60):
        mu = float(rng.choice([rng.uniform(0.0, 1.0), math.sqrt(3) / 2 * (1 + 1e-3 * rng.standard_normal()),
                               10.0 ** rng.uniform(-8, 0)]))
        s = math.sqrt((1 - mu) * (1 + mu))
        c2 = (mu - s) * (mu + s)
        v0 = float(rng.uniform(0.0, 0.5) if kind == 0 else rng.uniform(0.0, 20.0))
        w = float(rng.uniform(1e-3, 0.5) if kind == 0 else 10.0 ** rng.uniform(-2, 1.5))
        t0 = float(rng.uniform(0.0, 0.9))
        t1 = float(rng.uniform(t0 + 1e-3, 1.0))
        for sm in (0, 1, 2, 3):
            _outer._singular_points(n, p, mu, c2, sing)
            got = _outer._singular_ratio(kind, sm, v0, w, t0, t1, 0.0, sing)
            want = _outer.singular_ratio_reference(kind, sm, n, p, mu, c2, v0, w, t0, t1)
            assert got == pytest.approx(want, rel=1e-9, abs=1e-300), (kind, sm, n, p, mu, v0, w, t0, t1)
            # from a floor r0: the largest of r0 and the points' (points below r0 are skipped, the result is the same)
            r0 = 0.1
            assert _outer._singular_ratio(kind, sm, v0, w, t0, t1, r0, sing) == pytest.approx(max(r0, want), rel=1e-9)


def _pole(c):  # (f, exact integral on [0, 1], rho^-2 of the singular point for the rule on [0, 1])
    y = 2.0 * c - 1.0
    rho = y + math.sqrt(y * y - 1.0)
    return (lambda x: 1.0 / (c - x)), math.log(c / (c - 1.0)), 1.0 / rho**2


TEST_FUNCTIONS = {
    **{f"exp{k}": ((lambda x, k=k: k * np.exp(-k * x)), -math.expm1(-k), 0.0) for k in (5, 14.6, 20, 30, 40, 60)},
    **{f"cos{k}": ((lambda x, k=k: np.cos(k * x)), math.sin(k) / k, 0.0) for k in (10, 20, 30, 40)},
    **{f"pole{c}": _pole(c) for c in (1.001, 1.05, 1.1, 1.3, 2.0)},
    **{f"sqrt{c}": ((lambda x, c=c: np.sqrt(x + c)), 2 / 3 * ((1 + c) ** 1.5 - c**1.5), _pole(1.0 + c)[2])
       for c in (1e-3, 0.05, 0.1, 0.3)},
    **{f"runge{a}": ((lambda x, a=a: 1.0 / (1.0 + a * a * (x - 0.5) ** 2)), 2.0 * math.atan(a / 2) / a, 0.0)
       for a in (1, 5, 20)},
}


@pytest.mark.parametrize("name", list(TEST_FUNCTIONS))
def test_estimate_bounds_the_error_of_test_functions(name):
    """The smaller of QUADPACK's estimate and the sharper one (with rho^-2 of the function's singular point, where it
    has one) is at least the 21-point rule's true error."""
    fn, exact, rho2 = TEST_FUNCTIONS[name]
    x = _outer.NODES21
    f = fn(x)
    k = float(_outer.WK21 @ f)
    g = float(_outer.WG21 @ f)
    quadpack = calibrated_reference(abs(k - g), float(_outer.WK21 @ np.abs(f - k)), float(_outer.WK21 @ np.abs(f)))
    sharper = _outer.decay_error_reference(f, rho2)
    estimate = max(min(quadpack, sharper), 50 * 2.220446049250313e-16 * float(_outer.WK21 @ np.abs(f)))
    assert abs(k - exact) <= estimate, (name, abs(k - exact), estimate, quadpack, sharper)


def test_estimate_is_sharper_where_the_integrand_is_smooth():
    """e^-14.6 x, Phong n = 20's peak piece near normal incidence: QUADPACK's 2e-10, the sharper one at the floor."""
    f = 14.6 * np.exp(-14.6 * _outer.NODES21)
    assert _outer.decay_error_reference(f) < 1e-13


def test_nearly_coinciding_breaks_of_the_table():
    """Stretched Phong n = 10 at the 257-point table's mu = 0.8640 (the level's break 3 % of the peak piece beyond its
    end): without the singular points' rho^-2 the sharper estimate was 1.6e-14 against a true error of 2.4e-14."""
    mu = np.array([TABLE_MU[86], TABLE_MU[85], TABLE_MU[87]])
    refs = [phong_albedo_1d(10, m, stretched=True) for m in mu]
    for rtol in (1e-8, 1e-10, 1e-12):
        a, e, conv, _ = _polar.albedo_1d(BareLobe(10, 1.0), mu, rtol, 0.0, 20000)
        assert conv.all()
        for m, v, err, (ref, ref_err) in zip(mu, a, e, refs):
            assert abs(v - ref) <= err + ref_err, (m, rtol, v - ref, err)


@pytest.mark.parametrize("n,p", [(20, 0), (20, 1), (5000, 0), (2.5, 0)])
def test_against_mpmath_on_the_table(n, p):
    """Every 16th mu of the 257-point table, at rtol 1e-6 and 1e-10: the estimate bounds the true error."""
    mu = TABLE_MU[::16]
    refs = [phong_albedo_1d(n, m, stretched=bool(p)) for m in mu]
    for rtol in (1e-6, 1e-10):
        a, e, conv, _ = _polar.albedo_1d(BareLobe(n, p), mu, rtol, 0.0, 20000)
        assert conv.all()
        for m, v, err, (ref, ref_err) in zip(mu, a, e, refs):
            assert abs(v - ref) <= err + ref_err, (n, p, m, rtol, v - ref, err)


def test_fewer_evaluations_on_phong_20_and_the_same_values_within_the_errors():
    hint = pumpup.load({"type": "phong", "n": 20}).azimuth_hint()
    vo, eo, co, evo = _polar.run("lobe", hint, TABLE_MU, 1e-10, 0.0, 10000, decay_estimate=False)
    vn, en, cn, evn = _polar.run("lobe", hint, TABLE_MU, 1e-10, 0.0, 10000)
    assert co.all() and cn.all()
    assert np.all(np.abs(vn - vo) <= en + eo)
    assert np.all(en <= 1e-10 * np.abs(vn))
    assert evn.mean() <= 0.9 * evo.mean()  # (measured: 84.7 against 99.2 per mu)
    assert evn.mean() <= 4.1 * 21  # one rule per piece: about 4 pieces per mu


@pytest.mark.parametrize("spec", [{"type": "phong", "n": 20}, {"type": "stretched_phong", "n": 20},
                                  {"type": "retro", "n": 10}])
def test_values_do_not_depend_on_the_batch(spec):
    """Each mu's value and error are the same whether it is computed alone, with the whole table or with every third
    mu (what a thread of ``tabulate`` gets)."""
    hint = pumpup.load(spec).azimuth_hint()
    whole = _polar.run("lobe", hint, TABLE_MU, 1e-10, 0.0, 10000)[:2]
    for part in (slice(0, None, 3), slice(1, None, 3), slice(None, None, -1)):
        got = _polar.run("lobe", hint, TABLE_MU[part], 1e-10, 0.0, 10000)[:2]
        for g, w in zip(got, whole):
            np.testing.assert_array_equal(g, w[part])
    for i in (0, 86, 200, 256):
        alone = _polar.run("lobe", hint, TABLE_MU[i:i + 1], 1e-10, 0.0, 10000)[:2]
        assert (alone[0][0], alone[1][0]) == (whole[0][i], whole[1][i])


@pytest.mark.parametrize("threads", [1, 3])
def test_lobe_table_is_the_same_on_any_number_of_threads(threads):
    """A table on the ``lobe`` route computed in one thread and in several: bitwise the same."""
    f = pumpup.load({"type": "phong", "n": 20})
    one = pumpup.tabulate(f, mu=TABLE_MU, rtol=1e-10, threads=1)
    other = pumpup.tabulate(f, mu=TABLE_MU, rtol=1e-10, threads=threads + 1)
    for name in ("mu", "albedo", "albedo_error"):
        np.testing.assert_array_equal(other[name].values, one[name].values)


def test_off_by_choice():
    """``using(decay_estimate=False)`` gives QUADPACK's estimate alone: the values and errors of that path."""
    from pumpup.engine.routes import using

    f = pumpup.load({"type": "phong", "n": 20})
    mu = TABLE_MU[::8]
    with using(decay_estimate=False):
        a_off, e_off = pumpup.albedo(f, mu, rtol=1e-10, return_error=True)
    v, e, _, _ = _polar.run("lobe", f.azimuth_hint(), mu, 1e-10, 0.0, 10000, decay_estimate=False)
    np.testing.assert_array_equal(a_off, v)
    np.testing.assert_array_equal(e_off, e)
    a_on, e_on = pumpup.albedo(f, mu, rtol=1e-10, return_error=True)
    assert np.all(np.abs(a_on - a_off) <= e_on + e_off)

