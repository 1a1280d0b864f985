"""The ``fresnel`` wrapper over a sum: F(Theta_min) sum w_k f_k = sum w_k F f_k, each term with its own hint.
As one term, fresnel over plastic had the specular lobe's hint (the power map about the mirror)
for its Lambert part too, and the engines lost part of it with estimates of 1e-10: 0.2908 for 0.4060 at mu = 0.306
(eta 0.232), 0.0294 for 0.0396 (eta 1.5); over a pumped plastic half of it.  Checked against the rings of
:func:`helpers.rings` (scipy's quad in N.wo, Gauss-Legendre in phi_o), and at the normal against Gauss-Legendre in
N.wo."""

import math

import numpy as np
import pytest
from helpers import rings

import pumpup


def test_fresnel_over_a_sum_takes_its_terms():
    plastic = {"type": "plastic", "n": 34.4, "eta": 1.878, "ad": 0.33}
    f = pumpup.load({"type": "fresnel", "base": plastic, "eta": 1.5})
    terms = f.albedo_terms()
    assert [w for w, _ in terms] == [1.0, 0.33]
    assert ([t.spec["base"]["type"] for _, t in terms] == ["plastic", "lambert"]
            and terms[0][1].spec["base"]["ad"] == 0.0)
    one = pumpup.load({"type": "fresnel", "base": dict(plastic, ad=0.0), "eta": 1.5})
    assert one.albedo_terms() == [(1.0, one)]
    # a pumped base's terms (parts with no spec of the registry), each with F and its own hint
    pumped = pumpup.load({"type": "fresnel", "base": {"type": "pumped", "base": plastic}, "eta": 1.5})
    assert [t.base.type for _, t in pumped.albedo_terms()] == ["pumped-term", "pumped-term"]
    wi, wo = np.array([[0.6, 0.0, 0.8]] * 3), np.array([[-0.6, 0.0, 0.8], [0.0, 0.6, 0.8], [0.28, 0.0, 0.96]])
    np.testing.assert_allclose(sum(w * t.eval(wi, wo) for w, t in pumped.albedo_terms()), pumped.eval(wi, wo),
                               rtol=1e-14)


def test_fresnel_over_a_pumped_plastic_at_the_normal():
    """2-level g1 pumped plastic (n 290, ad 0.40) under F (eta 0.454, k 7.29) at mu = 1: as one term the nested engine
    gave 0.468 +- 4e-4 and the 2-D engine 0.441 +- 0.011 for 0.959 (scripts/studies/fuzz_engines.py --registry 48).  At
    wi = N the integrand depends on N.wo alone: the reference is Gauss-Legendre in N.wo, graded towards the lobe at
    1."""
    f = pumpup.load({"type": "fresnel", "base": {"type": "pumped", "base": {"type": "plastic", "n": 289.95982714742524,
                     "eta": 1.5957343463248426, "ad": 0.3995720056517486}, "g": "g1", "levels": 2},
                     "eta": 0.45428694960824667, "k": 7.293438073871147})
    wi = np.array([0.0, 0.0, 1.0])

    def brute(nx):
        x, w = np.polynomial.legendre.leggauss(nx)
        edges = np.unique(np.r_[np.linspace(0.0, 1.0, 21), 1.0 - np.geomspace(1e-9, 0.5, 40)])
        total = 0.0
        for a, b in zip(edges[:-1], edges[1:]):
            mo = a + (b - a) * (x + 1.0) / 2.0
            wo = np.stack([np.sqrt((1.0 - mo) * (1.0 + mo)), np.zeros_like(mo), mo], axis=-1)
            total += float(np.sum(w * (b - a) / 2.0 * f.reference(wi, wo) * mo))
        return 2.0 * math.pi * total

    ref, ref2 = brute(60), brute(90)
    assert abs(ref - ref2) < 1e-9
    for rtol in (1e-6, 1e-8):
        a, e = pumpup.albedo(f, 1.0, rtol=rtol, return_error=True)
        assert abs(float(a) - ref) <= float(e) + 1e-9, (rtol, float(a), ref, float(e))


@pytest.mark.parametrize("spec", [{"type": "fresnel", "base": {"type": "plastic", "n": 34.4, "eta": 1.878, "ad": 0.33},
                                   "eta": 1.5},
                                  {"type": "fresnel", "base": {"type": "plastic", "n": 34.4, "eta": 1.878, "ad": 0.33},
                                   "eta": 0.2, "k": 3.0}], ids=["dielectric", "conductor"])
@pytest.mark.parametrize("mu", [0.3057, 0.8])
def test_fresnel_over_plastic_against_rings(spec, mu):
    f = pumpup.load(spec)
    ref = rings(f, mu, lambda mo, so: [0.0, math.pi], [mu])  # (one piece: cos^34.4 vanishes smoothly where R.wo < 0)
    for rtol in (1e-6, 1e-8, 1e-10):
        a, e = pumpup.albedo(f, mu, rtol=rtol, return_error=True)
        assert abs(float(a) - ref) <= float(e) + 1e-11, (rtol, float(a), ref, float(e))
