"""Divergence analysis at grazing incidence (001 sec. 2.1): the fit, the verdicts, the concrete
lower bounds of 001 eq. 14-15, and the engine at mu = 1e-8 against the independent method."""

import numpy as np
import pytest

import pumpup
from pumpup.divergence import cook_torrance_bound, fit_power_law, grid, ward_bound


def test_fit_recovers_a_known_power_law():
    mu = grid()
    a = 0.3 * mu**-0.37 * (1 + 1e-9 * np.sin(np.arange(len(mu))))
    k, k_err, K = fit_power_law(mu, a, 1e-12 * a)
    assert abs(k - 0.37) < 1e-6 and abs(K - 0.3) < 1e-5 and k_err < 1e-6
    with pytest.raises(ValueError, match="at least 4"):
        fit_power_law(mu, a, a, window=(1e-8, 2e-8))


def test_ward_diverges_like_mu_to_the_minus_half():
    r = pumpup.divergence({"type": "ward", "m": 0.1})
    assert r.verdict == "diverging"
    assert abs(r.k - 0.5) < 1e-3 and r.k_error < 1e-3
    # 000 sec. 6.2: the independent reference gives a sqrt(mu) = 0.010960 near 89.999 deg
    assert r.K == pytest.approx(0.010960, rel=1e-3)


@pytest.mark.parametrize("spec", [{"type": "modified_ward", "m": 0.1}, {"type": "stretched_phong", "n": 20},
                                  {"type": "stretched_blinn", "n": 20}, {"type": "schlick", "r": 0.1},
                                  {"type": "cook_torrance", "m": 0.1}])
def test_bounded_models(spec):
    r = pumpup.divergence(spec)
    assert r.verdict == "bounded", str(r)
    assert abs(r.k) < 1e-3


def test_engine_at_the_smallest_mu_against_the_independent_method():
    from reference import independent_reference as ref  # never imports pumpup

    for name, code in [("ward", ref.WARD), ("cook_torrance", ref.CT)]:
        value, err = ref.albedo_A(code, 0.1, 1e-8)
        a, e = pumpup.albedo(pumpup.load({"type": name, "m": 0.1}), 1e-8, return_error=True)
        assert abs(float(a) - value) <= float(e) + err + 1e-12 * value
        assert abs(float(a) - value) <= 1e-8 * value


def test_ward_bound_is_a_lower_bound_and_diverges():
    f = pumpup.load({"type": "ward", "m": 0.1})
    d0 = ward_bound(0.1, 1e-6)[1]
    bounds = []
    for mu in [1e-2, 1e-4, 1e-6, 1e-8]:
        b, _ = ward_bound(0.1, mu, d0)
        assert b <= float(pumpup.albedo(f, mu))
        bounds.append(b)
    # 001 eq. 14: kappa / sqrt(N.L) times an integral that tends to a constant
    assert bounds[-1] / bounds[-2] == pytest.approx(10.0, rel=1e-3)


def test_cook_torrance_bound_vanishes_because_its_region_shrinks():
    # 001 eq. 15 needs G = 1 on a region that does not shrink with N.L; the region where the
    # masking term 2 (N.H)(N.L)/(V.H) >= 1 shrinks like (N.L)^2, so the best bound of that
    # form goes to zero instead of diverging, and the computed albedo stays bounded.
    areas, bounds = [], []
    for mu in [1e-4, 1e-6, 1e-8]:
        b, d0, area = cook_torrance_bound(0.1, mu)
        assert b <= float(pumpup.albedo(pumpup.load({"type": "cook_torrance", "m": 0.1}), mu))
        areas.append(area)
        bounds.append(b)
    assert areas[1] / areas[0] == pytest.approx(1e-4, rel=0.05)
    assert bounds[2] < bounds[1] < bounds[0]
