"""Pumping a BRDF with a delta lobe (he_torrance's specular part): the delta is divided by g too."""

import math

import numpy as np
import pytest

import pumpup


@pytest.fixture(scope="module")
def pumped():
    base = pumpup.load({"type": "he_torrance", "sigma_0": 0.1, "tau": 1.7, "n": 1.5})
    return base, pumpup.pump(base, g="g1")


def test_delta_is_divided_by_g_at_the_mirror_pair(pumped):
    base, p = pumped
    mu = np.array([1.0, 0.5, 0.2, 0.01])
    np.testing.assert_array_equal(p.delta_albedo(mu), base.delta_albedo(mu) / p.g(mu, mu))
    assert p.eval_rtol == base.eval_rtol
    assert getattr(pumpup.pump(pumpup.load("phong:n=20")), "delta_albedo") is None  # no delta, none added


def test_pumped_albedo_counts_the_delta(pumped):
    """The engine's pumped albedo = the generic path's integral of the pumped eval (no hint, other
    coordinates) + w(mu) / g(mu, mu); before, the delta's share (0.85 of 0.997 at mu = 0.2) was lost."""
    base, p = pumped
    mu = np.array([0.2])
    a, e = pumpup.albedo(p, mu, return_error=True)
    gen = pumpup.from_function(p.eval, name="pumped he_torrance")
    ag, eg = pumpup.albedo(gen, mu, return_error=True, rtol=1e-9)
    share = p.delta_albedo(mu)
    assert share[0] > 0.5  # grazing: the delta carries most of the energy
    assert abs(a[0] - (ag[0] + share[0])) <= e[0] + eg[0] + 1e-15 * share[0]


def test_pumped_he_torrance_conserves_energy(pumped):
    """g1 pumping bounds the albedo, delta included, by 1 from normal incidence down to grazing."""
    _, p = pumped
    mu = np.array([1.0, 0.5, 0.2, math.cos(math.radians(79.0)), 0.01])
    a, e = pumpup.albedo(p, mu, return_error=True)
    assert np.all(a - e <= 1.0)
    assert a.max() > 0.99  # and it is pumped up (the base reflects 0.04 at normal incidence)
