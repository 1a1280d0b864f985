"""1/E-scaled GGX, Beckmann (F = 1) and Schlick models on the 1-D path (pumpup/engine/polar.py, frame 6 about N times
Turquin's factor 1 + F0 (1 / U(N.wo) - 1), ``Polar.factor``): the factor depends on N.wo alone, so on each ring it is a
constant and frame 6's closed-form azimuth still holds; the elevation's rule multiplies by it.

Checked against the model's own ``eval`` integrated over the azimuth by scipy, against the nested engine at rtol 1e-13
(the 1-D path switched off alone) with the estimate bounding the difference at every rtol, against the 2-D engine,
and the white furnace toward the viewer."""


import helpers
import numpy as np
import pytest
from helpers import n_frame_integrand_against_eval, one_d_against_the_other_engines

import pumpup
from pumpup.engine import chain_frame as _chain_frame
from pumpup.engine import polar as _polar

MU = np.array([1.0, 0.999, 0.99, 0.9, 0.7, 0.5, 0.3, 0.1, 0.01, 1e-4, 1e-8])

CASES = [({"type": "ggx", "alpha": 0.3}, 1.0), ({"type": "beckmann", "alpha": 0.1}, 0.5),
         ({"type": "schlick", "r": 0.2}, 1.0), ({"type": "ggx", "alpha": 0.02, "shadowing": "correlated"}, 1.0)]


def _scaled(spec, f0):
    return pumpup.load({"type": "scaled", "base": spec, "f0": f0})


def _id(case):
    return "-".join(str(v) for v in case[0].values()) + f"-f0-{case[1]}"


def test_scaled_microfacet_models_take_frame_6():
    for spec, f0 in CASES:
        hint = helpers.view(_scaled(spec, f0))
        assert hint.factor is not None and hint.factor[0] == f0 and helpers.takes_normal(_scaled(spec, f0))
        with helpers.without_normal_frames():
            assert _polar.albedo_1d(_scaled(spec, f0), np.array([0.5]), 1e-8, 0.0, 1000) is None
    # a Fresnel factor (frame 4), a Phong lobe, a white of another kind: the nested engine, as before
    assert not helpers.hint_routes(pumpup.compensate({"type": "ggx", "alpha": 0.3, "ior": 1.5}, method="scale"))
    assert not helpers.hint_routes(_scaled({"type": "phong", "n": 5}, 1.0))
    # (its terms have theirs)
    assert not helpers.hint_routes(pumpup.compensate({"type": "ggx", "alpha": 0.3}, method="kulla_conty"))
    assert not helpers.hint_routes(pumpup.load({"type": "scaled", "base": {"type": "ggx", "alpha": 0.3},
                        "white": {"type": "phong", "n": 5}}))


@pytest.mark.parametrize("case", CASES[:3], ids=_id)
def test_integrand_against_the_models_own_eval(case):
    """The compiled integrand (frame 6's weight times the factor, as the rule computes it) against the scaled model's
    public ``eval`` times N.wo integrated over the azimuth by scipy; and not below the base's (U <= 1: brighter)."""
    # (U rounds to 1 where E is ~1)
    assert n_frame_integrand_against_eval(_scaled(*case), pumpup.load(case[0])) >= 1 - 1e-12


@pytest.mark.parametrize("case", CASES, ids=_id)
def test_estimate_bounds_the_truth_and_engines_agree(case):
    """Frame 6 times the factor at rtol 1e-6 ... 1e-12 against the nested engine at 1e-13: the difference within the
    summed estimates, and the estimate within the tolerance asked."""
    one_d_against_the_other_engines(_scaled(*case), MU, rtols=(1e-6, 1e-8, 1e-10, 1e-12), two_d_at=(), ref_rtol=1e-13)


def test_cuts_graded_towards_grazing(monkeypatch):
    """U(N.wo) is a spline in log N.wo, not analytic at 0: the cuts are graded in N.wo down to where U's look-up turns
    from the spline to the product table (1e-8).  Graded only down to a quarter of mu, as a pumped model's g needs,
    Schlick r = 0.2 at mu = 0.985 was 4.2e-12 off at rtol 1e-8 with an estimate of 1.2e-12 (the piece N.wo < 0.172:
    1.0e-11 off, estimate 2.7e-12)."""
    f = _scaled({"type": "schlick", "r": 0.2}, 1.0)
    mu = 0.9850430162253638
    x = _chain_frame.chain_cuts(helpers.view(f).levels(mu), 0.0, mu)
    assert np.sum(np.sin(x[x > 0]) < 0.125) >= 12  # N.wo = 1/8, 1/32, ... down to 2.5e-9
    with monkeypatch.context(), helpers.without_1d():
        ref, ref_err = pumpup.albedo(f, [mu], return_error=True, rtol=1e-13)
    for rtol in (1e-6, 1e-8):
        a, e = pumpup.albedo(f, [mu], return_error=True, rtol=rtol)
        assert np.all(np.abs(a - ref) <= e + ref_err), (rtol, a - ref, e, ref_err)


def test_against_the_2d_engine():
    f = _scaled({"type": "ggx", "alpha": 0.3}, 0.7)
    mu = np.array([0.6])
    a, e = pumpup.albedo(f, mu, return_error=True, rtol=1e-8)
    with helpers.two_d_only():
        b, eb = pumpup.albedo(f, mu, return_error=True, rtol=1e-8)
    assert np.all(np.abs(a - b) <= e + eb), (a - b, e, eb)


def test_furnace_toward_the_viewer_is_at_most_one():
    """With F0 = 1 the scaled model's albedo toward wo (``pumpup.furnace``) is E / U <= 1 within its error, and its
    albedo toward the light (this path) exceeds the base's: the 1/E factor brightens every ring."""
    f = _scaled({"type": "ggx", "alpha": 0.5}, 1.0)
    a, e = pumpup.furnace(f, MU, return_error=True, rtol=1e-9)
    assert np.all(a <= 1.0 + e)
    assert np.all(pumpup.albedo(f, MU, rtol=1e-9)
                  > pumpup.albedo(pumpup.load({"type": "ggx", "alpha": 0.5}), MU, rtol=1e-9))
