"""Diffuse models: minnaert (002 sec. 3.4), lacquer (002 sec. 3.3), oren_nayar (Oren & Nayar 1994)."""

import math

import helpers
import numpy as np
import pytest
from helpers import direction_pairs, polar
from scipy.integrate import quad

import pumpup

N = np.array([0.0, 0.0, 1.0])


# --- Minnaert -------------------------------------------------------------------------------


def test_minnaert_values():
    for k in [0.5, 1.0, 2.0, 3.7]:
        f = pumpup.load({"type": "minnaert", "k": k})
        b = (k + 1) / (2 * math.pi)
        assert f.p["b"] == pytest.approx(b, rel=1e-15)
        assert f.eval(N, N) == pytest.approx(b, rel=1e-15)  # wi = wo = N
        wi, wo = polar(math.radians(40), 0.3), polar(math.radians(75), 2.0)
        expected = b * (math.cos(math.radians(40)) * math.cos(math.radians(75))) ** (k - 1)
        assert f.eval(wi, wo) == pytest.approx(expected, rel=1e-14)
    # k = 1 is Lambert with albedo pi b
    f = pumpup.load({"type": "minnaert", "k": 1, "b": 0.2})
    g = pumpup.load({"type": "lambert", "albedo": 0.2 * math.pi})
    d = np.array([polar(0.1), polar(1.5, 1.0), polar(0.9, 4.0)])
    np.testing.assert_allclose(f.eval(d[:, None], d[None]), g.eval(d[:, None], d[None]), rtol=1e-15)


@pytest.mark.parametrize("k", [1.0, 1.8, 4.0])
@pytest.mark.parametrize("mu", [1.0, 0.5, 0.05])
def test_minnaert_albedo_closed_form(k, mu):
    """a(mu) = b 2 pi / (k + 1) mu^(k-1) (002 sec. 4.3), by quadrature over N.V."""
    f = pumpup.load({"type": "minnaert", "k": k})
    wi = np.array([math.sqrt(1 - mu * mu), 0.0, mu])

    def integrand(m):
        wo = np.array([0.0, math.sqrt(1 - m * m), m])
        return float(f.eval(wi, wo)) * m

    a = 2 * math.pi * quad(integrand, 0, 1, epsabs=0, epsrel=1e-12)[0]
    assert a == pytest.approx(mu ** (k - 1), rel=1e-10)


# --- lacquer --------------------------------------------------------------------------------


def test_lacquer_values():
    for c, s in [(1 / math.pi, 0.1), (0.4, 0.0), (0.2, 2.5)]:
        f = pumpup.load({"type": "lacquer", "c": c, "s": s})
        assert f.eval(N, N) == pytest.approx(c * math.exp(-2 * s), rel=1e-15)  # wi = wo = N
        wi, wo = polar(math.radians(60)), polar(math.radians(30), 1.0)
        expected = c * math.exp(-s * (2 + 2 / math.sqrt(3)))
        assert f.eval(wi, wo) == pytest.approx(expected, rel=1e-14)
    f = pumpup.load({"type": "lacquer"})
    assert f.p == {"c": 1 / math.pi, "s": 0.1}
    # grazing: exp(-s / 1e-8) underflows to exactly 0, no NaN
    g = np.array([math.sqrt(1 - 1e-16), 0.0, 1e-8])
    assert f.eval(g, N) == 0.0 and f.eval(N, g) == 0.0
    # s = 0 is Lambert with albedo pi c, also at grazing
    h = pumpup.load({"type": "lacquer", "c": 0.25, "s": 0.0})
    assert h.eval(g, g) == 0.25 and h.eval(N, g) == 0.25


# --- Oren-Nayar -----------------------------------------------------------------------------


def test_oren_nayar_sigma_zero_is_lambert(rng):
    wi, wo = direction_pairs(rng, 3000)
    for albedo in [1.0, 0.3]:
        f = pumpup.load({"type": "oren_nayar", "albedo": albedo, "sigma": 0.0})
        g = pumpup.load({"type": "lambert", "albedo": albedo})
        np.testing.assert_array_equal(f.eval(wi, wo), g.eval(wi, wo))


def test_oren_nayar_hand_values():
    albedo, sigma = 0.8, 0.5
    f = pumpup.load({"type": "oren_nayar", "albedo": albedo, "sigma": sigma})
    s2 = sigma**2
    A = 1 - 0.5 * s2 / (s2 + 0.33)
    B = 0.45 * s2 / (s2 + 0.09)
    t60, t30 = math.radians(60), math.radians(30)
    # same azimuth: cos(dphi) = 1, alpha = 60, beta = 30: sin 60 tan 30 = 1/2
    assert f.eval(polar(t60, 0.4), polar(t30, 0.4)) == pytest.approx(albedo / math.pi * (A + B / 2), rel=1e-14)
    assert f.eval(polar(t30, 0.4), polar(t60, 0.4)) == pytest.approx(albedo / math.pi * (A + B / 2), rel=1e-14)
    # azimuths 60 deg apart: cos(dphi) = 1/2
    assert f.eval(polar(t60, 0.0), polar(t30, math.pi / 3)) == pytest.approx(albedo / math.pi * (A + B / 4), rel=1e-14)
    # opposite azimuths, or either direction at the normal: the B term vanishes
    assert f.eval(polar(t60, 0.0), polar(t30, math.pi)) == pytest.approx(albedo / math.pi * A, rel=1e-14)
    assert f.eval(N, polar(t60, 1.0)) == pytest.approx(albedo / math.pi * A, rel=1e-14)
    assert f.eval(polar(t60, 1.0), N) == pytest.approx(albedo / math.pi * A, rel=1e-14)
    assert f.eval(N, N) == pytest.approx(albedo / math.pi * A, rel=1e-14)
    # both near grazing in the same azimuth: sin(alpha) tan(beta) -> 1 / 1e-8
    g = np.array([math.sqrt(1 - 1e-16), 0.0, 1e-8])
    assert f.eval(g, g) == pytest.approx(albedo / math.pi * (A + B * (1 - 1e-16) / 1e-8), rel=1e-12)


def test_hints_and_constants():
    for name, const in [("minnaert", "b"), ("lacquer", "c"), ("oren_nayar", "albedo")]:
        cls = pumpup.registry()[name]
        assert cls.constant == const and cls.reciprocal
    assert pumpup.load({"type": "minnaert", "k": 2}).lobe(0.4) == pumpup.Lobe(axis="normal", radial="cosine",
                                                                             symmetric=True)
    assert pumpup.load({"type": "lacquer"}).lobe(0.4) == pumpup.Lobe(axis="normal", radial="cosine", symmetric=True)
    assert pumpup.load({"type": "oren_nayar"}).lobe(0.4).levels == (0.4,)


def test_bad_input_names_the_parameter():
    bad = [
        ({"type": "minnaert", "k": 0}, "'k'"),
        ({"type": "minnaert", "k": -1}, "'k'"),
        ({"type": "minnaert"}, "'k'"),
        ({"type": "minnaert", "k": 2, "b": -0.1}, "'b'"),
        ({"type": "minnaert", "k": float("nan")}, "'k'"),
        ({"type": "lacquer", "s": -0.1}, "'s'"),
        ({"type": "lacquer", "c": float("nan")}, "'c'"),
        ({"type": "lacquer", "thickness": 1}, "'thickness'"),
        ({"type": "oren_nayar", "albedo": 1.2}, "'albedo'"),
        ({"type": "oren_nayar", "sigma": -0.2}, "'sigma'"),
        ({"type": "oren_nayar", "sigma": float("inf")}, "'sigma'"),
        ({"type": "oren_nayar", "roughness": 0.2}, "'roughness'"),
    ]
    for spec, name in bad:
        with pytest.raises(pumpup.SpecError, match=name):
            pumpup.load(spec)


def test_oren_nayar_albedo_in_closed_form():
    """The qualitative Oren-Nayar albedo in closed form (pumpup.models.diffuse.oren_nayar_albedo, the model's
    Polar "constant" hint) against a 40-digit mpmath quadrature of its 1-D integral over N.wo, and against
    the nested engine (the 1-D path switched off) on the BRDF itself."""
    import warnings

    mp = pytest.importorskip("mpmath")
    from pumpup.models.diffuse import oren_nayar_albedo

    mp.mp.dps = 40
    for sigma in (0.0, 0.3, 0.5, 1.2):
        s2 = mp.mpf(sigma) ** 2
        a_, b_ = 1 - s2 / 2 / (s2 + mp.mpf("0.33")), mp.mpf("0.45") * s2 / (s2 + mp.mpf("0.09"))
        for mu in (1.0, 0.999999, 0.99, 0.5, 0.2, 1e-3, 1e-8, 1e-300):
            m = mp.mpf(mu)
            inner = mp.quad(lambda t, m=m: t * mp.sqrt(1 - t * t) / max(m, t), [0, m, 1])
            ref = 0.7 * (a_ + 2 * b_ * mp.sqrt(1 - m * m) / mp.pi * inner)
            assert abs(float(oren_nayar_albedo(mu, 0.7, sigma)) - ref) <= 2.3e-16 * ref, (sigma, mu)
    mu = np.array([1.0, 0.9, 0.5, 0.2, 1e-3, 1e-8])
    for spec in ({"type": "oren_nayar"}, {"type": "oren_nayar", "albedo": 0.7, "sigma": 0.5},
                 {"type": "oren_nayar", "sigma": 1.2}):
        f = pumpup.load(spec)
        a, e = pumpup.albedo(f, mu, return_error=True)
        with helpers.without_1d(), warnings.catch_warnings():
            warnings.simplefilter("ignore")
            b, eb = pumpup.albedo(f, mu, return_error=True, rtol=1e-12)
        assert np.all(np.abs(a - b) <= e + eb) and np.all(e <= 1e-15 * a)


def test_minnaert_and_lacquer_albedos_in_closed_form():
    """Minnaert, 2 pi b mu^(k-1) / (k + 1) (002 sec. 4.3), and the lacquer, 2 pi c e^(-s/mu) E_3(s), are the
    models' Polar "constant" hints: against 30-digit mpmath (its own E_3 and powers) within their stated
    errors, and against the nested engine on the BRDFs themselves."""
    import warnings

    mp = pytest.importorskip("mpmath")

    mp.mp.dps = 30
    mu = np.array([1.0, 0.9, 0.5, 0.2, 0.05, 1e-2, 1e-3])
    for spec in ({"type": "lacquer", "s": s, "c": 0.3} for s in (0.0, 1e-6, 0.02, 0.1, 1.5, 30.0, 300.0)):
        a, e = pumpup.albedo(pumpup.load(spec), mu, return_error=True)
        s = spec["s"]
        for m, x, ex in zip(mu, a, e):
            ref = 2 * mp.pi * 0.3 * mp.exp(-mp.mpf(s) / mp.mpf(m)) * (mp.expint(3, s) if s > 0 else mp.mpf(0.5))
            assert abs(x - float(ref)) <= ex, (spec, m, x, ex)  # (in doubles: e^(-1500) is 0 there)
    for spec in ({"type": "minnaert", "k": k, "b": 0.2} for k in (0.5, 1.0, 1.37, 2.0, 50.0)):
        a, e = pumpup.albedo(pumpup.load(spec), mu, return_error=True)
        for m, x, ex in zip(mu, a, e):
            ref = 2 * mp.pi * 0.2 * mp.mpf(m) ** (spec["k"] - 1) / (spec["k"] + 1)
            assert abs(x - ref) <= ex, (spec, m, x, ex)
    for spec in ({"type": "lacquer"}, {"type": "lacquer", "s": 1.5}, {"type": "minnaert", "k": 0.8},
                 {"type": "minnaert", "k": 2.0}):
        f = pumpup.load(spec)
        a, e = pumpup.albedo(f, mu, return_error=True)
        with helpers.without_1d(), warnings.catch_warnings():
            warnings.simplefilter("ignore")
            b, eb = pumpup.albedo(f, mu, return_error=True, rtol=1e-12)
        assert np.all(np.abs(a - b) <= e + eb), spec
