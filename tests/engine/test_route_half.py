"""The 1-D albedo path's half-vector routes (pumpup/engine/half_frames.py, the azimuth of h about N in closed form):
``half`` (the Blinn family, the modified Ward model), ``ward`` (Ward's, by complete elliptic integrals) and ``vcavity``
(the V-cavity G with F = 1: Cook-Torrance, Torrance-Sparrow); the kernels against the geometry and their numpy twins,
the albedo against the nested and 2-D engines and closed forms."""

import math
import warnings

import helpers
import numpy as np
import pytest

import pumpup
from pumpup.core.hints import HalfVectorLobe, PowerLobe, VCavityLobe, WardLobe
from pumpup.engine import half_frames as _half_frames
from pumpup.engine import outer_rule as _outer_rule
from pumpup.engine import polar as _polar

# grazing, the breakpoints' special cases (mu = 1/2: s = cos 30 deg; 1/sqrt(2): cos 2 theta = 0;
# sqrt(3)/2: s = 1/2, the split of the tail), and ordinary angles
MU = [1.0, 0.99, 0.9, math.sqrt(3) / 2, 1 / math.sqrt(2), 0.5, 0.2, 0.05, 1e-3, 1e-6, 1e-8]


# --- the Blinn family: the half vector's azimuth about N in closed form (kind "half") -----------------


def _k_half_by_quad(p, mu, u, kind="max"):
    """K(u) of the half-vector frame straight from the geometry, by scipy quad over the azimuth of h:
    wo = 2 (wi.h) h - wi, integrand 4 (wi.h) N.wo / max(mu, N.wo)^p where N.wo > 0 (split at the arcs' ends);
    kind "root": 4 (wi.h) sqrt(N.wo) (Ward's, its 1 / sqrt(N.L) left out); "vcavity": 4 (wi.h) G with 001 eq. 10's
    G = min(1, 2 (N.h)(N.wo) / (wo.h), 2 (N.h)(N.wi) / (wo.h)) (Cook-Torrance's, F = 1), split at its kinks too."""
    from scipy.integrate import quad

    s, sa = math.sqrt((1 - mu) * (1 + mu)), math.sqrt((1 - u) * (1 + u))
    wi = np.array([s, 0.0, mu])

    def g(beta):
        h = np.array([sa * math.cos(beta), sa * math.sin(beta), u])
        c = float(wi @ h)
        nwo = 2 * c * u - mu
        if not (c > 0 and nwo > 0):
            return 0.0
        if kind == "vcavity":
            return 4 * c * min(1.0, 2 * u * nwo / c, 2 * u * mu / c)
        return 4 * c * math.sqrt(nwo) if kind == "root" else 4 * c * nwo / max(mu, nwo) ** p

    b, a = s * sa, mu * u
    cuts = (mu / (2 * u), mu / u) + ((2 * u * mu, 2 * u * mu / (4 * u * u - 1) if u != 0.5 else -9.0)
                                     if kind == "vcavity" else ())
    pts = [math.acos((cv - a) / b) for cv in cuts if b > 0 and abs((cv - a) / b) < 1]
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return 2 * quad(g, 0, math.pi, points=pts or None, epsabs=1e-15 if kind != "vcavity" else 0, epsrel=1e-13,
                        limit=400)[0]


@pytest.mark.parametrize("p", [0.0, 1.0])
def test_half_kernel_against_the_geometry_and_its_numpy_twin(rng, p):
    """_k_half against an independent quadrature of the integrand built from wi, h and wo, and its numpy twin
    (arccos and the antiderivatives of c and c^2), at random u and at both sides of every breakpoint."""
    for mu in (1.0, 0.99, 0.9, 1 / math.sqrt(2), 0.5, 0.2, 0.05, 1e-3, 1e-6):
        s = math.sqrt((1 - mu) * (1 + mu))
        psi, th = math.atan2(mu, s), math.atan2(s, mu)
        edges = [math.cos(math.pi / 4 + th / 2), math.cos(math.pi / 4 - th / 2), mu]
        us = np.concatenate([rng.uniform(0, 1, 12), [1.0, 1 - 1e-12],
                             [e * (1 + d) for e in edges for d in (-1e-6, 1e-6)]])
        for u in us[(us > 0) & (us <= 1)]:
            k = _half_frames._k_half(p, mu, s, psi, float(u), math.sqrt((1 - u) * (1 + u)))
            q = _k_half_by_quad(p, mu, float(u))
            twin = _half_frames.half_integrand_reference(p, mu, np.array([u]))[0]
            assert abs(k - q) <= 1e-13 * max(abs(q), 1.0), (p, mu, u, k, q)  # K is at most 8 pi (measured: 1.3e-15)
            # (the twin's differences of antiderivatives cancel, by ~1 / mu for p = 1: the kernel avoids them)
            assert abs(k - twin) <= 1e-11 * max(abs(twin), 1.0) + 1e-15 * mu**-p, (p, mu, u, k, twin)


def test_ward_kernel_against_the_geometry_and_its_twin(rng):
    """_k_ward (complete elliptic integrals, Carlson's R_F(0, y, 1) and R_D(0, y, 1)) against an independent
    quadrature of 4 (wi.h) sqrt(N.wo) built from wi, h and wo, and its twin (scipy quad of the arc integrals), at
    random u and on both sides of the arc's breaks; and the compiled R_F, R_D (the arithmetic-geometric mean, y from
    the smallest subnormal to 1) against scipy's, and against K(m), E(m) for m = 1 - y."""
    from scipy.special import ellipe, ellipk, elliprd, elliprf

    for mu in (1.0, 0.99, 0.9, 1 / math.sqrt(2), 0.5, 0.2, 0.05, 1e-3, 1e-6):
        s = math.sqrt((1 - mu) * (1 + mu))
        psi, th = math.atan2(mu, s), math.atan2(s, mu)
        edges = [math.cos(math.pi / 4 + th / 2), math.cos(math.pi / 4 - th / 2)]
        us = np.concatenate([rng.uniform(0, 1, 10), [1.0, 1 - 1e-12],
                             [e * (1 + d) for e in edges for d in (-1e-6, 1e-6)]])
        for u in us[(us > 0) & (us <= 1)]:
            k = _half_frames._k_ward(mu, s, psi, float(u), math.sqrt((1 - u) * (1 + u)))
            q = _k_half_by_quad(0.0, mu, float(u), kind="root")
            assert abs(k - q) <= 1e-13 * max(abs(q), 1.0), (mu, u, k, q)  # (measured: 1.7e-14)
            assert abs(k - _half_frames.ward_integrand_reference(mu, u)[0]) <= 1e-11 * max(abs(q), 1.0), (mu, u)
    ys = np.concatenate([rng.uniform(0, 1, 300), 10.0 ** rng.uniform(-300, 0, 300),
                         1 - 10.0 ** rng.uniform(-17, 0, 100), [1.0, 0.5, 1e-300, 5e-324]])
    for y in ys[ys > 0]:
        k, d = _half_frames._complete_kd(float(y))
        assert abs(k - elliprf(0.0, y, 1.0)) <= 2e-15 * elliprf(0.0, y, 1.0), y
        assert abs(d - elliprd(0.0, y, 1.0) / 3) <= 2e-15 * elliprd(0.0, y, 1.0) / 3, y
        if y >= 1e-3:  # (ellipk / ellipe of m = 1 - y: D = (K - E) / m, and K - D = B = (E - (1 - m) K) / m)
            m = 1.0 - y
            assert abs(k - ellipk(m)) <= 2e-15 * k and abs(k - m * d - ellipe(m)) <= 4e-15 * ellipe(m), y


def test_vcavity_kernel_against_the_geometry_and_its_twin(rng):
    """_k_vcavity (Cook-Torrance's G with F = 1, the azimuth of h in closed form) against an independent
    quadrature of 4 (wi.h) G built from wi, h, wo and 001 eq. 10's G itself, and its twin, at random u, at the
    pieces' breaks (u = 1/2, 1/sqrt(2), mu, cos of _vcavity_breaks' angles) and near grazing incidence, where the
    integrand lives on arcs of width ~mu (the plain differences of arccos lost 8 digits there)."""
    for mu in (1.0, 0.99, 0.9, 1 / math.sqrt(2), 0.5, 0.2, 0.05, 1e-3, 1e-6, 1e-8):
        s = math.sqrt((1 - mu) * (1 + mu))
        psi = math.atan2(mu, s)
        brk = [math.cos(x) for x in _outer_rule._vcavity_breaks(mu, s, psi) if x > 0]
        us = np.concatenate([rng.uniform(0, 1, 8), np.geomspace(mu, 1, 6), [0.5, 1 / math.sqrt(2), mu, 1.0],
                             [b * (1 + d) for b in brk for d in (-1e-7, 1e-7)]])
        for u in us[(us > 0) & (us <= 1)]:
            k = _half_frames._k_vcavity(mu, s, psi, float(u), math.sqrt((1 - u) * (1 + u)))
            q = _k_half_by_quad(0.0, mu, float(u), kind="vcavity")
            # relative, with a floor of 1e-14 mu (K <= 16 pi u mu, and the albedo is K / mu)
            assert abs(k - q) <= 1e-12 * abs(q) + 1e-14 * mu, (mu, u, k, q)
            assert abs(k - _half_frames.vcavity_integrand_reference(mu, u)[0]) <= 1e-11 * abs(q) + 1e-14 * mu, (mu, u)


def test_trig_tails_against_mpmath():
    """The four functions that cancel at small arcs (series below 1 rad, closed form above) to 1e-15 relative,
    against 50-digit mpmath quadratures of their definitions; and the numpy twin where it does not cancel."""
    mp = pytest.importorskip("mpmath")
    mp.mp.dps = 50
    defs = [lambda x: mp.quad(lambda t: 1 - mp.cos(t), [0, x]),
            lambda x: mp.quad(lambda t: mp.cos(t) - mp.cos(x), [0, x]),
            lambda x: mp.quad(lambda t: (mp.cos(t) - mp.cos(x)) ** 2, [0, x]),
            lambda x: mp.quad(lambda t: (1 - mp.cos(t)) ** 2, [0, x])]
    for x in (1e-9, 1e-4, 0.01, 0.3, 0.7, 0.999, 1.0, 1.5, 2.5, math.pi):
        twin = _half_frames.half_moments_reference(x)
        for which, f in enumerate(defs):
            ref = float(f(mp.mpf(x)))
            assert abs(_half_frames._trig_tail(x, which) - ref) <= 2e-15 * ref, (x, which)
            if x >= 1.0:
                assert abs(twin[which] - ref) <= 1e-14 * ref, (x, which)


HALF_SPECS = [{"type": "blinn", "n": 16}, {"type": "blinn", "n": 0.5}, {"type": "blinn", "n": 512, "c": 20.6},
              {"type": "blinn", "n": 1e5}, {"type": "stretched_blinn", "n": 8}, {"type": "stretched_blinn", "n": 1},
              {"type": "stretched_blinn", "n": 128, "c": 5.34}, {"type": "phong_blinn", "n": 20},
              {"type": "phong_blinn", "n": 5, "ks": 0.5, "kd": 0.1},
              # the modified Ward model: stretched Blinn's azimuth, the Beckmann weight in t = tan^2(alpha) / m^2
              {"type": "modified_ward", "m": 0.1}, {"type": "modified_ward", "m": 0.02},
              {"type": "modified_ward", "m": 0.4, "c": 1.63}, {"type": "modified_ward", "m": 1e-4},
              {"type": "modified_ward", "m": 5.0}, {"type": "modified_ward", "m": 100.0},
              # Ward: the azimuth by complete elliptic integrals, 1 / sqrt(N.L) in the scale (its albedo diverges)
              {"type": "ward", "m": 0.1}, {"type": "ward", "m": 0.02}, {"type": "ward", "m": 0.2},
              {"type": "ward", "m": 0.4, "c": 0.6}, {"type": "ward", "m": 1e-4}, {"type": "ward", "m": 5.0},
              # the V-cavity G with F = 1: the azimuth in closed form (a minimum of three lines in wi.h)
              {"type": "cook_torrance", "m": 0.3}, {"type": "cook_torrance", "m": 0.02},
              {"type": "cook_torrance", "m": 2.0},
              {"type": "torrance_sparrow", "d": "D1", "s": 20}, {"type": "torrance_sparrow", "d": "D1", "s": 0},
              {"type": "torrance_sparrow", "d": "D1", "s": 200, "b": 3.0},
              {"type": "torrance_sparrow", "d": "D4", "s": 0.1}]


@pytest.mark.parametrize("spec", HALF_SPECS,
                         ids=[f"{s['type']}-{s.get('n', s.get('m', s.get('s')))}" for s in HALF_SPECS])
def test_blinn_family_against_the_nested_and_two_d_engines(spec):
    """The 1-D path (kind "half") against the nested engine at rtol 1e-12 (the engine these models had before,
    reached by switching off the 1-D path alone) and the 2-D engine, from normal to grazing incidence; at
    rtol 1e-6 and 1e-10 the estimate bounds the difference, and at 1e-10 it meets the tolerance."""
    f = pumpup.load(spec)
    assert all(helpers.hint_routes(t) and helpers.view(t).kind == "half"
               for _, t in f.albedo_terms() if t.type != "lambert")
    mu = np.array(MU)
    with helpers.without_1d(), warnings.catch_warnings():
        warnings.simplefilter("ignore")  # (modified Ward m = 1e-4 misses 1e-12 near grazing: its error is still honest)
        b, eb = pumpup.albedo(f, mu, return_error=True, rtol=1e-12)
    for rtol in (1e-6, 1e-10):
        a, e = pumpup.albedo(f, mu, return_error=True, rtol=rtol)
        assert np.all(np.abs(a - b) <= e + eb), (rtol, (np.abs(a - b) / (e + eb)).max())
        assert np.all(e <= rtol * a * 1.0001 + 1e-14)  # (atol 1e-14: modified Ward m = 100's albedo is ~1e-4)
    with helpers.two_d_only():
        c, ec = pumpup.albedo(f, mu[[0, 5, 7, 9]], return_error=True, rtol=1e-10)
    assert np.all(np.abs(a[[0, 5, 7, 9]] - c) <= e[[0, 5, 7, 9]] + ec)


def test_blinn_family_closed_forms():
    """Blinn n = 0 is the constant c (albedo c pi at every mu); stretched Blinn n = 0 is c / max(N.L, N.V):
    its albedo is c (2 pi (1 - mu) + pi mu) = c pi (2 - mu) (the solid angle where N.wo >= mu, plus
    integral N.wo / mu where N.wo < mu)."""
    mu = np.array(MU)
    a, e = pumpup.albedo(pumpup.load({"type": "blinn", "n": 0, "c": 0.3}), mu, return_error=True, rtol=1e-12)
    assert np.all(np.abs(a - 0.3 * math.pi) <= e) and np.all(e <= 1e-12 * a)
    a, e = pumpup.albedo(pumpup.load({"type": "stretched_blinn", "n": 0, "c": 0.7}), mu, return_error=True, rtol=1e-12)
    assert np.all(np.abs(a - 0.7 * math.pi * (2 - mu)) <= e) and np.all(e <= 1e-12 * a)


def test_blinn_family_evaluations_and_refusals():
    mu = np.cos(np.linspace(0, np.pi / 2, 258)[:-1])
    for spec in ({"type": "blinn", "n": 16}, {"type": "stretched_blinn", "n": 8}, {"type": "modified_ward", "m": 0.1},
                 {"type": "ward", "m": 0.1}, {"type": "cook_torrance", "m": 0.3},
                 {"type": "torrance_sparrow", "d": "D1", "s": 20}):
        _, _, conv, evals = _polar.albedo_1d(pumpup.load(spec), mu, 1e-10, 1e-14, 20000)
        assert conv.all() and evals.mean() < 300 and evals.max() < 1000, (spec, evals.mean(), evals.max())
    for family, args, match in [(HalfVectorLobe, {"n": 5.0, "p": 0.5}, "p must be 0 or 1"),
                                (HalfVectorLobe, {"n": 0.1, "p": 1.0, "radial": "gauss"}, "radial"),
                                (HalfVectorLobe, {"n": 0.0, "p": 1.0, "radial": "beckmann"}, "radial"),
                                (WardLobe, {"m": 0.0}, "m must be"),
                                (VCavityLobe, {"n": 0.1, "radial": "gauss"}, "radial"),
                                (PowerLobe, {"n": 5.0, "p": 1.5}, "p must be"), (PowerLobe, {"n": -1.0}, "n must be")]:
        with pytest.raises(ValueError, match=match):
            family(**args)
    # pumped: the nested engine
    assert not helpers.hint_routes(pumpup.pump({"type": "stretched_blinn", "n": 8}, g="g1"))
