"""Schlick's model (000 eq. 36)."""

import json
import math

import numpy as np
import pytest

import pumpup

mpmath = pytest.importorskip("mpmath")

CASES = pumpup.registry()["schlick"].examples
IDS = [json.dumps(ex, sort_keys=True) for ex in CASES]
N = np.array([0.0, 0.0, 1.0])


@pytest.fixture
def rng():
    """A fixed random generator for this module."""
    return np.random.default_rng(20261126)


def random_directions(rng, n, below=0.1, grazing=0.05):
    """Unit vectors: mostly upper hemisphere, a fraction below it and a fraction near grazing."""
    v = rng.normal(size=(n, 3))
    v /= np.linalg.norm(v, axis=-1, keepdims=True)
    v[:, 2] = np.abs(v[:, 2])
    k = int(n * below)
    v[:k, 2] *= -1
    g = int(n * grazing)
    mu = 10.0 ** rng.uniform(-8, -2, g)
    phi = rng.uniform(0, 2 * np.pi, g)
    s = np.sqrt(1 - mu**2)
    v[k : k + g] = np.stack([s * np.cos(phi), s * np.sin(phi), mu], axis=-1)
    return v


def direction_pairs(rng, n=10_000):
    """~n pairs: random (some below the horizon, some near grazing), exact mirror pairs,
    pairs at mu = 1e-8 exactly, and grazing pairs with wi nearly opposite wo."""
    wi = random_directions(rng, n)
    wo = random_directions(rng, n)[::-1].copy()
    wo[:500] = wi[:500] * np.array([-1, -1, 1])  # mirror pairs: H = N
    for k, sl in enumerate([slice(500, 700), slice(700, 900)]):
        phi = rng.uniform(0, 2 * np.pi, 200)
        w = np.stack([np.cos(phi), np.sin(phi), np.full(200, 1e-8)], axis=-1)
        (wi if k == 0 else wo)[sl] = w
    phi = rng.uniform(0, 2 * np.pi, 200)
    mu = 10.0 ** rng.uniform(-8, -3, (2, 200))
    s = np.sqrt(1 - mu**2)
    wi[900:1100] = np.stack([s[0] * np.cos(phi), s[0] * np.sin(phi), mu[0]], axis=-1)
    wo[900:1100] = np.stack([-s[1] * np.cos(phi + 1e-6), -s[1] * np.sin(phi + 1e-6), mu[1]], axis=-1)
    return wi, wo


def polar(theta, phi=0.0):
    return np.array([math.sin(theta) * math.cos(phi), math.sin(theta) * math.sin(phi), math.cos(theta)])


def at_mu(mu, phi=0.0):
    """The direction with N.w = mu exactly (no round trip through an angle)."""
    s = math.sqrt((1 - mu) * (1 + mu))
    return np.array([s * math.cos(phi), s * math.sin(phi), mu])


def schlick_mp(wi, wo, r, c):
    """000 eq. 36 evaluated literally in 50-digit arithmetic, from the float inputs."""
    mpmath.mp.dps = 50
    L = [mpmath.mpf(float(x)) for x in wi]
    V = [mpmath.mpf(float(x)) for x in wo]
    r, c = mpmath.mpf(r), mpmath.mpf(c)
    S = [a + b for a, b in zip(L, V)]
    nh = S[2] / mpmath.sqrt(sum(x * x for x in S))
    return float(c / (4 * mpmath.pi) * r / (1 - (1 - r) * nh**2) ** 2 / (r + (1 - r) * L[2]) / (r + (1 - r) * V[2]))


@pytest.mark.parametrize("params", CASES, ids=IDS)
def test_kernel_matches_reference(params, rng):
    f = pumpup.load({"type": "schlick", **params})
    wi, wo = direction_pairs(rng)
    fast = f.eval(wi, wo)
    ref = f.reference(wi, wo)
    assert np.all(np.isfinite(fast)) and np.all(fast >= 0)
    np.testing.assert_allclose(fast, ref, rtol=1e-12, atol=0)
    below = (wi[:, 2] <= 0) | (wo[:, 2] <= 0)
    assert below.any() and np.all(fast[below] == 0)


@pytest.mark.parametrize("params", CASES, ids=IDS)
def test_reciprocal(params):
    f = pumpup.load({"type": "schlick", **params})
    r = pumpup.check_reciprocity(f)
    assert r.reciprocal is True, str(r)


@pytest.mark.parametrize("params", CASES, ids=IDS)
def test_spec_round_trip(params):
    f = pumpup.load({"type": "schlick", **params})
    text = json.dumps(f.spec)
    assert pumpup.load(json.loads(text)) == f
    assert pumpup.load(f.spec) == f


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
        assert "(0, 1]" in str(exc.value)
