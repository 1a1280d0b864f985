"""The Blinn family: blinn (000 eq. 31), stretched_blinn (000 eq. 32), phong_blinn (002 eq. 24)."""

import math

import numpy as np
import pytest
from helpers import at_mu, polar

import pumpup

N = np.array([0.0, 0.0, 1.0])


@pytest.mark.parametrize("n,c", [(0, 1.0), (1, 1.0), (20, 0.9), (512, 20.6), (10.5, 0.7)])
def test_blinn_special_values(n, c):
    f = pumpup.load({"type": "blinn", "n": n, "c": c})
    assert f.eval(N, N) == pytest.approx(c, rel=1e-15)  # wi = wo = N: H = N
    for theta in [0.1, 0.7, 1.4, math.acos(1e-8)]:
        # mirror direction: H = N, f = c at every incidence angle
        assert f.eval(polar(theta, 0.3), polar(theta, 0.3 + math.pi)) == pytest.approx(c, rel=1e-13)
        # wi = N, wo at theta: H is at theta / 2
        assert f.eval(N, polar(theta, 1.0)) == pytest.approx(c * math.cos(theta / 2) ** n, rel=1e-12)
    # wi at 60 degrees, wo at 30 degrees in the same plane: H at 45 degrees from N
    assert f.eval(polar(math.pi / 3), polar(math.pi / 6)) == pytest.approx(c * math.sqrt(0.5) ** n, rel=1e-12)


def test_blinn_default_constant_is_one():
    f = pumpup.load({"type": "blinn", "n": 7})
    assert f.spec == {"type": "blinn", "n": 7.0, "c": 1.0}
    assert f.eval(N, N) == 1.0


@pytest.mark.parametrize("n", [1, 20, 128])
def test_stretched_blinn_special_values(n):
    f = pumpup.load({"type": "stretched_blinn", "n": n})
    assert f.eval(N, N) == pytest.approx(1.0, rel=1e-15)
    for mu in [0.9, 0.5, 1e-3, 1e-8]:
        # mirror pair: (N.H) = 1, max(N.L, N.V) = mu
        assert f.eval(at_mu(mu), at_mu(mu, math.pi)) == pytest.approx(1.0 / mu, rel=1e-12)
    # wi = N: max(N.L, N.V) = 1, so it equals Blinn there
    b = pumpup.load({"type": "blinn", "n": n})
    wo = np.array([polar(t, 0.4) for t in [0.2, 0.9, 1.5]])
    np.testing.assert_allclose(f.eval(N, wo), b.eval(N, wo), rtol=1e-15)
    # generally f_stretched = f_blinn / max(N.L, N.V)
    wi, wo = polar(1.2, 0.1), polar(0.4, 2.0)
    assert f.eval(wi, wo) == pytest.approx(b.eval(wi, wo) / math.cos(0.4), rel=1e-14)


def test_phong_blinn_special_values():
    f = pumpup.load({"type": "phong_blinn", "n": 10, "ks": 0.5, "kd": 0.1})
    assert f.eval(N, N) == pytest.approx(0.6, rel=1e-15)  # kd + ks
    wo = polar(1.0, 0.2)
    assert f.eval(N, wo) == pytest.approx(0.1 + 0.5 * math.cos(0.5) ** 10, rel=1e-13)
    # n = 0 is a diffuse surface, f = kd + ks everywhere above the horizon (002 sec. 6)
    g = pumpup.load({"type": "phong_blinn", "n": 0, "ks": 0.1, "kd": 0.2})
    assert g.eval(polar(1.5), polar(0.3, 2.0)) == pytest.approx(0.3, rel=1e-15)
    # defaults: ks = 1, kd = 0
    h = pumpup.load({"type": "phong_blinn", "n": 4})
    assert h.spec == {"type": "phong_blinn", "n": 4.0, "ks": 1.0, "kd": 0.0}
    assert h.eval(N, N) == 1.0


def test_phong_blinn_albedo_terms():
    f = pumpup.load({"type": "phong_blinn", "n": 5, "ks": 0.5, "kd": 0.1})
    terms = f.albedo_terms()
    assert len(terms) == 2
    (w0, f0), (w1, f1) = terms
    assert w0 == 1.0 and f0 == pumpup.load({"type": "phong_blinn", "n": 5, "ks": 0.5, "kd": 0.0})
    assert w1 == pytest.approx(math.pi * 0.1) and f1 == pumpup.load({"type": "lambert", "albedo": 1.0})
    # the decomposition reproduces f
    wi, wo = polar(0.8, 0.0), polar(0.3, 2.5)
    total = sum(w * float(g.eval(wi, wo)) for w, g in terms)
    assert total == pytest.approx(float(f.eval(wi, wo)), rel=1e-14)
    g = pumpup.load({"type": "phong_blinn", "n": 5})
    assert g.albedo_terms() == [(1.0, g)]


def test_lobe_hints():
    assert pumpup.load({"type": "blinn", "n": 20}).lobe(0.5) == pumpup.Lobe(axis="half", radial="power", sharpness=20.0)
    lobe = pumpup.load({"type": "stretched_blinn", "n": 20}).lobe(0.25)
    assert lobe.axis == "half" and lobe.radial == "power" and lobe.sharpness == 20 and lobe.levels == (0.25,)
    lobe = pumpup.load({"type": "phong_blinn", "n": 3, "kd": 0.1}).lobe(0.5)
    assert lobe.axis == "half" and lobe.radial == "power" and lobe.sharpness == 3


@pytest.mark.parametrize(
    "spec,pname",
    [
        ({"type": "blinn", "n": -1}, "n"),
        ({"type": "blinn", "n": float("nan")}, "n"),
        ({"type": "blinn", "n": float("inf")}, "n"),
        ({"type": "blinn", "n": 3, "c": -0.1}, "c"),
        ({"type": "blinn", "n": 3, "c": float("nan")}, "c"),
        ({"type": "blinn"}, "n"),
        ({"type": "blinn", "n": "3"}, "n"),
        ({"type": "blinn", "n": 3, "m": 0.1}, "m"),
        ({"type": "stretched_blinn", "n": -1}, "n"),
        ({"type": "stretched_blinn", "n": 2, "p": 0.5}, "p"),
        ({"type": "phong_blinn", "n": -1}, "n"),
        ({"type": "phong_blinn", "n": 2, "kd": 0.5}, "kd"),
        ({"type": "phong_blinn", "n": 2, "kd": -0.1}, "kd"),
        ({"type": "phong_blinn", "n": 2, "ks": float("nan")}, "ks"),
    ],
)
def test_bad_input_names_the_parameter(spec, pname):
    with pytest.raises(pumpup.SpecError, match=repr(pname)):
        pumpup.load(spec)
