"""The compiled kink search of a pumped BRDF (pumpup.physics.lookups.kink_roots, _upper_root) against a numpy and
scipy search (np.insert, np.sign and brentq on the bound)."""

import numpy as np
import pytest
from scipy.optimize import brentq

import pumpup


def _reference_roots(lk, g, ug, kind, target, mu, scale):
    """The search as :meth:`pumpup.operators.pumping.Pumped._kink_levels` did it before it was compiled."""
    up = lk.upper
    if kind == 0:
        two = np.array([mu * (1 - 1e-6), mu * (1 + 1e-6)])
        two = two[two <= 1.0]
        at = np.searchsorted(g, two)
        g, ug = np.insert(g, at, two), np.insert(ug, at, up(two))
    vals = ug - (g if kind == 1 else target)
    vals = np.where(np.abs(vals) < 1e-13 * scale, 0.0, vals)
    cells = np.nonzero(np.sign(vals[:-1]) * np.sign(vals[1:]) < 0)[0]
    if kind == 0:
        cells = [i for i in cells if not (g[i] <= mu <= g[i + 1] and g[i + 1] - g[i] <= 2.01e-6 * mu)]
    fn = (lambda u: float(up(u)) - u) if kind == 1 else (lambda u: float(up(u)) - target)
    return [brentq(fn, g[i], g[i + 1], xtol=1e-15) for i in cells]


@pytest.mark.parametrize("spec", [
    {"type": "pumped", "base": {"type": "ggx", "alpha": 0.3}, "g": "g2"},
    {"type": "pumped", "base": {"type": "metal", "n": 20, "eta": 0.9, "k": 0.3}, "g": "g2"},
    {"type": "pumped", "base": {"type": "phong", "n": 20}, "g": "g1"},
])
def test_kink_roots_against_brentq(spec):
    """Every root the numpy/scipy search finds, the compiled one finds within 1e-14 (the same cells, both within
    1e-15 + 4 eps u of a root), and no other; at targets U(mu) (kind 0), v (kind 1) and mu (kind 2)."""
    f = pumpup.load(spec)
    lk = f.lookup()
    grid, au, _, _ = f._kink_fixed()
    tg, tu = f._kink_turns()
    found = 0
    for mu in (1e-3, 0.05, 0.3, 0.6, 0.9659, 0.99, 1.0):
        am = float(lk.upper(mu))
        for kind in (0, 1, 2):
            g, ug = (grid, au) if kind == 1 else (tg, tu)
            target = am if kind == 0 else mu
            got = pumpup.physics.lookups.kink_roots(g, ug, kind, target, mu, max(1.0, am), *lk.args())
            ref = _reference_roots(lk, g, ug, kind, target, mu, max(1.0, am))
            assert len(got) == len(ref), (mu, kind, got, ref)
            assert np.all(np.abs(np.asarray(got) - np.asarray(ref)) <= 1e-14), (mu, kind, got, ref)
            found += len(ref)
    assert found > 0  # (the comparison saw roots)


def test_upper_root_brackets_the_root():
    """The bisection's root: U - target changes sign across [root -+ 2e-15] (or is 0 there), at targets spread over the
    bound's own range (so that every one is crossed)."""
    f = pumpup.load({"type": "pumped", "base": {"type": "ggx", "alpha": 0.1}, "g": "g2"})
    lk = f.lookup()
    args = lk.args()
    grid = np.linspace(1e-3, 1.0, 2001)
    u = lk.upper(grid)
    checked = 0
    for target in u.min() + (u.max() - u.min()) * np.array([0.1, 0.5, 0.9]):
        vals = u - target
        for i in np.nonzero(np.sign(vals[:-1]) * np.sign(vals[1:]) < 0)[0]:
            r = pumpup.physics.lookups.upper_root(grid[i], grid[i + 1], 0, target, *args)
            lo, hi = lk.upper(r - 2e-15) - target, lk.upper(r + 2e-15) - target
            assert lo * hi <= 0.0, (target, r, lo, hi)
            checked += 1
    assert checked >= 3  # (each target crossed at least once)
