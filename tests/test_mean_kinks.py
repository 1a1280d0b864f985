"""mean_albedo of a pumped level, whose albedo has kinks (pumping.albedo_kinks; issue 14's twentieth session): its first
intervals end at them.  Without that, a 2-level g1 pumped stretched Phong (n = 0.127, p = 1) had a mean 1.05e-9 off with
an estimate of 1.0e-10 (found by scripts/fuzz_engines.py --mean).  Reference: scipy's quad of 2 mu a(mu), split at the
kinks, with each a(mu) at rtol 1e-13."""

import warnings

import pytest
from scipy.integrate import quad

import pumpup
from pumpup import pumping

SPEC = {"type": "pumped", "base": {"type": "stretched_phong", "n": 0.12655111259560692, "p": 1.0}, "g": "g1", "levels": 2}


@pytest.fixture(scope="module")
def reference():
    f = pumpup.load(SPEC)
    kinks = pumping.albedo_kinks(f, inside_grid=False)
    assert len(kinks) == 4 and all(0.3 < v < 0.75 for v in kinks)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        ref, err = quad(lambda x: 2 * x * float(pumpup.albedo(f, x, rtol=1e-13)), 0.0, 1.0,
                        points=[1e-6, 1e-4, 1e-2, 0.1, *kinks], epsabs=1e-15, epsrel=1e-13, limit=1000)
    return ref, err + 1e-13  # (each value's error, 1e-13 at most, integrated over [0, 1] with weight 2 mu)


@pytest.mark.parametrize("tabulated", [False, True])
@pytest.mark.parametrize("rtol", [pytest.param(1e-6, marks=pytest.mark.slow), 1e-9,
                                  pytest.param(1e-10, marks=pytest.mark.slow)])
def test_mean_of_a_pumped_level_bounds_its_error(reference, rtol, tabulated):
    ref, eref = reference
    f = pumpup.load(SPEC)
    if tabulated:  # the mean from the table just made (pumpup._reuse), where it takes it
        pumpup.tabulate(f, progress=False)
    m, e = pumpup.mean_albedo(f, rtol=rtol, return_error=True)
    assert abs(m - ref) <= e + eref, (m - ref, e)
