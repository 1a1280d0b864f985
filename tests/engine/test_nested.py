"""The nested albedo quadrature (pumpup.engine.nested, issue 14 item 2) against the 2-D engine, the independent
references and its own numpy twins; the switches; the work limit."""

import json
import math
import sys
import warnings

import helpers
import numpy as np
import pytest

import pumpup
from pumpup.engine import nested as _nested
from pumpup.engine import polar as _polar
from pumpup.engine.cubature import NODES, WG, WK, AlbedoWarning, _groups, _integrate_group
from pumpup.engine.lobe_geometry import kink_coefficients, smooth
from pumpup.engine.routes import using


@pytest.fixture(autouse=True)
def _nested_for_the_blinn_family_too():
    """These tests use the Blinn family as the nested engine's examples; its azimuth about N is closed-form
    (pumpup.engine.polar, kind "half"), so the 1-D path is switched off here and the nested engine integrates it."""
    with helpers.without_1d():
        yield

A = sys.modules["pumpup.engine.cubature"]
MU = np.array([1.0, 0.5, 1e-3, 1e-6])
FIRST = [(name, cls.examples[0]) for name, cls in pumpup.registry().items() if cls.examples]
DATA = json.loads((helpers.DATA / "independent_reference.json").read_text())
DIRECTIONAL = [e for e in DATA["entries"] if e["quantity"] == "directional_albedo" and e["mu"] > 0]


@pytest.fixture
def no_1d():
    """No 1-D route, so the nested engine takes the Phong family too."""
    with helpers.without_1d():
        yield


def _by_engine(f, mu, nested, rtol=1e-10):
    """(value, error, engine used per group) of f's albedo with either engine on every group."""
    mu = np.atleast_1d(np.asarray(mu, float))
    value, error, used = np.zeros_like(mu), np.zeros_like(mu), []
    for w, term in f.albedo_terms():
        for idx, g in _groups(term, mu):
            use = nested and _nested.supports(g)
            used.append(use)
            v, e, _ = (_nested.integrate if use else _integrate_group)(term, g, rtol, 1e-14, 20000)
            value[idx] += w * v
            error[idx] += abs(w) * e
    error += getattr(f, "eval_rtol", 0.0) * value
    return value, error, used


@pytest.mark.parametrize("name,params", FIRST, ids=[n for n, _ in FIRST])
def test_every_model_nested_and_2d_agree(name, params):
    f = pumpup.load({"type": name, **params})
    a, e, used = _by_engine(f, MU, nested=True)
    b, eb, _ = _by_engine(f, MU, nested=False)
    assert np.all(np.isfinite(a)) and np.all(e >= 0)
    bad = np.abs(a - b) > e + eb
    assert not bad.any(), (MU[bad], a[bad], e[bad], b[bad], eb[bad])
    assert all(used), "every built-in hint (phi = 0) goes to the nested engine"


@pytest.mark.parametrize("entry", DIRECTIONAL, ids=[f"{e['model']}-{e['params']}-{e['mu']:.3g}" for e in DIRECTIONAL])
def test_nested_against_independent_reference(entry, no_1d):
    f = pumpup.load({"type": entry["model"], **entry["params"]})
    a, e = pumpup.albedo(f, entry["mu"], return_error=True)
    diff = abs(float(a) - entry["value"])
    assert diff <= float(e) + entry["abs_err_estimate"], (float(a), entry["value"], float(e))
    assert float(e) <= 1e-9 * entry["value"] + 1e-14  # and it met rtol 1e-10 (with the rounding term)


@pytest.mark.parametrize("spec", [{"type": "stretched_phong", "n": 20, "p": 0.5}, {"type": "cook_torrance", "m": 0.3},
                                  {"type": "ward", "m": 0.1}, {"type": "blinn", "n": 16}])
@pytest.mark.parametrize("rtol", [1e-6, 1e-8, 1e-10])
def test_error_bounds_the_truth_at_every_rtol(spec, rtol):
    """The truth: the 2-D engine at rtol 1e-13 (a different cubature); its own error is added."""
    f = pumpup.load(spec)
    mu = np.array([1.0, 0.9, 0.5, 0.3414, 0.1, 1e-2, 1e-4, 1e-7])
    a, e = pumpup.albedo(f, mu, return_error=True, rtol=rtol)
    with helpers.without_nested():
        t, et = pumpup.albedo(f, mu, return_error=True, rtol=1e-13)
    assert np.all(np.abs(a - t) <= e + et), (mu, a - t, e)
    assert np.all(e <= rtol * a + 1e-14 + 64 * np.finfo(float).eps * a)


@pytest.mark.parametrize("mu", [1e-7, 1e-8])
@pytest.mark.parametrize("rtol", [1e-10, 1e-12])
def test_p_model_near_grazing_bounds_its_error(mu, rtol, monkeypatch):
    """Stretched Phong n = 1, p = 0.5 near grazing: N.wo^(1 - p) above the cut N.wo = mu has its branch
    point N.wo = 0 just beyond the piece's end (pumpup.engine.nested._end_grading; the 2-D engine's
    pumpup.engine.cubature._level_end_scales).  Before the grading, at mu = 1e-8 and rtol 1e-12: 0.4576558641015173
    +- 1.1e-13, true error 5.9e-13.  The truth: the 1-D path at rtol 1e-13 (closed-form azimuth and a
    Gauss-Jacobi rule at the arc's end, a different method; within 1e-15 of tests/data/independent_p.json),
    its own error added."""
    f = pumpup.load({"type": "stretched_phong", "n": 1, "p": 0.5})
    with using(engine="auto"):  # (the module's fixture left the 1-D routes out)
        t, et, *_ = _polar.albedo_1d(f, np.array([mu]), 1e-13, 0.0, 10000)
    a, e, used = _by_engine(f, mu, nested=True, rtol=rtol)
    assert all(used)
    assert abs(a[0] - t[0]) <= e[0] + et[0], (a[0], e[0], a[0] - t[0])


PUMPED = [("phong", "g1", 3), ("phong", "g2", 3), ("blinn", "g2", 2), ("cook_torrance", "g1", 1),
          pytest.param("cook_torrance", "g2", 2, marks=pytest.mark.slow)]
BASES = {"phong": {"type": "phong", "n": 20}, "blinn": {"type": "blinn", "n": 20, "c": 0.9},
         "cook_torrance": {"type": "cook_torrance", "m": 0.2}}


@pytest.mark.parametrize("base,g,levels", PUMPED, ids=["phong-g1-3", "phong-g2-3", "blinn-g2-2", "cook_torrance-g1-1",
                                                        "cook_torrance-g2-2"])
def test_pumped_nested_and_2d_agree(base, g, levels, no_1d):
    f = pumpup.pump(BASES[base], g=g, levels=levels)
    f.lookup()  # the tables of the levels below, built once (with every route: they define f)
    mu = np.array([1.0, 0.7, 0.2, 1e-3, 1e-6]) if base != "cook_torrance" else np.array([0.8, 0.1, 1e-4])
    a, e, used = _by_engine(f, mu, nested=True)
    b, eb, _ = _by_engine(f, mu, nested=False)
    assert all(used)
    bad = np.abs(a - b) > e + eb
    assert not bad.any(), (mu[bad], a[bad], e[bad], b[bad], eb[bad])


# --- the compiled kernels against their numpy twins -------------------------------------------------

KERNEL_CASES = [
    ({"type": "cook_torrance", "m": 0.3}, 0.4),  # half axis, beckmann, three model kinks
    ({"type": "torrance_sparrow", "d": "D1", "s": 20}, 0.8),  # half, power
    ({"type": "ggx", "alpha": 0.2}, 0.3),  # half, ggx
    ({"type": "stretched_phong", "n": 20, "p": 0.5}, 0.3),  # mirror, power, one level
    ({"type": "retro", "n": 10}, 0.6),  # retro
    ({"type": "oren_nayar"}, 0.2),  # normal, cosine
]


def _group(spec, mu):
    f = pumpup.load(spec)
    return f, next(g for _, g in _groups(f, np.array([mu])))


@pytest.mark.parametrize("spec,mu", KERNEL_CASES, ids=[c[0]["type"] for c in KERNEL_CASES])
def test_kernels_match_their_numpy_twins(spec, mu):
    from pumpup.engine.lobe_geometry import AXIS_CODE, RADIAL_CODE

    _, g = _group(spec, mu)
    lobe = g.lobe
    rng = np.random.default_rng(3)
    tx = np.concatenate([rng.uniform(0, 1, 200), [0.0, 1.0, 0.5, 1e-9, 1 - 1e-9]])
    N = len(tx)
    mu_n = np.full(N, mu)
    lev = np.repeat(g.levels, N, axis=0)
    if lobe.kinks is not None:
        x, xc, _ = smooth(tx)
        ka, kb = kink_coefficients(lobe, mu_n, x, xc)
    else:
        ka = kb = np.zeros((N, 0))
    ref = _nested._nodes_reference(lobe.axis, lobe.radial, float(lobe.sharpness), mu_n, lev, ka, kb, tx)
    E = lev.shape[1] + ka.shape[1] + 2
    got = [np.empty(N) for _ in range(4)] + [np.empty((N, E)), np.empty((N, E), np.int64), np.empty((N, E))]
    _nested._nodes_kernel(AXIS_CODE[lobe.axis], RADIAL_CODE[lobe.radial], float(lobe.sharpness), mu_n, lev,
                          np.ascontiguousarray(ka), np.ascontiguousarray(kb), tx, *got)
    for r_, k_ in zip(ref, got):
        np.testing.assert_allclose(k_, r_, rtol=1e-12, atol=1e-14)
    assert np.all(np.diff(got[4], axis=1) >= 0)  # pieces in order
    if lev.shape[1] and lobe.axis != "normal":
        assert np.any(got[5] >= 0)  # some edges are level cuts
    s_n, ca_n, sa_n, wr_n, edges = got[:5]
    # segments on every piece of some nodes, sub-intervals of v
    node = np.repeat(np.arange(0, N, 7), 2)
    piece = node % (edges.shape[1] - 1)
    lo = edges[node, piece]
    width = edges[node, piece + 1] - lo
    t0 = np.tile([0.0, 0.25], len(node) // 2)
    t1 = np.tile([0.25, 1.0], len(node) // 2)
    sm = np.arange(len(node)) % 4  # every inner substitution
    wi_r, wo_r, w_r = _nested._points_reference(lobe.axis, node, lo, width, t0, t1, mu_n, s_n, ca_n, sa_n, wr_n, sm)
    S = len(node) * 15
    wi, wo, w = np.empty((S, 3)), np.empty((S, 3)), np.empty(S)
    _nested._points_kernel(AXIS_CODE[lobe.axis], node, lo, width, t0, t1, sm, mu_n, s_n, ca_n, sa_n, wr_n, NODES,
                           wi, wo, w)
    np.testing.assert_allclose(wi, wi_r, rtol=1e-13, atol=1e-15)
    np.testing.assert_allclose(wo, wo_r, rtol=1e-12, atol=1e-14)
    np.testing.assert_allclose(w, w_r, rtol=1e-12, atol=1e-300)
    np.testing.assert_allclose(np.linalg.norm(wo[w > 0], axis=1), 1.0, atol=1e-13)
    f = np.abs(rng.normal(size=S))
    f[::5] = 0.0
    vals = np.zeros(S)
    assert _nested.accumulate(f, wo[:, 2], w, vals) == -1
    np.testing.assert_allclose(vals, _nested._values_reference(f, wo[:, 2], w), rtol=1e-15, atol=1e-300)
    K, G = np.zeros(S // 15), np.zeros(S // 15)
    _nested._rule_kernel(vals, WK, WG, K, G)
    for got_, ref_ in zip((K, G), _nested._rule_reference(vals, WK, WG)):
        np.testing.assert_allclose(got_, ref_, rtol=1e-13, atol=1e-300)
    f[17] = np.nan
    assert _nested.accumulate(f, wo[:, 2], w, vals) == 17


def test_nested_integrand_equals_the_2d_geometry():
    """At one outer node, the nested points of a piece are the 2-D engine's points (tau_x, tau_t)."""
    f, g = _group({"type": "cook_torrance", "m": 0.3}, 0.4)
    tx0 = 0.37
    n_pieces = g.levels.shape[1] + 3 + 1
    seg_int = np.zeros(n_pieces, int)
    # the value at one node, as the outer rule on a tiny interval around it would see it: compare the
    # inner sums with the 2-D engine's integrand summed by the same 15-point rule in tau_t
    h = 1e-12
    sv, *_ = _nested._evaluate(f, g, np.array([0]), np.array([tx0]), np.array([tx0 + h]), seg_int,
                               np.arange(n_pieces), np.zeros(n_pieces), np.ones(n_pieces))
    k = sv @ _nested._OUTER[1]  # the outer Kronrod sum of each segment
    tt = NODES
    total = 0.0
    for piece in range(n_pieces):
        v = A._integrand(f, g, np.zeros(15, int), np.full(15, piece), np.full(15, tx0 + h * 0.5), tt)
        total += v @ WK
    assert math.isclose(k.sum() / ((tx0 + h) - tx0), total, rel_tol=1e-9)


# --- switches, budget, evaluation counts ---------------------------------------------------------------

def test_two_d_only_and_disabled_switch_the_nested_path_off(monkeypatch):
    f = pumpup.load({"type": "blinn", "n": 16})
    calls = []
    real = _nested.integrate
    monkeypatch.setattr(_nested, "integrate", lambda *a: calls.append(1) or real(*a))
    pumpup.albedo(f, 0.5)
    assert calls == [1]
    with helpers.two_d_only():
        pumpup.albedo(f, 0.5)
    with helpers.without_nested():
        pumpup.albedo(f, 0.5)
    assert calls == [1]
    pumpup.albedo(f, 0.5, phi=0.3)  # isotropic: phi ignored, nested
    assert calls == [1, 1]
    aniso = pumpup.load({"type": "ward_aniso", "ax": 0.1, "ay": 0.3})
    pumpup.albedo(aniso, 0.5, phi=0.3)  # wi out of the xz-plane: nested too, turned
    assert calls == [1, 1, 1]
    user = pumpup.from_function(lambda wi, wo: np.full(wi.shape[:-1], 1 / np.pi), name="flat")
    pumpup.albedo(user, 0.5)  # no hint: the 2-D engine's generic path
    assert calls == [1, 1, 1]


def test_budget_exhausted_warns_and_the_error_stays_honest():
    f = pumpup.load({"type": "cook_torrance", "m": 0.3})
    mu = np.array([0.9, 0.05])
    with pytest.warns(AlbedoWarning, match="tolerance"):
        a, e = pumpup.albedo(f, mu, return_error=True, rtol=1e-14, max_regions=3)
    t, et = pumpup.albedo(f, mu, return_error=True, rtol=1e-12)
    assert np.all(np.abs(a - t) <= e + et)
    assert np.all(e > 1e-14 * a)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        pumpup.albedo(f, mu, rtol=1e-8)


def test_bad_brdf_value_is_reported():
    class Bad(type(pumpup.load({"type": "blinn", "n": 4}))):
        def _eval(self, wi, wo):
            out = super()._eval(wi, wo)
            out[len(out) // 2] = -1.0
            return out

    f = Bad(n=4)
    with pytest.raises(ValueError, match="finite and non-negative"):
        pumpup.albedo(f, 0.5)


@pytest.mark.parametrize("spec", [{"type": "blinn", "n": 16}, {"type": "cook_torrance", "m": 0.3},
                                  {"type": "stretched_phong", "n": 20, "p": 0.5}])
def test_evaluation_counts_per_mu(spec, capsys, no_1d):
    """The nested engine spends fewer evaluations per mu than the 2-D engine (counts printed)."""
    f = pumpup.load(spec)
    mu = np.cos(np.linspace(0, np.pi / 2, 18)[:-1])
    pumpup.albedo(f, mu)
    nested = _nested.LAST_EVALS.astype(float)
    count = [0]
    orig = A.accumulate  # (the 2-D cubature's own name for it: nested has its own)

    def counting(fv, cos_o, weight, total):
        count[0] += fv.shape[0]
        return orig(fv, cos_o, weight, total)

    A.accumulate = counting
    try:
        with helpers.without_nested():
            pumpup.albedo(f, mu)
    finally:
        A.accumulate = orig
    two_d = count[0] / len(mu)
    with capsys.disabled():
        print(f"\n{spec}: evaluations per mu, nested {nested.mean():.0f} (max {nested.max():.0f}), 2-D {two_d:.0f}")
    assert nested.mean() < two_d


@pytest.mark.slow
def test_scaled_phong_against_brute_force_spherical_quadrature():
    """scaled over Phong n = 5 at mu = 0.823: the nested value against scipy quad in (theta_o, phi_o)
    (measured: agree to 1e-12; the 2-D engine was 5e-7 off with an estimate of 1e-13)."""
    from scipy.integrate import quad

    f = pumpup.load({"type": "scaled", "base": {"type": "phong", "n": 5}})
    mu = 0.8229838658936565
    a, e = pumpup.albedo(f, mu, return_error=True, rtol=1e-13)
    wi = np.array([math.sqrt(1 - mu * mu), 0.0, mu])

    def ring(th):
        def g(ph):
            wo = np.array([math.sin(th) * math.cos(ph), math.sin(th) * math.sin(ph), math.cos(th)])
            return float(f.reference(wi, wo))
        return 2 * quad(g, 0, math.pi, epsabs=1e-14, epsrel=1e-13, limit=200)[0] * math.cos(th) * math.sin(th)

    ref, ref_err = quad(ring, 0, math.pi / 2, epsabs=1e-13, epsrel=1e-12, limit=200)
    assert abs(float(a) - ref) <= float(e) + max(ref_err, 1e-12 * ref)


@pytest.mark.parametrize("n", [1073.0, 1074.0, 1e4, 1e5])
def test_sharp_power_lobes_where_the_split_underflows(n):
    """y_s = 2^-(n+1) underflows to 0 for n > 1073: the grid above the split must still end (it
    looped for ever) and the value agree with the 2-D engine."""
    f = pumpup.load({"type": "blinn", "n": n})
    mu = np.array([1.0, 0.5, 1e-3])
    a, e = pumpup.albedo(f, mu, return_error=True)
    with helpers.without_nested():
        b, eb = pumpup.albedo(f, mu, return_error=True)
    assert np.all(np.abs(a - b) <= e + eb), (a - b, e, eb)


@pytest.mark.parametrize("ax,ay", [(1e-6, 1e-3), (1e-3, 1e-6)])
def test_anisotropic_ridge_at_phi_zero(ax, ay):
    """A lobe narrow across one tangent axis is a ridge on beta = 0 or on the hint's y-axis cut; the
    nested engine must resolve it at phi = 0 (it gave 0.761 +- 6e-12 for 0.9999985 without the
    square-root substitution at those ends)."""
    f = pumpup.load({"type": "ward_aniso", "ax": ax, "ay": ay})
    a, e = pumpup.albedo(f, np.array([1.0, 0.5]), return_error=True)
    with helpers.without_nested():
        b, eb = pumpup.albedo(f, np.array([1.0, 0.5]), return_error=True)
    assert np.all(np.abs(a - b) <= e + eb), (a, b, e, eb)
    assert abs(a[0] - 1.0) < 2e-6


def test_graded_breaks_on_an_end_terminate():
    """A break exactly on an end of the tau range (found by the property test: GGX at an extreme
    parameter put one at tau = 1) is the end itself; grading towards it looped forever (d = 0)."""
    from pumpup.engine.nested import _graded_coarse

    out = _graded_coarse(np.array([0.0, 1.0, 1e-3]))
    assert set(out) >= {0.0, 1.0, 1e-3} and np.all((out >= 0) & (out <= 1)) and len(out) < 20


def test_segments_in_chunks_change_no_bit(monkeypatch):
    """``_evaluate`` in calls of at most SEG_CHUNK segments (a nested reference at max_regions 200000 grew past
    23 GB without them, and a case of it peaks at 0.81 GB with them, 2.8 GB without): each segment's values do not
    depend on the others in its call, so 7 segments per call give the same bits as one call."""
    mu = np.array([1e-4, 0.03, 0.4, 0.8, 1.0])
    for spec in ({"type": "ward_aniso", "ax": 0.05, "ay": 0.3},
                 {"type": "pumped", "base": {"type": "blinn", "n": 30}, "g": "g2", "levels": 2}):
        f = pumpup.load(spec)
        f.azimuth_hint()  # (the pumped tables first, with the default chunks)
        with helpers.without_1d(), warnings.catch_warnings():
            warnings.simplefilter("ignore")
            a, e = pumpup.albedo(f, mu, rtol=1e-10, return_error=True)
            monkeypatch.setattr(_nested, "SEG_CHUNK", 7)
            b, eb = pumpup.albedo(f, mu, rtol=1e-10, return_error=True)
            monkeypatch.setattr(_nested, "SEG_CHUNK", 100_000)
        assert np.array_equal(a, b) and np.array_equal(e, eb), spec
