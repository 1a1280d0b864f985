"""mean_albedo of pumped levels (cases found by scripts/studies/fuzz_engines.py --mean):

* a pumped level's albedo has kinks (Pumped.albedo_kinks): the first intervals end at them.  Without that, a 2-level g1
  pumped stretched Phong (n = 0.127, p = 1) had a mean 1.05e-9 off with an estimate of 1.0e-10;
* the albedo turns near grazing incidence on the roughness's scale: two more first intervals towards mu = 0 (tau = 1/16,
  1/32).  Without them a 1-level g2 pumped GGX alpha 0.0194 had a mean 1.05e-9 off with an estimate of 4.0e-10.

Reference: scipy's quad of 2 mu a(mu), split at the kinks and at small mu, with each a(mu) at rtol 1e-13 (it agrees with
mean_albedo at rtol 1e-12 to 4e-13 on both)."""

import functools
import warnings

import pytest
from scipy.integrate import quad

import pumpup

SPECS = {
    "stretched_phong": {"type": "pumped", "base": {"type": "stretched_phong", "n": 0.12655111259560692, "p": 1.0},
                        "g": "g1", "levels": 2},
    "ggx": {"type": "pumped", "base": {"type": "ggx", "alpha": 0.01938936609714776}, "g": "g2", "levels": 1},
}


@functools.cache
def _reference(name):
    f = pumpup.load(SPECS[name])
    kinks = f.albedo_kinks()
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        ref, err = quad(lambda x: 2 * x * float(pumpup.albedo(f, x, rtol=1e-13)), 0.0, 1.0,
                        points=[1e-6, 1e-4, 1e-3, 1e-2, 0.03, 0.1, *kinks], epsabs=1e-15, epsrel=1e-13, limit=1000)
    return ref, err + 1e-13  # (each value's error, 1e-13 at most, integrated over [0, 1] with weight 2 mu)


def test_the_stretched_phong_level_has_four_kinks():
    kinks = pumpup.load(SPECS["stretched_phong"]).albedo_kinks()
    assert len(kinks) == 4 and all(0.3 < v < 0.75 for v in kinks)


@pytest.mark.parametrize("name", list(SPECS))
@pytest.mark.parametrize("tabulated", [False, True])
@pytest.mark.parametrize("rtol", [pytest.param(1e-6, marks=pytest.mark.slow), 1e-9,
                                  pytest.param(1e-10, marks=pytest.mark.slow)])
def test_mean_of_a_pumped_level_bounds_its_error(name, rtol, tabulated):
    ref, eref = _reference(name)
    f = pumpup.load(SPECS[name])
    if tabulated:  # the mean from the table just made (pumpup.tables.reuse), where it takes it
        pumpup.tabulate(f, progress=False)
    m, e = pumpup.mean_albedo(f, rtol=rtol, return_error=True)
    assert abs(m - ref) <= e + eref, (m - ref, e)
