"""The Ward family: ward (000 eq. 34, 001 eq. 8), ward_aniso (Ward 1992), modified_ward (000 eq. 35)."""

import math

import numpy as np
import pytest
from helpers import at_mu, direction_pairs, polar

import pumpup

N = np.array([0.0, 0.0, 1.0])


@pytest.mark.parametrize("m,c", [(0.1, 1.0), (0.02, 1.0), (0.4, 0.6)])
def test_ward_special_values(m, c):
    f = pumpup.load({"type": "ward", "m": m, "c": c})
    k = c / (4 * math.pi * m * m)
    assert f.eval(N, N) == pytest.approx(k, rel=1e-15)  # 000 eq. 34 at wi = wo = N
    for mu in [0.9, 0.5, 1e-3, 1e-8]:
        # mirror pair: delta = 0, sqrt((N.L)(N.V)) = mu
        assert f.eval(at_mu(mu, 1.0), at_mu(mu, 1.0 + math.pi)) == pytest.approx(k / mu, rel=1e-12)
    # wi = N, wo at theta: delta = theta / 2
    for theta in [0.05, 0.3, 1.2]:
        want = k * math.exp(-(math.tan(theta / 2) ** 2) / m**2) / math.sqrt(math.cos(theta))
        assert f.eval(N, polar(theta, 2.0)) == pytest.approx(want, rel=1e-12)


@pytest.mark.parametrize("m", [0.1, 0.4])
def test_modified_ward_special_values(m):
    f = pumpup.load({"type": "modified_ward", "m": m})
    k = 1 / (4 * math.pi * m * m)
    assert f.eval(N, N) == pytest.approx(k, rel=1e-15)
    for mu in [0.9, 0.5, 1e-3, 1e-8]:
        assert f.eval(at_mu(mu), at_mu(mu, math.pi)) == pytest.approx(k / mu, rel=1e-12)  # max = mu
    for theta in [0.05, 0.3, 1.2]:  # wi = N: max(N.L, N.V) = 1
        want = k * math.exp(-(math.tan(theta / 2) ** 2) / m**2)
        assert f.eval(N, polar(theta, 2.0)) == pytest.approx(want, rel=1e-12)
    # in general: modified = ward * sqrt((N.L)(N.V)) / max(N.L, N.V)
    w = pumpup.load({"type": "ward", "m": m})
    wi, wo = polar(1.1, 0.3), polar(0.6, 2.9)
    ratio = math.sqrt(math.cos(1.1) * math.cos(0.6)) / math.cos(0.6)
    assert f.eval(wi, wo) == pytest.approx(w.eval(wi, wo) * ratio, rel=1e-13)


def test_ward_aniso_special_values():
    ax, ay, c = 0.1, 0.3, 0.8
    f = pumpup.load({"type": "ward_aniso", "ax": ax, "ay": ay, "c": c})
    k = c / (4 * math.pi * ax * ay)
    assert f.eval(N, N) == pytest.approx(k, rel=1e-15)
    assert f.eval(polar(1.3, 0.2), polar(1.3, 0.2 + math.pi)) == pytest.approx(k / math.cos(1.3), rel=1e-12)
    # wi = N and H tilted by delta towards x (phi_h = 0) or y (phi_h = pi/2): wo at 2 delta
    for delta in [0.02, 0.1, 0.4]:
        root = math.sqrt(math.cos(2 * delta))
        want_x = k * math.exp(-(math.tan(delta) ** 2) / ax**2) / root
        want_y = k * math.exp(-(math.tan(delta) ** 2) / ay**2) / root
        assert f.eval(N, polar(2 * delta, 0.0)) == pytest.approx(want_x, rel=1e-12)
        assert f.eval(N, polar(2 * delta, math.pi / 2)) == pytest.approx(want_y, rel=1e-12)
        # phi_h = 45 degrees: cos^2 = sin^2 = 1/2
        want_d = k * math.exp(-(math.tan(delta) ** 2) * (0.5 / ax**2 + 0.5 / ay**2)) / root
        assert f.eval(N, polar(2 * delta, math.pi / 4)) == pytest.approx(want_d, rel=1e-12)


def test_ward_aniso_with_equal_slopes_is_ward(rng):
    wi, wo = direction_pairs(rng, 2000)
    a = pumpup.load({"type": "ward_aniso", "ax": 0.15, "ay": 0.15, "c": 0.9})
    b = pumpup.load({"type": "ward", "m": 0.15, "c": 0.9})
    fa, fb = a.eval(wi, wo), b.eval(wi, wo)
    # the rounding error of exp(-x) is relative ~ x eps: compare tightly where x < 230
    big = fb > 1e-100
    np.testing.assert_allclose(fa[big], fb[big], rtol=1e-12, atol=0)
    np.testing.assert_allclose(fa[~big], fb[~big], rtol=0, atol=1e-100)


def test_grazing_is_finite_and_ward_grows():
    # 001 sec. 2.1: Ward's BRDF at the mirror direction grows like 1 / mu at grazing
    f = pumpup.load({"type": "ward", "m": 0.1})
    for mu in [1e-8, 1e-100, 1e-200]:
        wi = at_mu(mu, 0.3)
        v = f.eval(wi, wi * [-1, -1, 1])
        assert np.isfinite(v) and v == pytest.approx(1 / (4 * math.pi * 0.01 * mu), rel=1e-12)


def test_lobe_hints():
    lobe = pumpup.load({"type": "ward", "m": 0.1}).lobe(0.5)
    assert (lobe.axis, lobe.radial, lobe.sharpness, lobe.levels) == ("half", "beckmann", 0.1, ())
    lobe = pumpup.load({"type": "modified_ward", "m": 0.2}).lobe(0.5)
    assert (lobe.axis, lobe.radial, lobe.sharpness, lobe.levels) == ("half", "beckmann", 0.2, (0.5,))
    lobe = pumpup.load({"type": "ward_aniso", "ax": 0.3, "ay": 0.05}).lobe(0.5)
    assert (lobe.axis, lobe.radial, lobe.sharpness, lobe.symmetric) == ("half", "beckmann", 0.3, True)  # wider slope


@pytest.mark.parametrize(
    "spec,pname",
    [
        ({"type": "ward", "m": 0}, "m"),
        ({"type": "ward", "m": -1}, "m"),
        ({"type": "ward", "m": float("nan")}, "m"),
        ({"type": "ward", "m": float("inf")}, "m"),
        ({"type": "ward"}, "m"),
        ({"type": "ward", "m": 0.1, "c": -1}, "c"),
        ({"type": "ward", "m": 0.1, "n": 3}, "n"),
        ({"type": "modified_ward", "m": 0}, "m"),
        ({"type": "modified_ward", "m": -1}, "m"),
        ({"type": "modified_ward", "m": float("nan")}, "m"),
        ({"type": "ward_aniso", "ax": 0, "ay": 0.1}, "ax"),
        ({"type": "ward_aniso", "ax": 0.1, "ay": -1}, "ay"),
        ({"type": "ward_aniso", "ax": 0.1}, "ay"),
        ({"type": "ward_aniso", "ax": 0.1, "ay": 0.1, "m": 0.1}, "m"),
    ],
)
def test_bad_input_names_the_parameter(spec, pname):
    with pytest.raises(pumpup.SpecError, match=repr(pname)) as exc:
        pumpup.load(spec)
    if pname in ("m", "ax", "ay") and spec.get(pname) in (0, -1):
        assert "[1e-06, 1000]" in str(exc.value)  # the range where the engine is accurate (issue 13)
