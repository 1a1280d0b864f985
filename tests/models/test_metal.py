"""Metal and plastic BRDFs (000 eq. 27-30), the Fresnel reflectance and per_channel."""

import math

import numpy as np
import pytest
from helpers import direction_pairs, polar

import pumpup
from pumpup.models.metal import _fresnel_real, fresnel, per_channel

N = np.array([0.0, 0.0, 1.0])
INDICES = [(0.2, 3.0), (0.18, 3.42), (1.37, 1.77), (1.5, 0.0), (1.0001, 0.0), (0.67, 0.0), (1.1, 6.0),
           (2.5, 0.01), (0.05, 0.0), (40.0, 30.0)]


def f0(eta, k):
    """Fresnel reflectance at normal incidence."""
    return ((eta - 1) ** 2 + k**2) / ((eta + 1) ** 2 + k**2)


@pytest.mark.parametrize("eta,k", INDICES)
def test_fresnel_real_and_complex_agree(eta, k):
    cos_i = np.concatenate([np.linspace(0, 1, 2001), [1e-8, 1e-12, 1 - 1e-12], np.cos(np.linspace(0, 1.5707, 997))])
    exact = fresnel(cos_i, eta, k)
    real = np.array([_fresnel_real(c, eta, k) for c in cos_i])
    np.testing.assert_allclose(real, exact, rtol=1e-12, atol=1e-15)
    assert np.all((exact >= 0) & (exact <= 1 + 1e-15))
    assert fresnel(1.0, eta, k) == pytest.approx(f0(eta, k), rel=1e-13, abs=1e-17)  # normal incidence
    assert _fresnel_real(1.0, eta, k) == pytest.approx(f0(eta, k), rel=1e-13, abs=1e-17)
    assert fresnel(0.0, eta, k) == pytest.approx(1.0, rel=1e-14)  # grazing


@pytest.mark.parametrize("eta,k", [(1.0, 0.0), (1.0 + 1e-7, 0.0), (1.0 - 1e-9, 1e-6), (1.0 + 1e-12, 1e-10), (1.2, 0.0)])
def test_fresnel_near_index_one_at_grazing_incidence(eta, k):
    """F near e = 1 at grazing incidence against 40-digit mpmath: e^2 - sin^2 is computed as (e - 1)(e + 1) + c^2 (as
    e^2 - (1 - c)(1 + c) it lost every digit: eta 1, c = 1e-8 gave F = 0.039 for 0), in both formulas."""
    import mpmath as mp

    with mp.workdps(40):
        e = mp.mpf(eta) + 1j * mp.mpf(k)
        for c in (1e-8, 1e-5, 1e-3, 0.3, 1.0):
            a = mp.sqrt((e - 1) * (e + 1) + mp.mpf(c) ** 2)  # e cos_t
            ref = float((abs((e * e * c - a) / (e * e * c + a)) ** 2 + abs((c - a) / (c + a)) ** 2) / 2)
            for got in (float(fresnel(c, eta, k)), _fresnel_real(c, eta, k)):
                assert abs(got - ref) <= 1e-13 * ref + 1e-300, (c, got, ref)


def test_metal_with_index_one_reflects_nothing():
    """eta = 1, k = 0: F = 0 at every angle, so the albedo is 0 exactly, grazing incidence included (it was
    1.9e-10 +- 6e-12 at mu = 1e-8)."""
    a, e = pumpup.albedo(pumpup.load({"type": "metal", "n": 1, "eta": 1.0}), [1.0, 0.5, 1e-3, 1e-8], return_error=True)
    assert np.all(a == 0.0) and np.all(e == 0.0), (a, e)


def test_fresnel_dielectric_special_angles():
    eta = 1.5
    # Brewster angle: r_par = 0, F = R_perp / 2
    tb = math.atan(eta)
    ci, st = math.cos(tb), math.sin(tb) / eta
    ct = math.sqrt(1 - st * st)
    r_perp = (ci - eta * ct) / (ci + eta * ct)
    assert fresnel(ci, eta) == pytest.approx(r_perp**2 / 2, rel=1e-13)
    assert _fresnel_real(ci, eta, 0.0) == pytest.approx(r_perp**2 / 2, rel=1e-13)
    # total internal reflection from the dense side (eta < 1) beyond the critical angle
    crit = math.asin(1 / 1.5)
    for t in [crit, crit + 0.1, 1.5]:
        assert fresnel(math.cos(t), 1 / 1.5) == pytest.approx(1.0, rel=1e-12)
        assert _fresnel_real(math.cos(t), 1 / 1.5, 0.0) == pytest.approx(1.0, rel=1e-12)


def test_metal_hand_values():
    n, eta, k = 50.0, 0.2, 3.0
    f = pumpup.load({"type": "metal", "n": n, "eta": eta, "k": k})
    c = (n + 2) / (2 * math.pi)
    assert f.p["c"] == pytest.approx(c, rel=1e-15)
    assert f.eval(N, N) == pytest.approx(c * f0(eta, k), rel=1e-13)  # normal incidence
    for theta in [0.3, 1.0, 1.4]:
        wi = polar(theta, 0.7)
        wo = wi * np.array([-1, -1, 1])  # mirror direction: cos(alpha) = 1, Theta_min = theta
        mu = math.cos(theta)
        assert f.eval(wi, wo) == pytest.approx(c / mu * float(fresnel(mu, eta, k)), rel=1e-13)
    # off the mirror: wi at 60 deg, wo = N: cos(alpha) = cos(60), Theta_min = 0
    assert f.eval(polar(math.radians(60)), N) == pytest.approx(c * 0.5**n * f0(eta, k), rel=1e-12)


def test_plastic_hand_values_and_limits(rng):
    n, ad, a_s, eta = 80.0, 0.3, 0.6, 1.5
    f = pumpup.load({"type": "plastic", "n": n, "ad": ad, "a_s": a_s, "eta": eta})
    cs = (n + 2) / (2 * math.pi)
    assert f.eval(N, N) == pytest.approx(ad / math.pi + a_s * cs * 0.04, rel=1e-13)
    wi = polar(1.2, 0.5)
    wo = wi * np.array([-1, -1, 1])
    mu = math.cos(1.2)
    assert f.eval(wi, wo) == pytest.approx(ad / math.pi + a_s * cs / mu * float(fresnel(mu, eta)), rel=1e-13)
    # far from the lobe only the diffuse part is left
    assert f.eval(polar(1.2, 0.5), polar(1.2, 0.5)) == pytest.approx(ad / math.pi, rel=1e-13)
    # eta omitted (000 eq. 30), ad = 0, a_s = 1: stretched Phong with p = 1
    g = pumpup.load({"type": "plastic", "n": n, "ad": 0.0, "a_s": 1.0})
    h = pumpup.load({"type": "stretched_phong", "n": n, "p": 1.0})
    wi, wo = direction_pairs(rng, 3000)
    np.testing.assert_allclose(g.eval(wi, wo), h.eval(wi, wo), rtol=1e-12, atol=1e-14 * cs)
    assert "eta" not in g.spec and g.p["eta"] is None
    # albedo decomposition: specular part plus ad times a unit Lambertian
    terms = f.albedo_terms()
    assert terms[0] == (1.0, f.with_params(ad=0.0))
    assert terms[1][0] == ad and terms[1][1] == pumpup.load({"type": "lambert"})
    wi, wo = direction_pairs(rng, 1000)
    total = sum(w * t.eval(wi, wo) for w, t in terms)
    np.testing.assert_allclose(total, f.eval(wi, wo), rtol=1e-13, atol=0)
    assert g.albedo_terms() == [(1.0, g)]


def test_hints():
    f = pumpup.load({"type": "metal", "n": 30, "eta": 0.2, "k": 3})
    assert f.lobe(0.5) == pumpup.Lobe(axis="mirror", radial="power", sharpness=30.0, levels=(0.5,))
    g = pumpup.load({"type": "plastic", "n": 30})
    assert g.lobe(0.5) == pumpup.Lobe(axis="mirror", radial="power", sharpness=30.0, levels=(0.5,))
    assert pumpup.registry()["metal"].constant == "c"


def test_per_channel():
    eta, k = [0.18, 0.42, 1.37], [3.42, 2.35, 1.77]  # gold-like RGB values, illustrative only
    gold = per_channel("metal", n=200, eta=eta, k=k)
    assert [g.spec for g in gold] == [{"type": "metal", "n": 200.0, "eta": e, "k": kk, "c": 202 / (2 * math.pi)}
                                      for e, kk in zip(eta, k)]
    for g, e, kk in zip(gold, eta, k):
        assert g.eval(N, N) == pytest.approx(202 / (2 * math.pi) * f0(e, kk), rel=1e-13)
    # per-channel exponents and a shared scale
    m = per_channel("metal", n=np.array([10.0, 20.0]), eta=1.5, c=0.5)
    assert [x.p["n"] for x in m] == [10.0, 20.0] and all(x.p["c"] == 0.5 and x.p["k"] == 0 for x in m)
    # plastic: per-channel diffuse albedo (000 eq. 30 with eta omitted)
    p = per_channel("plastic", n=100, eta=None, ad=[0.5, 0.3, 0.1], a_s=0.4)
    assert [x.spec for x in p] == [{"type": "plastic", "n": 100.0, "ad": a, "a_s": 0.4} for a in [0.5, 0.3, 0.1]]
    assert len(per_channel("metal", n=5, eta=0.3, k=2.0)) == 1
    with pytest.raises(pumpup.SpecError, match="'eta' has 3.*'k' has 2"):
        per_channel("metal", n=10, eta=[0.2, 0.3, 0.4], k=[3.0, 2.0])
    with pytest.raises(pumpup.SpecError, match="'k'"):
        per_channel("plastic", n=10, eta=1.5, k=0.5)
    with pytest.raises(pumpup.SpecError, match="'kind'"):
        per_channel("glass", n=10, eta=1.5)
    with pytest.raises(pumpup.SpecError, match="'a_s'"):
        per_channel("plastic", n=10, eta=1.5, ad=[0.5, 0.9], a_s=0.4)
    with pytest.raises(pumpup.SpecError, match="'eta'"):
        per_channel("metal", n=10, eta=[0.2, -0.3], k=[3.0, 2.0])


def test_bad_input_names_the_parameter():
    bad = [
        ({"type": "metal", "n": -1, "eta": 0.2}, "'n'"),
        ({"type": "metal", "eta": 0.2}, "'n'"),
        ({"type": "metal", "n": 10}, "'eta'"),
        ({"type": "metal", "n": 10, "eta": 0.0}, "'eta'"),
        ({"type": "metal", "n": 10, "eta": -1.0}, "'eta'"),
        ({"type": "metal", "n": 10, "eta": 0.2, "k": -3}, "'k'"),
        ({"type": "metal", "n": 10, "eta": float("nan")}, "'eta'"),
        ({"type": "metal", "n": 10, "eta": 0.2, "kappa": 3}, "'kappa'"),
        ({"type": "plastic", "n": 10, "ad": 0.6, "a_s": 0.5}, "'a_s' \\+ 'ad'"),
        ({"type": "plastic", "n": 10, "ad": 1.1, "a_s": 0.0}, "'ad'"),
        ({"type": "plastic", "n": 10, "eta": 0.0}, "'eta'"),
        ({"type": "plastic", "n": float("nan")}, "'n'"),
        ({"type": "plastic", "n": 10, "as": 0.3}, "'as'"),
    ]
    for spec, name in bad:
        with pytest.raises(pumpup.SpecError, match=name):
            pumpup.load(spec)
    # a_s + ad = 1 exactly is allowed
    assert pumpup.load({"type": "plastic", "n": 10, "ad": 0.7, "a_s": 0.3}).p["a_s"] == 0.3
