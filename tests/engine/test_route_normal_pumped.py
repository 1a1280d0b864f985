"""Pumped GGX, Beckmann (F = 1) and Schlick models on the 1-D path (pumpup/engine/polar.py, frame 6 about N divided by
g, ``_integrate_n`` with ``Polar.chain``): g_1 ... g_k depends on N.wi and N.wo only, so on each ring N.wo = t it is a
constant and the closed-form azimuth of frame 6 still holds; the elevation's rule divides by it.

Checked against the model's own ``eval`` integrated over the azimuth by scipy, against the nested engine at rtol 1e-13
(the 1-D path switched off alone) with the estimate bounding the difference at every rtol, against the 2-D engine,
and the near-kinks that the levels' tables carry (``Pumped.table_kinks``)."""


import helpers
import numpy as np
import pytest
from helpers import n_frame_integrand_against_eval, nested_reference, one_d_against_the_other_engines

import pumpup
from pumpup.engine import polar as _polar

MU = np.array([1.0, 0.999, 0.99, 0.9, 0.7, 0.5, 0.3, 0.1, 0.01, 1e-4, 1e-8])

CASES = [({"type": "ggx", "alpha": 0.5}, "g1", 1), ({"type": "beckmann", "alpha": 0.3}, "g2", 2),
         ({"type": "schlick", "r": 0.2}, "g1", 2), ({"type": "ggx", "alpha": 0.1, "shadowing": "correlated"}, "g2", 2),
         ({"type": "ggx", "alpha": 0.02}, "g2", 1), ({"type": "beckmann", "alpha": 0.05, "g1": "walter"}, "g1", 1)]


def _id(case):
    spec, g, levels = case
    return "-".join(str(v) for v in spec.values()) + f"-{g}-{levels}"


def test_pumped_microfacet_models_take_frame_6():
    for spec, g, levels in CASES:
        f = pumpup.pump(spec, g=g, levels=levels)
        hint = helpers.view(f)
        assert hint.chain is not None and helpers.takes_normal(f), spec
        with helpers.without_normal_frames():  # off frame 6 a pumped half-vector model goes to the nested engine
            assert _polar.albedo_1d(f, np.array([0.5]), 1e-8, 0.0, 1000) is None
    # alpha > 1: the nested engine; with Fresnel: frame 6 at mu >= N_FRESNEL_MU_MIN only
    # (tests/engine/test_route_normal_pumped_fresnel.py)
    assert not helpers.hint_routes(pumpup.pump({"type": "ggx", "alpha": 1.5}, g="g1"))
    f = pumpup.pump({"type": "ggx", "alpha": 0.3, "ior": 1.5}, g="g1")
    assert helpers.view(f).chain is not None and not helpers.takes_1d(f)
    assert helpers.one_d_mask(f, np.array([0.1, 0.5])).tolist() == [False, True]


@pytest.mark.parametrize("case", CASES[:3], ids=_id)
def test_integrand_against_the_models_own_eval(case):
    """The compiled integrand (frame 6's weight divided by the chain's g, as the rule computes it) against the pumped
    model's public ``eval`` times N.wo integrated over the azimuth by scipy, on both sides of mu and of a level."""
    f = pumpup.pump(*case[:1], g=case[1], levels=case[2])
    assert n_frame_integrand_against_eval(f, f.chain()[0].base) > 1.0  # divided by g < 1: pumped up


@pytest.mark.parametrize("case", CASES[:4], ids=_id)
def test_estimate_bounds_the_truth_and_engines_agree(case):
    """Frame 6 divided by g at rtol 1e-6 ... 1e-12 against the nested engine at 1e-13: the difference within the summed
    estimates, and the estimate within the tolerance asked."""
    f = pumpup.pump(case[0], g=case[1], levels=case[2])
    one_d_against_the_other_engines(f, MU, rtols=(1e-6, 1e-8, 1e-10, 1e-12), two_d_at=(), ref_rtol=1e-13)


def test_near_kinks_of_the_levels_tables():
    """A 2-level g2 pumped GGX (alpha 0.1, height-correlated): level 2's table has a kink at v = 0.98814, where level
    1's bound crosses the diagonal (u(v) = v); before ``table_kinks`` the 1-D path was 5e-7 off at mu = 0.993068 with an
    estimate of 1.6e-7.  Beckmann alpha 0.3, g2 x 2: with the kink cut but not the knots bunched around it, 2.1e-12 off
    at mu = 0.99888 with an estimate 4.8 x smaller.  The table is split at the kink
    (AlbedoTable's breaks) and its grid does not bunch towards it; the cuts hold the kink; the estimates bound the
    truth."""
    f = pumpup.pump({"type": "ggx", "alpha": 0.1, "shadowing": "correlated"}, g="g2", levels=2)
    kinks = np.array(f.table_kinks())
    diag = [v for v in f.chain()[0]._kink_fixed()[2] if 0 < v < 1]
    assert diag and abs(diag[0] - 0.98814) < 1e-4
    assert np.min(np.abs(kinks - diag[0])) == 0.0
    assert diag[0] in f.chain()[1].table().breaks  # level 2's table is split at the kink
    knots = np.exp(f.chain()[1].lookup().logx)
    near = knots[np.abs(np.log(knots / diag[0])) < 0.01]
    assert 1 <= len(near) <= 6, near  # its grid does not bunch there (at least 10 knots on each side before the split)
    # the 1-D path's cuts (the nested engine: the lobe's alone)
    assert set(kinks.tolist()) <= set(helpers.view(f).levels(0.5))
    mu = np.array([0.993068])
    ref, ref_err = nested_reference(f, mu, 1e-13)
    for rtol in (1e-6, 1e-8, 1e-10):
        a, e = pumpup.albedo(f, mu, return_error=True, rtol=rtol)
        assert np.all(np.abs(a - ref) <= e + ref_err), (rtol, a - ref, e, ref_err)
    g = pumpup.pump({"type": "beckmann", "alpha": 0.3}, g="g2", levels=2)
    mu = np.array([0.9988849199740253])
    ref, ref_err = nested_reference(g, mu, 1e-13)
    for rtol in (1e-10, 1e-12):
        a, e = pumpup.albedo(g, mu, return_error=True, rtol=rtol)
        assert np.all(np.abs(a - ref) <= e + ref_err), (rtol, a - ref, e, ref_err)


def test_against_the_2d_engine():
    f = pumpup.pump({"type": "ggx", "alpha": 0.3}, g="g2", levels=2)
    mu = np.array([0.6])  # (the 2-D engine: 6 s per mu here)
    a, e = pumpup.albedo(f, mu, return_error=True, rtol=1e-8)
    with helpers.two_d_only():
        b, eb = pumpup.albedo(f, mu, return_error=True, rtol=1e-8)
    assert np.all(np.abs(a - b) <= e + eb), (a - b, e, eb)


@pytest.mark.slow
@pytest.mark.parametrize("case", CASES[4:], ids=_id)
def test_estimate_bounds_the_truth_narrow_lobes(case):
    """As above for the narrow lobes (alpha 0.02 and 0.05), over the figures' angles too."""
    f = pumpup.pump(case[0], g=case[1], levels=case[2])
    mu = np.unique(np.concatenate([MU, np.cos(np.radians(np.linspace(0, 89.9, 60)))]))
    one_d_against_the_other_engines(f, mu, rtols=(1e-6, 1e-8, 1e-10, 1e-12), two_d_at=(), ref_rtol=1e-13)
