"""The chain kernel's level table (pumpup.operators.pumping._LevelTable, pumpup.physics.lookups.g_pair): every level's
bound on one set of polynomial pieces in m, for chains whose bounds are not monotone (GGX); and its split table
(pumpup.operators.pumping._SplitTable, pumpup.physics.lookups.g_split): the product of all levels as F(min) H(max) in
the cells of (min, max) where every level's term is fixed.

What must hold, pointwise: the pumped BRDF is at least what the level-by-level path gives (the baseline,
``Pumped._eval_levelwise``) and at most the ideal operator's (the exact albedo of each level, from pumpup.albedo with
its error), at random, near-mirror and grazing pairs; the compiled kernel matches its numpy reference.
"""

import math

import numpy as np
import pytest
from helpers import random_directions
from numba import njit

import pumpup
from pumpup.operators.pumping import _LevelTable, _SplitTable
from pumpup.physics.lookups import cell_piece


@pytest.fixture(scope="module")
def ggx2():
    """2-level g2 pumped GGX alpha 0.3: its bounds fall, then rise (no product table)."""
    return pumpup.pump({"type": "ggx", "alpha": 0.3}, g="g2", levels=2)


@pytest.fixture(scope="module")
def ggx3():
    """3-level g2 pumped GGX alpha 0.3: the split table serves most pairs."""
    return pumpup.pump({"type": "ggx", "alpha": 0.3}, g="g2", levels=3)


@pytest.fixture(scope="module")
def ggx2_g1():
    """2-level g1 pumped GGX alpha 0.3 (height-correlated): a split table without the terms m."""
    return pumpup.pump({"type": "ggx", "alpha": 0.3, "shadowing": "correlated"}, g="g1", levels=2)


@pytest.fixture(scope="module")
def phong5():
    """5-level g2 pumped Phong n = 20: the top level's bound falls near mu = 1 (no product table), and the base's bound
    is within 1e-6 of mu, so its split table takes max(U_1(m), m) as one term."""
    return pumpup.pump({"type": "phong", "n": 20}, g="g2", levels=5)


@pytest.fixture(scope="module")
def ggx1_g1():
    return pumpup.pump({"type": "ggx", "alpha": 0.3, "shadowing": "correlated"}, g="g1", levels=1)


def _pairs(rng, n=300):
    """Random pairs, near-mirror pairs and grazing pairs (cosines down to 1e-7), all above the horizon."""
    wi, wo = random_directions(rng, n), random_directions(rng, n)
    mu = 10 ** rng.uniform(-7, 0, n)
    phi = rng.uniform(0, 2 * math.pi, n)
    s = np.sqrt(1 - mu * mu)
    a = np.stack([s * np.cos(phi), s * np.sin(phi), mu], axis=-1)
    mirror = a * np.array([-1, -1, 1]) + 1e-4 * rng.normal(size=(n, 3))
    mirror[:, 2] = np.abs(mirror[:, 2]) + 1e-9
    mirror /= np.linalg.norm(mirror, axis=-1, keepdims=True)
    mu2 = 10 ** rng.uniform(-7, -2, n)
    s2 = np.sqrt(1 - mu2 * mu2)
    graze = np.stack([s2 * np.cos(phi + 1.0), s2 * np.sin(phi + 1.0), mu2], axis=-1)
    return np.concatenate([wi, a, a, graze]), np.concatenate([wo, mirror, graze, wo])


@pytest.mark.parametrize("name", ["ggx2", "ggx3", "ggx2_g1", "ggx1_g1", "phong5"])
@pytest.mark.parametrize("path", ["new", "level table"])
def test_level_table_between_the_levelwise_and_the_ideal_operator(name, path, request, rng):
    """Both the level table alone and with the split table (``_eval``) are pointwise between the level-by-level path
    and the ideal operator."""
    f = request.getfixturevalue(name)
    assert f.product() is None and f.level_table() is not None  # the level table is what this tests
    assert (f.split_table() is not None) == (f.depth >= 2)  # and the split table with two levels or more
    wi, wo = _pairs(rng)
    if f.depth >= 2:  # pairs in cells of every pattern, and in cells without one
        mi, mo = _cell_pairs(f.split_table(), rng)
        wi = np.concatenate([wi, _at_cosine(mi, rng)])
        wo = np.concatenate([wo, _at_cosine(mo, rng)])
    new = f._eval(wi, wo) if path == "new" else f._eval_level_table(wi, wo)
    old = f._eval_levelwise(wi, wo)
    assert np.all(new >= old)  # at least what the level-by-level path gives, exactly
    up = new > 0
    assert np.count_nonzero(up) > 0.5 * len(up)
    assert np.max(np.abs(new[up] / old[up] - 1)) < 1e-13  # and no more than the fits' 2 epsilon each above
    keep = (wi[:, 2] > 0) & (wo[:, 2] > 0)
    assert np.all(new[keep] <= _ideal(f, wi[keep], wo[keep]))


def _ideal(f, wi, wo):
    """The ideal operator's value at pairs above the horizon, f / prod_j max(a_j(mu_i), a_j(mu_o)[, mu_i, mu_o]),
    with every level's albedo a_j raised by its error estimate (so a check against it is stricter than against the
    ideal's own value)."""
    mi, mo = wi[:, 2], wo[:, 2]
    mus = np.concatenate([mi, mo])
    g = np.ones(len(wi))
    for lev in f.chain():
        a, e = pumpup.albedo(lev.base, mus, return_error=True, rtol=1e-10)
        hi = a + e
        gj = np.maximum(hi[:len(wi)], hi[len(wi):])
        if lev.controlled:
            gj = np.maximum(gj, np.maximum(mi, mo))
        g = g * gj
    return f.chain()[0].base._eval(wi, wo) / g


@pytest.mark.parametrize("spec, g", [({"type": "phong", "n": 20}, "g2"), ({"type": "phong", "n": 20}, "g1"),
                                     # (Blinn's levels' albedos at 2400 cosines, for the ideal operator, take a minute)
                                     pytest.param({"type": "blinn", "n": 20}, "g1", marks=pytest.mark.slow)])
def test_product_table_between_the_value_divided_by_g_and_the_ideal_operator(spec, g, rng):
    """Where the product table serves, eval multiplies by its inverse 1 / G: at most the ideal operator's, and within
    the fits' 2 epsilon of the value divided by the table's G (the level-by-level path's value there, what eval gave
    before it multiplied), at random, near-mirror and grazing pairs.  (Where a level's bound is its cap, 1, and its
    albedo 1, at normal incidence above an energy-conserving base, there is no room above the ideal operator's:
    test_pump.py's user function's level keeps its albedo at most 1 there.)"""
    f = pumpup.pump(spec, g=g, levels=3)
    p = f.product()
    assert p is not None and f.level_table() is None
    wi, wo = _pairs(rng)
    new = f._eval(wi, wo)
    old = f._eval_levelwise(wi, wo)  # (the product table's G where it serves, else level by level)
    up = new > 0
    assert np.count_nonzero(up) > 0.5 * len(up)
    np.testing.assert_allclose(new[up], old[up], rtol=2.5 * p.epsilon, atol=0)
    keep = (wi[:, 2] > 0) & (wo[:, 2] > 0)
    assert np.all(new[keep] <= _ideal(f, wi[keep], wo[keep]))


def test_kernel_against_its_numpy_reference(ggx2, rng):
    q = ggx2.level_table()
    m = np.concatenate([10 ** rng.uniform(math.log10(q.mlo) + 1e-9, 0, 4000), [1.0], q.lo[1:-1],
                        q.lo[1:-1] * (1 - 1e-15)])
    m = m[(m > q.mlo) & (m <= 1.0)]
    mi, mo = rng.permutation(m), m
    # the kernel, through the chain kernel (f = 1 / g), at directions with these cosines
    wi = np.stack([np.sqrt(1 - mi * mi), np.zeros_like(mi), mi], axis=-1)
    wo = np.stack([np.zeros_like(mo), np.sqrt(1 - mo * mo), mo], axis=-1)
    from pumpup.operators.pumping import _chain_kernel

    f = np.ones(len(m))
    _chain_kernel(f, wi, wo, *ggx2._level_table_args())  # (the split table off: the level table everywhere)
    ref = 1.0 / q.g(mi, mo)
    np.testing.assert_allclose(f, ref, rtol=4e-16 * 8, atol=0)
    # every level's piece is at most the level's bound and within 2 epsilon below it
    for j, lk in enumerate(q.looks):
        u, got = lk.upper(m), q.levels(m)[j]
        assert np.all(got <= u) and np.all(got >= u * (1 - 2 * q.epsilon - 1e-15))


def test_level_table_layout(ggx2):
    """The rows hold centre, inverse half-width and each level's PRODUCT_DEGREE + 1 coefficients; the GChain names."""
    from pumpup.physics.lookups import PRODUCT_DEGREE

    q = ggx2.level_table()
    args = ggx2._chain_args()
    assert q.rows.shape == (len(q.lo) - 1, 2 + 2 * (PRODUCT_DEGREE + 1))
    assert args.pair_mlo == q.mlo and args.pair_rows is q.rows
    assert _LevelTable.TOL <= 1e-14


def test_phong_keeps_its_product_table():
    """Where every level's bound increases, the product table serves (one look-up per pair) and no level table."""
    f = pumpup.pump({"type": "phong", "n": 20}, g="g2", levels=1)
    assert f.product() is not None and f.level_table() is None
    assert f._chain_args().pair_mlo == math.inf


@pytest.mark.parametrize("spec", [{"type": "ggx", "alpha": 0.3}, {"type": "beckmann", "alpha": 0.2, "ior": 1.5},
                                  {"type": "phong", "n": 20}])
def test_fused_kernel_is_the_base_then_the_chain_kernel(spec, ggx2, rng):
    """A base's fused kernel (BRDF.eval_divided: microfacet, Phong) gives, bit for bit, its own value divided by the
    chain kernel: on every path (product or level table, level by level below its mlo, below the horizon)."""
    from pumpup.operators.pumping import _chain_kernel

    f = ggx2 if spec.get("alpha") == 0.3 else pumpup.pump(spec, g="g1")
    base = f.chain()[0].base
    wi, wo = _pairs(rng, 200)
    wi, wo = np.concatenate([wi, random_directions(rng, 200)]), np.concatenate([wo, random_directions(rng, 200)])
    wi[:3, 2], wo[3:6, 2] = 1e-9, 3e-10  # below the level table's mlo: level by level
    wi /= np.linalg.norm(wi, axis=-1, keepdims=True)
    wo /= np.linalg.norm(wo, axis=-1, keepdims=True)
    fused = base.eval_divided(wi, wo, f._chain_args())
    assert fused is not None
    two = np.array(base._eval(wi, wo))
    _chain_kernel(two, wi, wo, *f._chain_args())
    np.testing.assert_array_equal(fused, two)
    np.testing.assert_array_equal(f._eval(wi, wo), two)
    assert base.eval_divided(wi[:, None], wo[None, :], f._chain_args()) is None  # broadcast shapes: the two passes


def _at_cosine(mu, rng):
    """Unit directions with N.w = ``mu`` at random azimuths."""
    phi = rng.uniform(0, 2 * math.pi, len(mu))
    s = np.sqrt(1 - mu * mu)
    return np.stack([s * np.cos(phi), s * np.sin(phi), mu], axis=-1)


def _cell_pairs(r, rng, per=3):
    """Cosine pairs (N.wi, N.wo) in cells of every pattern of the split table ``r`` (``per`` random pairs in up to 40
    cells of each), in 200 cells without a pattern, and on the cells' edges (k / CELLS exactly, and one ulp below)."""
    n = r.ncell
    cells = []
    for p in range(-1, len(r.patterns)):
        ik = np.argwhere(r.pattern == p)
        if p < 0:
            ik = ik[ik[:, 0] < ik[:, 1]]  # (the upper triangle: min <= max)
        cells.append(ik[rng.permutation(len(ik))[:200 if p < 0 else 40]])
    ik = np.repeat(np.concatenate(cells), per, axis=0)
    lo = np.maximum((ik[:, 0] + rng.random(len(ik))) / n, r.mlo * 2)
    hi = np.minimum((ik[:, 1] + rng.random(len(ik))) / n, 1.0)
    edge = np.arange(1, n) / n
    lo = np.concatenate([lo, edge[:-1], np.nextafter(edge[:-1], 0), edge[:-1]])
    hi = np.concatenate([hi, edge[1:], np.nextafter(edge[1:], 0), np.nextafter(edge[1:], 0)])
    keep = (lo > r.mlo) & (lo <= hi)
    lo, hi = lo[keep], hi[keep]
    swap = rng.random(len(lo)) < 0.5  # either direction may hold the smaller cosine
    return np.where(swap, hi, lo), np.where(swap, lo, hi)


@pytest.mark.parametrize("name", ["ggx2", "ggx3", "ggx2_g1", "phong5"])
def test_split_table_patterns_hold_in_their_cells(name, request, rng):
    """In a cell with a pattern, every level's g takes the pattern's term: that term is the largest of U_j(l), U_j(m)
    and (g2) m, or is max(U_j(m), m) and at least U_j(l), at every pair tried there, so F(l) H(m) is the product of the
    levels' g."""
    f = request.getfixturevalue(name)
    r = f.split_table()
    mi, mo = _cell_pairs(r, rng, per=20)
    p = r.cell(mi, mo)
    on = p >= 0
    assert set(np.unique(p[on])) == set(range(len(r.patterns)))  # every pattern tried
    lo, hi, codes = np.minimum(mi, mo)[on], np.maximum(mi, mo)[on], r.patterns[p[on]]
    for j, lk in enumerate(r.looks):
        terms = np.stack([lk.upper(lo), lk.upper(hi), hi if r.controlled[j] else np.zeros_like(hi)])
        terms = np.concatenate([terms, np.maximum(terms[1], terms[2])[None]])  # code 3: max(U_j(m), m)
        chosen = terms[codes[:, j], np.arange(len(lo))]
        assert np.all(chosen >= terms.max(axis=0))  # 001 eq. 20, 21: the max is the pattern's term
    # and the tabulated functions are at most their products of bounds, within 2 epsilon below them
    for k, fn in enumerate(r.functions):
        m = np.geomspace(r.mlo * 1.001, 1.0, 3000)
        exact = r._function(fn)(m)
        got = r.function(k, m)
        assert np.all(got <= exact) and np.all(got >= exact * (1 - 2 * r.epsilon - 1e-15))


@pytest.mark.parametrize("name", ["ggx2", "ggx3", "ggx2_g1", "phong5"])
def test_split_kernel_against_its_numpy_reference(name, request, rng):
    """The compiled chain kernel (f = 1, so it returns 1 / g) against :meth:`_SplitTable.g`, on both of its paths."""
    from pumpup.operators.pumping import _chain_kernel

    f = request.getfixturevalue(name)
    r = f.split_table()
    mi, mo = _cell_pairs(r, rng)
    m = 10 ** rng.uniform(math.log10(r.mlo) + 1e-9, 0, 2000)
    mi, mo = np.concatenate([mi, m, r.lo[1:-1]]), np.concatenate([mo, rng.permutation(m), rng.permutation(r.lo[1:-1])])
    assert np.any(r.cell(mi, mo) >= 0) and np.any(r.cell(mi, mo) < 0)  # both paths
    out = np.ones(len(mi))
    _chain_kernel(out, _at_cosine(mi, rng), _at_cosine(mo, rng), *f._chain_args())
    np.testing.assert_allclose(out, 1.0 / r.g(mi, mo), rtol=4e-16 * 8, atol=0)


def test_split_table_layout_and_switch(ggx3, ggx2):
    """The GChain's split fields hold the table; ``_level_table_args`` turns it off; one level has none."""
    from pumpup.physics.lookups import PRODUCT_DEGREE

    r = ggx3.split_table()
    args = ggx3._chain_args()
    assert args.split_cells == r.ncell == _SplitTable.CELLS and args.split_coef is r.coef
    assert r.coef.shape == (len(r.functions), len(r.lo) - 1, PRODUCT_DEGREE + 3)
    assert r.functions[0] == ((), 0, ()) and np.all(r.coef[0, :, :PRODUCT_DEGREE + 1] == np.eye(PRODUCT_DEGREE + 1)[-1])
    assert not np.any(np.all(r.patterns == 2, axis=1))  # where every level takes m, the level table serves
    assert r.pattern.shape == (r.ncell, r.ncell) and r.pattern.dtype == np.int8
    assert np.all(np.tril(r.pattern + 1) == 0)  # only cells with min < max hold a pattern
    i, k = np.triu_indices(r.ncell)
    assert args.split_pattern is r.packed and np.array_equal(r.packed[k * (k + 1) // 2 + i], r.pattern[i, k])
    assert args.split_cell is r.entries and args.pair_cell is ggx3.level_table().entries
    assert r.share() > 0.85  # most uniform pairs take one product
    # F is empty in too few cells to skip its look-up: those patterns read a copy of row 0 (the kernel's branch on
    # row 0 is never taken)
    assert not r.skips and np.all(r.fid > 0) and r.functions[-1] == ((), 0, ())
    assert np.array_equal(r.coef[-1], r.coef[0]) and np.count_nonzero(r.fid == len(r.functions) - 1) > 0
    off = ggx3._level_table_args()
    assert off.split_cells == 0 and off.pair_rows is args.pair_rows
    assert pumpup.pump({"type": "ggx", "alpha": 0.3}, g="g2", levels=1).split_table() is None
    assert ggx2.split_table().looks is ggx2.level_table().looks


def test_split_table_takes_max_of_bound_and_cosine(phong5):
    """Where a level's bound and m are too close to tell apart over a cell (Phong's albedo is within 1e-6 of mu), the
    split table takes their max as one term of H (code 3), and most pairs take one product; each such pattern has a
    level whose term is its bound below the cap (the room the fit's scaling down takes)."""
    r = phong5.split_table()
    with3 = np.any(r.patterns == 3, axis=1)
    assert np.any(with3) and r.share() > 0.9
    assert r.skips and np.any(r.fid == 0)  # F is empty (exactly 1) in most cells: the kernel skips its look-up
    assert np.all(np.any((r.patterns[with3] == 0) | (r.patterns[with3] == 1), axis=1))
    assert all(fn[2] == tuple(np.nonzero(r.patterns[p] == 3)[0]) for p, fn in
               ((p, r.functions[h]) for p, h in enumerate(r.hid)))


@njit(cache=True)
def _cell_pieces(m, shift, cbase, cell, lo):  # pragma: no cover - compiled
    out = np.empty(m.shape[0], dtype=np.int64)
    for q in range(m.shape[0]):
        out[q] = cell_piece(m[q], shift, cbase, cell, lo)
    return out


@pytest.mark.parametrize("name", ["ggx2", "ggx3", "phong3"])
def test_cell_entries_find_every_piece(name, request, rng):
    """The cells' entries (one int64: a cell's first piece and where the next starts, rounded up) land on the piece
    that holds m, never past it, at random m, at every piece's start and just below it, and at the ends of cells; the
    compiled look-up equals its numpy reference."""
    from pumpup.physics.lookups import CELL_HIGH, CELL_LOW, CELL_SHIFT, float_bits_reference

    f = pumpup.pump({"type": "phong", "n": 20}, g="g2", levels=3) if name == "phong3" else request.getfixturevalue(name)
    tables = [f.product()] if name == "phong3" else [f.level_table(), f.split_table()]
    for t in tables:
        if t is None:
            continue
        shift = CELL_SHIFT if t is f.product() else t.shift
        starts = t.lo[1:-1]
        edges = (np.arange(t.cbase, t.cbase + len(t.entries), dtype=np.int64) << shift).view(np.float64)
        m = np.concatenate([np.exp(rng.uniform(np.log(t.mlo), 0, 100_000)), starts, np.nextafter(starts, 0),
                            edges, np.nextafter(edges, 0), [1.0]])
        m = m[(m > t.mlo) & (m <= 1.0)]
        s = t.piece(m)
        assert np.all((t.lo[s] <= m) & (m < t.lo[s + 1]))
        first = t.entries & CELL_LOW
        assert np.array_equal(first, t.cstart)
        # the bound in the high half is at least the next piece's start: the branch-free step never overshoots
        assert np.all((t.entries & CELL_HIGH) >= float_bits_reference(t.lo[first + 1]))
        c = np.minimum((float_bits_reference(m) >> shift) - t.cbase, len(t.entries) - 1)
        assert np.all(first[c] <= s)
        assert np.array_equal(_cell_pieces(m, shift, t.cbase, t.entries, t.lo), s)


def _noisy(m):
    """1 + m / 3 with a deterministic relative error of up to 6 ulps, as a function rounded on some machine."""
    m = np.asarray(m, dtype=np.float64)
    bits = m.view(np.int64)
    wobble = ((bits * 2654435761) >> 7) % 13 - 6  # -6 ... 6, from m's bits
    return (1.0 + m / 3.0) * (1.0 + wobble * np.finfo(np.float64).eps)


def test_fit_pieces_stops_at_the_rounding_of_the_functions():
    """A function that misses its interpolant by its own rounding (a few ulps at every width) is fitted without running
    into the piece limit; the miss it reports is that rounding (at most ROUNDING_ULPS ulps), not below it."""
    from pumpup.operators.pumping import ROUNDING_ULPS, fit_pieces

    lo, hi = np.array([0.1, 0.5]), np.array([0.5, 1.0])
    _, plo, _, _, _, worst = fit_pieces([_noisy], lo, hi, 1e-15, "noise test")
    assert len(plo) < 1000
    assert 1e-15 < worst.max() <= ROUNDING_ULPS * np.finfo(np.float64).eps


def test_fit_pieces_still_bisects_a_kink_to_its_tolerance():
    """A kink inside a piece is bisected until the miss meets the tolerance or the piece is 1e-9 m wide: its miss, about
    the piece's width, stays far above the rounding rule's few ulps, so the rule does not stop it early."""
    from pumpup.operators.pumping import fit_pieces

    def kink(m):
        return 1.0 + np.abs(np.asarray(m) - 0.3 - 1e-3 * math.pi)

    _, plo, phi, _, _, worst = fit_pieces([kink], np.array([0.1]), np.array([1.0]), 1e-15, "kink test")
    assert np.all((worst <= 1e-15) | (phi - plo <= 1e-9 * phi))
    inside = (plo <= 0.3 + 1e-3 * math.pi) & (0.3 + 1e-3 * math.pi < phi)
    assert (phi - plo)[inside].max() <= 1e-9
