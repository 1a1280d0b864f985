"""He-Torrance-Sillion-Greenberg (pumpup.models.he_torrance): limits, albedo against an
independent brute-force quadrature, reciprocity, bad input, pumping and sampling."""

import math

import helpers
import numpy as np
import pytest
from scipy.optimize import brentq
from scipy.special import erfc, gammaln

import pumpup
from pumpup.models.he_torrance import SERIES_RTOL, effective_sigma, fresnel_unpolarised, shadowing

FIG5 = {"type": "he_torrance", "sigma_0": 0.1, "tau": 1.7}


# ---------------------------------------------------------------------------------------
# An independent implementation: direct series (log-space terms up to a fixed, generous M),
# brentq for the effective roughness, scipy's erfc, and a brute-force tensor Gauss-Legendre
# rule in spherical coordinates (theta_o, phi_o) around N.
# ---------------------------------------------------------------------------------------


def _sigma_brentq(mu_i, mu_o, s0, tau):
    m0 = 2 * s0 / tau

    def K(mu):
        s = math.sqrt(max(0.0, 1 - mu * mu))
        return 0.0 if s == 0 else s / mu * erfc(mu / (s * m0))

    a = s0 / 4 * (K(mu_i) + K(mu_o))
    if a < 1e-100:  # z0 < 1e-100: exp(-z0^2 / (2 s0^2)) = 1 to rounding
        z0 = a / math.sqrt(math.pi / 2)
        return s0 / math.sqrt(1 + (z0 / s0) ** 2)
    z0 = brentq(lambda z: math.sqrt(math.pi / 2) * z - a * math.exp(-z * z / (2 * s0 * s0)), 0.0, a, xtol=1e-300,
                rtol=1e-15)
    return s0 / math.sqrt(1 + (z0 / s0) ** 2)


def _smith(mu, m0):
    if np.all(mu == 1.0):
        return np.ones_like(mu, dtype=float)
    c = mu / (np.sqrt(1 - mu * mu) * m0)
    return (1 - erfc(c) / 2) / (1 + (np.exp(-c * c) / (math.sqrt(math.pi) * c) - erfc(c)) / 2)


def _f_independent(spec, wi, theta_o, phi_o):
    """f_dd + f_ud on a (theta, phi) grid for one wi, the series summed to beyond 1e-14."""
    p = pumpup.load(spec).p
    s0, tau, lam = p["sigma_0"], p["tau"], p["wavelength"]
    k = 2 * math.pi / lam
    T, P = np.meshgrid(theta_o, phi_o, indexing="ij")
    wo = np.stack([np.sin(T) * np.cos(P), np.sin(T) * np.sin(P), np.cos(T)], axis=-1)
    s = wi + wo
    sig = np.array([_sigma_brentq(wi[2], math.cos(t), s0, tau) for t in theta_o])[:, None]
    g = (k * sig * s[..., 2]) ** 2
    q = (k * tau) ** 2 * (s[..., 0] ** 2 + s[..., 1] ** 2) / 4
    M = int(np.max(g) + 40 * math.sqrt(np.max(g)) + 80)
    m = np.arange(1, M + 1, dtype=float)
    logt = m * np.log(g[..., None]) - g[..., None] - gammaln(m + 1) - np.log(m) - q[..., None] / m
    series = np.exp(logt).sum(axis=-1)
    # the neglected tail is below P(M+1) / (M+1) / (1 - g / (M+2)): check it is < 1e-14 of the sum
    tail = np.exp((M + 1) * np.log(g) - g - gammaln(M + 2)) / (M + 1) / (1 - g / (M + 2))
    assert np.all(tail <= 1e-14 * series)
    D = (math.pi * tau / lam) ** 2 / 4 * series
    s2 = np.sum(s * s, axis=-1)
    F = fresnel_unpolarised(np.sqrt(s2) / 2, p["n"], p["k"])
    m0 = 2 * s0 / tau
    S = _smith(wi[2], m0) * _smith(wo[..., 2], m0)
    return F * (s2 / s[..., 2]) ** 2 * S * D / (math.pi * wi[2] * wo[..., 2]) + p["diffuse"] / math.pi


def _panels(breaks, n):
    x, w = np.polynomial.legendre.leggauss(n)
    xs, ws = [], []
    for a, b in zip(breaks[:-1], breaks[1:]):
        xs.append(a + (b - a) * (x + 1) / 2)
        ws.append(w * (b - a) / 2)
    return np.concatenate(xs), np.concatenate(ws)


def brute_albedo(spec, mu, n):
    """a(mu) - specular weight by tensor Gauss-Legendre in (theta_o, phi_o), n nodes per panel;
    panels are graded around the mirror direction (theta_i, pi) and at the horizon."""
    th_i = math.acos(mu)
    wi = np.array([math.sin(th_i), 0.0, mu])
    w = 0.03
    tb = np.unique(np.clip(np.concatenate([th_i + w * np.array([-16, -8, -4, -2, -1, 0, 1, 2, 4, 8, 16]),
                                           np.linspace(0, math.pi / 2, 9)]), 0, math.pi / 2))
    pb = np.unique(np.clip(np.concatenate([math.pi - w / max(math.sin(th_i), 0.05) * np.array([16, 8, 4, 2, 1, 0]),
                                           np.linspace(0, math.pi, 9)]), 0, math.pi))
    t, wt = _panels(tb, n)
    ph, wp = _panels(pb, n)
    f = _f_independent(spec, wi, t, ph)
    return 2 * np.einsum("ij,i,j->", f, wt * np.cos(t) * np.sin(t), wp)


@pytest.mark.parametrize(
    "spec,mu",
    [(FIG5, 1.0),
     # (the same model at two more incidences: -m slow)
     pytest.param(FIG5, 0.5, marks=pytest.mark.slow), pytest.param(FIG5, 0.2, marks=pytest.mark.slow),
     ({"type": "he_torrance", "sigma_0": 0.18, "tau": 1.0, "wavelength": 0.4, "n": 1.5, "k": 0.3, "diffuse": 0.2},
      0.7)],
)
def test_albedo_matches_brute_force_quadrature(spec, mu):
    f = pumpup.load(spec)
    a, err = pumpup.albedo(f, mu, return_error=True)
    w = float(f.specular_weight(mu))
    b1, b2 = brute_albedo(spec, mu, 24), brute_albedo(spec, mu, 40)
    brute_err = abs(b2 - b1)  # the coarse rule's error bounds the fine one's (Gauss-Legendre converges fast)
    assert brute_err < 1e-9, brute_err
    assert abs(float(a) - (b2 + w)) <= float(err) + brute_err + 1e-12, (float(a), b2 + w, float(err), brute_err)


def test_independent_pieces_agree():
    # the effective roughness, by Newton (kernel), bisection (reference) and brentq (here)
    for mu_i, mu_o in [(1.0, 1.0), (0.5, 0.3), (0.05, 0.9), (1e-6, 1e-3)]:
        want = _sigma_brentq(mu_i, mu_o, 0.1, 1.7)
        assert abs(float(effective_sigma(mu_i, mu_o, 0.1, 1.7)) - want) <= 1e-14 * want
    mu = np.array([1e-6, 0.01, 0.3, 0.9, 1 - 1e-12])
    np.testing.assert_allclose(shadowing(mu, 0.12), _smith(mu, 0.12), rtol=1e-14)
    # conductor at normal incidence: ((n-1)^2 + k^2) / ((n+1)^2 + k^2)
    assert abs(float(fresnel_unpolarised(1.0, 0.13, 4.0)) - (0.87**2 + 16) / (1.13**2 + 16)) < 1e-15


def test_reciprocal():
    for spec in (FIG5, {"type": "he_torrance", "sigma_0": 0.3, "tau": 0.9, "wavelength": 0.45, "n": 1.6, "k": 2.0}):
        r = pumpup.check_reciprocity(pumpup.load(spec))
        assert r.reciprocal, str(r)


def test_smooth_limit_specular_weight_is_fresnel_times_shadowing():
    # sigma_0 -> 0: g -> 0, so the specular weight -> |F|^2 S and the directional diffuse -> 0
    mu = np.array([1.0, 0.6, 0.2])
    for s0 in (1e-3, 1e-5):
        f = pumpup.load({"type": "he_torrance", "sigma_0": s0, "tau": 1.7, "n": 1.5})
        m0 = 2 * s0 / 1.7
        fs = fresnel_unpolarised(mu, 1.5) * shadowing(mu, m0) ** 2
        w = f.specular_weight(mu)
        g = (4 * math.pi * s0 * mu / 0.55) ** 2
        np.testing.assert_allclose(w, fs * np.exp(-g), rtol=1e-14)
        np.testing.assert_allclose(w, fs, rtol=2 * np.max(g) + 1e-15)
    f = pumpup.load({"type": "he_torrance", "sigma_0": 1e-4, "tau": 1.7, "n": 1.5})
    a = pumpup.albedo(f, mu)
    dd = a - f.specular_weight(mu)
    assert np.all(dd >= 0) and np.all(dd < 1e-5), dd  # the directional diffuse is O(g)
    np.testing.assert_allclose(a, fresnel_unpolarised(mu, 1.5), rtol=1e-5)  # a mirror: albedo |F|^2


def test_rough_limit_is_torrance_sparrow_and_specular_vanishes():
    # sigma_0 / lambda large: g >> 1, e^-g S -> 0, and rho_dd tends to Beckmann Torrance-Sparrow with
    # Smith shadowing and m = 2 sigma / tau, the geometric-optics limit of the Kirchhoff theory; the
    # relative difference is O(1/g)
    th = math.radians(30)
    wi = np.array([math.sin(th), 0, math.cos(th)])
    wo = np.array([[-math.sin(th + d), 0, math.cos(th + d)] for d in (0.0, 0.05, 0.1)])
    devs = []
    for s0 in (0.1, 0.3, 1.0):
        spec = {"type": "he_torrance", "sigma_0": s0, "tau": 10 * s0, "wavelength": 0.5}
        f = pumpup.load(spec)
        s = wi + wo
        t2 = (s[:, 0] ** 2 + s[:, 1] ** 2) / s[:, 2] ** 2
        sig = effective_sigma(wi[2], wo[:, 2], s0, 10 * s0)
        m = 2 * sig / (10 * s0)
        S = _smith(wi[2], 0.2) * _smith(wo[:, 2], 0.2)
        ts = S * np.exp(-t2 / m**2) * (1 + t2) ** 2 / (4 * math.pi * m**2 * wi[2] * wo[:, 2])
        devs.append(np.max(np.abs(f.eval(wi, wo) / ts - 1)))
        if s0 == 1.0:
            assert float(f.specular_weight(math.cos(th))) < 1e-200
    assert devs[0] > devs[1] > devs[2] and devs[2] < 3e-3, devs


def test_truncation_error_is_in_the_albedo_error():
    f = pumpup.load(FIG5)
    mu = np.array([0.8])
    a, err = pumpup.albedo(f, mu, return_error=True)
    assert err[0] >= SERIES_RTOL * (a[0] - f.specular_weight(mu)[0])


@pytest.mark.parametrize(
    "change,name",
    [({"sigma_0": 0.0}, "sigma_0"), ({"sigma_0": -1.0}, "sigma_0"), ({"tau": 0.0}, "tau"), ({"tau": -2.0}, "tau"),
     ({"wavelength": 0.0}, "wavelength"), ({"k": 1.0}, "k"), ({"n": -1.5}, "n"), ({"diffuse": 1.5}, "diffuse"),
     ({"sigma_0": 2.0, "wavelength": 0.5}, "sigma_0")],
)
def test_bad_input_names_the_parameter(change, name):
    with pytest.raises(pumpup.SpecError, match=repr(name)):
        pumpup.load({**FIG5, **change})


def test_sampling_cosine_fallback_and_mc_albedo():
    f = pumpup.load({"type": "he_torrance", "sigma_0": 0.03, "tau": 0.8, "n": 1.5, "k": 3.0, "diffuse": 0.1})
    rng = np.random.default_rng(7)
    mu = 0.6
    wo = np.array([math.sqrt(1 - mu * mu), 0.0, mu])
    wi, pdf = pumpup.sample(f, wo, 2000, rng)
    assert wi.shape == (2000, 3) and np.all(wi[:, 2] > 0)
    np.testing.assert_allclose(pdf, wi[:, 2] / math.pi, rtol=1e-12)  # the cosine fallback
    est, se = pumpup.mc_albedo(f, mu, 40000, rng, kind="cosine")
    # the delta part is not sampled but added exactly (no variance)
    a = float(pumpup.albedo(f, mu))
    assert float(f.specular_weight(mu)) > 10 * se
    assert abs(est - a) < 5 * se + 1e-9, (est, se, a)


@pytest.mark.slow  # tabulating the albedo that pumping divides by: ~50 s on a loaded machine
def test_pumping_works():
    f = pumpup.load({"type": "he_torrance", "sigma_0": 0.25, "tau": 1.0, "n": 1.5, "diffuse": 0.5})
    g = pumpup.pump(f, g="g1")
    wi = np.array([[0.6, 0.0, 0.8], [0.0, 0.0, 1.0]])
    wo = np.array([[-0.6, 0.0, 0.8], [0.28, 0.0, 0.96]])
    want = f.eval(wi, wo) / np.maximum(pumpup.albedo(f, wi[:, 2]), pumpup.albedo(f, wo[:, 2]))  # 001 eq. 20
    np.testing.assert_allclose(g.eval(wi, wo), want, rtol=1e-6)
    assert np.all(pumpup.albedo(g, np.array([0.3, 0.9])) <= 1 + 1e-9)


def test_agrees_with_westins_reference_implementation():
    """An independent implementation: Westin's reference code of He et al. (1991), transcribed by a
    reviewer who did not write this model (tests/data/he_torrance_westin.json says where from)."""
    import json

    data = json.loads((helpers.DATA / "he_torrance_westin.json").read_text())
    n = 0
    for case in data["cases"]:
        f = pumpup.load(case["spec"])
        for p in case["pairs"]:
            got = float(f.eval(np.array(p["wi"]), np.array(p["wo"])))
            # the reference's series runs to a relative 1e-17 (Westin's own absolute 1e-12 cut-off limited the
            # agreement to 1.9e-7); pumpup truncates at a proven relative 1e-13: measured worst 9.6e-14
            assert abs(got - p["f"]) <= 1e-12 * p["f"], (case["spec"], p, got)
            n += 1
        for s in case["specular"]:
            assert abs(float(f.specular_weight(s["mu"])) - s["weight"]) <= 1e-12 * s["weight"] + 1e-300, (
                case["spec"], s)
    assert n >= 20


def test_tiny_wavelength_is_refused_in_one_line():
    """g = (4 pi sigma_0 / lambda)^2 overflowed for lambda = 3.4e-181 (found by the slow property test): the
    ratio is compared before squaring, and the refusal names both parameters and the allowed range."""
    for wl in (3.3692610298414625e-181, 1e-300):
        with pytest.raises(pumpup.SpecError, match=r"'sigma_0' / 'wavelength' = .* outside its allowed range"):
            pumpup.load({"type": "he_torrance", "sigma_0": 0.1, "tau": 1.7, "wavelength": wl})


def test_fresnel_near_index_one_is_metals():
    """He-Torrance's Fresnel factor is metal's (no cancellation near n + i k = 1: n = 1 at c = 1e-8 gave 0.039 for 0),
    compiled and numpy, against 40-digit mpmath."""
    import mpmath as mp

    from pumpup.models.he_torrance import _fresnel_c

    assert fresnel_unpolarised(np.array([1e-8, 0.5]), 1.0)[0] == 0.0 and _fresnel_c(1e-8, 1.0, 0.0) == 0.0
    with mp.workdps(40):
        for n, k in ((1.0 + 1e-7, 0.0), (1.5, 0.0), (0.2, 3.0)):
            e = mp.mpf(n) + 1j * mp.mpf(k)
            for c in (1e-8, 1e-3, 0.5, 1.0):
                a = mp.sqrt((e - 1) * (e + 1) + mp.mpf(c) ** 2)
                ref = float((abs((e * e * c - a) / (e * e * c + a)) ** 2 + abs((c - a) / (c + a)) ** 2) / 2)
                for got in (float(fresnel_unpolarised(c, n, k)), _fresnel_c(c, n, k)):
                    assert abs(got - ref) <= 1e-13 * ref + 1e-300, (n, k, c, got, ref)
