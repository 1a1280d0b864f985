"""Microfacet models: cook_torrance (001 eq. 9-10) and torrance_sparrow (002 eq. 10, D1-D4)."""

import json
import math

import numpy as np
import pytest
from helpers import at_mu, direction_pairs, polar, random_directions

import pumpup
from pumpup.models.cook_torrance import _g_kinks, fresnel

MODELS = ["cook_torrance", "torrance_sparrow"]
CASES = [(name, ex) for name in MODELS for ex in pumpup.registry()[name].examples]
IDS = [f"{name}-{json.dumps(ex, sort_keys=True)}" for name, ex in CASES]
N = np.array([0.0, 0.0, 1.0])


# --- the spec (kernel vs reference, reciprocity and the JSON round trip: test_models_common) ---


@pytest.mark.parametrize("name,params", CASES, ids=IDS)
def test_spec_has_ior_only_if_given(name, params):
    f = pumpup.load({"type": name, **params})
    assert ("ior" in f.spec) == ("ior" in params)  # no index given: not in the spec (Fresnel 1)


# --- Fresnel --------------------------------------------------------------------------------


@pytest.mark.parametrize("n", [1.0001, 1.33, 1.5, 2.4, 20.0])
def test_fresnel_normal_incidence(n):
    assert fresnel(1.0, n) == pytest.approx(((n - 1) / (n + 1)) ** 2, rel=1e-13)


@pytest.mark.parametrize("n", [1.33, 1.5, 2.4])
def test_fresnel_matches_s_and_p_polarised_average(n):
    # an independent form: F = (R_s + R_p) / 2 with Snell's law
    ci = np.linspace(0.01, 1.0, 50)
    ct = np.sqrt(1 - (1 - ci**2) / n**2)
    rs = ((ci - n * ct) / (ci + n * ct)) ** 2
    rp = ((ct - n * ci) / (ct + n * ci)) ** 2
    np.testing.assert_allclose(fresnel(ci, n), (rs + rp) / 2, rtol=1e-12)


def test_fresnel_limits():
    assert fresnel(0.0, 1.5) == pytest.approx(1.0, rel=1e-15)  # grazing incidence on the facet
    np.testing.assert_array_equal(fresnel(np.array([0.0, 0.3, 1.0]), None), 1.0)


# --- Cook-Torrance special values -----------------------------------------------------------


@pytest.mark.parametrize("m", [0.02, 0.1, 0.6])
def test_cook_torrance_at_normal(m):
    f = pumpup.load({"type": "cook_torrance", "m": m})
    # wi = wo = N: delta = 0, G = 1, F = 1: f = 1 / (4 pi m^2)
    assert f.eval(N, N) == pytest.approx(1 / (4 * math.pi * m * m), rel=1e-15)
    g = pumpup.load({"type": "cook_torrance", "m": m, "ior": 1.5})
    assert g.eval(N, N) == pytest.approx(0.04 / (4 * math.pi * m * m), rel=1e-13)


def test_cook_torrance_mirror_pairs():
    m = 0.1
    f = pumpup.load({"type": "cook_torrance", "m": m})
    for mu in [0.9, 0.5, 1e-3, 1e-8]:
        wi = at_mu(mu, 0.7)
        wo = wi * [-1, -1, 1]
        # H = N: D = 1 / (4 pi m^2), G = min(1, 2 mu / mu, ...) = 1, f = D / mu^2
        assert f.eval(wi, wo) == pytest.approx(1 / (4 * math.pi * m * m) / mu**2, rel=1e-12)
        # with an index: F at c = V.H = mu
        g = pumpup.load({"type": "cook_torrance", "m": m, "ior": 1.5})
        assert g.eval(wi, wo) == pytest.approx(float(fresnel(mu, 1.5)) / (4 * math.pi * m * m) / mu**2, rel=1e-12)


@pytest.mark.parametrize("theta_deg", [20.0, 50.0, 70.0, 85.0])
def test_cook_torrance_geometry_factor_branch(theta_deg):
    # wi = N, wo at theta: delta = theta / 2, N.H = V.H = cos(theta / 2), N.V = cos(theta), N.L = 1:
    # G = min(1, 2 cos(theta), 2) (001 eq. 10), which is below 1 past 60 degrees
    m = 0.3
    theta = math.radians(theta_deg)
    f = pumpup.load({"type": "cook_torrance", "m": m})
    half = theta / 2
    d = math.exp(-(math.tan(half) ** 2) / m**2) / (4 * math.pi * m * m * math.cos(half) ** 4)
    g = min(1.0, 2 * math.cos(theta))
    want = d * g / math.cos(theta)
    assert f.eval(N, polar(theta, 0.4)) == pytest.approx(want, rel=1e-12)
    assert f.eval(polar(theta, 0.4), N) == pytest.approx(want, rel=1e-12)


def test_cook_torrance_with_fresnel_off_normal():
    # wi = N, wo at 40 degrees: c = V.H = cos(20 degrees), G = 1
    m, n, theta = 0.2, 1.5, math.radians(40)
    f = pumpup.load({"type": "cook_torrance", "m": m, "ior": n})
    c = math.cos(theta / 2)
    g = math.sqrt(n * n + c * c - 1)
    F = (g - c) ** 2 / (2 * (g + c) ** 2) * (1 + (c * (g + c) - 1) ** 2 / (c * (g - c) + 1) ** 2)
    d = math.exp(-(math.tan(theta / 2) ** 2) / m**2) / (4 * math.pi * m * m * c**4)
    assert f.eval(N, polar(theta)) == pytest.approx(F * d / math.cos(theta), rel=1e-12)


@pytest.mark.filterwarnings("ignore:.*encountered in _ct_kernel:RuntimeWarning")
def test_grazing_values_have_no_nan():
    # below mu ~ 1e-154 the true value ~ 1 / mu^2 exceeds the float range: inf is right, NaN is not
    f = pumpup.load({"type": "cook_torrance", "m": 0.1, "ior": 1.5})
    for mu in [1e-8, 1e-100, 1e-200, 1e-300]:
        wi = at_mu(mu, 0.2)
        for wo in [wi * [-1, -1, 1], wi * [-1, -1, 1] + [1e-9, 0, 0], wi, at_mu(mu, 0.2 + math.pi + 1e-6)]:
            wo = wo / np.linalg.norm(wo)
            v = f.eval(wi, wo)
            assert not np.isnan(v) and v >= 0
    assert np.isfinite(f.eval(at_mu(1e-8), at_mu(1e-8, math.pi)))


# --- Torrance-Sparrow -------------------------------------------------------------------------


@pytest.mark.parametrize("ior", [None, 1.5])
@pytest.mark.parametrize("m", [0.05, 0.3])
def test_torrance_sparrow_d4_is_cook_torrance(m, ior, rng):
    spec = {"m": m} if ior is None else {"m": m, "ior": ior}
    ct = pumpup.load({"type": "cook_torrance", **spec})
    ts = pumpup.load({"type": "torrance_sparrow", "d": "D4", "s": m, **({} if ior is None else {"ior": ior})})
    wi, wo = direction_pairs(rng, 3000)
    a, b = ts.eval(wi, wo), ct.eval(wi, wo)
    # same formula, different order of operations: exp(-x) carries a relative rounding error
    # ~ x eps, and values below 1e-300 lose digits as subnormals
    big = b > 1e-100
    np.testing.assert_allclose(a[big], b[big], rtol=1e-13, atol=0)
    np.testing.assert_allclose(a[~big], b[~big], rtol=0, atol=1e-100)


@pytest.mark.parametrize("d,s", [("D1", 0.0), ("D1", 20.0), ("D2", 5.0), ("D3", 0.3), ("D3", 2.0)])
def test_torrance_sparrow_at_normal(d, s):
    # wi = wo = N: alpha = 0, every D1-D3 equals b there, G = 1: f = F b / pi
    f = pumpup.load({"type": "torrance_sparrow", "d": d, "s": s, "b": 0.7})
    assert f.eval(N, N) == pytest.approx(0.7 / math.pi, rel=1e-14)
    g = pumpup.load({"type": "torrance_sparrow", "d": d, "s": s, "b": 0.7, "ior": 1.5})
    assert g.eval(N, N) == pytest.approx(0.04 * 0.7 / math.pi, rel=1e-13)


@pytest.mark.parametrize("theta_deg", [30.0, 80.0])
@pytest.mark.parametrize("d,s", [("D1", 20.0), ("D2", 3.0), ("D3", 0.4), ("D3", 1.7), ("D4", 0.25)])
def test_torrance_sparrow_distributions_by_hand(d, s, theta_deg):
    # wi = N, wo at theta: alpha = theta / 2, G = min(1, 2 cos(theta)), F = 1; 002 eq. 10 and sec. 3.2
    b = 1.0 if d == "D4" else 0.8
    theta = math.radians(theta_deg)
    a = theta / 2
    ca = math.cos(a)
    D = {
        "D1": lambda: b * ca**s,
        "D2": lambda: b * math.exp(-((s * a) ** 2)),
        "D3": lambda: b * (s * s / (ca * ca * (s * s - 1) + 1)) ** 2,
        "D4": lambda: math.exp(-(1 - ca * ca) / (s * s * ca * ca)) / (4 * s * s * ca**4),
    }[d]()
    G = min(1.0, 2 * math.cos(theta))
    want = G * D / (math.pi * 1.0 * math.cos(theta))
    f = pumpup.load({"type": "torrance_sparrow", "d": d, "s": s, "b": b})
    assert f.eval(N, polar(theta, 1.1)) == pytest.approx(want, rel=1e-12)


def test_torrance_sparrow_d1_is_blinn_with_geometry(rng):
    # D1 with e = n: f = G (N.H)^n b / (pi (N.L)(N.V)): compare with the blinn model
    wi, wo = random_directions(rng, 2000, below=0), random_directions(rng, 2000, below=0)
    ts = pumpup.load({"type": "torrance_sparrow", "d": "D1", "s": 12.0})
    bl = pumpup.load({"type": "blinn", "n": 12.0})
    s = wi + wo
    h = s / np.linalg.norm(s, axis=-1, keepdims=True)
    vh = np.einsum("...k,...k->...", wo, h)
    G = np.minimum(1, np.minimum(2 * h[:, 2] * wo[:, 2] / vh, 2 * h[:, 2] * wi[:, 2] / vh))
    want = G * bl.eval(wi, wo) / (np.pi * wi[:, 2] * wo[:, 2])
    np.testing.assert_allclose(ts.eval(wi, wo), want, rtol=1e-9)


# --- kinks of the geometry factor -----------------------------------------------------------


def test_g_kinks_are_the_branch_switches(rng):
    # in the parametrisation of the albedo engine, a + b cos(phi) must equal the quantities
    # whose sign decides G's branch: 2 cos_a wo_z - wi.h, 2 cos_a mu - wi.h and wo_z - mu
    n = 2000
    mu = rng.uniform(1e-6, 1, n)
    s = np.sqrt(1 - mu**2)
    alpha = rng.uniform(0, np.pi / 2, n)
    phi = rng.uniform(0, 2 * np.pi, n)
    cos_a, sin_a = np.cos(alpha), np.sin(alpha)
    wi = np.stack([s, 0 * s, mu], axis=-1)
    h = np.stack([sin_a * np.cos(phi), sin_a * np.sin(phi), cos_a], axis=-1)
    wih = np.einsum("...k,...k->...", wi, h)
    wo = 2 * wih[:, None] * h - wi
    pairs = _g_kinks(mu, s, cos_a, sin_a)
    assert len(pairs) == 3
    targets = [2 * cos_a * wo[:, 2] - wih, 2 * cos_a * mu - wih, wo[:, 2] - mu]
    for (a, b), want in zip(pairs, targets):
        np.testing.assert_allclose(a + b * np.cos(phi), want, rtol=0, atol=1e-13)
    # and G really switches there: 2 (N.H)(N.V) / (V.H) < 1 exactly where the first is negative
    up = (wo[:, 2] > 0) & (wih > 0)
    term = 2 * cos_a * wo[:, 2] / wih
    a, b = pairs[0]
    q = a + b * np.cos(phi)
    clear = up & (np.abs(q) > 1e-9)
    assert np.array_equal(term[clear] < 1, q[clear] < 0)


def test_lobe_hints():
    lobe = pumpup.load({"type": "cook_torrance", "m": 0.1}).lobe(0.5)
    assert (lobe.axis, lobe.radial, lobe.sharpness, lobe.kinks) == ("half", "beckmann", 0.1, _g_kinks)
    want = {
        ("D1", 20.0): ("power", 20.0),
        ("D2", 5.0): ("gaussian", 5.0),
        ("D3", 0.5): ("ggx", 0.25),  # D3 is Schlick's form with r = c3^2
        ("D3", 2.0): ("ggx", 1.0),
        ("D4", 0.2): ("beckmann", 0.2),
    }
    for (d, s), (radial, sharp) in want.items():
        lobe = pumpup.load({"type": "torrance_sparrow", "d": d, "s": s}).lobe(0.3)
        assert (lobe.axis, lobe.radial, lobe.kinks) == ("half", radial, _g_kinks)
        assert lobe.sharpness == pytest.approx(sharp)


def test_d3_is_schlick_form_with_r_c3_squared():
    # D3 = b [c3^2 / (cos^2 (c3^2 - 1) + 1)]^2 = b r * r / (1 - (1 - r) cos^2)^2 with r = c3^2
    c3 = 0.4
    r = c3 * c3
    ca = np.linspace(0.01, 1, 30)
    d3 = (c3 * c3 / (ca**2 * (c3 * c3 - 1) + 1)) ** 2
    np.testing.assert_allclose(d3, r * r / (1 - (1 - r) * ca**2) ** 2, rtol=1e-13)


# --- bad input ------------------------------------------------------------------------------


@pytest.mark.parametrize(
    "spec,pname",
    [
        ({"type": "cook_torrance", "m": 0}, "m"),
        ({"type": "cook_torrance", "m": -1}, "m"),
        ({"type": "cook_torrance", "m": float("nan")}, "m"),
        ({"type": "cook_torrance"}, "m"),
        ({"type": "cook_torrance", "m": 0.1, "ior": 1.0}, "ior"),
        ({"type": "cook_torrance", "m": 0.1, "ior": 0.5}, "ior"),
        ({"type": "cook_torrance", "m": 0.1, "ior": float("nan")}, "ior"),
        ({"type": "cook_torrance", "m": 0.1, "ior": "glass"}, "ior"),
        ({"type": "cook_torrance", "m": 0.1, "c": 1.0}, "c"),
        ({"type": "torrance_sparrow", "d": "D5", "s": 1.0}, "d"),
        ({"type": "torrance_sparrow", "d": 4, "s": 1.0}, "d"),
        ({"type": "torrance_sparrow", "s": 1.0}, "d"),
        ({"type": "torrance_sparrow", "d": "D1"}, "s"),
        ({"type": "torrance_sparrow", "d": "D1", "s": -1.0}, "s"),
        ({"type": "torrance_sparrow", "d": "D2", "s": 0.0}, "s"),
        ({"type": "torrance_sparrow", "d": "D3", "s": 0.0}, "s"),
        ({"type": "torrance_sparrow", "d": "D4", "s": 0.0}, "s"),
        ({"type": "torrance_sparrow", "d": "D4", "s": -1.0}, "s"),
        ({"type": "torrance_sparrow", "d": "D4", "s": 0.1, "b": 2.0}, "b"),
        ({"type": "torrance_sparrow", "d": "D1", "s": 1.0, "b": -1.0}, "b"),
        ({"type": "torrance_sparrow", "d": "D1", "s": 1.0, "ior": 1.0}, "ior"),
        ({"type": "torrance_sparrow", "d": "D1", "s": 1.0, "m": 0.1}, "m"),
    ],
)
def test_bad_input_names_the_parameter(spec, pname):
    with pytest.raises(pumpup.SpecError, match=repr(pname)):
        pumpup.load(spec)


def test_d4_error_says_s_is_m():
    with pytest.raises(pumpup.SpecError, match=r"'s' \(m of D4\).*\(0, inf\)"):
        pumpup.load({"type": "torrance_sparrow", "d": "D4", "s": 0.0})


def test_d1_exponent_zero_is_allowed():
    f = pumpup.load({"type": "torrance_sparrow", "d": "D1", "s": 0})
    assert f.eval(N, N) == pytest.approx(1 / math.pi)
