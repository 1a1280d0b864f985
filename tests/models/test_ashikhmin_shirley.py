"""The Ashikhmin-Shirley BRDF (Ashikhmin and Shirley 2000, eq. 4-9): pumpup.models.ashikhmin_shirley against the
independent implementation and quadrature of tests/reference/ashikhmin_shirley.py."""

import functools
import math

import helpers
import numpy as np
import pytest
from helpers import at_mu, direction_pairs
from reference import ashikhmin_shirley as ref

import pumpup
from pumpup.testing import chi2_test

N = np.array([0.0, 0.0, 1.0])


def load(**p):
    return pumpup.load({"type": "ashikhmin_shirley", **p})


def upper(rng, n, zmin):
    """n unit vectors with N.w uniform in [zmin, 1], azimuth uniform."""
    z = rng.uniform(zmin, 1.0, n)
    ph = rng.uniform(0.0, 2.0 * np.pi, n)
    s = np.sqrt((1.0 - z) * (1.0 + z))
    return np.stack([s * np.cos(ph), s * np.sin(ph), z], axis=-1)


def pairs(rng, n=20000, zmin=0.05):
    """Random pairs above the horizon, a tenth of them exact mirror pairs (h = N, the peak) and a tenth near them."""
    wi, wo = upper(rng, n, zmin), upper(rng, n, zmin)
    k = n // 10
    wo[:k] = wi[:k] * [-1.0, -1.0, 1.0]
    near = wi[k:2 * k] * [-1.0, -1.0, 1.0] + rng.normal(scale=0.02, size=(k, 3))
    near[:, 2] = np.abs(near[:, 2]) + zmin
    wo[k:2 * k] = near / np.linalg.norm(near, axis=-1, keepdims=True)
    return wi, wo


SPECS = [
    {"nu": 10, "nv": 10, "rs": 0.5},
    {"nu": 100, "nv": 100, "rs": 1.0},
    {"nu": 10, "nv": 1000, "rs": 0.05, "rd": 0.3},
    {"nu": 1000, "nv": 3, "rs": 0.9},
    {"nu": 0, "nv": 0, "rs": 0.04, "rd": 1.0},
    {"nu": 0, "nv": 250, "rs": 0.2, "rd": 0.6},
    {"nu": 37.5, "nv": 4.25, "rs": 0.7, "rd": 0.25},
]


# --- values ------------------------------------------------------------------------------------------------


def test_special_values():
    # wi = wo = N: h = N, h.k = 1, F = rs, max = 1; each diffuse factor 1 - (1/2)^5
    nu, nv, rs, rd = 30.0, 700.0, 0.3, 0.6
    f = load(nu=nu, nv=nv, rs=rs, rd=rd)
    want = math.sqrt((nu + 1) * (nv + 1)) / (8 * math.pi) * rs + 28 * rd / (23 * math.pi) * (1 - rs) * (31 / 32) ** 2
    assert f.eval(N, N) == pytest.approx(want, rel=1e-15)
    # mirror pairs: h = N, h.k = N.wi = N.wo = mu, F = rs + (1 - rs)(1 - mu)^5
    g = load(nu=nu, nv=nv, rs=rs)
    for mu in [0.9, 0.5, 1e-3, 1e-8]:
        for phi in [0.0, 1.0, 2.5]:
            want = math.sqrt((nu + 1) * (nv + 1)) / (8 * math.pi) * (rs + (1 - rs) * (1 - mu) ** 5) / mu**2
            assert g.eval(at_mu(mu, phi), at_mu(mu, phi + math.pi)) == pytest.approx(want, rel=1e-12)
    # wi = N, wo at 2 delta in the xz-plane (h at delta towards x: exponent nu) and in the yz-plane (nv):
    # h.k = cos(delta), N.h = cos(delta), max(N.wi, N.wo) = 1
    for delta in [0.01, 0.1, 0.4]:
        fr = rs + (1 - rs) * (1 - math.cos(delta)) ** 5
        c = math.sqrt((nu + 1) * (nv + 1)) / (8 * math.pi) * fr / math.cos(delta)
        wx = np.array([math.sin(2 * delta), 0.0, math.cos(2 * delta)])
        wy = np.array([0.0, math.sin(2 * delta), math.cos(2 * delta)])
        assert g.eval(N, wx) == pytest.approx(c * math.cos(delta) ** nu, rel=1e-12)
        assert g.eval(N, wy) == pytest.approx(c * math.cos(delta) ** nv, rel=1e-12)


@pytest.mark.parametrize("spec", SPECS, ids=str)
def test_eval_matches_the_independent_reference(spec, rng):
    f = load(**spec)
    wi, wo = pairs(rng)
    a, b = f.eval(wi, wo), ref.brdf(wi, wo, **spec)
    normal = b > 1e-280  # (where (N.h)^e is subnormal or 0, both lose their digits: 1e-315 differed by 10%)
    assert np.count_nonzero(normal) > len(b) // 2
    np.testing.assert_allclose(a[normal], b[normal], rtol=1e-12, atol=0)
    assert np.all(a[~normal] < 1e-270)
    # broadcasting: (50, 1, 3) x (1, 40, 3)
    out = f.eval(wi[:50, None, :], wo[None, :40, :])
    assert out.shape == (50, 40)
    np.testing.assert_allclose(out, ref.brdf(wi[:50, None, :], wo[None, :40, :], **spec), rtol=1e-12, atol=1e-280)


def test_eval_with_rs_zero_matches_the_reference_away_from_retro_reflection(rng):
    # rs = 0: F = (1 - h.k)^5 alone; the literal 1 - h.k cancels where wi ~ wo (h.k ~ 1), the model's
    # |wi - wo|^2 / (4 (1 + h.k)) does not, so the comparison is made where |wi - wo|^2 > 0.1
    spec = {"nu": 20, "nv": 60, "rs": 0.0}
    wi, wo = pairs(rng)
    far = np.sum((wi - wo) ** 2, axis=-1) > 0.1
    a, b = load(**spec).eval(wi[far], wo[far]), ref.brdf(wi[far], wo[far], **spec)
    np.testing.assert_allclose(a, b, rtol=1e-12, atol=0)


def test_eval_with_large_exponents(rng):
    # the literal (N.h)^e rounds N.h to eps relative and raises it to e: a relative error of about e eps |ln N.h|
    # where the value is not negligible; 1e-10 covers e = 1e5 (measured 2e-11)
    spec = {"nu": 1e5, "nv": 1e4, "rs": 0.5}
    wi, wo = pairs(rng)
    a, b = load(**spec).eval(wi, wo), ref.brdf(wi, wo, **spec)
    big = b > 1e-200
    np.testing.assert_allclose(a[big], b[big], rtol=1e-10, atol=0)


@pytest.mark.parametrize("spec", SPECS + [{"nu": 1e6, "nv": 0, "rs": 0.0, "rd": 1.0}], ids=str)
def test_kernel_matches_numpy_twin(spec, rng):
    f = load(**spec)
    # random pairs (some below the horizon, some near grazing), mirror pairs, mu = 1e-8, grazing near-opposite
    wi, wo = direction_pairs(rng)
    fast, twin = f.eval(wi, wo), f.reference(wi, wo)
    assert np.all(np.isfinite(fast)) and np.all(fast >= 0)
    np.testing.assert_allclose(fast, twin, rtol=1e-12, atol=0)


def test_grazing_and_subnormal_directions():
    f = load(nu=100, nv=10, rs=0.5, rd=0.5)
    c = math.sqrt(101 * 11) / (8 * math.pi)
    for mu in [1e-8, 1e-100, 1e-150, 1e-300, 5e-324]:
        wi = at_mu(mu, 0.3)
        # the mirror pair is c F / mu^2: finite while representable; wi = wo is c rs mu^(e - 1) (h = wi, N.h = mu,
        # e >= 10) plus the diffuse term (O(mu^2)): small
        for wo, size in [(wi * [-1, -1, 1], c / mu / mu), (wi, c * mu), (at_mu(0.5, 1.0), 1.0), (at_mu(mu, 2.0), 1.0)]:
            with np.errstate(over="ignore"):
                v, t = f.eval(wi, wo), f.reference(wi, wo)
            if size < 1e300:
                assert np.isfinite(v) and v >= 0 and v == pytest.approx(t, rel=1e-12)
                if size < 1e-7:
                    assert v <= size
            else:  # (beyond the largest double: inf, as the twin)
                assert v == t and v > 1e300


@pytest.mark.parametrize("spec", SPECS, ids=str)
def test_reciprocity(spec):
    f = load(**spec)
    assert f.reciprocal
    r = pumpup.check_reciprocity(f)
    assert r.reciprocal, str(r)


@pytest.mark.parametrize("spec", SPECS, ids=str)
def test_zero_below_the_horizon(spec, rng):
    f = load(**spec)
    wi, wo = upper(rng, 500, 0.0), upper(rng, 500, 0.0)
    down = wo * [1, 1, -1]
    assert np.all(f.eval(wi, down) == 0) and np.all(f.eval(down, wi) == 0)
    assert np.all(f.eval(wi * [1, 1, 0] / np.linalg.norm(wi[:, :2], axis=-1, keepdims=True), wo) == 0)  # N.wi = 0
    assert np.all(f.reference(wi, down) == 0) and np.all(f.reference(down, wi) == 0)


# --- parameters and spec -----------------------------------------------------------------------------------


@pytest.mark.parametrize(
    "spec,pname,range_text",
    [
        ({"nu": -1, "nv": 10, "rs": 0.5}, "nu", "[0, 1e+06]"),
        ({"nu": 10, "nv": -0.5, "rs": 0.5}, "nv", "[0, 1e+06]"),
        ({"nu": 10, "nv": 2e6, "rs": 0.5}, "nv", "[0, 1e+06]"),
        ({"nu": 10, "nv": 10, "rs": 1.5}, "rs", "[0, 1]"),
        ({"nu": 10, "nv": 10, "rs": -0.1}, "rs", "[0, 1]"),
        ({"nu": 10, "nv": 10, "rs": 0.5, "rd": 1.01}, "rd", "[0, 1]"),
        ({"nu": 10, "nv": 10, "rs": 0.5, "rd": -1}, "rd", "[0, 1]"),
        ({"nu": float("nan"), "nv": 10, "rs": 0.5}, "nu", "[0, 1e+06]"),
        ({"nu": 10, "nv": float("inf"), "rs": 0.5}, "nv", "[0, 1e+06]"),
        ({"nv": 10, "rs": 0.5}, "nu", "[0, 1e+06]"),
        ({"nu": 10, "nv": 10}, "rs", "[0, 1]"),
    ],
)
def test_bad_parameters_name_the_parameter_and_its_range(spec, pname, range_text):
    with pytest.raises(pumpup.SpecError, match=repr(pname)) as exc:
        load(**spec)
    assert range_text in str(exc.value)


def test_unknown_parameter():
    with pytest.raises(pumpup.SpecError, match="'n'"):
        load(nu=1, nv=1, rs=0.5, n=3)


@pytest.mark.parametrize("spec", SPECS, ids=str)
def test_spec_round_trip(spec):
    f = load(**spec)
    assert pumpup.load(f.spec) == f
    assert pumpup.load(dict(f.spec)).spec == f.spec
    assert f.spec["rd"] == spec.get("rd", 0.0)
    assert "ashikhmin_shirley" in pumpup.registry()


def test_hints():
    f = load(nu=10, nv=1000, rs=0.5)
    lobe = f.lobe(0.3)
    # the smaller exponent: x^((e + 1) / (n + 1) - 1) is bounded for every azimuth of h
    assert (lobe.axis, lobe.radial, lobe.sharpness, lobe.levels, lobe.symmetric) == ("half", "power", 10, (0.3,), True)
    assert lobe.kinks is not None and f.azimuth_range() == pytest.approx(math.pi / 2)
    g = load(nu=40, nv=40, rs=0.5, rd=0.5)
    assert g.lobe(0.7).kinks is None and g.azimuth_range() is None
    terms = g.albedo_terms()
    assert len(terms) == 2 and terms[0][1] == load(nu=40, nv=40, rs=0.5)
    assert terms[1][0] == pytest.approx(0.25) and terms[1][1].azimuth_range() is None
    assert load(nu=40, nv=40, rs=1.0, rd=0.5).albedo_terms()[0][1].spec["rd"] == 0.5  # (no diffuse term at rs = 1)


# --- albedo ------------------------------------------------------------------------------------------------

ALBEDO_CASES = [
    ({"nu": 100, "nv": 100, "rs": 1.0}, 1.0, 0.0),
    ({"nu": 100, "nv": 100, "rs": 1.0}, 0.5, 0.0),
    ({"nu": 100, "nv": 100, "rs": 1.0}, 0.05, 0.0),
    ({"nu": 10, "nv": 10, "rs": 0.5, "rd": 0.5}, 1.0, 0.0),
    ({"nu": 10, "nv": 10, "rs": 0.5, "rd": 0.5}, 0.3, 0.0),
    ({"nu": 10, "nv": 10, "rs": 0.5, "rd": 0.5}, 0.05, 0.0),
    ({"nu": 10, "nv": 1000, "rs": 1.0}, 1.0, 0.0),
    ({"nu": 10, "nv": 1000, "rs": 1.0}, 1.0, 0.3),
    ({"nu": 10, "nv": 1000, "rs": 1.0}, 0.5, 0.0),
    ({"nu": 10, "nv": 1000, "rs": 1.0}, 0.5, 0.7),
    ({"nu": 10, "nv": 1000, "rs": 1.0}, 0.05, 0.0),
    ({"nu": 10, "nv": 1000, "rs": 1.0}, 0.05, 1.2),
    ({"nu": 10, "nv": 1000, "rs": 0.3, "rd": 0.4}, 0.9, 0.4),
    ({"nu": 10, "nv": 1000, "rs": 0.3, "rd": 0.4}, 0.05, 1.2),
    ({"nu": 800, "nv": 20, "rs": 0.1, "rd": 0.9}, 0.2, 2.5),
    ({"nu": 800, "nv": 20, "rs": 0.1, "rd": 0.9}, 0.7, -0.4),
]


@pytest.mark.parametrize("spec,mu,phi", ALBEDO_CASES, ids=str)
def test_albedo_against_the_independent_quadrature(spec, mu, phi):
    f = load(**spec)
    a, err = pumpup.albedo(f, mu, return_error=True, phi=phi)
    r, r_err = ref.albedo(mu, phi=phi, **spec)
    assert r_err < 1e-10  # the reference resolves the lobe (else the comparison would say little)
    assert abs(float(a) - r) <= float(err) + r_err, (float(a), float(err), r, r_err)


def _agrees_with_the_cylinder_reference(spec, mu, phi):
    """pumpup's albedo against the reference in cylindrical coordinates about the narrow axis (method B), within the
    sum of both error estimates."""
    f = load(**spec)
    a, err = pumpup.albedo(f, mu, return_error=True, phi=phi)
    r, r_err = ref.albedo_cylinder(mu, phi=phi, **spec)
    assert r_err < 1e-10
    assert abs(float(a) - r) <= float(err) + r_err, (float(a), float(err), r, r_err)


@pytest.mark.parametrize("spec,mu,phi", [({"nu": 1, "nv": 1e5, "rs": 1.0}, 0.9, 0.4),
                                         ({"nu": 0, "nv": 1e4, "rs": 1.0}, 0.05, 1.2)], ids=str)
def test_albedo_of_a_strongly_anisotropic_lobe(spec, mu, phi):
    # a ridge: (theta, phi) rules do not resolve it (the reference's method A reports 8e-4 and 3e-5), the
    # cylindrical coordinates about the narrow axis do (method B)
    _agrees_with_the_cylinder_reference(spec, mu, phi)


@pytest.mark.parametrize("n", [0, 1, 10, 100, 1e4])
def test_albedo_at_normal_incidence_in_closed_form(n):
    # mu = 1, rs = 1: wo_z = 2 (N.h)^2 - 1, so a = (n + 1) int_{1/sqrt 2}^1 c^n (2 c^2 - 1) dc
    want = 2 * (n + 1) * (1 - 2 ** (-(n + 3) / 2)) / (n + 3) - (1 - 2 ** (-(n + 1) / 2))
    a, err = pumpup.albedo(load(nu=n, nv=n, rs=1.0), 1.0, return_error=True)
    assert abs(float(a) - want) <= float(err) + 1e-15
    r, r_err = ref.albedo(1.0, n, n, 1.0)
    assert abs(r - want) <= r_err  # (and the reference's own error estimate holds there)


def test_diffuse_albedo_in_closed_form():
    # eq. 5's 28 / (23 pi) makes the diffuse albedo rd (1 - rs) (1 - (1 - mu / 2)^5)
    mu = np.array([1e-6, 0.05, 0.3, 0.7, 1.0])
    f, g = load(nu=50, nv=5, rs=0.2, rd=0.9), load(nu=50, nv=5, rs=0.2)
    a, ea = pumpup.albedo(f, mu, return_error=True)
    b, eb = pumpup.albedo(g, mu, return_error=True)
    want = 0.9 * 0.8 * (1 - (1 - mu / 2) ** 5)
    assert np.all(np.abs((a - b) - want) <= ea + eb + 1e-15)


def test_reference_error_estimate_holds_at_a_finer_resolution():
    # the reference's error (the difference of n and 3n/2 nodes per panel) against 2n nodes per panel
    for spec, mu, phi in [({"nu": 10, "nv": 1000, "rs": 1.0}, 0.05, 1.2),
                          ({"nu": 100, "nv": 100, "rs": 0.5, "rd": 0.5}, 0.3, 0.0)]:
        r, r_err = ref.albedo(mu, phi=phi, **spec)
        fine, _ = ref.albedo(mu, phi=phi, n=28, **spec)
        assert abs(r - fine) <= r_err


@pytest.mark.parametrize("nu,nv", [(0, 0), (10, 10), (1e4, 1e4), (10, 1000), (1e6, 1e6)])
def test_albedo_never_exceeds_one(nu, nv):
    # with F = 1 the specular albedo is the integral of p_h(h) N.wo / max(N.wi, N.wo) <= p_h(h) over h: at most 1
    f = load(nu=nu, nv=nv, rs=1.0)
    mu = np.concatenate([np.geomspace(1e-6, 0.05, 5), np.cos(np.linspace(0, np.pi / 2, 17)[:-1])])
    phis = [0.0] if nu == nv else [0.0, 0.7, math.pi / 2]
    for phi in phis:
        a, err = pumpup.albedo(f, mu, return_error=True, phi=phi)
        assert np.all(err < 1e-8)
        assert np.all(a <= 1.0), (phi, mu[np.argmax(a)], a.max())


# --- sampling ----------------------------------------------------------------------------------------------

VIEWS = np.array([at_mu(0.99, 0.2), at_mu(0.6, 2.0), at_mu(0.08, -0.7)])
SAMPLED = [
    {"nu": 20, "nv": 20, "rs": 0.5},
    {"nu": 10, "nv": 300, "rs": 0.5},
    {"nu": 2000, "nv": 40, "rs": 1.0},
    {"nu": 50, "nv": 5, "rs": 0.1, "rd": 0.7},
    {"nu": 0, "nv": 0, "rs": 0.3, "rd": 1.0},
]


def _sampler(f):
    return lambda wo, n, rng: f.sample_wi(wo, *rng.random((2, n)))


@pytest.mark.parametrize("spec", SAMPLED, ids=str)
def test_sampler_chi2(spec):
    f = load(**spec)
    res = chi2_test(_sampler(f), f.pdf_wi, VIEWS, n_samples=300_000, seed=7)
    assert res.passed, str(res)
    # the pdf integrates to the fraction of draws that were not rejected (wi above the horizon), measured by
    # the independent quadrature, within 5 standard deviations of the binomial count
    for j, wo in enumerate(VIEWS):
        total, total_err = ref.pdf_integral(f.pdf_wi, wo, spec["nu"], spec["nv"])
        assert total_err < 1e-9 and total <= 1.0 + 1e-12
        accepted = 1.0 - res.observed_rejected[j] / res.n_samples
        sigma = math.sqrt(total * (1.0 - total) / res.n_samples)
        assert abs(accepted - total) <= 5.0 * sigma, (j, accepted, total, sigma)
        assert abs(res.pdf_integral[j] - total) <= res.integration_error[j] + total_err


def test_sampler_catches_a_wrong_exponent():
    # sampled with nv = 300 but reported (and binned against) the density of nv = 330: the test must fail
    f, wrong = load(nu=10, nv=300, rs=0.5), load(nu=10, nv=330, rs=0.5)

    def sample(wo, n, rng):
        wi, _ = f.sample_wi(wo, *rng.random((2, n)))
        return wi, np.where(wi[:, 2] > 0, wrong.pdf_wi(wi, wo), 0.0)

    assert not chi2_test(sample, wrong.pdf_wi, VIEWS[:1], n_samples=300_000, seed=7).passed


def test_sampler_shapes_rejections_and_density(rng):
    f = load(nu=30, nv=300, rs=0.2, rd=0.5)
    wo = at_mu(0.3, 0.4)
    u1, u2 = rng.random((2, 5000))
    wi, pdf = f.sample_wi(wo, u1, u2)
    assert wi.shape == (5000, 3) and pdf.shape == (5000,)
    rejected = np.all(wi == 0, axis=1)
    assert rejected.any() and np.all(pdf[rejected] == 0)
    ok = ~rejected
    assert np.all(wi[ok, 2] > 0) and np.allclose(np.linalg.norm(wi[ok], axis=1), 1, atol=1e-12)
    np.testing.assert_allclose(pdf[ok], f.pdf_wi(wi[ok], wo), rtol=1e-9)
    assert np.all(f.pdf_wi(wi[ok] * [1, 1, -1], wo) == 0)
    # wo below the horizon: every draw rejected
    wi, pdf = f.sample_wi(wo * [1, 1, -1], u1, u2)
    assert np.all(wi == 0) and np.all(pdf == 0)
    # the mixture's probability (documented): rd (1 - rs) / (1 + rd (1 - rs))
    assert f.diffuse_probability() == pytest.approx(0.4 / 1.4)
    assert load(nu=30, nv=30, rs=0.2).diffuse_probability() == 0.0


def test_sampler_follows_the_paper_for_the_lobe():
    # rd = 0: u2 = 0 gives cos(theta_h) = 1 (h = N, wi the mirror image of wo); u1 = 0 and 1/4 give phi_h = 0
    # and pi/2 (the quadrant's ends), where the exponent is nu and nv: cos(theta_h) = (1 - u2)^(1 / (e + 1))
    f = load(nu=8, nv=99, rs=0.5)
    wo = at_mu(0.7, 1.1)
    wi, pdf = f.sample_wi(wo, np.array([0.3]), np.array([0.0]))
    np.testing.assert_allclose(wi[0], wo * [-1, -1, 1], atol=1e-15)
    assert pdf[0] == pytest.approx(math.sqrt(9 * 100) / (2 * math.pi) / (4 * 0.7), rel=1e-12)  # p_h(N) / (4 wo.h)
    for u1, e, axis in [(0.0, 8, 0), (np.nextafter(0.25, 0.0), 99, 1)]:
        wi, _ = f.sample_wi(wo, np.array([u1]), np.array([0.5]))
        h = (wi[0] + wo) / np.linalg.norm(wi[0] + wo)
        assert h[2] == pytest.approx(0.5 ** (1 / (e + 1)), rel=1e-9)
        assert abs(h[1 - axis]) < 1e-7


# --- slow: harder cases ------------------------------------------------------------------------------------


@pytest.mark.slow
@pytest.mark.parametrize("spec,mu,phi", [({"nu": 1e4, "nv": 1e4, "rs": 1.0}, 0.05, 0.0),
                                         ({"nu": 1e5, "nv": 100, "rs": 0.2}, 0.9, 0.4),
                                         ({"nu": 1, "nv": 1e5, "rs": 1.0}, 0.05, 1.2),
                                         ({"nu": 10, "nv": 1000, "rs": 0.3, "rd": 0.4}, 1e-3, 0.3),
                                         ({"nu": 100, "nv": 100, "rs": 1.0}, 1e-3, 0.0)], ids=str)
def test_albedo_hard_cases(spec, mu, phi):
    _agrees_with_the_cylinder_reference(spec, mu, phi)


def test_pumpup_sample_uses_the_papers_sampling():
    """pumpup.sample, pumpup.sampling.pdf and pumpup.mc_albedo draw with the model's own sampler (BRDF.own_sampler)."""
    f = pumpup.load({"type": "ashikhmin_shirley", "nu": 10, "nv": 1000, "rs": 0.5, "rd": 0.3})
    wo = np.array([0.6, 0.0, 0.8])
    wi, p = pumpup.sample(f, wo, 2000, np.random.default_rng(3))
    u = np.random.default_rng(3).random((2, 2000))
    wi2, p2 = f.sample_wi(wo, u[0], u[1])
    np.testing.assert_array_equal(wi, wi2)
    np.testing.assert_array_equal(p, p2)
    np.testing.assert_allclose(pumpup.sampling.pdf(f, wi[p > 0], wo), p[p > 0], rtol=1e-12)
    assert str(pumpup.sampling.strategy(f)) == "1 x ashikhmin_shirley's own"
    a, e = pumpup.mc_albedo(f, 0.8, 200_000, np.random.default_rng(5))
    exact = float(pumpup.albedo(f, [0.8])[0])
    assert abs(a - exact) < 5 * e, (a, e, exact)


def test_the_diffuse_term_is_a_closed_form_term():
    """The albedo splits into the specular lobe (a half-vector hint, Lobe) and the diffuse term, whose hint is the
    closed form of an existing family (``ClosedForm``): its albedo is rd (1 - rs) (1 - (1 - mu / 2)^5) exactly."""
    f = pumpup.load({"type": "ashikhmin_shirley", "nu": 100, "nv": 100, "rs": 0.05, "rd": 0.8})
    terms = f.albedo_terms()
    assert len(terms) == 2
    mu = np.array([1.0, 0.5, 0.05])
    (wd, diffuse), = [(w, t) for w, t in terms if t.type == "ashikhmin_shirley-diffuse"]
    assert helpers.hint_routes(diffuse) and helpers.view(diffuse).kind == "constant"
    np.testing.assert_allclose(wd * pumpup.albedo(diffuse, mu), 0.8 * 0.95 * (1 - (1 - mu / 2) ** 5), rtol=1e-14)


@pytest.mark.parametrize("spec", [{"nu": 10, "nv": 10, "rs": 1.0}, {"nu": 100, "nv": 100, "rs": 0.05, "rd": 0.8},
                                  {"nu": 0, "nv": 0, "rs": 0.2, "rd": 0.5}, {"nu": 5000, "nv": 5000, "rs": 0.9}],
                         ids=str)
def test_isotropic_lobe_takes_a_1d_route(spec):
    """Isotropic, the specular lobe takes the rule on the half vector's arc (``half_arc``; the 1 / (h.k) cancels the
    Jacobian): its route is a 1-D one at every mu, and its albedo agrees with the nested engine at rtol 1e-12 within
    the summed estimates, from normal to grazing incidence; anisotropic, the nested engine."""
    from pumpup.engine.routes import plan

    f = load(**spec)
    mu = np.array([1.0, 0.9, 0.5, 0.2, 0.05, 1e-3, 1e-6])
    routes = {r for _, t in f.albedo_terms() for r, _, _ in plan(t, mu)}
    assert routes <= {"half_arc", "closed"} and "half_arc" in routes, routes
    a, e = pumpup.albedo(f, mu, return_error=True, rtol=1e-10, engine="1d")
    with helpers.without_1d():
        b, eb = pumpup.albedo(f, mu, return_error=True, rtol=1e-12)
    assert np.all(np.abs(a - b) <= e + eb), (np.abs(a - b) / (e + eb)).max()
    assert np.all(e <= 1e-10 * a)
    assert {r for _, t in load(nu=10, nv=1000, rs=0.5).albedo_terms() for r, _, _ in plan(t, mu)} == {"nested"}


@functools.cache
def _cylinder_reference(mu, nu, nv, rs, phi):
    """The cylindrical reference (30 points per dimension; 2-5 s each), once per case for both engines."""
    return ref.albedo_cylinder(mu, nu, nv, rs, phi=phi, n=30)


@pytest.mark.parametrize("nu, nv, mu, phi", [(10, 1000, 0.5, 0.0), (1000, 10, 0.5, 0.0), (10, 1000, 0.05, 0.0),
                                             (10, 1000, 0.5, 0.7), (100, 10000, 0.5, 0.0)])
@pytest.mark.parametrize("engine", ["nested", "2d"])
def test_strongly_anisotropic_albedo_within_its_error_on_every_engine(nu, nv, mu, phi, engine):
    """A lobe narrow across one axis is a ridge along the other: both engines resolve it (the hint's cuts graded
    towards the ridge) and their estimates bound the error against the independent cylindrical quadrature."""
    f = pumpup.load({"type": "ashikhmin_shirley", "nu": nu, "nv": nv, "rs": 0.5})
    a, e = pumpup.albedo(f, mu, phi=phi, return_error=True, rtol=1e-10, engine=engine)
    r, r_err = _cylinder_reference(mu, nu, nv, 0.5, phi)
    assert abs(float(a) - r) <= float(e) + r_err
