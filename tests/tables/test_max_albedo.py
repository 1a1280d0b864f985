"""The location of an albedo maximum comes with an error (tables.max_albedo's theta_error)."""

import math

import numpy as np
import pytest

import pumpup
from pumpup.tables import max_albedo


def test_interior_maximum_is_located_within_its_error():
    """Stretched Phong n = 1 overshoots near 12.9 deg (000 text, tables/text.nc). An independent
    locate: the vertex of a quartic fitted by least squares to 41 albedo values at rtol 1e-12 on
    mu0 +- 1e-3 and +- 3e-3 (where the fit's own bias is below 1e-5 deg) lies within theta_error."""
    f = pumpup.load({"type": "stretched_phong", "n": 1.0})
    m = max_albedo(f)
    assert not m.at_boundary and m.theta_error > 0
    for w in (1e-3, 3e-3):
        mu = np.linspace(m.mu - w, m.mu + w, 41)
        c = np.polyfit(mu - m.mu, pumpup.albedo(f, mu, rtol=1e-12), 4)
        r = np.roots(np.polyder(c))
        v = r[np.isreal(r)].real
        v = v[np.argmin(abs(v))]
        assert abs(math.degrees(math.acos(m.mu + v)) - m.theta_deg) <= m.theta_error
    # and the estimate is not vacuous: well below the scan's spacing (1 deg)
    assert m.theta_error < 1e-2


def test_boundary_maximum_has_no_location_error():
    m = max_albedo(pumpup.load({"type": "modified_ward", "m": 0.3}))
    assert m.at_boundary and m.mu == 1.0 and m.theta_error == 0.0  # the end of the range is exact


def test_ward_albedo_has_no_maximum():
    """Ward's albedo diverges as mu^-1/2 towards grazing incidence (001 sec. 2.1: the 1 / sqrt(N.L N.V) factor over a
    lobe of fixed width): max_albedo says so with the exponent instead of the value at its smallest mu, and
    max_constant returns 0 with a warning.  The exponent is checked against two albedos a decade apart far below the
    probe (independent of the probe's points)."""
    f = pumpup.load("ward:m=0.1")
    m = max_albedo(f)
    assert m.diverges and m.albedo == math.inf and m.constant == 0.0 and m.mu == 0.0
    a = pumpup.albedo(f, [1e-13, 1e-14])
    assert abs(m.exponent - math.log10(a[1] / a[0])) < 1e-3
    assert abs(m.exponent - 0.5) < 1e-3
    assert "unbounded" in str(m) and "mu^-0.5" in str(m)
    with pytest.warns(pumpup.engine.AlbedoWarning, match="no maximum"):
        assert pumpup.max_constant(f) == (0.0, 90.0)


@pytest.mark.parametrize("spec, mu_min", [("schlick:r=0.1", 1e-12), ("schlick:r=0.1", 1e-6),
                                          ("stretched_phong:n=1", 1e-6)])
def test_bounded_albedo_rising_to_grazing_keeps_its_maximum(spec, mu_min):
    """Schlick's albedo rises towards grazing incidence to a finite limit (000 sec. 6.2): its supremum is a number,
    within its error of the albedo far below mu_min."""
    f = pumpup.load(spec)
    m = max_albedo(f, mu_min=mu_min)
    assert not m.diverges and math.isfinite(m.albedo) and m.constant > 0
    if mu_min == 1e-12:  # the limit: the rise below mu falls tenfold per decade, 2.5e-12 relative at 1e-12
        assert m.mu == mu_min and abs(float(pumpup.albedo(f, 1e-15)) - m.albedo) <= 1e-10 * m.albedo
