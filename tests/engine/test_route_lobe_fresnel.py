"""The lobe frame with 000 eq. 28's Fresnel factor F(Theta_min) (pumpup.engine.polar frame 5,
:func:`pumpup.engine.lobe_fresnel._k_lobe_fresnel`): ``metal``, ``plastic`` with an index, and
the ``fresnel`` wrapper over a lobe with p in {0, 1} (Phong, stretched Phong, Lafortune, retro, Phong's shader), whose
F(max(N.L, N.V)) the rule integrates on the arc where N.V >= N.L."""

import math

import helpers
import numpy as np
import pytest
from helpers import one_d_against_the_other_engines

import pumpup
from pumpup.core.hints import AzimuthHint, FresnelAtMax, PowerLobe
from pumpup.engine import chain_frame as _chain_frame
from pumpup.engine import half_arc as _half_arc
from pumpup.engine import lobe_frame as _lobe_frame
from pumpup.engine import lobe_fresnel as _lobe_fresnel
from pumpup.engine import polar as _polar
from pumpup.engine.lobe_fresnel import lobe_fresnel_ok
from pumpup.engine.routes import using
from pumpup.physics import fresnel as _fresnel_mod

MU = [1.0, 0.99, 0.9, math.sqrt(3) / 2, 1 / math.sqrt(2), 0.5, 0.2, 0.05, 1e-3, 1e-6, 1e-8]

SPECS = [
    {"type": "metal", "n": 20, "eta": 0.2, "k": 3.0}, {"type": "metal", "n": 1, "eta": 1.5},
    {"type": "metal", "n": 500, "eta": 1.1, "k": 6.0}, {"type": "metal", "n": 7.5, "eta": 0.6, "k": 0.3, "c": 0.5},
    {"type": "metal", "n": 0, "eta": 0.999, "k": 0.001},  # F's branch point x0 0.049, y0 0.020: graded cuts at both
    {"type": "metal", "n": 20, "eta": 0.5, "k": 0.002},  # y0 = 1.15e-3, just above LOBE_F_Y0_MIN: 14 cuts per arc
    {"type": "plastic", "n": 20, "eta": 1.5, "ad": 0.3},
    {"type": "fresnel", "base": {"type": "phong", "n": 1}, "eta": 1.1, "k": 30.0},  # F's pole at -0.0012 + 0.033 i
    {"type": "fresnel", "base": {"type": "phong", "n": 20}, "eta": 0.05, "k": 30.0},
    {"type": "fresnel", "base": {"type": "lafortune", "n": 20, "cx": 1.1, "cy": 1.1, "cz": 1.1, "p": 1.0}, "eta": 1.33},
    {"type": "fresnel", "base": {"type": "retro", "n": 10}, "eta": 0.2, "k": 3.0},
    {"type": "fresnel", "base": {"type": "phong_shader", "n": 20}, "eta": 3.0, "k": 0.3},
]
IDS = [f"{s['type']}-{s.get('n', s.get('base', {}).get('type'))}-{s['eta']}-{s.get('k', 0)}" for s in SPECS]


def _lobe(spec):
    """The spec whose hint frame 5 takes (plastic's diffuse part is split off by albedo_terms)."""
    return pumpup.load(dict(spec, ad=0.0) if spec["type"] == "plastic" else spec)


@pytest.mark.parametrize("spec", SPECS, ids=IDS)
def test_kernel_against_scipy_quad(rng, spec):
    """K(u) against its twin: scipy's quad over the azimuth about R of N.wo F(max(mu, N.wo)) / max(mu, N.wo)^p with the
    complex-arithmetic Fresnel function (none of the kernel's cuts, arcs or real-arithmetic F), at random u and next to
    where the arc's ends pass F's branch point and pole, from normal to grazing incidence."""
    f = _lobe(spec)
    hint = helpers.view(f)
    assert helpers.takes_1d(f) and hint.kind == "lobe" and hint.fresnel[1] == spec["eta"]
    x0, y0 = _fresnel_mod.fresnel_branch(spec["eta"], spec.get("k", 0.0))
    for mu in (1.0, 0.7, 0.2, 1e-3):
        th = math.acos(mu)
        angles = ([th - math.acos(min(x0, 1.0)) + d for d in (-2 * y0, 0.0, 2 * y0)]
                  + list(rng.uniform(0, math.pi / 2, 4)))
        us = np.cos([a for a in angles if 0.0 <= a < math.pi / 2] + [0.0])
        k, e = _lobe_fresnel.numeric_integrand(f, mu, us, rtol=1e-13)
        q = _lobe_fresnel.lobe_fresnel_integrand_reference(f, mu, us)
        assert np.all(np.abs(k - q) <= 1e-11 * np.abs(q) + 1e-15), (mu, us, k, q)
        assert np.all(e <= 2e-13 * np.abs(k) + 1e-300)  # the tolerance is met


@pytest.mark.parametrize("spec", SPECS, ids=IDS)
def test_against_the_nested_and_two_d_engines(spec):
    """The 1-D path against the nested engine at rtol 1e-12 (the engine these models had before) and the 2-D engine,
    from normal to grazing incidence; at rtol 1e-6, 1e-8 and 1e-10 the estimate bounds the difference and meets the
    tolerance."""
    assert helpers.takes_1d(_lobe(spec))
    one_d_against_the_other_engines(pumpup.load(spec), MU, (1e-6, 1e-8, 1e-10), whole=True)


@pytest.mark.parametrize("spec", [s for s in SPECS
                                  if s.get("n", s.get("base", {}).get("n", 0)) >= _chain_frame.LOBE_N_MIN],
                         ids=[i for s, i in zip(SPECS, IDS)
                              if s.get("n", s.get("base", {}).get("n", 0)) >= _chain_frame.LOBE_N_MIN])
def test_lobe_about_n_against_frame_5(spec):
    """A lobe with n >= LOBE_N_MIN takes the frame of N (the pumped lobe's, g = 1: the ring table and F(max(mu, N.wo))
    per node) instead of frame 5 (the lobe frame with a rule on the arc): the two agree
    within their estimates at rtol 1e-12, and at rtol 1e-6, 1e-8, 1e-10 the frame of N's estimate bounds its distance
    from frame 5 at 1e-12 (less frame 5's own estimate) and meets the tolerance."""
    f = _lobe(spec)
    assert helpers.takes_lobe_normal(f.azimuth_hint())
    mu = np.array(MU)
    with helpers.without_normal_frames():
        assert not helpers.takes_lobe_normal(f.azimuth_hint())
        b, eb, *_ = _polar.albedo_1d(f, mu, 1e-12, 0.0, 10000)
    a, ea, conv, _ = _polar.albedo_1d(f, mu, 1e-12, 0.0, 10000)
    assert conv.all() and np.all(np.abs(a - b) <= ea + eb), (a - b, ea, eb)
    for rtol in (1e-6, 1e-8, 1e-10):
        a, ea, conv, _ = _polar.albedo_1d(f, mu, rtol, 0.0, 10000)
        assert conv.all() and np.all(np.abs(a - b) - eb <= ea) and np.all(ea <= rtol * a), (rtol, a - b, ea, eb)


def test_normal_incidence_is_the_fresnel_factor():
    """At mu = 1 every N.wo <= mu, so F(Theta_min) = F(1) and the albedo of c u^n F / max is F(1) c 2 pi / (n + 2):
    metal's (c = (n + 2) / (2 pi), 000 eq. 6) is F(1) = ((eta - 1)^2 + k^2) / ((eta + 1)^2 + k^2) exactly."""
    for n, eta, k in ((20, 0.2, 3.0), (1, 1.5, 0.0), (500, 1.1, 6.0), (0, 0.999, 0.001)):
        a, e = pumpup.albedo(pumpup.load({"type": "metal", "n": n, "eta": eta, "k": k}), [1.0], return_error=True,
                             rtol=1e-12)
        f1 = ((eta - 1) ** 2 + k * k) / ((eta + 1) ** 2 + k * k)
        assert abs(a[0] - f1) <= e[0] + 4e-16 * f1, (n, eta, k, a[0] - f1, e[0])


def test_which_models_take_it():
    """Near-kinks of F (its branch point within LOBE_F_Y0_MIN of the real axis, or on it in (0, 1): a dielectric's total
    reflection below eta = 1), p in (0, 1), a Lambertian or half-vector base stay on the nested engine; the hint's
    refusals."""
    assert lobe_fresnel_ok(0.2, 3.0) and lobe_fresnel_ok(1.5, 0.0) and lobe_fresnel_ok(1.0, 0.0)
    assert not lobe_fresnel_ok(0.6, 0.0) and not lobe_fresnel_ok(0.5, 1e-4)
    assert not helpers.hint_routes(pumpup.load({"type": "metal", "n": 20, "eta": 0.6}))
    assert not helpers.hint_routes(pumpup.load({"type": "plastic", "n": 20, "eta": 0.6, "ad": 0.0}))
    # a pumped metal keeps its Fresnel factor in the chain frame (a first version dropped it: a pumped gold's albedo was
    # 2.4, caught by tests/spectral/test_spectral.py), as does the fresnel wrapper of a pumped lobe; not with a
    # near-kink
    assert helpers.view(pumpup.pump({"type": "metal", "n": 20, "eta": 0.2, "k": 3.0})).fresnel == (0.0, 0.2, 3.0)
    assert not helpers.hint_routes(pumpup.pump({"type": "metal", "n": 20, "eta": 0.6}))
    # about N (g = 1) from n = LOBE_N_MIN on, frame 5 below it; a pumped metal's chain takes its own frame of N
    assert [helpers.takes_lobe_normal(pumpup.load({"type": "metal", "n": n, "eta": 0.2, "k": 3.0}).azimuth_hint())
            for n in (7.5, 8.0, 500.0)] == [False, True, True]
    assert not helpers.takes_lobe_normal(pumpup.pump({"type": "metal", "n": 20, "eta": 0.2, "k": 3.0}).azimuth_hint())
    assert not helpers.takes_lobe_normal(pumpup.load({"type": "phong", "n": 20}).azimuth_hint())
    for base in ({"type": "stretched_phong", "n": 20, "p": 0.5}, {"type": "lambert"}, {"type": "blinn", "n": 20},
                 {"type": "pumped", "base": {"type": "blinn", "n": 20}}):
        assert not helpers.hint_routes(pumpup.load({"type": "fresnel", "base": base, "eta": 0.2, "k": 3.0})), base
    # F(max) on a lobe with p outside {0, 1} without a chain, or with a near-kink: no 1-D route
    for p, eta, k in [(0.5, 0.2, 3.0), (1.0, 0.6, 0.0), (1.0, 0.5, 1e-4)]:
        hint = AzimuthHint(PowerLobe(n=5.0, p=p), scale=lambda m: np.ones(np.shape(m)), factors=(FresnelAtMax(eta, k),))
        assert not helpers.hint_routes(hint), (p, eta, k)
    assert helpers.hint_routes(AzimuthHint(PowerLobe(n=5.0, p=1.0), scale=lambda m: np.ones(np.shape(m)),
                                           factors=(FresnelAtMax(0.2, 3.0),))) == {"lobe_fresnel"}


def test_fresnel_wrapper_of_stretched_phong_is_metal():
    """``{"type": "fresnel", "base": stretched Phong p = 1, eta, k}`` is ``metal`` (000 eq. 28): the same hint, the
    same numbers."""
    a = pumpup.albedo(pumpup.load({"type": "metal", "n": 100, "eta": 1.1, "k": 6.0}), MU, rtol=1e-10)
    b = pumpup.albedo(pumpup.load({"type": "fresnel", "base": {"type": "stretched_phong", "n": 100, "p": 1.0},
                                   "eta": 1.1, "k": 6.0}), MU, rtol=1e-10)
    np.testing.assert_array_equal(a, b)


@pytest.mark.parametrize("n,eta,k,mu,ref", [
    (20, 0.2, 3.0, 0.5, 0.80112984762665040829275345444433606957),
    (20, 0.2, 3.0, 0.05, 0.53691967160246328697175732129175531695),
    (7.5, 0.6, 0.3, 0.3, 0.35247684815542318022616560198697820634),
    (1, 1.1, 30.0, 0.001, 0.74238552420483239024887086292862664743),  # F's pole near c = 0
    (1, 1.5, 0.0, 0.2, 0.10831605403944787866771866254573111683)])
def test_metal_against_mpmath(n, eta, k, mu, ref):
    """metal against 40-digit mpmath values independent of pumpup (tests/reference/metal_mpmath_reference.py: tanh-sinh
    in the lobe frame about R and in spherical coordinates about N, agreeing to 1e-41), at rtol 1e-8, 1e-10 and
    1e-12."""
    f = pumpup.load({"type": "metal", "n": n, "eta": eta, "k": k})
    for rtol in (1e-8, 1e-10, 1e-12):
        a, e = pumpup.albedo(f, np.array([mu]), return_error=True, rtol=rtol)
        assert abs(a[0] - ref) <= e[0] <= rtol * ref, (rtol, a[0] - ref, e[0])


CHAINS = [({"type": "metal", "n": 20, "eta": 0.2, "k": 3.0}, "g1", 1),
          ({"type": "metal", "n": 20, "eta": 0.2, "k": 3.0}, "g2", 2),
          ({"type": "metal", "n": 5, "eta": 1.1, "k": 30.0}, "g1", 1),
          ({"type": "metal", "n": 200, "eta": 0.6, "k": 0.3}, "g2", 1),
          ({"type": "fresnel", "base": {"type": "pumped", "base": {"type": "stretched_phong", "n": 20}},
            "eta": 0.2, "k": 3.0}, None, 0),
          ({"type": "fresnel", "base": {"type": "pumped", "base": {"type": "stretched_phong", "n": 20, "p": 0.5},
                                        "g": "g2", "levels": 2}, "eta": 0.999, "k": 0.001}, None, 0)]


@pytest.mark.parametrize("spec,g,levels", CHAINS, ids=[f"{s['type']}-{g}-{lv}" for s, g, lv in CHAINS])
def test_pumped_metal_against_the_nested_and_two_d_engines(spec, g, levels):
    """A pumped metal (001 eq. 16 over 000 eq. 28) and the fresnel wrapper of a pumped lobe (one channel of the
    colour-keeping pumped metal) take the pumped lobe's frame of N with F(max(mu, N.wo)): against the nested engine at
    rtol 1e-12 and the 2-D engine; the estimate bounds the difference at rtol 1e-6 and 1e-10 and meets the tolerance."""
    f = pumpup.pump(spec, g=g, levels=levels) if g else pumpup.load(spec)
    assert helpers.view(f).chain is not None and any(helpers.view(f).fresnel)
    a, e = one_d_against_the_other_engines(f, MU)
    assert np.all(a - e <= 1.0)  # (a pumped BRDF conserves energy, 001 eq. 18)


def test_colour_keeping_pumped_metal_channels():
    """Every wavelength of the colour-keeping pumped metal (pumpup.spectral.SpectralPumpedLobe: the F = 1 lobe pumped
    once, times F(Theta_min) per wavelength) takes the pumped lobe's frame with its F: against the nested engine."""
    from pumpup import spectral

    k = spectral.SpectralPumpedLobe(spectral.SpectralMetal("Cu", n=20, wavelengths=[450.0, 650.0]))
    assert all(helpers.hint_routes(m) and helpers.view(m).fresnel[1] == e for m, e in zip(k.models, k.eta))
    mu = np.array([1.0, 0.7, 0.2, 1e-3])
    a, e = k.albedo(mu, return_error=True, rtol=1e-10)
    with helpers.without_1d():
        b, eb = k.albedo(mu, return_error=True, rtol=1e-12)
    assert np.all(np.abs(a - b) <= e + eb) and np.all(e <= 1e-10 * a * 1.0001)


# --- frame 5's Gauss-Legendre pieces with an a-priori bound -------------------------------------------------------

#: (eta, k): dielectrics (Brewster's zero on the real axis), conductors, a strong absorber (F's pole near c = 0), F's
#: branch point near the real axis (x0 0.87, y0 1.2e-3; x0 0.049, y0 0.02), eta near 1
MATERIALS = [(1.5, 0.0), (1.33, 0.0), (3.0, 0.3), (0.2, 3.0), (0.6, 0.3), (1.1, 30.0), (0.05, 30.0), (0.5, 0.002),
             (0.999, 0.001), (1.1, 6.0), (2.5, 0.01)]


def _fresnel_mp(eta, k, c):
    """F(c) at real c by the complex-arithmetic formula of pumpup.models.metal.fresnel, in mpmath (r_par with the index
    squared times c against the refracted cosine times the index, r_perp with c against it)."""
    import mpmath as mp

    e = mp.mpf(eta) + 1j * mp.mpf(k)
    a = mp.sqrt(e * e - 1 + c * c)  # the refracted cosine times e, Re >= 0
    r_par = (e * e * c - a) / (e * e * c + a)
    r_perp = (c - a) / (c + a)
    return (abs(r_par) ** 2 + abs(r_perp) ** 2) / 2


def test_fresnel_mp_is_the_models_fresnel():
    """The mpmath F of the tests below is pumpup.models.metal.fresnel (pbrt-v4's FrComplex) at double precision."""
    import mpmath as mp

    from pumpup.models.metal import fresnel

    with mp.workdps(30):
        for eta, k in MATERIALS:
            for c in (1.0, 0.7, 0.3, 0.05, 1e-3):
                assert float(_fresnel_mp(eta, k, mp.mpf(c))) == pytest.approx(float(fresnel(c, eta, k)), rel=1e-13,
                                                                              abs=1e-300)


def test_brewster_zero_of_the_continued_numerator():
    """fresnel_brewster's c_b is a zero of N = A c - (1 - c^2) for A continued from the real axis: A followed in 4000
    small steps from Re c_b up to c_b (each step's root the one nearer the last); for a dielectric c_b is
    cos(theta_B) = 1 / sqrt(1 + eta^2), on the real axis."""
    for eta, k in MATERIALS:
        cb, ok = _fresnel_mod.fresnel_brewster(eta, k)
        assert ok, (eta, k)
        e2 = complex(eta * eta - k * k, 2 * eta * k)
        a = (e2 - 1 + cb.real**2) ** 0.5  # principal on the real axis
        for t in np.linspace(0.0, 1.0, 4001)[1:]:
            c = complex(cb.real, t * cb.imag)
            r = (e2 - 1 + c * c) ** 0.5
            a = r if abs(r - a) <= abs(r + a) else -r
        assert abs(a * cb - (1 - cb * cb)) <= 1e-12, (eta, k, cb)
        if k == 0.0:
            assert cb.imag == 0.0 and cb.real == pytest.approx(1 / math.sqrt(1 + eta * eta), rel=1e-15)


def _pieces(rng, count):
    """Random pieces of frame 5's arcs: (mu, T, L, lo, d, first), from grazing to normal incidence."""
    out = []
    while len(out) < count:
        mu = float(10 ** rng.uniform(-4, 0)) if rng.uniform() < 0.5 else float(rng.uniform(0.01, 0.99))
        u = float(rng.uniform(-1, 1))
        s, sa = math.sqrt(1 - mu * mu), math.sqrt(1 - u * u)
        top, low = mu * u + s * sa, mu * u - s * sa
        if not top > mu * (1 + 1e-9):
            continue
        first = rng.uniform() < 0.5
        if first:
            lo = mu if rng.uniform() < 0.5 else float(rng.uniform(mu, top))
            out.append((mu, top, low, lo, top - lo, True))
        else:
            x = np.sort(rng.uniform(mu, top, 2))
            hi = float(x[1]) if rng.uniform() < 0.7 else mu + (top - mu) * 0.5
            lo = float(x[0]) if x[0] < hi else mu
            out.append((mu, top, low, lo, hi - lo, False))
    return out


@pytest.mark.parametrize("eta,k", MATERIALS)
def test_gauss_piece_and_its_bound_against_mpmath(rng, eta, k):
    """_lobe_f_piece's n-point rule errs by at most _lobe_f_bound's bound (plus the returned rounding allowance),
    against 30-digit mpmath tanh-sinh of integral F(t) t^q / sqrt((T - t)(t - L)) dt over the piece, F from the complex
    formula: random pieces (in s beside T and in t), q in {0, 1}, tolerances 1e-6 .. 1e-14 of the piece; and the bound
    meets the tolerance asked."""
    import mpmath as mp

    mpar = _half_arc.numeric_params(pumpup.load({"type": "metal", "n": 5, "eta": eta, "k": k}).azimuth_hint())
    assert mpar[18] == 1.0  # (Brewster's zero found)
    ran = 0
    with mp.workdps(30):
        for (mu, top, low, lo, d, first), q, rt in zip(_pieces(rng, 18), [0.0, 1.0] * 9, [1e-6, 1e-10, 1e-14] * 6):
            ref_scale = math.sqrt(d) * 3.0  # (the piece is about sqrt(d) in size; the tolerance is relative to that)
            n, bound, v = _lobe_fresnel._lobe_f_bound(mpar, q, lo, d, top, low, first, rt * ref_scale)
            if n > _lobe_frame.GL_MAX:
                continue  # (the caller falls back to the adaptive rule)
            ran += 1
            assert bound <= rt * ref_scale and v == ((n + 1) // 2 if first else n)
            p = _lobe_fresnel._lobe_f_piece(eta, k, q, lo, d, top, low, first, n)
            g = lambda t: _fresnel_mp(eta, k, t) * t**q / mp.sqrt((top - t) * (t - low))  # noqa: E731
            hi = mp.mpf(top) if first else mp.mpf(lo) + mp.mpf(d)
            ref = mp.quad(g, [mp.mpf(lo) if not first else mp.mpf(top) - mp.mpf(d), hi])
            err = abs(float(p - ref))
            allow = bound + (n + 64) * np.finfo(float).eps * abs(p)
            assert err <= allow, (mu, top, low, lo, d, first, q, rt, n, err, bound)
    assert ran >= 6, ran  # (pieces across F's branch point are the adaptive rule's: the engine cuts there)


@pytest.mark.parametrize("spec", SPECS, ids=IDS)
def test_gauss_pieces_against_the_adaptive_rule(spec):
    """Frame 5 with the Gauss-Legendre pieces against frame 5 with the adaptive 7/15 rule alone
    (``without_lobe_f_gauss``) at rtol 1e-12: at rtol 1e-6, 1e-8, 1e-10 and 1e-12 the estimate
    bounds the distance (less the other's estimate), and up to 1e-10 it meets the tolerance (at 1e-12 the engine's
    rounding allowance, 64 eps, may take it a little beyond)."""
    f = _lobe(spec)
    mu = np.array(MU)
    with helpers.without_normal_frames():  # (n >= LOBE_N_MIN takes the frame of N otherwise)
        with using(lobe_fresnel_gauss=False):
            b, eb, *_ = _polar.albedo_1d(f, mu, 1e-12, 0.0, 10000)
        for rtol in (1e-6, 1e-8, 1e-10, 1e-12):
            a, ea, conv, _ = _polar.albedo_1d(f, mu, rtol, 0.0, 10000)
            assert conv.all() and np.all(np.abs(a - b) - eb <= ea), (rtol, a - b, ea, eb)
            assert rtol < 1e-10 or np.all(ea <= rtol * a), (rtol, ea / a)


def test_gauss_piece_against_its_numpy_twin(rng):
    """_lobe_f_piece at its bound's n against lobe_f_piece_reference (numpy, 200 points, the complex Fresnel
    formula)."""
    for eta, k in MATERIALS:
        mpar = _half_arc.numeric_params(pumpup.load({"type": "metal", "n": 5, "eta": eta, "k": k}).azimuth_hint())
        for (mu, top, low, lo, d, first), q in zip(_pieces(rng, 6), [0.0, 1.0] * 3):
            n, bound, _ = _lobe_fresnel._lobe_f_bound(mpar, q, lo, d, top, low, first, 1e-13 * math.sqrt(d))
            if n > _lobe_frame.GL_MAX:
                continue
            p = _lobe_fresnel._lobe_f_piece(eta, k, q, lo, d, top, low, first, n)
            r = _lobe_fresnel.lobe_f_piece_reference(eta, k, q, lo, d, top, low, first)
            assert abs(p - r) <= bound + 1e-13 * abs(r), (eta, k, mu, lo, d, first, q, p - r, bound)
