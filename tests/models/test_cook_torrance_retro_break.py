"""The albedo of the models with 001 eq. 10's geometry factor has a jump in its second derivative at mu = 1 / sqrt(2)
(``pumpup.models.cook_torrance.RETRO_BREAK``), and the lobes that carry a table of it in N.wo (a 1/E scaling's U, a
pumped level's g) have a level there."""

import contextlib
import math

import helpers
import numpy as np
import pytest
from helpers import rings
from scipy.optimize import brentq

import pumpup
from pumpup.models.cook_torrance import RETRO_BREAK

VCAVITY = [{"type": "cook_torrance", "m": 0.538}, {"type": "torrance_sparrow", "d": "D1", "s": 2.0}]


def _one_sided(f, c, side):
    """a(c), a'(c), a''(c) from a degree-6 fit of the albedo (rtol 1e-13) on 30 incidences on one side of c."""
    x = c + side * np.linspace(1e-4, 0.03, 30)
    p = np.polynomial.Polynomial.fit(x - c, pumpup.albedo(f, x, rtol=1e-13), 6).convert()
    return np.array([p.deriv(k)(0.0) for k in range(3)])


@pytest.mark.parametrize("spec", VCAVITY, ids=lambda s: s["type"])
def test_second_derivative_jumps_at_the_retro_break(spec):
    """a and a' are continuous at 1 / sqrt(2) and a'' jumps (0.864 -> 0.952 for Cook-Torrance m = 0.538, 2.28 -> 2.68
    for Torrance-Sparrow D1 e = 2); at mu = 0.6 the same fits agree in a'' to 1e-4 (the check can tell)."""
    f = pumpup.load(spec)
    assert f.albedo_breaks() == (RETRO_BREAK,)
    lo, hi = _one_sided(f, RETRO_BREAK, -1), _one_sided(f, RETRO_BREAK, 1)
    assert abs(hi[0] - lo[0]) < 1e-7 and abs(hi[1] - lo[1]) < 1e-3, (lo, hi)
    assert hi[2] - lo[2] > 0.05, (lo, hi)
    lo, hi = _one_sided(f, 0.6, -1), _one_sided(f, 0.6, 1)
    assert abs(hi[2] - lo[2]) < 1e-4, (lo, hi)


def test_g_at_the_retro_direction_is_two_mu_squared():
    """The mechanism: at wo = wi, G = min(1, 2 mu^2) (both of its terms are 2 mu^2 there), read off Cook-Torrance's
    eval (f(wi, wi) = D(theta_i) G / mu^2, D = exp(-tan^2 / m^2) / (4 pi m^2 cos^4)): below 1 exactly below the
    break."""
    m = 0.538
    f = pumpup.load({"type": "cook_torrance", "m": m})
    for mu in (0.5, RETRO_BREAK - 1e-3, RETRO_BREAK + 1e-3, 0.9):
        wi = np.array([math.sqrt(1.0 - mu * mu), 0.0, mu])
        t2 = (1.0 - mu * mu) / (mu * mu)
        d = math.exp(-t2 / (m * m)) / (4.0 * math.pi * m * m * mu**4)
        g = float(f.eval(wi, wi)) * mu * mu / d
        assert g == pytest.approx(min(1.0, 2.0 * mu * mu), rel=1e-12), (mu, g)


def _ct_rings(f, mu, extra):
    """The albedo of a Cook-Torrance-based lobe whose other factors depend on N.wo alone, by rings (quad in N.wo,
    Gauss-Legendre in the azimuth between G's kink, :func:`helpers.rings`): on the ring N.wo = mo, G =
    min(1, 2 (mu + mo) min(mu, mo) / (1 + wi.wo)) switches where cos(phi) = (2 (mu + mo) min(mu, mo) - 1 - mu mo) /
    (s so); ``extra``: the other factors' kinks and pieces in N.wo."""
    s = math.sqrt((1.0 - mu) * (1.0 + mu))

    def ck(mo):
        so = math.sqrt((1.0 - mo) * (1.0 + mo))
        return (2.0 * min(mu, mo) * (mu + mo) - 1.0 - mu * mo) / (s * so)

    def cuts(mo, so):
        c = ck(mo) if s > 0.0 else 2.0
        return [0.0] + ([math.acos(c)] if -1 < c < 1 else []) + [math.pi]

    pts = [mu, *extra]
    if s > 0.0:
        grid = np.linspace(1e-9, 1 - 1e-12, 4001)
        for sign in (1.0, -1.0):
            h = np.array([ck(v) - sign for v in grid])
            pts += [brentq(lambda v: ck(v) - sign, grid[i], grid[i + 1], xtol=1e-16)
                    for i in np.nonzero(np.sign(h[:-1]) * np.sign(h[1:]) < 0)[0]]
    return rings(f, mu, cuts, pts)


#: (m, mu): scaled Cook-Torrance (F0 0.32) 5.3 x its estimate at (0.538, 0.9999), 1.57 x at (0.597, 1), 1.04 x at
#: (0.428, 1) (scripts/studies/fuzz_engines.py --registry 49), with the table's spline across the break
SCALED_CASES = [(0.5380484445259031, 0.9999), (0.5966016958353019, 1.0), (0.42826548851833385, 1.0)]


@pytest.mark.parametrize("engine", ["nested", "2-D"])
@pytest.mark.parametrize("m, mu", SCALED_CASES)
def test_scaled_cook_torrance_near_the_normal_against_rings(m, mu, engine):
    f = pumpup.load({"type": "scaled", "base": {"type": "cook_torrance", "m": m}, "f0": 0.32242538833573897})
    assert RETRO_BREAK in f.bound.table.breaks and RETRO_BREAK in f.lobe(mu).levels
    lo = f.bound.product.lo
    ref = _ct_rings(f, mu, [*lo[(lo > 0) & (lo < 1)], *f.bound.kinks])
    with helpers.two_d_only() if engine == "2-D" else contextlib.nullcontext():
        for rtol in (1e-8, 1e-10):
            a, e = pumpup.albedo(f, mu, return_error=True, rtol=rtol)
            assert abs(float(a) - ref) <= float(e) + 1e-14, (rtol, float(a), ref, float(e))


def test_pumped_cook_torrance_has_the_break_where_its_bound_leads():
    """A pumped level's g = max(u(mu), u(N.wo)) has the table's break as a kink where u(N.wo) is the larger (at mu =
    0.9, not at 0.5, where u(0.5) is above u(1 / sqrt(2))); at mu = 0.9999 its albedo agrees with the rings (it did
    before this level too, within 0.31 of its estimate: the check is that the level keeps it so)."""
    f = pumpup.load({"type": "pumped", "base": {"type": "cook_torrance", "m": 0.538}, "g": "g1", "levels": 1})
    up = f.lookup().upper
    assert RETRO_BREAK in f.lookup().table.breaks
    assert RETRO_BREAK in f.kink_levels(0.9) and float(up(RETRO_BREAK)) > float(up(0.9))
    assert RETRO_BREAK not in f.kink_levels(0.5) and float(up(RETRO_BREAK)) < float(up(0.5))
    mu = 0.9999
    knots = np.exp(f.lookup().logx)
    ref = _ct_rings(f, mu, [*(v for v in f.kink_levels(mu) if 0.0 < v < 1.0), *knots[(knots > 0) & (knots < 1)]])
    for rtol in (1e-8, 1e-10):
        a, e = pumpup.albedo(f, mu, return_error=True, rtol=rtol)
        assert abs(float(a) - ref) <= float(e) + 1e-14, (rtol, float(a), ref, float(e))
