"""Schlick's model (000 eq. 36)."""

import math

import numpy as np
import pytest
from helpers import at_mu, polar, random_directions

import pumpup

mpmath = pytest.importorskip("mpmath")

N = np.array([0.0, 0.0, 1.0])


def schlick_mp(wi, wo, r, c):
    """000 eq. 36 evaluated literally in 50-digit arithmetic, from the float inputs."""
    mpmath.mp.dps = 50
    L = [mpmath.mpf(float(x)) for x in wi]
    V = [mpmath.mpf(float(x)) for x in wo]
    r, c = mpmath.mpf(r), mpmath.mpf(c)
    S = [a + b for a, b in zip(L, V)]
    nh = S[2] / mpmath.sqrt(sum(x * x for x in S))
    return float(c / (4 * mpmath.pi) * r / (1 - (1 - r) * nh**2) ** 2 / (r + (1 - r) * L[2]) / (r + (1 - r) * V[2]))


@pytest.mark.parametrize("r,c", [(1.0, 1.0), (0.5, 2.14), (0.1, 1.0), (1e-3, 0.042)])
def test_special_values(r, c):
    f = pumpup.load({"type": "schlick", "r": r, "c": c})
    k = c / (4 * math.pi)
    assert f.eval(N, N) == pytest.approx(k / r, rel=1e-14)  # wi = wo = N: r / r^2 / 1 / 1
    for mu in [0.9, 0.5, 1e-3, 1e-8]:
        # mirror pair: N.H = 1, so f = c / (4 pi r) / (r + (1 - r) mu)^2
        want = k / r / (r + (1 - r) * mu) ** 2
        assert f.eval(at_mu(mu, 0.5), at_mu(mu, 0.5 + math.pi)) == pytest.approx(want, rel=1e-12)
    # wi = N, wo at theta: N.H = cos(theta / 2)
    for theta in [0.1, 0.8, 1.5]:
        d = 1 - (1 - r) * math.cos(theta / 2) ** 2
        want = k * r / d**2 / (r + (1 - r) * math.cos(theta))
        assert f.eval(N, polar(theta, 1.0)) == pytest.approx(want, rel=1e-12)


def test_r_one_is_constant(rng):
    f = pumpup.load({"type": "schlick", "r": 1.0, "c": 0.5})
    wi, wo = random_directions(rng, 500, below=0), random_directions(rng, 500, below=0)
    np.testing.assert_allclose(f.eval(wi, wo), 0.5 / (4 * math.pi), rtol=1e-15)


@pytest.mark.parametrize("r", [1e-6, 1e-3, 0.3])
def test_against_high_precision_near_the_highlight(r, rng):
    # the 1 - (1 - r)(N.H)^2 of eq. 36 cancels near H = N for small r; the kernel must not
    f = pumpup.load({"type": "schlick", "r": r})
    for _ in range(20):
        theta = rng.uniform(0, 1.5)
        phi = rng.uniform(0, 2 * np.pi)
        wi = polar(theta, phi)
        wo = polar(theta + rng.normal() * 1e-4, phi + math.pi + rng.normal() * 1e-4)
        assert f.eval(wi, wo) == pytest.approx(schlick_mp(wi, wo, r, 1.0), rel=1e-11)


def test_lobe_hint():
    lobe = pumpup.load({"type": "schlick", "r": 0.1}).lobe(0.5)
    assert (lobe.axis, lobe.radial, lobe.sharpness) == ("half", "ggx", 0.1)


@pytest.mark.parametrize(
    "spec,pname",
    [
        ({"type": "schlick", "r": 0}, "r"),
        ({"type": "schlick", "r": 1.5}, "r"),
        ({"type": "schlick", "r": -0.2}, "r"),
        ({"type": "schlick", "r": float("nan")}, "r"),
        ({"type": "schlick"}, "r"),
        ({"type": "schlick", "r": 0.5, "c": -1}, "c"),
        ({"type": "schlick", "r": 0.5, "m": 0.1}, "m"),
    ],
)
def test_bad_input_names_the_parameter(spec, pname):
    with pytest.raises(pumpup.SpecError, match=repr(pname)) as exc:
        pumpup.load(spec)
    if pname == "r" and "r" in spec and not math.isnan(spec["r"]):
        assert "[1e-12, 1]" in str(exc.value)  # r >= 1e-12: the lobe is sqrt(r) >= 1e-6 wide (issue 13)
