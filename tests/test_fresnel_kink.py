"""A Fresnel factor F(eta + i k, max(N.wi, N.wo)) with eta < 1 and k = 0 (a dielectric seen from its denser side) is 1
up to cos = x0 = sqrt(1 - eta^2), total reflection, and has a square-root kink there; a small k makes it a near-kink.
The 1-D path declines such a factor and the nested engine, blind to the kink, bisected towards it: fresnel over Blinn
n = 5, eta = 0.551 took 0.25-0.41 s per value at rtol 1e-10, a pumped one's base table minutes (issue 14's twenty-first
session, ``scripts/fuzz_engines.py --registry``).  The hints now carry the level N.wo = x0
(:func:`pumpup.models.metal.fresnel_levels`) and the albedo's kink at mu = x0 (``BRDF.albedo_breaks``).  The values are
checked against an independent quadrature in spherical coordinates about N split at the kink."""

import math
import sys

import pytest

import pumpup
from pumpup import pumping
from pumpup.models.metal import fresnel_levels

sys.path.insert(0, str(__import__("pathlib").Path(__file__).parent))
from test_albedo_breaks import _rings  # noqa: E402

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
                                  {"type": "mix", "a": {"type": "lambert"}, "b": {"type": "metal", "n": 5.0, "eta": ETA}}],
                         ids=lambda s: s["type"])
def test_hints_carry_the_kink(spec):
    f = pumpup.load(spec)
    assert f.albedo_breaks() == pytest.approx((X0,), rel=1e-15)
    if spec["type"] != "mix":
        assert any(abs(u - X0) < 1e-15 for u in f.lobe(0.3).levels)
    assert pumping.albedo_kinks(f) == pytest.approx([X0], rel=1e-15)  # its tables are split there
    assert pumping.albedo_kinks(pumpup.load({"type": "lambert"})) is None


@pytest.mark.parametrize("n", [0.358, 5.0])
@pytest.mark.parametrize("mu", [0.01, 0.3, 0.7, 0.9])
def test_fresnel_over_blinn_with_total_reflection(n, mu):
    """Reference: quad over mu_o split at mu and x0 (F's kinks), Gauss-Legendre in phi_o (Blinn is smooth in it)."""
    f = pumpup.load({"type": "fresnel", "base": {"type": "blinn", "n": n}, "eta": ETA})
    ref = _rings(f, mu, lambda mo, so: [0.0, math.pi], [mu, X0])
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
            a, b = mu * mo, s * so  # R.V = b cos(phi_o) + a with phi_o from the mirror side: here R.V = a - b cos(phi_o)
            return [0.0 if a >= b else math.acos(a / b), math.pi]

        ref = _rings(f, mu, cuts, [mu, X0, s])
        a, e = pumpup.albedo(f, mu, return_error=True, rtol=1e-10)
        assert abs(float(a) - ref) <= float(e) + 1e-13, (mu, float(a) - ref, float(e))
    m, em = pumpup.mean_albedo(f, return_error=True)
    pts = [0.0, 1e-4, 1e-2, 0.1, X0, 1.0]
    ref = sum(quad(lambda x: 2.0 * x * float(pumpup.albedo(f, x, rtol=1e-13)), a, b, epsabs=1e-15, epsrel=1e-13,
                   limit=200)[0] for a, b in zip(pts[:-1], pts[1:]))
    assert abs(m - ref) <= em + 1e-12, (m - ref, em)
