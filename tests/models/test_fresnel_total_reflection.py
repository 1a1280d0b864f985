"""A Fresnel factor F(eta + i k, max(N.wi, N.wo)) with eta < 1 and k = 0 (a dielectric seen from its denser side) is 1
up to cos = x0 = sqrt(1 - eta^2), total reflection, and has a square-root kink there; a small k makes it a near-kink.
The 1-D path declines such a factor and the nested engine, blind to the kink, bisected towards it: fresnel over Blinn
n = 5, eta = 0.551 took 0.25-0.41 s per value at rtol 1e-10, a pumped one's base table minutes
(``scripts/studies/fuzz_engines.py --registry``).  The hints carry the level N.wo = x0
(:func:`pumpup.models.metal.fresnel_levels`) and the albedo's kink at mu = x0 (``BRDF.albedo_breaks``).  The values are
checked against an independent quadrature in spherical coordinates about N split at the kink."""

import math

import helpers
import numpy as np
import pytest
from helpers import rings

import pumpup
from pumpup.models.metal import fresnel_levels
from pumpup.operators import pumping

ETA = 0.551
X0 = math.sqrt(1.0 - ETA * ETA)


def test_fresnel_levels():
    assert fresnel_levels(ETA, 0.0) == pytest.approx((X0,), rel=1e-15)
    assert fresnel_levels(1.5, 0.0) == ()  # no total reflection above eta = 1
    assert fresnel_levels(0.2, 3.0) == ()  # a metal: the branch point far from the real axis
    (x,) = fresnel_levels(0.55, 0.01)  # a near-kink
    assert abs(x - 0.8352) < 1e-3
    assert fresnel_levels(0.5, 0.1) == ()  # 0.057 off the axis: a smooth factor


@pytest.mark.parametrize("spec", [{"type": "metal", "n": 5.0, "eta": ETA},
                                  {"type": "plastic", "n": 5.0, "eta": ETA, "ad": 0.2, "a_s": 0.7},
                                  {"type": "fresnel", "base": {"type": "blinn", "n": 5.0}, "eta": ETA},
                                  {"type": "mix", "a": {"type": "lambert"},
                                   "b": {"type": "metal", "n": 5.0, "eta": ETA}}],
                         ids=lambda s: s["type"])
def test_hints_carry_the_kink(spec):
    f = pumpup.load(spec)
    assert f.albedo_breaks() == pytest.approx((X0,), rel=1e-15)
    if spec["type"] != "mix":
        assert any(abs(u - X0) < 1e-15 for u in f.lobe(0.3).levels)
    assert f.albedo_kinks(*pumping.grid_interior()) == pytest.approx([X0], rel=1e-15)  # its tables are split there
    assert pumpup.load({"type": "lambert"}).albedo_kinks(*pumping.grid_interior()) is None


@pytest.mark.parametrize("n", [0.358, 5.0])
@pytest.mark.parametrize("mu", [0.01, 0.3, 0.7, 0.9])
def test_fresnel_over_blinn_with_total_reflection(n, mu):
    """Reference: quad over mu_o split at mu and x0 (F's kinks), Gauss-Legendre in phi_o (Blinn is smooth in it)."""
    f = pumpup.load({"type": "fresnel", "base": {"type": "blinn", "n": n}, "eta": ETA})
    ref = rings(f, mu, lambda mo, so: [0.0, math.pi], [mu, X0])
    for rtol in (1e-8, 1e-11):
        a, e = pumpup.albedo(f, mu, return_error=True, rtol=rtol)
        assert abs(float(a) - ref) <= float(e) + 1e-13, (float(a) - ref, float(e))


def test_metal_with_total_reflection_and_its_mean():
    """Metal (000 eq. 28) with eta = 0.551, k = 0: the albedo against the rings (Phong's cut R.V = 0 in phi_o), the mean
    against scipy's quad of 2 mu a(mu) split at x0."""
    from scipy.integrate import quad

    f = pumpup.load({"type": "metal", "n": 5.0, "eta": ETA})
    for mu in (0.05, 0.5, 0.95):
        s = math.sqrt(1.0 - mu * mu)

        def cuts(mo, so, s=s, mu=mu):
            # R.V = b cos(phi_o) + a with phi_o from the mirror side: here R.V = a - b cos(phi_o)
            a, b = mu * mo, s * so
            return [0.0 if a >= b else math.acos(a / b), math.pi]

        ref = rings(f, mu, cuts, [mu, X0, s])
        a, e = pumpup.albedo(f, mu, return_error=True, rtol=1e-10)
        assert abs(float(a) - ref) <= float(e) + 1e-13, (mu, float(a) - ref, float(e))
    m, em = pumpup.mean_albedo(f, return_error=True)
    pts = [0.0, 1e-4, 1e-2, 0.1, X0, 1.0]
    ref = sum(quad(lambda x: 2.0 * x * float(pumpup.albedo(f, x, rtol=1e-13)), a, b, epsabs=1e-15, epsrel=1e-13,
                   limit=200)[0] for a, b in zip(pts[:-1], pts[1:]))
    assert abs(m - ref) <= em + 1e-12, (m - ref, em)


# --- microfacet models: F(wi.h) of a conductor with eta < 1 -----------------------------------------------------------


def _wih_reference(f, mu, x0, nodes=160):
    """integral of f(wi, wo) cos(theta_o) d omega_o in spherical coordinates about N (azimuth psi from the mirror side):
    scipy's quad over theta_o, split where the kink circle wi.h = x0 (wi.wo = 2 x0^2 - 1) touches psi = 0 or pi; in psi
    Gauss-Legendre pieces split at the circle, with psi = cut -+ d v^2 on the pieces that end there (F - 1 ~ sqrt of the
    distance past it), and graded towards the mirror side.  160 and 240 nodes agree to 2e-16 at mu = 0.95."""
    from scipy.integrate import quad

    xg, wg = np.polynomial.legendre.leggauss(nodes)
    ck = 2.0 * x0 * x0 - 1.0
    s = math.sqrt(1.0 - mu * mu)
    wi = np.array([s, 0.0, mu])
    ti = math.acos(mu)

    def ring(t):
        ct, st = math.cos(t), math.sin(t)
        cuts = {0.0, math.pi, *(0.3 * 2.0**-j for j in range(1, 12))}
        kc = None
        c = (mu * ct - ck) / (s * st) if s * st > 0 else 2.0
        if -1.0 < c < 1.0:
            kc = math.acos(c)
            cuts.add(kc)
        cuts = sorted(cuts)
        total = 0.0
        for a, b in zip(cuts[:-1], cuts[1:]):
            v, wv = (xg + 1.0) / 2.0, wg / 2.0
            if a == kc or b == kc:
                ps = a + (b - a) * v * v if a == kc else b - (b - a) * v * v
                w = (b - a) * 2.0 * v * wv
            else:
                ps, w = a + (b - a) * v, (b - a) * wv
            wo = np.stack([-st * np.cos(ps), st * np.sin(ps), np.full_like(ps, ct)], -1)
            total += float(np.sum(w * f.eval(np.broadcast_to(wi, wo.shape), wo)))
        return 2.0 * total * ct * st

    a = math.acos(ck)
    pts = sorted({0.0, ti, math.pi / 2, *(v for v in (ti + a, ti - a, a - ti) if 0.0 < v < math.pi / 2)})
    return sum(quad(ring, p, q, epsabs=1e-15, epsrel=1e-13, limit=400)[0] for p, q in zip(pts[:-1], pts[1:]))


@pytest.mark.parametrize("spec,mu", [({"type": "ggx", "alpha": 0.3, "eta": ETA}, 0.05),
                                     ({"type": "ggx", "alpha": 0.3, "eta": ETA}, 0.95),
                                     ({"type": "beckmann", "alpha": 0.1, "eta": ETA}, 0.95)], ids=str)
def test_microfacet_with_total_reflection(spec, mu):
    """F(wi.h) with eta = 0.551, k = 0 has a square-root kink at wi.h = x0.  Frame 4 of the 1-D path, which took it, was
    1.0e-7 off with an estimate of 7.9e-13 for GGX 0.3 at mu = 0.05, 1.9e-12 with 2.1e-14 at 0.95, and Beckmann 0.1 at
    0.95 3.8e-11 with 9.2e-14 (and 19 s); the nested engine, now with the kink in its hint, is its path."""

    f = pumpup.load(spec)
    assert not helpers.takes_1d(f) and f.lobe(mu).kinks is not None
    ref = _wih_reference(f, mu, X0)
    for rtol in (1e-8, 1e-10, 1e-12):
        a, e = pumpup.albedo(f, mu, return_error=True, rtol=rtol)
        assert abs(float(a) - ref) <= float(e) + 2e-15, (rtol, float(a) - ref, float(e))


def test_microfacet_paths_by_the_branch_point():
    """The 1-D path declines F(wi.h) whose branch point lies closer than POLAR_F_Y0_MIN to (0, 1); the hint's kink
    follows fresnel_levels."""

    for k, one_d, kink in ((0.0, False, True), (1e-9, False, True), (1e-3, True, True), (0.1, True, False)):
        f = pumpup.load({"type": "ggx", "alpha": 0.3, "eta": ETA, "k": k})
        assert helpers.takes_1d(f) == one_d and (f.lobe(0.5).kinks is not None) == kink, k
    assert pumpup.load({"type": "ggx", "alpha": 0.3, "eta": 0.2, "k": 3.0}).lobe(0.5).kinks is None
    import pickle

    f = pumpup.load({"type": "beckmann", "alpha": 0.1, "eta": ETA})
    g = pickle.loads(pickle.dumps(f))  # (a dask sweep pickles its BRDFs)
    assert g.lobe(0.5).kinks.x0 == f.lobe(0.5).kinks.x0 == pytest.approx(X0, rel=1e-15)


def test_he_torrance_below_index_one():
    """He-Torrance's |F|^2 at the bisector angle (wi.h) with n = 0.6: total reflection below wi.h = 0.8.  The hint
    carries the kink (the nested engine took 0.8-2.9 s for three values without it, 0.2-0.3 s with it; the 2-D engine 95
    s, 0.4 s); the values with and without it agree within their estimates, and the delta's F(mu) puts a kink in the
    albedo at 0.8."""
    f = pumpup.load({"type": "he_torrance", "sigma_0": 0.18, "tau": 3.0, "n": 0.6})
    assert f.lobe(0.5).kinks.x0 == pytest.approx(0.8, rel=1e-15) and f.albedo_breaks() == pytest.approx((0.8,))
    assert pumpup.load({"type": "he_torrance", "sigma_0": 0.18, "tau": 3.0, "n": 1.5}).lobe(0.5).kinks is None
    mu = np.array([0.1, 0.5, 0.9])
    a, e = pumpup.albedo(f, mu, rtol=1e-10, return_error=True)
    f.__dict__["_f_kinks"] = None  # the hint as before
    b, eb = pumpup.albedo(f, mu, rtol=1e-10, return_error=True)
    assert np.all(np.abs(a - b) <= e + eb), (a - b, e, eb)


def test_tabulate_splits_at_the_models_own_kink():
    """``pumpup.tabulate`` takes the model's albedo_breaks by default: the spline is split at mu = x0, where the albedo
    has a square-root kink, and the interpolant stays within its margin on both sides of it."""
    from pumpup.tables import AlbedoTable

    f = pumpup.load({"type": "metal", "n": 5.0, "eta": ETA})
    ds = pumpup.tabulate(f, interp_tol=1e-5)
    assert float(ds.attrs["interpolation_breaks"]) == pytest.approx(X0, rel=1e-15)
    t = AlbedoTable.from_dataset(ds)
    mu = np.concatenate([X0 + np.logspace(-8, -1, 8), X0 - np.logspace(-8, -1, 8)])
    a, e = pumpup.albedo(f, mu, rtol=1e-12, return_error=True)
    assert np.all(np.abs(t(mu) - a) <= t.margin + e)
    assert "interpolation_breaks" not in pumpup.tabulate(pumpup.load({"type": "metal", "n": 5.0, "eta": 1.5}),
                                                          interp_tol=1e-5).attrs


@pytest.mark.parametrize("spec,mu", [
    # (the grazing case's 2-D reference takes minutes: -m slow; the rough one checks the same route by default)
    pytest.param({"type": "beckmann", "alpha": 0.003203041150077256, "shadowing": "correlated", "g1": "walter",
                  "ior": 1.9173977996887648}, 1.75340447e-06, id="grazing", marks=pytest.mark.slow),
    pytest.param({"type": "beckmann", "alpha": 0.3, "shadowing": "correlated", "g1": "walter", "ior": 1.5}, 0.3,
                 id="rough")])
def test_beckmann_walter_correlated_with_fresnel(spec, mu):
    """Walter's G1 (a jump at its switch level) in the height-correlated G with a Fresnel factor: frame 4 was 7 x its
    estimate at rtol 1e-10 (the first case: 1.27e-11 off, estimate 1.8e-12) and 3.8 x at 1e-12 (the second), against the
    2-D engine at rtol 1e-13 (found by ``scripts/studies/fuzz_engines.py --registry``).  The nested engine takes it
    now."""

    f = pumpup.load(spec)
    assert not helpers.takes_1d(f)
    with helpers.two_d_only():
        ref, eref = pumpup.albedo(f, mu, return_error=True, rtol=1e-13, max_regions=400000)
    for rtol in (1e-8, 1e-10, 1e-12):
        a, e = pumpup.albedo(f, mu, return_error=True, rtol=rtol)
        assert abs(float(a) - float(ref)) <= float(e) + float(eref), (rtol, float(a) - float(ref), float(e))
