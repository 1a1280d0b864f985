"""Lewis's energy-conserving Phong shader (002 eq. 22) and H_s (002 sec. 4.1)."""

import json
import math

import numpy as np
import pytest
from helpers import polar
from scipy.integrate import dblquad, quad

import pumpup
from pumpup.models.lewis import phong_hs

NAME = "lewis_phong"
EXAMPLES = pumpup.registry()[NAME].examples
IDS = [json.dumps(ex, sort_keys=True) for ex in EXAMPLES]
N = np.array([0.0, 0.0, 1.0])


def hs_quad(mu, n):
    """H_s by scipy.quad in the mirror frame: u = cos(alpha), the azimuth over the visible
    arc |beta| <= beta0(u) in closed form, split at the kink u = s (the brief's method)."""
    s = math.sqrt((1 - mu) * (1 + mu))

    def g(u):
        w = math.sqrt(max(0.0, (1 - u) * (1 + u)))
        b0 = math.pi if s * w == 0 else math.acos(min(1.0, max(-1.0, -mu * u / (s * w))))
        return u**n * 2 * (mu * u * b0 + s * w * math.sin(b0))

    opts = dict(epsabs=0, epsrel=1e-13, limit=500)
    lower = quad(g, 0, s, **opts)[0] if s > 0 else 0.0
    return lower + quad(g, s, 1, **opts)[0]


@pytest.mark.parametrize("params", EXAMPLES, ids=IDS)
def test_not_reciprocal(params):
    f = pumpup.load({"type": NAME, **params})
    assert f.reciprocal is False
    r = pumpup.check_reciprocity(f)
    assert not r.reciprocal and r.max_rel_error > 1e-3, str(r)


@pytest.mark.parametrize("n", [0, 0.3, 1, 2, 7.5, 20, 100, 5000, 1e6])
def test_hs_closed_forms(n):
    assert phong_hs(1.0, n) == pytest.approx(2 * math.pi / (n + 2), rel=1e-14)  # H_s(1) = 2 pi / (n + 2)
    # at grazing incidence R lies on the horizon: H_s(0) = 2 int_0^(pi/2) sin^n cos^2 = B((n+1)/2, 3/2)
    b = math.exp(math.lgamma((n + 1) / 2) + math.lgamma(1.5) - math.lgamma(n / 2 + 2))
    assert phong_hs(0.0, n) == pytest.approx(b, rel=1e-14 * (1 + math.log1p(n) ** 2))


def test_hs_n0_is_cosine_weighted_half_space():
    """n = 0: H_s is the cosine-weighted solid angle of the half space R.V > 0 above the
    horizon: the whole hemisphere (pi) at mu = 1, a quarter sphere (pi / 2) at mu = 0."""
    assert phong_hs(1.0, 0) == pytest.approx(math.pi, rel=1e-15)
    assert phong_hs(0.0, 0) == pytest.approx(math.pi / 2, rel=1e-15)


def test_hs_against_adaptive_quadrature():
    worst = 0.0
    for n in [0, 0.5, 1, 3, 10, 64, 300]:
        for mu in [1e-8, 1e-3, 0.05, 0.2, 0.45, 0.7, 0.9, 0.99, 0.999999]:
            h = float(phong_hs(mu, n))
            worst = max(worst, abs(h - hs_quad(mu, n)) / h)
    assert worst < 1e-11


def test_hs_against_mpmath():
    mp = pytest.importorskip("mpmath")
    mp.mp.dps = 30
    for n, mu in [(0.5, 1e-4), (2.7, 0.3), (20, 0.5), (5000, 1e-8), (5000, 0.02), (1e5, 0.01)]:
        m, nn = mp.mpf(mu), mp.mpf(n)
        s = mp.sqrt(1 - m * m)

        def g(u):
            w = mp.sqrt(1 - u * u)
            c = -m * u / (s * w) if w > 0 else mp.mpf(-2)
            b0 = mp.acos(max(-1, min(1, c)))
            return u**nn * 2 * (m * u * b0 + s * w * mp.sin(b0))

        pts = sorted({mp.mpf(0), s, mp.mpf(1)}
                     | ({s * (1 - mp.mpf(10) / nn), 1 - mp.mpf(10) / nn} if n > 10 else set()))
        exact = mp.quad(g, [p for p in pts if 0 <= p <= 1])
        assert float(phong_hs(mu, n)) == pytest.approx(float(exact), rel=1e-13)


def test_values_at_special_directions():
    n, k_rho, k_sigma = 20.0, 0.8, 0.6
    f = pumpup.load({"type": NAME, "n": n, "k_rho": k_rho, "k_sigma": k_sigma})
    # wi = wo = N: F_s = 1, H_s(1) = 2 pi / (n + 2)
    assert f.eval(N, N) == pytest.approx(k_rho * ((1 - k_sigma) / math.pi + k_sigma * (n + 2) / (2 * math.pi)),
                                         rel=1e-14)
    # mirror direction at 70 deg: F_s = 1
    wi = polar(math.radians(70), 0.4)
    wo = wi * np.array([-1, -1, 1])
    h = float(phong_hs(math.cos(math.radians(70)), n))
    assert f.eval(wi, wo) == pytest.approx(k_rho * ((1 - k_sigma) / math.pi + k_sigma / h), rel=1e-13)
    # outside the lobe only the diffuse part is left
    assert f.eval(wi, wi) == pytest.approx(k_rho * (1 - k_sigma) / math.pi, rel=1e-14)
    # not reciprocal: wi at 70 deg, wo = N and the reverse differ by H_s(cos 70) / H_s(1)
    g = pumpup.load({"type": NAME, "n": n})
    assert g.eval(wi, N) / g.eval(N, wi) == pytest.approx(2 * math.pi / (n + 2) / h, rel=1e-13)
    # k_sigma = 0 is Lambert with albedo k_rho
    d = pumpup.load({"type": NAME, "n": n, "k_rho": 0.3, "k_sigma": 0.0})
    assert d.eval(wi, wo) == pytest.approx(0.3 / math.pi, rel=1e-15)


@pytest.mark.parametrize("n,k_rho,k_sigma", [(5, 1.0, 1.0), (20, 0.7, 0.5), (2, 0.9, 1.0)])
@pytest.mark.parametrize("mu", [1.0, 0.6, 0.15])
def test_directional_albedo_is_k_rho(n, k_rho, k_sigma, mu):
    """Brute force: dblquad of f cos(theta_o) over (N.wo, phi_o), with wi in the xz-plane."""
    f = pumpup.load({"type": NAME, "n": n, "k_rho": k_rho, "k_sigma": k_sigma})
    wi = np.array([math.sqrt(1 - mu * mu), 0.0, mu])

    def integrand(phi, m):
        s = math.sqrt(1 - m * m)
        wo = np.array([s * math.cos(phi), s * math.sin(phi), m])
        return float(f._eval(wi, wo)) * m

    # f is even in phi (wi in the xz-plane): integrate phi over [0, pi] and double
    a, err = dblquad(integrand, 0.0, 1.0, 0.0, math.pi, epsabs=1e-10, epsrel=1e-8)
    assert 2 * a == pytest.approx(k_rho, rel=1e-7)


def test_hints_and_albedo_terms():
    f = pumpup.load({"type": NAME, "n": 30})
    assert f.lobe(0.4) == pumpup.Lobe(axis="mirror", radial="power", sharpness=30.0)
    assert f.albedo_terms() == [(1.0, f)]
    g = pumpup.load({"type": NAME, "n": 30, "k_rho": 0.8, "k_sigma": 0.25})
    assert g.lobe(0.4) == pumpup.BRDF.lobe(g, 0.4)
    (w1, t1), (w2, t2) = g.albedo_terms()
    assert w1 == pytest.approx(0.2) and t1 == f and w2 == pytest.approx(0.6) and t2 == pumpup.load({"type": "lambert"})
    assert pumpup.registry()[NAME].constant == "k_rho"


def test_bad_input_names_the_parameter():
    bad = [
        ({"type": NAME, "n": -1}, "'n'"),
        ({"type": NAME}, "'n'"),
        ({"type": NAME, "n": float("nan")}, "'n'"),
        ({"type": NAME, "n": 5, "k_rho": 1.5}, "'k_rho'"),
        ({"type": NAME, "n": 5, "k_sigma": -0.1}, "'k_sigma'"),
        ({"type": NAME, "n": 5, "ks": 0.5}, "'ks'"),
    ]
    for spec, name in bad:
        with pytest.raises(pumpup.SpecError, match=name):
            pumpup.load(spec)
