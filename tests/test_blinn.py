"""The Blinn family: blinn (000 eq. 31), stretched_blinn (000 eq. 32), phong_blinn (002 eq. 24)."""

import json
import math

import numpy as np
import pytest

import pumpup

MODELS = ["blinn", "stretched_blinn", "phong_blinn"]
CASES = [(name, ex) for name in MODELS for ex in pumpup.registry()[name].examples]
IDS = [f"{name}-{json.dumps(ex, sort_keys=True)}" for name, ex in CASES]


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
        w[:, :2] *= math.sqrt(1 - 1e-16)
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


@pytest.mark.parametrize("name,params", CASES, ids=IDS)
def test_kernel_matches_reference(name, params, rng):
    f = pumpup.load({"type": name, **params})
    wi, wo = direction_pairs(rng)
    fast = f.eval(wi, wo)
    ref = f.reference(wi, wo)
    assert np.all(np.isfinite(fast)) and np.all(fast >= 0)
    np.testing.assert_allclose(fast, ref, rtol=1e-12, atol=0)
    below = (wi[:, 2] <= 0) | (wo[:, 2] <= 0)
    assert below.any() and np.all(fast[below] == 0)


@pytest.mark.parametrize("name,params", CASES, ids=IDS)
def test_reciprocal(name, params):
    f = pumpup.load({"type": name, **params})
    r = pumpup.check_reciprocity(f)
    assert r.reciprocal is True, str(r)


@pytest.mark.parametrize("name,params", CASES, ids=IDS)
def test_spec_round_trip(name, params):
    f = pumpup.load({"type": name, **params})
    text = json.dumps(f.spec)
    assert pumpup.load(json.loads(text)) == f
    assert pumpup.load(f.spec) == f


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
