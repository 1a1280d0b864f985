"""The 1-D albedo path of pumped Phong-family BRDFs (pumpup/_polar.py, ``Polar.chain``): the
closed-form azimuth of the base lobe outside, an inner rule on the arc for g(mu, N.wo) inside.

Checked against an independent quadrature about the normal (numpy's level-by-level reference of
the pumped BRDF, scipy), against the nested and the 2-D engines, and its error estimate against
the truth at every tolerance tested; and the pieces that the levels of g add to the outer
integral."""

import math
import warnings

import numpy as np
import pytest
from scipy.integrate import quad
from scipy.special import roots_legendre

import pumpup
from pumpup import _nested, _polar

# (0.8495: a wide piece that one first interval got wrong; 1e-8 and below: the tables' first node, and
# sin(theta_i) rounding to 1)
MU = np.array([1.0, 0.99, 0.9, 0.8494679351215211, 0.7, 0.5, 0.3, 0.1, 0.01, 1e-4, 1e-7, 1e-8, 5e-9, 1e-10])

CASES = [({"type": "phong", "n": 20}, "g2", 2), ({"type": "phong", "n": 20}, "g1", 1),
         ({"type": "stretched_phong", "n": 20}, "g2", 3), ({"type": "phong", "n": 5}, "g2", 2),
         ({"type": "stretched_phong", "n": 1000}, "g1", 2), ({"type": "stretched_phong", "n": 3}, "g1", 3)]


def _pumped(spec, g, levels):
    return pumpup.pump(spec, g=g, levels=levels)


def albedo_about_normal(f, mu, epsrel=1e-12):
    """a(mu) of the pumped Phong-family BRDF ``f`` in spherical coordinates about N, independent of
    the 1-D path: integral_0^1 N.wo dt integral over the azimuth phi of f.reference (numpy, the
    levels' g looked up one by one, no product table) by a 2 x 128-point Gauss-Legendre rule split
    where the lobe u = R.wo ends (u^n is analytic on each side), and scipy's quad in N.wo = t split
    at the kinks of g and at the breakpoints of every level's spline (g depends on t only, so the
    pieces are analytic; without the spline's breakpoints quad's estimate missed 4.6e-12 at
    mu = 0.5).  Returns (value, quad's error estimate)."""
    s = math.sqrt((1 - mu) * (1 + mu))
    wi = np.array([s, 0.0, mu])
    x, w = roots_legendre(128)
    x, w = 0.5 * (x + 1), 0.5 * w

    def inner(t):
        st = math.sqrt((1 - t) * (1 + t))
        # u = R.wo = mu t - s st cos(phi) (R = (-s, 0, mu)); u = 0 at cos(phi_c) = mu t / (s st)
        c = mu * t / (s * st) if s * st > 0 else 2.0
        phic = math.pi if c <= -1 else (0.0 if c >= 1 else math.acos(c))
        total = 0.0
        for lo, hi in ((0.0, phic), (phic, math.pi)):
            if hi <= lo:
                continue
            ph = lo + (hi - lo) * x
            wo = np.stack([st * np.cos(ph), st * np.sin(ph), np.full_like(ph, t)], axis=-1)
            total += (hi - lo) * np.dot(w, f.reference(wi, wo))
        return 2.0 * t * total  # phi in [-pi, pi]: twice [0, pi]

    knots = np.exp(np.concatenate([lev.lookup().logx for lev in f.chain()]))
    pts = sorted({float(v) for v in np.concatenate([f.lobe(mu).levels, knots]) if 0 < v < 1})
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return quad(inner, 0.0, 1.0, points=pts or None, epsabs=0, epsrel=epsrel, limit=2000)


def test_pumped_phong_family_takes_the_1d_path():
    for spec, g, levels in CASES:
        hint = _pumped(spec, g, levels).polar()
        assert hint is not None and hint.chain is not None, spec
    # no closed-form azimuth under the divisor: the nested engine, as before
    assert pumpup.pump({"type": "blinn", "n": 16}, g="g2").polar() is None
    assert pumpup.pump({"type": "lambert"}, g="g1").polar() is None


@pytest.mark.parametrize("case", CASES[:3], ids=lambda c: f"{c[0]['type']}-{c[0]['n']}-{c[1]}-{c[2]}")
def test_against_an_independent_quadrature_about_the_normal(case):
    f = _pumped(*case)
    mu = np.array([0.9, 0.5, 0.1])
    a, e = pumpup.albedo(f, mu, return_error=True, rtol=1e-12)
    for m, v, err in zip(mu, a, e):
        ref, ref_err = albedo_about_normal(f, float(m))
        # the BRDF divides by the product table, the reference by the levels one by one: they differ by
        # at most 2 epsilon ~ 4e-14 of the value (pumpup.pumping._Product)
        assert abs(v - ref) <= err + ref_err + 1e-13 * ref, (case, m, v, ref, err, ref_err)
        assert abs(v - ref) <= 5e-12 * ref


@pytest.mark.parametrize("case", CASES, ids=lambda c: f"{c[0]['type']}-{c[0]['n']}-{c[1]}-{c[2]}")
def test_estimate_bounds_the_truth_and_engines_agree(case, monkeypatch):
    """The 1-D path at rtol 1e-8 ... 1e-12 against the nested engine at 1e-13 (the 1-D path switched
    off alone; asserted to run): the difference within the summed estimates."""
    f = _pumped(*case)
    with monkeypatch.context() as m:
        m.setattr(_polar, "albedo_1d", lambda *a, **k: None)
        _nested.LAST_EVALS = None
        ref, ref_err = pumpup.albedo(f, MU, return_error=True, rtol=1e-13)
        assert _nested.LAST_EVALS is not None  # the nested engine ran
    for rtol in (1e-8, 1e-10, 1e-12):
        a, e = pumpup.albedo(f, MU, return_error=True, rtol=rtol)
        assert np.all(np.abs(a - ref) <= e + ref_err), (case, rtol, MU[np.argmax(np.abs(a - ref) / (e + ref_err))])
        assert np.all(e <= 1.0001 * rtol * a + 1e-14)


def test_against_the_2d_engine():
    f = _pumped({"type": "phong", "n": 20}, "g2", 3)
    mu = np.array([0.95, 0.6, 0.2, 1e-3])
    a, e = pumpup.albedo(f, mu, return_error=True, rtol=1e-11)
    with _polar.two_d_only():
        b, eb = pumpup.albedo(f, mu, return_error=True, rtol=1e-11)
    assert np.all(np.abs(a - b) <= e + eb), (a - b, e, eb)


def test_levels_of_g_include_where_a_bound_reaches_its_cap():
    """g = max(U(mu), u(v), ...) with u capped at 1: u(v) reaching the cap is a kink of g (the product
    table splits there; the hints once missed it and the 1-D path with them, by 1.8e-11)."""
    f = _pumped({"type": "phong", "n": 20}, "g2", 2)
    caps = []
    for lev in f.chain():
        lk = lev.lookup()
        grid = np.linspace(0.5, 1.0, 20001)
        cross = np.nonzero(np.diff(np.sign(lk.upper(grid, capped=False) - lk.cap)))[0]
        caps += [grid[i] for i in cross]
    assert caps  # the case has them
    levels = f.lobe(0.5).levels
    for c in caps:
        assert min(abs(lv - c) for lv in levels) < 1e-4, (c, levels)


def test_level_rows_and_the_arc_cut():
    """(L, 1 - u_A, 1 - u_B): the circle of the lobe crosses N.wo = L exactly for u in (u_A, u_B), and
    (u_B - u)(u - u_A) = b^2 - (L - a)^2 (the cut's b sin(beta_L), without cancellation)."""
    rng = np.random.default_rng(3)
    for mu in (0.9, 0.5, 0.05):
        s = math.sqrt(1 - mu * mu)
        levels = np.concatenate([[mu], rng.uniform(0.01, 0.999, 6)])
        rows = _polar.level_rows(levels, mu)
        for L, uma, umb in rows:
            ua, ub = 1 - uma, 1 - umb
            for u in rng.uniform(0, 1, 50):
                a, b = mu * u, s * math.sqrt(1 - u * u)
                assert math.isclose((ub - u) * (u - ua), b * b - (L - a) ** 2, abs_tol=1e-13)
                crosses = a - b < L < a + b
                assert crosses == (ua < u < ub) or min(abs(u - ua), abs(u - ub)) < 1e-12


def test_pieces_cut_at_every_level():
    """The outer pieces tile u in [0, 1]; each level's u_A, u_B is a piece end, smoothed on the side
    where the level cuts the circle (its square-root end)."""
    n, mu = 20.0, 0.6
    s = math.sqrt(1 - mu * mu)
    lev = _polar.level_rows([mu, 0.3, 0.95, 0.9999], mu)
    size = _polar.MAX_PIECES + 2 * len(lev)
    kinds, sms = np.empty(size, np.int64), np.empty(size, np.int64)
    v0, w, v1 = np.empty(size), np.empty(size), np.empty(size)
    k, _, _ = _polar._pieces(n, 0.0, mu, s, kinds, sms, v0, w, v1, lev, len(lev))

    def u_of(kind, v):
        return v if kind == 0 else math.exp(-v / (n + 1))

    ends = []  # (u at the piece's lower end in u, u at its upper end, smoothed there?)
    for i in range(k):
        a, b = u_of(kinds[i], v0[i]), u_of(kinds[i], v1[i])
        left, right = bool(sms[i] & 1), bool(sms[i] & 2)
        if kinds[i] == 1:  # z runs against u
            a, b, left, right = b, a, right, left
        ends.append((a, b, left, right))
    ends.sort()
    assert ends[0][0] == 0.0 and abs(ends[-1][1] - 1.0) < 1e-15
    assert all(abs(p[1] - q[0]) < 1e-12 for p, q in zip(ends, ends[1:]))  # a tiling
    for _, uma, umb in lev:
        for u, inside_above in ((1 - uma, True), (1 - umb, False)):
            if not 0 < u < 1:
                continue
            at = [e for e in ends if abs(e[0] - u) < 1e-12 or abs(e[1] - u) < 1e-12]
            assert at, u
            # smoothing on the side where the level cuts the circle: above u_A, below u_B
            assert any((abs(e[0] - u) < 1e-12 and e[2]) if inside_above else (abs(e[1] - u) < 1e-12 and e[3]) for e in at), (u, at)
