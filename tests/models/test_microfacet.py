"""Microfacet models with Smith shadowing: beckmann and ggx (pumpup/models/microfacet.py)."""

import itertools
import json
import math
import warnings

import numpy as np
import pytest
from helpers import at_mu, direction_pairs, polar
from reference import independent_microfacet as ind
from scipy.integrate import quad

import pumpup
from pumpup.models.cook_torrance import fresnel as fresnel_dielectric
from pumpup.models.metal import fresnel as fresnel_complex
from pumpup.models.microfacet import ndf, smith_g1, smith_lambda, walter_level

N = np.array([0.0, 0.0, 1.0])

# every combination of distribution, shadowing, G1 and Fresnel
FRESNEL = [{}, {"ior": 1.5}, {"eta": 0.2, "k": 3.0}]
CONFIGS = [
    {"type": d, "alpha": a, "shadowing": s, **({"g1": g} if d == "beckmann" else {}), **fr}
    for d, g in [("beckmann", "exact"), ("beckmann", "walter"), ("ggx", None)]
    for s in ("separable", "correlated")
    for a, fr in zip((0.03, 0.4, 1.7), FRESNEL)
]
IDS = [json.dumps(c, sort_keys=True) for c in CONFIGS]


# --- kernel, reference, reciprocity ---------------------------------------------------------


@pytest.mark.parametrize("spec", CONFIGS, ids=IDS)
def test_kernel_matches_reference(spec, rng):
    # random pairs, some below the horizon, mirror pairs, mu = 1e-8 exactly, grazing near-opposite pairs
    f = pumpup.load(spec)
    wi, wo = direction_pairs(rng)
    fast, ref = f.eval(wi, wo), f.reference(wi, wo)
    assert np.all(np.isfinite(fast)) and np.all(fast >= 0)
    np.testing.assert_allclose(fast, ref, rtol=1e-12, atol=0)
    below = (wi[:, 2] <= 0) | (wo[:, 2] <= 0)
    assert below.any() and np.all(fast[below] == 0)
    assert np.count_nonzero(fast > 0) > 1000  # not only zeros (a sharp Beckmann lobe underflows elsewhere)


@pytest.mark.parametrize("spec", CONFIGS, ids=IDS)
def test_reciprocal_to_the_last_bit(spec, rng):
    f = pumpup.load(spec)
    wi, wo = direction_pairs(rng, 3000)
    np.testing.assert_array_equal(f.eval(wi, wo), f.eval(wo, wi))
    assert pumpup.check_reciprocity(f, tol=0.0).reciprocal


def test_spec_round_trip_and_defaults():
    f = pumpup.load({"type": "beckmann", "alpha": 0.2})
    assert f.spec == {"type": "beckmann", "alpha": 0.2, "shadowing": "separable", "g1": "exact"}
    g = pumpup.load({"type": "ggx", "alpha": 0.2, "eta": 0.3, "k": 2.0})
    assert g.spec == {"type": "ggx", "alpha": 0.2, "shadowing": "separable", "eta": 0.3, "k": 2.0}
    assert pumpup.load(json.loads(json.dumps(g.spec))) == g


# --- values by hand ---------------------------------------------------------------------------


@pytest.mark.parametrize("dist", ["beckmann", "ggx"])
@pytest.mark.parametrize("alpha", [0.01, 0.3, 2.0])
def test_normal_incidence_and_fresnel(dist, alpha):
    # wi = wo = N: h = N, D = 1 / (pi alpha^2) for both, G = 1, wi.h = 1
    f = pumpup.load({"type": dist, "alpha": alpha})
    assert f.eval(N, N) == pytest.approx(1 / (4 * math.pi * alpha**2), rel=1e-14)
    g = pumpup.load({"type": dist, "alpha": alpha, "ior": 1.5})
    assert g.eval(N, N) == pytest.approx(0.04 / (4 * math.pi * alpha**2), rel=1e-13)
    h = pumpup.load({"type": dist, "alpha": alpha, "eta": 0.2, "k": 3.0})
    F0 = ((0.2 - 1) ** 2 + 9) / ((0.2 + 1) ** 2 + 9)
    assert h.eval(N, N) == pytest.approx(F0 / (4 * math.pi * alpha**2), rel=1e-13)


@pytest.mark.parametrize("shadowing", ["separable", "correlated"])
@pytest.mark.parametrize("dist,g1", [("beckmann", "exact"), ("beckmann", "walter"), ("ggx", "exact")])
def test_mirror_pairs(dist, g1, shadowing):
    # h = N: D = 1 / (pi alpha^2); G = G1(mu)^2 or 1 / (1 + 2 Lambda(mu)); f = D G / (4 mu^2)
    alpha = 0.25
    spec = {"type": dist, "alpha": alpha, "shadowing": shadowing, **({"g1": g1} if dist == "beckmann" else {})}
    f = pumpup.load(spec)
    for mu in [0.9, 0.5, 0.05, 1e-3]:
        wi = at_mu(mu, 0.7)
        wo = wi * [-1, -1, 1]
        lam = float(smith_lambda(mu, alpha, dist, g1))
        G = 1 / (1 + lam) ** 2 if shadowing == "separable" else 1 / (1 + 2 * lam)
        assert f.eval(wi, wo) == pytest.approx(G / (4 * math.pi * alpha**2 * mu**2), rel=1e-12)


@pytest.mark.parametrize("theta_deg", [10.0, 30.0, 44.0])
@pytest.mark.parametrize("alpha", [0.1, 0.4])
def test_beckmann_has_cook_torrance_distribution(alpha, theta_deg):
    # wi = wo = w: h = w, wi.h = 1; Cook-Torrance's G = min(1, 2 cos^2 theta) = 1 below 45 degrees,
    # Smith's G = G1(w)^2: so beckmann / G1^2 = cook_torrance with m = alpha (same D, 001 eq. 9)
    w = polar(math.radians(theta_deg), 0.3)
    bk = pumpup.load({"type": "beckmann", "alpha": alpha})
    ct = pumpup.load({"type": "cook_torrance", "m": alpha})
    g1 = float(smith_g1(w[2], alpha))
    assert bk.eval(w, w) / g1**2 == pytest.approx(float(ct.eval(w, w)), rel=1e-13)


@pytest.mark.parametrize("dist", ["beckmann", "ggx"])
def test_kernel_distribution_is_ndf(dist):
    # retro pairs wi = wo = w: f = D(theta) G1(w)^2 / (4 cos^2 theta) (separable, F = 1)
    alpha = 0.3
    f = pumpup.load({"type": dist, "alpha": alpha})
    for theta in np.radians([0.0, 5.0, 30.0, 60.0, 85.0]):
        w = polar(theta, 1.0)
        c = math.cos(theta)
        want = float(ndf(c, alpha, dist)) * float(smith_g1(c, alpha, dist)) ** 2 / (4 * c * c)
        assert f.eval(w, w) == pytest.approx(want, rel=1e-12)


def test_fresnel_factors_are_the_shared_ones(rng):
    wi, wo = direction_pairs(rng, 2000)
    up = (wi[:, 2] > 0) & (wo[:, 2] > 0)
    wi, wo = wi[up], wo[up]
    c = 0.5 * np.linalg.norm(wi + wo, axis=-1)  # wi.h
    for dist in ("beckmann", "ggx"):
        base = pumpup.load({"type": dist, "alpha": 0.3}).eval(wi, wo)
        keep = base > 1e-200
        ior = pumpup.load({"type": dist, "alpha": 0.3, "ior": 1.5}).eval(wi, wo)
        np.testing.assert_allclose(ior[keep], (base * fresnel_dielectric(c, 1.5))[keep], rtol=1e-13)
        cond = pumpup.load({"type": dist, "alpha": 0.3, "eta": 0.2, "k": 3.0}).eval(wi, wo)
        np.testing.assert_allclose(cond[keep], (base * fresnel_complex(c, 0.2, 3.0))[keep], rtol=1e-12)
        # a conductor with k = 0 is the dielectric with that index
        eta = pumpup.load({"type": dist, "alpha": 0.3, "eta": 1.5}).eval(wi, wo)
        np.testing.assert_allclose(eta[keep], ior[keep], rtol=1e-12)


def test_correlated_reflects_at_least_as_much_as_separable(rng):
    # 1 + L_i + L_o <= (1 + L_i)(1 + L_o): the height-correlated G is the larger one
    wi, wo = direction_pairs(rng, 3000)
    for spec in [{"type": "beckmann", "alpha": 0.5}, {"type": "ggx", "alpha": 0.5}]:
        sep = pumpup.load(spec).eval(wi, wo)
        cor = pumpup.load({**spec, "shadowing": "correlated"}).eval(wi, wo)
        assert np.all(cor >= sep * (1 - 1e-15))
        assert np.count_nonzero(cor > sep * (1 + 1e-3)) > 100


# --- grazing directions -------------------------------------------------------------------------


def _mp_value(dist, alpha, wi, wo, shadowing):
    """The textbook formula in 50-digit arithmetic (mpmath), from the directions' components."""
    import mpmath as mp

    mp.mp.dps = 50
    L = [mp.mpf(float(x)) for x in wi]
    V = [mp.mpf(float(x)) for x in wo]
    S = [a + b for a, b in zip(L, V)]
    tan2 = (S[0] ** 2 + S[1] ** 2) / S[2] ** 2
    cos2 = 1 / (1 + tan2)
    a2 = mp.mpf(alpha) ** 2
    if dist == "beckmann":
        D = mp.e ** (-tan2 / a2) / (mp.pi * a2 * cos2**2)
    else:
        D = a2 / (mp.pi * cos2**2 * (a2 + tan2) ** 2)

    def lam(w):
        nw = mp.sqrt(w[0] ** 2 + w[1] ** 2 + w[2] ** 2)
        z, s = w[2] / nw, mp.sqrt(w[0] ** 2 + w[1] ** 2) / nw
        a = z / (mp.mpf(alpha) * s)
        if dist == "beckmann":
            return (mp.erf(a) - 1) / 2 + mp.e ** (-(a**2)) / (2 * a * mp.sqrt(mp.pi))
        return (-1 + mp.sqrt(1 + 1 / a**2)) / 2

    li, lo = lam(L), lam(V)
    G = 1 / ((1 + li) * (1 + lo)) if shadowing == "separable" else 1 / (1 + li + lo)
    return float(D * G / (4 * L[2] * V[2]))


@pytest.mark.parametrize("shadowing", ["separable", "correlated"])
@pytest.mark.parametrize("dist", ["beckmann", "ggx"])
def test_grazing_values_are_accurate(dist, shadowing):
    # against 50-digit arithmetic at mu down to 1e-12 (mirror, off-mirror and one grazing, one not)
    alpha = 0.2
    f = pumpup.load({"type": dist, "alpha": alpha, "shadowing": shadowing})
    for mu in [1e-3, 1e-6, 1e-8, 1e-12]:
        wi = at_mu(mu, 0.3)
        # the mirror pair, near-mirror pairs (one grazing, one not), and a pair far off the mirror
        for wo in [wi * [-1, -1, 1], at_mu(mu * 3, 0.3 + math.pi + 2 * mu), at_mu(0.05, math.pi + 0.3),
                   at_mu(0.2, math.pi + 0.35)]:
            want = _mp_value(dist, alpha, wi, wo, shadowing)
            assert want > 0
            assert f.eval(wi, wo) == pytest.approx(want, rel=1e-13)
            assert f.eval(wo, wi) == pytest.approx(want, rel=1e-13)


@pytest.mark.parametrize("spec", CONFIGS, ids=IDS)
def test_no_nan_down_to_the_smallest_mu(spec):
    # one direction grazing: f stays bounded (G1 vanishes like N.w); both grazing: f may be large
    f = pumpup.load(spec)
    wo = at_mu(0.5, 3.0)
    values = [float(f.eval(at_mu(mu, 0.2), wo)) for mu in [1e-8, 1e-12, 1e-100, 1e-300]]
    assert all(np.isfinite(values)) and all(v >= 0 for v in values)
    assert values[-1] == pytest.approx(values[1], rel=1e-6)  # the grazing limit is reached
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)  # overflow to inf is allowed, NaN is not
        for mu in [1e-8, 1e-100, 1e-300]:
            wi = at_mu(mu, 0.2)
            for w in [wi * [-1, -1, 1], wi, at_mu(mu, 0.2 + math.pi + 1e-6), at_mu(mu * 0.5, 0.25)]:
                v = f.eval(wi, w / np.linalg.norm(w))
                assert not np.isnan(v) and v >= 0


# --- distribution and Smith functions ----------------------------------------------------------


@pytest.mark.parametrize("dist", ["beckmann", "ggx"])
@pytest.mark.parametrize("alpha", [0.01, 0.1, 0.5, 1.0, 3.0])
def test_ndf_is_normalised(dist, alpha):
    # integral over the hemisphere of D(m) (N.m) d omega_m = 1, in theta_m by QUADPACK, with
    # break points at multiples of the lobe width
    def g(theta):
        c = math.cos(theta)
        return 2 * math.pi * float(ndf(c, alpha, dist)) * c * math.sin(theta) if c > 0 else 0.0

    w = math.atan(alpha)
    pts = [p for p in (w / 4, w / 2, w, 2 * w, 4 * w, 8 * w) if p < math.pi / 2]
    v, e = quad(g, 0, math.pi / 2, points=pts, epsabs=0, epsrel=1e-13, limit=500)
    assert e < 1e-11
    assert v == pytest.approx(1.0, abs=1e-11)


@pytest.mark.parametrize("dist", ["beckmann", "ggx"])
@pytest.mark.parametrize("alpha", [0.2, 1.0])
@pytest.mark.parametrize("theta_deg", [20.0, 60.0, 85.0, 89.99])
def test_lambda_is_the_projected_area(dist, alpha, theta_deg):
    # Smith's Lambda is defined by the projected area of the facets (Heitz 2014):
    # integral of D(m) max(0, w.m) d omega_m = (N.w) (1 + Lambda(w)).  With w.m = A + B cos(phi),
    # A = cos(theta) cos(t), B = sin(theta) sin(t), the azimuth is done in closed form and t by QUADPACK
    theta = math.radians(theta_deg)
    ct, st = math.cos(theta), math.sin(theta)

    def g(t):
        A, B = ct * math.cos(t), st * math.sin(t)
        if A >= B:
            arc = 2 * math.pi * A
        else:
            p0 = math.acos(-A / B)
            arc = 2 * (A * p0 + B * math.sin(p0))
        return float(ndf(math.cos(t), alpha, dist)) * arc * math.sin(t)

    w = math.atan(alpha)
    pts = sorted({math.pi / 2 - theta, *(p for p in (w / 4, w / 2, w, 2 * w, 4 * w) if p < math.pi / 2)})
    v, e = quad(g, 0, math.pi / 2, points=pts, epsabs=0, epsrel=1e-13, limit=500)
    assert e < 1e-12
    assert v == pytest.approx(ct * (1 + float(smith_lambda(ct, alpha, dist))), rel=1e-11)


def test_walter_fit_within_its_published_error():
    # Walter et al. 2007 eq. 27: the rational fit of the Beckmann G1 has relative error below 0.35 %
    c = np.concatenate([np.geomspace(1e-9, 0.05, 2000), np.linspace(0.05, 1.0, 20000)])
    for alpha in [0.05, 0.3, 1.0, 4.0]:
        exact = smith_g1(c, alpha)
        fit = smith_g1(c, alpha, g1="walter")
        rel = np.abs(fit / exact - 1)
        assert rel.max() < 0.0035
        assert rel.max() > 0.003  # it is the fit, not the exact function: its largest error is 0.31 %
    # the fit is 1 from a = 1.6 on (cos = walter_level(alpha)), and jumps there by 5.7e-5
    alpha = 0.3
    u = walter_level(alpha)
    assert u / (alpha * math.sqrt(1 - u * u)) == pytest.approx(1.6, rel=1e-14)
    below, above = smith_g1([u * (1 - 1e-9), u * (1 + 1e-9)], alpha, g1="walter")
    assert above == 1.0 and below == pytest.approx(1.0000569, abs=1e-7)


def test_smith_functions_limits():
    for dist in ("beckmann", "ggx"):
        assert smith_g1(1.0, 0.5, dist) == 1.0 and smith_lambda(1.0, 0.5, dist) == 0.0
        g = smith_g1(np.array([1e-6, 1e-9, 1e-12]), 0.5, dist)
        assert np.all(np.isfinite(g)) and np.all(np.diff(g) < 0)
    # G1 -> 2 a sqrt(pi) (Beckmann) and 2 a (GGX) as a = 1 / (alpha tan theta) -> 0
    mu = 1e-9
    assert smith_g1(mu, 0.5) == pytest.approx(2 * math.sqrt(math.pi) * mu / 0.5, rel=1e-8)
    assert smith_g1(mu, 0.5, "ggx") == pytest.approx(2 * mu / 0.5, rel=1e-8)
    # GGX closed form
    assert smith_g1(0.6, 1.0, "ggx") == pytest.approx(2 / (1 + math.sqrt(1 + (0.8 / 0.6) ** 2)), rel=1e-15)


# --- albedo -------------------------------------------------------------------------------------


def test_ggx_alpha_one_at_normal_incidence_is_one_minus_ln2():
    # alpha = 1: D = 1 / pi; wi = N: a = 2 int_0^{pi/4} cos(2t) tan(t) dt = 1 - ln 2 (either shadowing)
    for s in ("separable", "correlated"):
        a, e = pumpup.albedo(pumpup.load({"type": "ggx", "alpha": 1.0, "shadowing": s}), 1.0, return_error=True)
        assert abs(a - (1 - math.log(2))) <= e and e < 1e-9


MUS = np.array([1.0, 0.9, 0.5, 0.2, 0.05, 1e-2, 1e-3, 1e-5, 1e-8])


@pytest.mark.parametrize("shadowing", ["separable", "correlated"])
@pytest.mark.parametrize("dist,g1", [("beckmann", "exact"), ("beckmann", "walter"), ("ggx", "exact")])
def test_albedo_at_most_one_and_energy_lost_when_rough(dist, g1, shadowing):
    extra = {"g1": g1} if dist == "beckmann" else {}
    at_normal = []
    for alpha in [0.005, 0.05, 0.3, 1.0, 2.5]:
        f = pumpup.load({"type": dist, "alpha": alpha, "shadowing": shadowing, **extra})
        with warnings.catch_warnings():
            warnings.simplefilter("error")  # the engine must converge without warnings
            a, e = pumpup.albedo(f, MUS, return_error=True)
        assert np.all(e < 1e-9)
        assert np.all(a - e <= 1.0), (alpha, a.max())
        at_normal.append(a[0])
    # single scattering loses energy, more with roughness (a smooth surface reflects 1 at normal incidence)
    assert at_normal[0] > 0.9999  # (GGX's long tail loses 2.5e-5 even at alpha = 0.005)
    assert np.all(np.diff(at_normal) <= 1e-12) and np.all(np.diff(at_normal[1:]) < 0)
    assert at_normal[-2] < 0.5 and at_normal[-1] < 0.2


CROSS = [
    ("beckmann", "separable", "exact"),
    ("beckmann", "separable", "walter"),
    ("beckmann", "correlated", "exact"),
    ("ggx", "separable", "exact"),
    ("ggx", "correlated", "exact"),
]


@pytest.mark.parametrize("dist,shadowing,g1", CROSS)
def test_albedo_against_independent_quadrature(dist, shadowing, g1):
    # tests/reference/independent_microfacet.py: textbook formulas, spherical coordinates about N, nested
    # QUADPACK; it never imports pumpup
    for alpha, mu in itertools.product([0.05, 0.6], [1.0, 0.3, 1e-4]):
        spec = {"type": dist, "alpha": alpha, "shadowing": shadowing, **({"g1": g1} if dist == "beckmann" else {})}
        a, e = pumpup.albedo(pumpup.load(spec), mu, return_error=True)
        r, re = ind.albedo(dist, alpha, mu, shadowing, g1)
        assert abs(a - r) <= e + re, (alpha, mu, a, r, e, re)
        assert abs(a - r) < 1e-9 * r


def test_albedo_near_grazing_against_independent_quadrature():
    for dist in ("beckmann", "ggx"):
        a, e = pumpup.albedo(pumpup.load({"type": dist, "alpha": 0.2}), 1e-8, return_error=True)
        r, re = ind.albedo(dist, 0.2, 1e-8)
        assert abs(a - r) <= e + re and abs(a - r) < 1e-9


def test_lobe_hints():
    lobe = pumpup.load({"type": "beckmann", "alpha": 0.1}).lobe(0.5)
    assert (lobe.axis, lobe.radial, lobe.sharpness, lobe.levels) == ("half", "beckmann", 0.1, ())
    lobe = pumpup.load({"type": "beckmann", "alpha": 0.1, "g1": "walter"}).lobe(0.5)
    assert lobe.levels == (walter_level(0.1),)  # the jump of the fit, as a break point in N.wo
    lobe = pumpup.load({"type": "ggx", "alpha": 0.3}).lobe(0.5)
    assert (lobe.axis, lobe.radial) == ("half", "ggx") and lobe.sharpness == pytest.approx(0.09)
    assert pumpup.load({"type": "ggx", "alpha": 2.0}).lobe(0.5).sharpness == 1.0


# --- bad input ------------------------------------------------------------------------------------


@pytest.mark.parametrize(
    "spec,pname",
    [
        ({"type": "beckmann"}, "alpha"),
        ({"type": "beckmann", "alpha": 0}, "alpha"),
        ({"type": "ggx", "alpha": -0.1}, "alpha"),
        ({"type": "ggx", "alpha": float("nan")}, "alpha"),
        ({"type": "ggx", "alpha": float("inf")}, "alpha"),
        ({"type": "beckmann", "alpha": 0.1, "shadowing": "v-cavity"}, "shadowing"),
        ({"type": "beckmann", "alpha": 0.1, "g1": "schlick"}, "g1"),
        ({"type": "ggx", "alpha": 0.1, "g1": "walter"}, "g1"),
        ({"type": "ggx", "alpha": 0.1, "g1": "exact"}, "g1"),
        ({"type": "beckmann", "alpha": 0.1, "ior": 1.0}, "ior"),
        ({"type": "beckmann", "alpha": 0.1, "ior": 1.5, "eta": 1.5}, "ior"),
        ({"type": "ggx", "alpha": 0.1, "k": 3.0}, "k"),
        ({"type": "ggx", "alpha": 0.1, "eta": 0.0, "k": 3.0}, "eta"),
        ({"type": "ggx", "alpha": 0.1, "eta": 0.2, "k": -1.0}, "k"),
        ({"type": "ggx", "alpha": 0.1, "m": 0.1}, "m"),
    ],
)
def test_bad_input_names_the_parameter(spec, pname):
    with pytest.raises(pumpup.SpecError, match=repr(pname)):
        pumpup.load(spec)


def test_ggx_g1_error_explains():
    with pytest.raises(pumpup.SpecError, match="Beckmann distribution only"):
        pumpup.load({"type": "ggx", "alpha": 0.1, "g1": "walter"})


def test_helper_bad_input():
    with pytest.raises(pumpup.SpecError, match="'distribution'"):
        ndf(0.5, 0.1, "phong")
    with pytest.raises(pumpup.SpecError, match="'g1'"):
        smith_g1(0.5, 0.1, "ggx", g1="walter")
    with pytest.raises(ValueError, match="cos_theta"):
        smith_lambda(0.0, 0.1)


# --- Mitsuba 3 (skipped where it is not installed) -------------------------------------------------


@pytest.fixture(scope="module")
def mi():
    mitsuba = pytest.importorskip("mitsuba")
    mitsuba.set_variant("scalar_rgb")  # the LLVM variants need a newer libLLVM than some machines have
    return mitsuba


def _mitsuba_bsdf(mi, dist, alpha):
    # roughconductor with the default material "none" (eta = 0, k = 1): Fresnel factor 1
    return mi.load_dict({"type": "roughconductor", "distribution": dist, "alpha": alpha, "sample_visible": False})


def _like_mitsuba(dist, alpha):
    return pumpup.load({"type": dist, "alpha": alpha, **({"g1": "walter"} if dist == "beckmann" else {})})


def _si(mi, w):
    si = mi.SurfaceInteraction3f()
    si.n = mi.Normal3f(0, 0, 1)
    si.sh_frame = mi.Frame3f(si.n)
    si.wi = mi.Vector3f(*map(float, w))
    return si


@pytest.mark.parametrize("dist", ["beckmann", "ggx"])
def test_eval_matches_mitsuba(mi, dist, rng):
    # Mitsuba's eval is f_r cos(theta_o) in single precision
    ctx = mi.BSDFContext()
    for alpha in [0.05, 0.3, 1.0]:
        b, f = _mitsuba_bsdf(mi, dist, alpha), _like_mitsuba(dist, alpha)
        # wi random, wo its reflection about a facet normal tilted by about alpha: values of any size
        wi = rng.normal(size=(400, 3))
        wi[:, 2] = np.abs(wi[:, 2])
        wi /= np.linalg.norm(wi, axis=-1, keepdims=True)
        h = np.concatenate([alpha * rng.normal(size=(400, 2)), np.ones((400, 1))], axis=-1)
        h /= np.linalg.norm(h, axis=-1, keepdims=True)
        wo = 2 * np.sum(wi * h, axis=-1, keepdims=True) * h - wi
        ours = f.eval(wi, wo) * wo[:, 2]
        checked = 0
        for k in range(len(wi)):
            theirs = b.eval(ctx, _si(mi, wi[k]), mi.Vector3f(*map(float, wo[k])))[0]
            if wo[k, 2] > 1e-3 and ours[k] > 1e-6:
                assert theirs == pytest.approx(ours[k], rel=5e-5)
                checked += 1
        assert checked > 100


@pytest.mark.parametrize("dist", ["beckmann", "ggx"])
def test_albedo_matches_mitsuba_monte_carlo(mi, dist):
    # Mitsuba's importance sampling (sample_visible False) gives weights f cos / pdf; their mean is an
    # unbiased estimate of the albedo.  Agreement within 4 standard errors, 250 000 samples per value
    # (test_eval_matches_mitsuba checks the configuration pointwise, to single precision).
    ctx = mi.BSDFContext()
    rng = np.random.default_rng(7)
    n = 250_000
    for alpha, mu in [(0.1, 0.8), (0.5, 0.3), (1.0, 0.9), (0.3, 0.02)]:
        b = _mitsuba_bsdf(mi, dist, alpha)
        si = _si(mi, at_mu(mu))
        u = rng.random((n, 3))
        w = np.empty(n)
        for i in range(n):
            _, weight = b.sample(ctx, si, float(u[i, 0]), mi.Point2f(float(u[i, 1]), float(u[i, 2])))
            w[i] = weight[0]
        est, se = w.mean(), w.std(ddof=1) / math.sqrt(n)
        a = float(pumpup.albedo(_like_mitsuba(dist, alpha), mu))
        assert abs(est - a) <= 4 * se, (dist, alpha, mu, a, est, se)
        assert se < 0.005


def test_pumped_ggx_reflects_more_and_at_most_one():
    # 001 eq. 16-20: pumping a microfacet model raises its albedo towards 1 and never above it
    base = pumpup.load({"type": "ggx", "alpha": 0.5})
    pumped = pumpup.pump(base, g="g1")
    mu = np.array([1.0, 0.5, 0.1, 1e-3])
    a, e = pumpup.albedo(pumped, mu, return_error=True)
    b = pumpup.albedo(base, mu)
    assert np.all(a > b + 0.1) and np.all(a - e <= 1.0)
    assert pumpup.check_reciprocity(pumped).reciprocal
