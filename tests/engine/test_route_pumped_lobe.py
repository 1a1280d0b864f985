"""The 1-D albedo path of pumped Phong-family BRDFs (pumpup/engine/polar.py, ``Polar.chain``): the
closed-form azimuth of the base lobe outside, an inner rule on the arc for g(mu, N.wo) inside.

Checked against an independent quadrature about the normal (numpy's level-by-level reference of
the pumped BRDF, scipy), against the nested and the 2-D engines, and its error estimate against
the truth at every tolerance tested; and the pieces that the levels of g add to the outer
integral."""

import math
import warnings

import helpers
import numpy as np
import pytest
from scipy.integrate import quad
from scipy.special import roots_legendre

import pumpup
from pumpup.engine import chain_frame as _chain_frame
from pumpup.engine import half_arc as _half_arc
from pumpup.engine import lobe_frame as _lobe_frame
from pumpup.engine import nested as _nested
from pumpup.engine import outer_rule as _outer_rule

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
        f = _pumped(spec, g, levels)
        assert helpers.takes_1d(f) and helpers.view(f).chain is not None, spec
    # no closed-form azimuth under the divisor: the nested engine, as before
    assert not helpers.hint_routes(pumpup.pump({"type": "blinn", "n": 16}, g="g2"))
    assert not helpers.hint_routes(pumpup.pump({"type": "lambert"}, g="g1"))


@pytest.mark.parametrize("case", CASES[:3], ids=lambda c: f"{c[0]['type']}-{c[0]['n']}-{c[1]}-{c[2]}")
def test_against_an_independent_quadrature_about_the_normal(case):
    f = _pumped(*case)
    mu = np.array([0.9, 0.5, 0.1])
    a, e = pumpup.albedo(f, mu, return_error=True, rtol=1e-12)
    for m, v, err in zip(mu, a, e):
        ref, ref_err = albedo_about_normal(f, float(m))
        # the BRDF divides by the product table, the reference by the levels one by one: they differ by
        # at most 2 epsilon ~ 4e-14 of the value (pumpup.operators.pumping._Product)
        assert abs(v - ref) <= err + ref_err + 1e-13 * ref, (case, m, v, ref, err, ref_err)
        assert abs(v - ref) <= 5e-12 * ref


@pytest.mark.parametrize("case", CASES, ids=lambda c: f"{c[0]['type']}-{c[0]['n']}-{c[1]}-{c[2]}")
def test_estimate_bounds_the_truth_and_engines_agree(case, monkeypatch):
    """The 1-D path at rtol 1e-8 ... 1e-12 against the nested engine at 1e-13 (the 1-D path switched
    off alone; asserted to run): the difference within the summed estimates."""
    f = _pumped(*case)
    with monkeypatch.context(), helpers.without_1d():
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
    with helpers.two_d_only():
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


def _v_reference(n, kappa):
    """V(kappa) = integral over phi in (-pi, pi] of (1 - kappa sin^2(phi / 2))_+^n, independently: for
    kappa <= 1 and integer n the finite sum 2 pi sum_k C(n, k) (-kappa)^k (2k)! / (4^k k!^2) (the mean of
    sin^2k(phi / 2) over the circle; n <= 30) in 40-digit mpmath, otherwise mpmath's tanh-sinh quadrature (which
    takes the end where the lobe vanishes, (phi0 - phi)^n, in its stride)."""
    mpmath = pytest.importorskip("mpmath")
    with mpmath.workdps(40):
        k = mpmath.mpf(kappa)
        if k <= 1 and float(n).is_integer() and n <= 30:  # (beyond, the alternating sum cancels)
            return float(2 * mpmath.pi * mpmath.fsum(mpmath.binomial(int(n), j) * (-k) ** j * mpmath.factorial(2 * j)
                                                    / (4 ** j * mpmath.factorial(j) ** 2) for j in range(int(n) + 1)))
        phi0 = mpmath.pi if k <= 1 else 2 * mpmath.asin(1 / mpmath.sqrt(k))
        sig = mpmath.sqrt(2 / (n * k)) if k > 0 else phi0
        pts = [0] + [sig * 2 ** j for j in range(8) if sig * 2 ** j < phi0] + [phi0]  # the peak's widths
        return float(2 * mpmath.quad(lambda ph: max(0, 1 - k * mpmath.sin(ph / 2) ** 2) ** n, pts))


@pytest.mark.parametrize("n", [0.5, 1.0, 3.0, 20.0, 1000.0, 1e6])
def test_ring_table_against_mpmath(n):
    """The lobe u^n on a circle N.wo = t is (A + B)^n V(kappa): the ring table's V (Chebyshev pieces, or the
    quadrature where a piece next to kappa = 1 could not be fitted) against 40-digit references, within
    its own error and 1e-13; the table covers [0, 2] without gaps.  (n = 1e6, kappa = 0.95: the quadrature
    once cut the half-arc only at 4 widths, and the rule beyond saw zeros at its nodes: 6.3e-5 off.)"""
    kb, kc, keps = _chain_frame.ring_table(n)
    assert kb[0] == 0.0 and kb[-1] == 2.0 and np.all(np.diff(kb) > 0)
    nodes, wk, wg = _outer_rule._RULES["gk21"]
    ibuf, iwork = np.empty(21), np.empty((5, _lobe_frame.INNER_MAX))
    rng = np.random.default_rng(int(n * 10))
    kappas = np.concatenate([[0.0, 1e-9, 0.3, 0.95, 1.0 - 1e-7, 1.0, 1.0 + 1e-7, 1.5, 2.0], rng.uniform(0, 2, 12),
                             1.0 + rng.uniform(-1e-5, 1e-5, 4)])
    for kappa in kappas:
        v, e = _chain_frame._ring_at(kappa, kb, kc, keps)
        if e < 0:  # a piece left to quadrature
            v, e = _chain_frame._ring_quad(n, kappa, 1e-15, nodes, wk, wg, ibuf, iwork)
        ref = _v_reference(n, kappa)
        assert abs(v - ref) <= e + 1e-15 * ref, (n, kappa, v, ref, e)
        assert e <= 1e-13 * ref, (n, kappa, e)


def test_chain_cuts():
    """The elevation's cuts: the ends, every level of g, N.wo = mu and s, the peak's theta_i +- 3, 8 and 13
    over sqrt(n) where they fall inside, N.wo = 1/2, 1/8, ... (g's tables are splines in ln N.wo), every
    pi / 16, and for small n a grading towards x_s; sorted, no duplicates."""
    mu, n = 0.3, 200.0
    s = math.sqrt(1 - mu * mu)
    levels = (mu, 0.95, 0.999)
    x = _chain_frame.chain_cuts(levels, n, mu)
    assert x[0] == 0.0 and x[-1] == 0.5 * math.pi and np.all(np.diff(x) > 0)
    xmu = math.atan2(mu, s)
    want = [math.asin(v) for v in levels] + [xmu, math.atan2(s, mu), math.asin(0.5), math.asin(0.125)]
    want += [xmu + k / math.sqrt(n) for k in (-3, 3, -8, 8, -13, 13) if 0 < xmu + k / math.sqrt(n) < 0.5 * math.pi]
    want += [k * math.pi / 16 for k in range(1, 8)]
    for w in want:
        assert np.min(np.abs(x - w)) < 1e-14, w
    assert np.min(np.abs(x - math.asin(0.25 * 0.125))) > 1e-3  # no grading below a quarter of mu
    few = _chain_frame.chain_cuts(levels, 2.0, mu)  # small n: graded towards x_s on both sides
    xs = math.atan2(s, mu)
    for d in (0.125, 0.5 * 0.25 ** 5):
        assert np.min(np.abs(few - (xs - d))) < 1e-14 and np.min(np.abs(few - (xs + d))) < 1e-14
    assert np.min(np.abs(few - (xs - 0.5))) < 1e-14 and few[-1] == 0.5 * math.pi  # (xs + 0.5 is beyond pi / 2)
    assert np.min(np.abs(x - (xs - 0.125))) > 1e-3  # n = 200: no grading


def test_compiled_chain_cuts_are_chain_cuts():
    """The compiled cuts the engine uses (:func:`pumpup.engine.chain_frame.chain_cut_matrix`) are chain_cuts, value for
    value: pumped lobes, a pumped metal (F's cuts), a pumped GGX and a 1/E-scaled one (frame 6, n = 0), and a metal's
    lobe about N (no chain: no levels but mu, no grading for g), from normal incidence to 1e-300; each cut of either
    within 2 ulps of one of the other (numpy's vectorised arctan2 and the scalar one may differ in the last bit, so a
    level mu and x_mu can be two cuts in one, one in the other)."""

    def same(a, b):
        return all(np.min(np.abs(b - v)) <= 4.5e-16 for v in a) and all(np.min(np.abs(a - v)) <= 4.5e-16 for v in b)

    mu = np.r_[np.cos(np.linspace(0, np.pi / 2, 33)[:-1]), 1e-3, 1e-9, 1e-300]
    cases = [(pumpup.pump({"type": "phong", "n": 20}, g="g2", levels=2), None, True),
             (pumpup.pump({"type": "stretched_phong", "n": 2.0, "p": 0.5}), None, True),
             (pumpup.pump({"type": "metal", "n": 20, "eta": 0.2, "k": 3.0}), (0.2, 3.0), True),
             (pumpup.pump({"type": "ggx", "alpha": 0.3}, g="g2"), None, True),
             (pumpup.compensate({"type": "schlick", "r": 0.2}, method="scale"), None, True)]
    for f, fres, chain in cases:
        hint = helpers.view(f)
        n = 0.0 if hint.kind == "half" else float(hint.n)
        cut, ncut = _chain_frame.chain_cut_matrix(hint.levels, n, mu, fres, chain)
        for q, m in enumerate(mu):
            assert same(cut[q, :ncut[q]],
                        _chain_frame.chain_cuts(hint.levels(float(m)), n, float(m), fres, chain)), (f, m)
    # (the compiled kernel's room per mu: 4 fixed, 6 about the peak, 2 x 15 towards x_s, 20 graded,
    # the pi / 16 ones, F's)
    assert _chain_frame.CHAIN_CUTS_ROOM >= 4 + 6 + 30 + 20 + _chain_frame.X_PIECES - 1 + 3 * _half_arc.LOBE_F_CUTS
    for n in (0.0, 2.0, 20.0, 500.0):
        for eta, k in ((0.2, 3.0), (1.5, 0.0), (1.1, 30.0), (0.6, 0.3), (0.999, 0.001)):
            cut, ncut = _chain_frame.chain_cut_matrix(None, n, mu, (eta, k), chain=False)
            for q, m in enumerate(mu):
                assert same(cut[q, :ncut[q]],
                            _chain_frame.chain_cuts([], n, float(m), (eta, k), chain=False)), (n, eta, k, m)


def test_pumped_plastic_takes_the_chain_path():
    """Plastic without Fresnel (000 eq. 30) has stretched Phong's lobe, so its pumped levels take the 1-D
    path about N (pumpup.engine.chain_frame._integrate_chain); against the nested engine on the same BRDFs (their tables
    built first) at rtol 1e-12."""
    mu = np.array([1.0, 0.7, 0.3, 0.05, 1e-3])
    for g in ("g1", "g2"):
        f = pumpup.pump({"type": "plastic", "n": 20, "ad": 0.0, "a_s": 0.9}, g=g, levels=2)
        assert helpers.hint_routes(f) and helpers.view(f).chain is not None
        a, e = pumpup.albedo(f, mu, return_error=True)
        with helpers.without_1d(), warnings.catch_warnings():
            warnings.simplefilter("ignore")
            b, eb = pumpup.albedo(f, mu, return_error=True, rtol=1e-12)
        assert np.all(np.abs(a - b) <= e + eb), (g, (np.abs(a - b) / (e + eb)).max())


def _v_closed_form(n, kappa):
    """V(kappa) in closed form, in 40-digit mpmath: 2 pi 2F1(-n, 1/2; 1; kappa) for kappa <= 1 (the mean of
    (1 - kappa sin^2 theta)^n over theta in [0, pi / 2]), and for kappa > 1, where the arc ends at
    sin(phi0 / 2) = 1 / sqrt(kappa), 2 / sqrt(kappa) B(1/2, n + 1) 2F1(1/2, 1/2; n + 3/2; 1 / kappa) (sin(phi / 2)
    = sin(theta) / sqrt(kappa), the series of (1 - sin^2(theta) / kappa)^(-1/2) term by term)."""
    mpmath = pytest.importorskip("mpmath")
    with mpmath.workdps(40):
        k = mpmath.mpf(kappa)
        if k <= 1:
            return float(2 * mpmath.pi * mpmath.hyp2f1(-n, 0.5, 1, k))
        return float(2 / mpmath.sqrt(k) * mpmath.beta(0.5, n + 1) * mpmath.hyp2f1(0.5, 0.5, n + 1.5, 1 / k))


@pytest.mark.parametrize("n", [0.127, 0.5, 0.9, 1.5, 3.7])
def test_ring_quadrature_at_the_end_of_the_arc(n):
    """V by quadrature (what the ring table leaves next to kappa = 1, and the table's own values) with the work
    arrays the engine gives it, within 1e-14 and its own error of V's closed form, where the integrand's derivative
    is unbounded at the arc's end ((phi0 - phi)^n for kappa > 1, (pi - phi)^(2n) at kappa = 1) or bends within
    sqrt(1 - kappa) of it.  (n = 0.127 at kappa = 1 was 5.8e-11 off with the estimate 3.1e-13 when the arc's end was
    bisected in phi.)"""
    assert _v_closed_form(n, 1.0) == pytest.approx(2 * math.sqrt(math.pi) * math.gamma(n + 0.5) / math.gamma(n + 1),
                                                   rel=1e-15)  # (Gauss's sum at 1)
    nodes, wk, wg = _outer_rule._RULES["gk21"]
    ibuf, iwork = np.empty(21), np.empty((4, _lobe_frame.INNER_MAX))
    for kappa in [0.5, 0.99, 1 - 1e-3, 0.9995, 1 - 1e-6, 1 - 1e-9, 1 - 1e-13, 1.0, 1 + 1e-15, 1 + 1e-13, 1 + 1e-9,
                  1 + 1e-6, 1.01, 1.5, 1.9, 2.0]:
        v, e = _chain_frame._ring_quad(n, kappa, 1e-15, nodes, wk, wg, ibuf, iwork)
        ref = _v_closed_form(n, kappa)
        assert abs(v - ref) <= e, (n, kappa, v, ref, e)
        assert e <= 1e-14 * ref, (n, kappa, e / ref)
