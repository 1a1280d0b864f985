"""Frame 6: GGX and Beckmann with F = 1 (either Smith G, exact or Walter's G1) and Schlick's
model about N, the weight's azimuth in closed form (:func:`pumpup.engine.normal_frame._ggx_ring`, :func:`_beckmann_ring`
with :func:`_kummer_fast`), one rule over the elevation of wo (:func:`_integrate_n`).

Its independent references: scipy's quadrature of Walter's D over the azimuth (the closed form), the model's own
``eval`` integrated over the azimuth (the integrand), frame 4 (the rule on h's arc these models took before, reached
with ``without_n_frame``: other variables, other cuts, an inner rule), the nested engine where it is honest, and the
30-digit mpmath values of tests/engine/test_route_half_arc.py, which now go through frame 6."""

import math
import warnings

import helpers
import numpy as np
import pytest

import pumpup
from pumpup.engine import normal_frame as _normal_frame

SPECS = [{"type": "ggx", "alpha": a} for a in (1e-8, 1e-4, 0.02, 0.3, 1.0)] + \
        [{"type": "ggx", "alpha": a, "shadowing": "correlated"} for a in (1e-6, 0.01, 0.5)] + \
        [{"type": "schlick", "r": r} for r in (1e-12, 1e-3, 0.2, 1.0)] + [{"type": "schlick", "r": 0.05, "c": 0.3}] + \
        [{"type": "beckmann", "alpha": a} for a in (1e-8, 0.003, 0.1, 1.0)] + \
        [{"type": "beckmann", "alpha": 0.4, "shadowing": "correlated"},
         {"type": "beckmann", "alpha": 0.05, "g1": "walter"},
         {"type": "beckmann", "alpha": 0.7, "g1": "walter", "shadowing": "correlated"}]
IDS = [f"{s['type']}-{s.get('alpha', s.get('r'))}-{s.get('shadowing', '')}" for s in SPECS]
MU = np.array([1.0, 1.0 - 1e-9, 0.99, 0.9, 0.7, 0.5, 0.2, 0.05, 1e-3, 1e-6, 1e-8])


def _ring_mpmath(a2, mu, d, distribution=1):
    """The integral of Walter's GGX (``distribution`` 1) or Beckmann (0) D over the azimuth of wo at elevation asin(mu)
    + d, at 40 digits (mpmath), graded towards the mirror direction (d, the offset from the peak, is what the closed
    forms take exactly)."""
    import mpmath as mp

    with mp.workdps(40):
        a2, mu = mp.mpf(a2), mp.mpf(mu)
        s, x = mp.sqrt(1 - mu * mu), mp.asin(mu) + mp.mpf(d)

        def dist(phi):
            hx, hy, hz = s + mp.cos(x) * mp.cos(phi), mp.cos(x) * mp.sin(phi), mu + mp.sin(x)
            if distribution == 1:
                hh = hx * hx + hy * hy + hz * hz
                return a2 / (mp.pi * (a2 * hz * hz / hh + (hx * hx + hy * hy) / hh) ** 2)  # Walter eq. 33
            t2 = (hx * hx + hy * hy) / (hz * hz)
            return mp.exp(-t2 / a2) * (1 + t2) ** 2 / (mp.pi * a2)  # Walter eq. 25

        w = [mp.sqrt(a2) * mp.mpf(3) ** k for k in range(-6, 14)]
        return float(2 * mp.quad(dist, [mp.mpf(0)] + sorted(mp.pi - v for v in w if v < mp.pi) + [mp.pi]))


@pytest.mark.parametrize("a2", [1e-6, 1e-4, 0.01, 0.25, 0.81, 1.0])
def test_ring_closed_form_against_mpmath(a2):
    """The integral of Walter's D over the azimuth of wo in closed form against a 40-digit mpmath quadrature of D
    itself, at the peak (x = x_mu), beside it, far from it, near the horizon and near the normal.  (scipy's quadrature
    of D in double precision, ``ring_reference``, is 7e-11 off at a2 = 1e-6, mu = 1e-3.)"""
    pytest.importorskip("mpmath")
    for mu in (1.0, 0.95, 0.6, 1e-3):
        s = math.sqrt((1.0 - mu) * (1.0 + mu))
        xmu, xs = math.atan2(mu, s), math.atan2(s, mu)
        for x in (xmu, xmu - 0.5 * math.sqrt(a2), xmu + 2.0 * math.sqrt(a2), 0.3, 1e-3, 0.5 * math.pi - 1e-3):
            if not 0.0 <= x <= 0.5 * math.pi:
                continue
            assert _normal_frame._ggx_ring(a2, xmu, xs, x - xmu) == pytest.approx(_ring_mpmath(a2, mu, x - xmu),
                                                                                   rel=1e-14), (mu, x)
        if a2 >= 0.01:
            assert _normal_frame._ggx_ring(a2, xmu, xs, 0.3 - xmu) == pytest.approx(
                _normal_frame.ring_reference(1, a2, mu, 0.3), rel=1e-12)


@pytest.mark.parametrize("a2", [1e-6, 1e-4, 0.01, 0.25, 1.0])
def test_beckmann_ring_against_mpmath(a2):
    """The Beckmann weight's integral over the azimuth (Kummer functions) against 40-digit mpmath, to 1e-13 of its value
    or 1e-14 of its peak (far in the Gaussian's tail exp(-tau^2 / a2) turns tau's last bit into 1e-8 of a value 1e-100
    small); and scipy's double-precision quadrature where the lobe is wide."""
    pytest.importorskip("mpmath")
    for mu in (1.0, 0.95, 0.6, 0.1, 1e-3):
        s = math.sqrt((1.0 - mu) * (1.0 + mu))
        xmu, xs = math.atan2(mu, s), math.atan2(s, mu)
        peak = _normal_frame._beckmann_ring(a2, xmu, xs, 0.0)
        for x in (xmu, xmu + 0.5 * math.sqrt(a2), xmu - 2.0 * math.sqrt(a2), 0.3, 1e-3, 0.5 * math.pi - 1e-3):
            if not 0.0 <= x <= 0.5 * math.pi:
                continue
            ref = _ring_mpmath(a2, mu, x - xmu, distribution=0)
            assert abs(_normal_frame._beckmann_ring(a2, xmu, xs, x - xmu) - ref) <= 1e-13 * ref + 1e-14 * peak, (mu, x)
        if a2 >= 0.01:
            got = _normal_frame._beckmann_ring(a2, xmu, xs, 0.3 - xmu)
            assert got == pytest.approx(_normal_frame.ring_reference(0, a2, mu, 0.3), rel=1e-12)


def test_kummer_functions_against_mpmath():
    """H_j = z^j e^-z 1F1(1/2; j + 1; z): the series and asymptotic sums (_kummer_half) within 10 ulps of 30-digit
    mpmath, the Chebyshev pieces (_kummer_fast) within 32 ulps of the largest value on their piece, from 0 to 1e6 and at
    inf."""
    mp = pytest.importorskip("mpmath")
    edges = _normal_frame.KUMMER_EDGES
    zs = np.concatenate([np.linspace(0.0, 210.0, 421), [1e-12, 49.99999, 50.0, 199.9999, 1e3, 1e6], edges])
    with mp.workdps(30):
        def ref(z):
            return [float(mp.mpf(z) ** j * mp.exp(-mp.mpf(z)) * mp.hyp1f1(0.5, j + 1, mp.mpf(z))) for j in range(3)]

        for z in zs:
            r, slow, fast = ref(z), _normal_frame._kummer_half(float(z)), _normal_frame._kummer_fast(float(z))
            i = min(np.searchsorted(edges, z, side="right") - 1, len(edges) - 2)
            scale = np.maximum(np.abs(ref(edges[i])), np.abs(ref(edges[i + 1]))) if z < edges[-1] else np.abs(r)
            for j in range(3):
                assert abs(slow[j] - r[j]) <= 10 * 2.2e-16 * abs(r[j]) + 1e-300, (z, j)
                assert abs(fast[j] - r[j]) <= 32 * 2.2e-16 * scale[j] + 1e-300, (z, j)
    assert _normal_frame._kummer_fast(math.inf) == (0.0, 0.0, 0.0)


WIDE = [2, 3, 6, 7, 10, 11, 12, 15, 16, 17, 18, 19]


@pytest.mark.parametrize("spec", [SPECS[i] for i in WIDE], ids=[IDS[i] for i in WIDE])
def test_integrand_against_the_models_own_eval(spec):
    """The compiled integrand against the model's public ``eval`` times N.wo integrated over the azimuth by scipy (none
    of the closed form's algebra), divided by the hint's scale; lobes at least 0.01 wide (for narrower ones ``eval``'s
    own rounding near the peak, ~ulp / alpha, and scipy's reach 1e-9: the closed form is checked against mpmath
    above)."""
    f = pumpup.load(spec)
    for mu in (1.0, 0.8, 0.3, 1e-3):
        xmu = math.asin(mu)
        a = spec.get("alpha", math.sqrt(spec.get("r", 0.0)))
        xs = np.array([xmu, xmu + 0.7 * a, xmu - 1.5 * a, 0.05, 0.7, 1.5])
        xs = xs[(xs > 0.0) & (xs < 0.5 * math.pi)]
        got = _normal_frame.n_integrand(f, mu, xs)
        ref = _normal_frame.n_integrand_reference(f, mu, xs)
        assert np.all(np.abs(got - ref) <= 1e-10 * np.abs(ref)), (mu, xs, got / ref - 1)


_FRAME_4 = {}


def _frame_4(f, mu):
    """Frame 4 at rtol 1e-13 (once per model: both rtols compare with it), mu at least 1e-100."""
    key = repr(f)
    if key not in _FRAME_4:
        with helpers.without_normal_frames(), warnings.catch_warnings():
            warnings.simplefilter("ignore")  # (Beckmann alpha = 1e-8 stops short of 1e-13 there; its estimate says so)
            assert not helpers.takes_normal(f.azimuth_hint())
            _FRAME_4[key] = pumpup.albedo(f, np.maximum(mu, 1e-100), return_error=True, rtol=1e-13)
    return _FRAME_4[key]


@pytest.mark.parametrize("spec", SPECS, ids=IDS)
@pytest.mark.parametrize("rtol", [1e-8, 1e-12])
def test_against_frame_4_and_the_nested_engine(spec, rtol):
    """Frame 6 against frame 4 at rtol 1e-13 within the summed estimates, from mu = 1 to 1e-300 (frame 4 at 1e-100
    there: it stops at HALF_MU_MIN, and the albedo is flat to ~mu near grazing incidence); the estimate within rtol; and
    where the nested engine is honest (alpha >= 0.01, mu >= 0.2; the nested engine misses narrow lobes) against it
    too."""
    f = pumpup.load(spec)
    assert helpers.takes_normal(f.azimuth_hint())
    mu = np.concatenate([MU, [1e-100, 1e-300]])
    a, e = pumpup.albedo(f, mu, return_error=True, rtol=rtol)
    b, eb = _frame_4(f, mu)
    assert np.all(np.abs(a - b) <= e + eb), (np.abs(a - b) / (e + eb)).max()
    assert np.all(e <= rtol * a)
    alpha = spec.get("alpha", math.sqrt(spec.get("r", 0.0)))
    if alpha >= 0.01:
        near = mu >= 0.2
        with helpers.without_1d(), warnings.catch_warnings():
            warnings.simplefilter("ignore")
            c, ec = pumpup.albedo(f, mu[near], return_error=True, rtol=1e-12)
        assert np.all(np.abs(a[near] - c) <= e[near] + ec), (np.abs(a[near] - c) / (e[near] + ec)).max()


def test_which_models_take_frame_6():
    """GGX and Beckmann with F = 1 and alpha <= 1, and Schlick's model (and GGX with a Fresnel factor:
    tests/engine/test_route_normal_fresnel.py); not Beckmann with a Fresnel factor (frame 4) or
    alpha > 1 (the nested engine), not the V-cavity models."""
    takes = [{"type": "ggx", "alpha": 0.2}, {"type": "ggx", "alpha": 1.0, "shadowing": "correlated"},
             {"type": "schlick", "r": 0.3}]
    takes += [{"type": "beckmann", "alpha": 0.2}, {"type": "beckmann", "alpha": 1.0, "g1": "walter"}]
    not_takes = [{"type": "beckmann", "alpha": 0.2, "ior": 1.5}, {"type": "torrance_sparrow", "d": "D3", "s": 0.3},
                 {"type": "cook_torrance", "m": 0.3}]
    for spec in takes:
        assert helpers.takes_normal(pumpup.load(spec).azimuth_hint()), spec
    for spec in not_takes:
        assert not helpers.takes_normal(pumpup.load(spec).azimuth_hint()), spec
    assert not helpers.hint_routes(pumpup.load({"type": "ggx", "alpha": 1.5}))
    assert not helpers.hint_routes(pumpup.load({"type": "beckmann", "alpha": 1.5}))


@pytest.mark.parametrize("spec", [SPECS[0], SPECS[5], SPECS[8], SPECS[10]], ids=[IDS[0], IDS[5], IDS[8], IDS[10]])
def test_cuts_keep_every_piece_off_the_singularities(spec):
    """The breakpoints are sorted in [0, pi / 2] with 0, pi / 2 and x_mu among them, and every piece lies at least a
    third of its length from the peak's singularities x_mu +- 2 i atanh(alpha), from B = 0's at pi - x_mu +- 2 i
    atanh(alpha) and from P(t)'s (or Schlick's pole) near 0: in x, or for a piece off the peak (GGX and Schlick,
    :data:`pumpup.engine.normal_frame.N_LOG_GRADE`) in u = ln |x - x_mu|, or near x = 0 in u = ln x, the variable the
    engine integrates it in."""
    import cmath

    f = pumpup.load(spec)
    hint = helpers.view(f)
    alpha = math.sqrt(hint.schlick) if hint.schlick is not None else hint.smith[3]
    near0 = hint.schlick / (1.0 - hint.schlick) if hint.schlick is not None else math.atanh(alpha)
    for mu in (1.0, 0.9, 0.5, 0.01, 1e-9):
        x = _normal_frame.n_cuts_reference(f, mu)
        xmu = math.atan2(mu, math.sqrt((1.0 - mu) * (1.0 + mu)))
        assert np.all(np.diff(x) >= 0) and x[0] == 0.0 and x[-1] == 0.5 * math.pi
        assert np.any(np.abs(x - xmu) <= 1e-15)
        # the singularities in d = x - x_mu: the peak's, P(t)'s (or Schlick's pole), B = 0's
        sing = [complex(0.0, 2.0 * math.atanh(alpha)),
                complex(-xmu, near0) if hint.schlick is None else complex(-near0 - xmu, 0.0),
                complex(math.pi - 2.0 * xmu, 2.0 * math.atanh(alpha))]
        for lo, hi, kind in _normal_frame.n_pieces_reference(f, mu):
            if kind:  # u = ln |d| beyond the peak (1) or short of it (2); u = ln x = ln(x_mu + d) near x = 0 (3)
                side, shift = (1.0, 0.0) if kind == 1 else ((-1.0, 0.0) if kind == 2 else (1.0, xmu))
                a, b = sorted((math.log(side * (lo + shift)), math.log(side * (hi + shift))))
                dist = [abs(cmath.log(side * (z + shift)) - min(max(cmath.log(side * (z + shift)).real, a), b))
                        for z in sing]
                assert min(dist) >= (b - a) / 3.0, (mu, lo, hi, kind, dist)
            else:
                dist = [abs(z - complex(min(max(z.real, lo), hi), 0.0)) for z in sing]
                assert min(dist) >= (hi - lo) / 3.0, (mu, lo, hi, dist)


def test_frame_4_at_a_grazing_narrow_lobe_with_a_fresnel_factor():
    """Frame 4 (GGX with an ior keeps it) at mu = 1e-100, alpha = 1e-8: u^4 underflowed there and the weight divided by
    0 (ZeroDivisionError out of pumpup.albedo); and its pieces overflowed their arrays at rtol
    1e-13 (tests/engine/test_polar_boundscheck.py runs that under bounds checking).  The albedo is flat to ~mu near
    grazing incidence."""
    f = pumpup.load({"type": "ggx", "alpha": 1e-8, "ior": 1.5})
    for rtol in (1e-8, 1e-13):
        a, e = pumpup.albedo(f, np.array([1e-100, 1e-50]), return_error=True, rtol=rtol)
        assert np.all(np.isfinite(a)) and abs(a[0] - a[1]) <= e[0] + e[1]
    with helpers.without_normal_frames():
        g = pumpup.load({"type": "ggx", "alpha": 1e-8})
        a, e = pumpup.albedo(g, np.array([1e-100, 1e-50]), return_error=True, rtol=1e-13)
    assert np.all(np.isfinite(a)) and abs(a[0] - a[1]) <= e[0] + e[1]
