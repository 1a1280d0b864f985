"""The Mitsuba 3 bridge (pumpup.mitsuba): probe and fallback, the plugin against pumpup, Mitsuba's
chi-square test, and Mitsuba's BSDFs measured by pumpup.

Skipped when mitsuba is not installed; the llvm tests are skipped when the llvm variant does not
pass the subprocess probe (e.g. libLLVM < 17), the scalar ones run wherever mitsuba imports.
"""

from __future__ import annotations

import json
import math
import os
import subprocess
import sys

import helpers
import numpy as np
import pytest

import pumpup

ROOT = str(helpers.ROOT)


def _run(code, env=None, timeout=300):
    e = dict(os.environ)
    e["PYTHONPATH"] = ROOT + os.pathsep + e.get("PYTHONPATH", "")
    e.update(env or {})
    return subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, cwd=ROOT, env=e,
                          timeout=timeout)


mi = pytest.importorskip("mitsuba")
dr = pytest.importorskip("drjit")
pm = pytest.importorskip("pumpup.mitsuba")

LLVM = "llvm_ad_rgb"
LLVM_OK, LLVM_WHY = pm.probe(LLVM)
needs_llvm = pytest.mark.skipif(not LLVM_OK, reason=f"{LLVM} unusable here: {LLVM_WHY}")

LLVM15 = "/usr/lib/x86_64-linux-gnu/libLLVM-15.so.1"

#: one spec per supported type (and Fresnel / shadowing options); pumped ones at the end
SPECS = [
    {"type": "lambert", "albedo": 0.3},
    {"type": "phong", "n": 20},
    {"type": "phong", "n": 5000},
    {"type": "stretched_phong", "n": 50, "p": 0.5},
    {"type": "stretched_phong", "n": 20},
    {"type": "retro", "n": 10},
    {"type": "blinn", "n": 30},
    {"type": "stretched_blinn", "n": 20},
    {"type": "ward", "m": 0.2},
    {"type": "modified_ward", "m": 0.2},
    {"type": "ward_aniso", "ax": 0.1, "ay": 0.3},
    {"type": "schlick", "r": 0.1},
    {"type": "cook_torrance", "m": 0.3, "ior": 1.5},
    {"type": "ggx", "alpha": 0.3},
    {"type": "ggx", "alpha": 0.4, "ior": 1.5, "shadowing": "correlated"},
    {"type": "beckmann", "alpha": 0.2, "g1": "walter", "eta": 0.2, "k": 3.0},
    {"type": "beckmann", "alpha": 0.5, "shadowing": "correlated"},
    {"type": "metal", "n": 20, "eta": 0.2, "k": 3.0},
    {"type": "plastic", "n": 100, "ad": 0.3, "a_s": 0.6, "eta": 1.5},
    {"type": "pumped", "base": {"type": "phong", "n": 20}, "g": "g2", "levels": 2},
    {"type": "pumped", "base": {"type": "ward", "m": 0.2}, "g": "g1"},
]
PUMPED = [s for s in SPECS if s["type"] == "pumped"]
#: the models the default suite runs the Monte Carlo and chi-square checks on (all of SPECS under -m slow):
#: the Phong lobe, its stretched p-model, both microfacet half-vector lobes with Fresnel, a mixture,
#: the anisotropic tangent frame, and both pumped chains
FAST = [SPECS[i] for i in (1, 3, 10, 13, 15, 18)] + PUMPED


def _split(specs):
    """pytest params: FAST specs in the default suite, the others marked slow."""
    return [pytest.param(s, id=json.dumps(s, separators=(",", ":"))[:60],
                         marks=() if s in FAST else pytest.mark.slow) for s in specs]


def _ids(specs):
    return [json.dumps(s, separators=(",", ":"))[:60] for s in specs]


def _pairs(n, rng):
    """Random pairs above the horizon plus grazing ones (cosines down to 1e-9, below the 1e-8 where pumped
    chains leave their product table), float32-exact."""
    def dirs(m, zmin=None):
        x = rng.normal(size=(m, 3))
        x[:, 2] = np.abs(x[:, 2])
        x /= np.linalg.norm(x, axis=1)[:, None]
        if zmin is not None:  # grazing: z in [zmin, 1e-2], log-uniform
            z = np.exp(rng.uniform(np.log(zmin), np.log(1e-2), m))
            s = np.sqrt(1 - z * z)
            ph = rng.uniform(0, 2 * np.pi, m)
            x = np.stack([s * np.cos(ph), s * np.sin(ph), z], -1)
        return x.astype(np.float32).astype(np.float64)
    v = dirs(n)  # near the mirror direction (sharp lobes): wi = mirror(wo) + 0.02 x noise
    m = v * np.array([-1.0, -1.0, 1.0]) + 0.02 * rng.normal(size=v.shape)
    m[:, 2] = np.abs(m[:, 2])
    m = (m / np.linalg.norm(m, axis=1)[:, None]).astype(np.float32).astype(np.float64)
    wi = np.concatenate([dirs(n), m, dirs(n // 4, 1e-9), dirs(n // 4)])
    wo = np.concatenate([dirs(n), v, dirs(n // 4), dirs(n // 4, 1e-9)])
    return wi, wo


def _plugin_eval(b, wi, wo, channel=0):
    """Mitsuba eval with si.wi = pumpup's wo and Mitsuba's wo = pumpup's wi."""
    ctx = mi.BSDFContext()
    if dr.is_jit_v(mi.Float):
        si = dr.zeros(mi.SurfaceInteraction3f, len(wi))
        si.wi = mi.Vector3f(*(mi.Float(wo[:, i].astype(np.float32)) for i in range(3)))
        w = mi.Vector3f(*(mi.Float(wi[:, i].astype(np.float32)) for i in range(3)))
        val, pdf = b.eval_pdf(ctx, si, w)
        ev = b.eval(ctx, si, w)
        assert np.array_equal(np.array(ev), np.array(val))  # eval_pdf = (eval, pdf)
        assert np.array_equal(np.array(b.pdf(ctx, si, w)), np.array(pdf))
        return np.array(val[channel], dtype=np.float64), np.array(pdf, dtype=np.float64)
    vals, pdfs = [], []
    si = mi.SurfaceInteraction3f()
    for a, c in zip(wi, wo):
        si.wi = mi.Vector3f(*map(float, c))
        w = mi.Vector3f(*map(float, a))
        v, p = b.eval_pdf(ctx, si, w)
        assert v[channel] == b.eval(ctx, si, w)[channel] and p == b.pdf(ctx, si, w)
        vals.append(v[channel])
        pdfs.append(p)
    return np.array(vals), np.array(pdfs)


#: relative bound of one rounding to float32, plus the double evaluation's own error
F32 = 2.0**-24 + 1e-12


def _check_agreement(spec, variant, n, rng):
    pm.register(variant)
    f = pumpup.load(spec)
    b = pm.load_dict({"type": "pumpup", "spec": spec})
    wi, wo = _pairs(n, rng)
    got, pdf = _plugin_eval(b, wi, wo)
    ref = f.eval(wi, wo) * wi[:, 2]  # Mitsuba's eval includes cos(theta) of its wo (pumpup's wi)
    tiny = np.finfo(np.float32).tiny  # below it float32 rounds absolutely (denormals)
    pumped = spec["type"] == "pumped"
    tol = 2.0**-23 + F32 if pumped else F32  # pumped values are rounded down by 2^-23 before the cast
    err = np.abs(got - ref)
    assert np.all(err <= np.maximum(tol * ref, tiny)), f"worst relative difference {np.max(err / ref):.3g}"
    if pumped:  # never above pumpup's value
        assert np.all(got <= ref * (1 + 1e-12) + tiny)
    assert np.sum(ref > 1e-30) > n // 3  # many pairs tested with a non-zero value
    return pdf


@needs_llvm
@pytest.mark.parametrize("spec", SPECS, ids=_ids(SPECS))
def test_eval_agrees_with_pumpup_llvm(spec, rng):
    _check_agreement(spec, LLVM, 2000, rng)


#: pumped chains whose levels' bounds are not all monotone (GGX's albedo falls, then rises), so that g depends on both
#: cosines: the plugin looks every level's bound up in fixed cells of each cosine where quartics fit them
#: (:class:`pumpup.mitsuba._CellG`; 2 levels: one cell split at a kink; 3 levels: refined cells, the third level's
#: bound crowding with features)
LEVEL_TABLE = [{"type": "pumped", "base": {"type": "ggx", "alpha": 0.3}, "g": "g2", "levels": 2},
               {"type": "pumped", "base": {"type": "ggx", "alpha": 0.3}, "g": "g2", "levels": 3}]


@needs_llvm
@pytest.mark.parametrize("spec,refined", zip(LEVEL_TABLE, [False, True]), ids=_ids(LEVEL_TABLE))
def test_level_table_chains_agree_with_pumpup_llvm(spec, refined, rng):
    pm.register(LLVM)
    fast = pm._DrModel(pumpup.load(spec)).fast
    assert isinstance(fast, pm._CellG) and fast.rest_table is None and fast.cells.coarse is None
    assert fast.rest == ([2] if refined else []) and (fast.rest_cells is not None) == refined
    assert not refined or fast.rest_cells.coarse is not None
    _check_agreement(spec, LLVM, 2000, rng)


#: pumped chains of many bases, g1 and g2, 1 to 3 levels: the plugin's look-up takes every path on them (fixed cells,
#: with and without low cells, cells split at kinks, levels in refined cells or a level table of their own, pumpup's
#: product table)
MANY_PUMPED = [{"type": "pumped", "base": base, "g": g, "levels": levels}
               for base in ({"type": "ggx", "alpha": 0.02}, {"type": "ggx", "alpha": 1.0},
                            {"type": "beckmann", "alpha": 0.4}, {"type": "phong", "n": 1}, {"type": "phong", "n": 5000},
                            {"type": "blinn", "n": 30}, {"type": "ward", "m": 0.3}, {"type": "schlick", "r": 0.1},
                            {"type": "cook_torrance", "m": 0.3, "ior": 1.5},
                            {"type": "ggx", "alpha": 0.3, "eta": 0.2, "k": 3.0})
               for g in ("g1", "g2") for levels in (1, 3)]


@needs_llvm
@pytest.mark.slow
@pytest.mark.parametrize("spec", MANY_PUMPED, ids=_ids(MANY_PUMPED))
def test_many_pumped_chains_agree_with_pumpup_llvm(spec, rng):
    _check_agreement(spec, LLVM, 1000, rng)


@needs_llvm
def test_levels_the_cells_do_not_fit_come_from_a_level_table_of_their_own(rng, monkeypatch):
    """3-level g2 GGX alpha 0.3 without refined cells: the third level's bound crowds with features that no quartic in
    the fixed cells fits, so the plugin keeps the first two levels in the cells and takes the third from a level table
    of that level alone (:class:`pumpup.mitsuba._PairG`).  The Dr.Jit look-up equals its numpy reference to the last
    bit, and lies within 1e-14 below and 2 x 1e-13 above pumpup's level table of all three levels (both tables fit
    each bound to 1e-15 from below; the cells lift theirs by at most 1e-13); through the plugin it agrees with
    pumpup."""
    pm.register(LLVM)
    monkeypatch.setattr(pm._CellPolynomials, "MAX_EXTRA_BITS", 0)
    f = pumpup.load(LEVEL_TABLE[1])
    fast = pm._DrModel(f).fast
    assert fast.rest == [2] and fast.cells.nfun == 2 and fast.rest_cells is None and not fast.whole
    x = _cell_points(fast.cells, rng)
    x = x[x > fast.mlo]  # (below it the plugin looks pairs up level by level)
    y = rng.permutation(x)
    got = np.array(fast(mi.Float64(x), mi.Float64(y)), dtype=np.float64)
    ref = fast.reference(x, y)
    assert np.array_equal(got, ref)
    good = ~fast.in_bad(x, y)
    table = f.level_table().g(x, y)
    assert np.all(ref[good] >= table[good] * (1.0 - 1e-14))
    assert np.all(ref[good] <= table[good] * (1.0 + 2e-13))
    _check_agreement(LEVEL_TABLE[1], LLVM, 1000, rng)


@pytest.mark.parametrize("spec", SPECS[:: 3] + PUMPED[:1] + LEVEL_TABLE[:1],
                         ids=_ids(SPECS[:: 3] + PUMPED[:1] + LEVEL_TABLE[:1]))
def test_eval_agrees_with_pumpup_scalar(spec, rng):
    _check_agreement(spec, "scalar_rgb", 24, rng)


def _table_points(t, rng):
    """Cosines above a table's mlo: uniform, log-uniform, every piece start and the float below it, and 1."""
    lo = t.lo[1:-1]
    x = np.concatenate([rng.uniform(t.mlo, 1.0, 4000), np.exp(rng.uniform(math.log(t.mlo), 0.0, 4000)), lo,
                        np.nextafter(lo, 0.0), [1.0]])
    return x[x > t.mlo]


def _table_g(f):
    """The Dr.Jit look-up of pumpup's own table of a chain (the product table where it has one, else the level table)
    and that table."""
    t = f.product() if f.product() is not None else f.level_table()
    return (pm._ProductG(t) if f.product() is not None else pm._PairG(t)), t


@needs_llvm
@pytest.mark.parametrize("spec", [PUMPED[0], LEVEL_TABLE[1], {**PUMPED[0], "levels": 3}],
                         ids=["product-2", "level-table-3", "product-3"])
def test_table_kernels_equal_their_numpy_references(spec, rng):
    """The Dr.Jit look-ups of the product table and the level table (a cell gather, two-level cells where the pieces
    crowd, one row per piece in 64-byte packets, Horner; the plugin's path where the cells of _CellG do not fit) against
    their plain numpy references, _Product.__call__ and _LevelTable.g: the same pieces, the same value to the last bit,
    at random cosines and at both sides of every piece start (crowded cells included)."""
    pm.register(LLVM)
    f = pumpup.load(spec)
    fast, t = _table_g(f)
    x = _table_points(t, rng)
    y = rng.permutation(x)
    got = np.array(fast(mi.Float64(x), mi.Float64(y)), dtype=np.float64)
    ref = t(np.maximum(x, y)) if f.product() is not None else t.g(x, y)
    assert np.array_equal(got, ref)
    assert np.array_equal(np.array(fast.cells(mi.Float64(x))), t.piece(x))
    if spec["levels"] == 3 and f.product() is None:  # crowded pieces: two-level cells, at most 3 starts per fine cell
        c = fast.cells
        assert c.fine is not None and c.width == 4 and np.isinf(c.fine[:, 1:]).sum() < c.fine[:, 1:].size
    for table in (fast.rows.dr, fast.cells.dr):  # 64-byte aligned: Dr.Jit reads them in packets
        assert np.asarray(table).__array_interface__["data"][0] % 64 == 0


#: chains whose g the plugin takes from fixed cells (:class:`pumpup.mitsuba._CellG`): each level's bound at both
#: cosines (1-level and 2-level GGX, a 2-level Beckmann), the product of every level's g at the larger cosine where
#: every level's bound increases (2-level Phong; 3-level Phong, whose product crowds with features near m = 1, in top
#: cells there), and 3-level GGX in refined cells
PHONG_TOP = {"type": "pumped", "base": {"type": "phong", "n": 20}, "g": "g2", "levels": 3}
CELL_CHAINS = [{"type": "pumped", "base": {"type": "ggx", "alpha": 0.3}, "g": "g2", "levels": 1}, LEVEL_TABLE[0],
               {"type": "pumped", "base": {"type": "beckmann", "alpha": 0.05}, "g": "g1", "levels": 2}, PUMPED[0],
               LEVEL_TABLE[1], PHONG_TOP]


def _cell_range(cells, c):
    """The cosines [lo, hi) of fine or top cells ``c`` of a cell table (of refined cells: fine cell c - first of
    coarse cell k, one of its 2^e)."""
    c = np.asarray(c, dtype=np.int64)
    k, sub, e, base, shift = c, 0, 0, cells.cbase, cells.shift
    if cells.coarse is not None:
        first = (cells.coarse >> 5).astype(np.int64)
        k = np.searchsorted(first, c, side="right") - 1
        sub, e = c - first[k], (cells.coarse[k] & 31).astype(np.int64)
    if cells.ntop:
        top = c >= cells.nfine + cells.nlow
        k = np.where(top, c - cells.nfine - cells.nlow, k)
        base, shift = np.where(top, cells.top_base, base), np.where(top, cells.top_shift, shift)
    lo = ((k + base) << shift).view(np.float64)
    w = (((k + base + 1) << shift).view(np.float64) - lo) / 2.0**e
    return lo + w * sub, lo + w * (sub + 1)


def _kink_points(cells, rng):
    """Cosines in the cells split at kinks and in the cells that miss: 50 random ones in each, and every kink with
    the floats on both sides of it."""
    split = [c for c, _, _ in cells.splits]
    lo, hi = _cell_range(cells, split + cells.bad)
    x = [rng.uniform(lo[:, None], hi[:, None], (len(lo), 50)).ravel(), lo]
    for (c, kinks, _), a, b in zip(cells.splits, lo, hi):
        k = a + (b - a) * np.array(kinks)
        x += [k, np.nextafter(k, 0.0), np.nextafter(k, 2.0)]
    return np.concatenate(x)


def _cell_points(cells, rng):
    """Cosines from a cell table's mlo to 1: uniform, log-uniform, the edges of every 7th fine cell and of every 7th
    top cell and the floats below them, 1, the table's mlo, and those of :func:`_kink_points`; where the table has low
    cells, those of :func:`_low_points` too."""
    top = cells.nfine + cells.nlow
    lo, _ = _cell_range(cells, np.concatenate([np.arange(0, cells.nfine - 1, 7), np.arange(top, top + cells.ntop, 7)]))
    x = np.concatenate([rng.uniform(cells.mlo, 1.0, 4000), np.exp(rng.uniform(math.log(cells.mlo), 0.0, 4000)),
                        lo, np.nextafter(lo, 0.0), [1.0, np.nextafter(1.0, 0.0), cells.mlo], _kink_points(cells, rng)])
    x = x[(x >= cells.mlo) & (x <= 1.0)]
    return np.concatenate([x, _low_points(cells, rng)]) if cells.nlow else x


def _low_points(cells, rng):
    """Float32 cosines below a cell table's mlo, where its low cells hold them: log-uniform down to float32's smallest
    subnormal, the low cells' edges, the float64 and the float32 below mlo."""
    edges = (np.arange(cells.low_base, cells.low_base + cells.nlow, dtype=np.int64) << cells.low_shift).view(np.float64)
    f32 = np.float32(cells.mlo)
    f32 = f32 if f32 < cells.mlo else np.nextafter(f32, np.float32(0.0))
    x = np.concatenate([np.exp(rng.uniform(math.log(1.4e-45), math.log(cells.mlo), 4000)), edges[edges > 1.4e-45],
                        [np.finfo(np.float32).smallest_subnormal, f32]]).astype(np.float32).astype(np.float64)
    return np.concatenate([x[(x > 0) & (x < cells.mlo)], [np.nextafter(cells.mlo, 0.0)]])


@needs_llvm
@pytest.mark.parametrize("spec", CELL_CHAINS, ids=_ids(CELL_CHAINS))
def test_cell_polynomials_equal_their_numpy_reference_and_bound_pumpups_g(spec, rng):
    """g from fixed cells (:class:`pumpup.mitsuba._CellG`): the Dr.Jit look-up equals its plain numpy reference to the
    last bit (random and log-uniform cosines, both sides of cell edges, refined cells' too, in and about the cells
    split at kinks, 1, and for the chains looked up level by level, float32 cosines in the low cells, down to the
    smallest subnormal);
    outside the cells that miss (``bad``, where the plugin looks pairs up level by level) it is at least pumpup's
    levelwise g (from each level's look-up, as pumpup's kernels divide by it), so the plugin never exceeds pumpup, and
    at most LIFT (1e-13) per function above it."""
    pm.register(LLVM)
    f = pumpup.load(spec)
    fast = pm._DrModel(f).fast
    assert isinstance(fast, pm._CellG) and fast.increasing == (f.product() is not None)
    cells = fast.cells
    assert len(cells.bad) <= (cells.MAX_TOP_BAD if cells.ntop else cells.MAX_BAD)
    assert len(cells.splits) <= cells.MAX_SPLITS
    nfun = cells.nfun + (0 if fast.rest_cells is None else fast.rest_cells.nfun)
    assert nfun == (1 if fast.increasing else spec.get("levels", 1))
    assert fast.whole == (not fast.increasing) and (cells.nlow > 0) == fast.whole  # (the product: pairs below mlo
    # take both cosines' bounds, level by level)
    x = _cell_points(cells, rng)
    if fast.rest_cells is not None:  # (and the refined cells' edges, fine cells and cells that miss)
        x = np.concatenate([x, _cell_points(fast.rest_cells, rng)])
    y = rng.permutation(x)
    got = np.array(fast(mi.Float64(x), mi.Float64(y)), dtype=np.float64)
    ref = fast.reference(x, y)
    assert np.array_equal(got, ref)
    assert np.array_equal(np.array(fast.in_bad(mi.Float64(x), mi.Float64(y))), fast.in_bad(x, y))
    good = ~fast.in_bad(x, y)
    assert good.mean() > 0.95
    levelwise = np.ones(len(x))
    for lev in f.chain():  # as pumpup's kernels compute it, from each level's look-up (where a level's bound dips
        lk = lev.lookup()  # within its margin, the look-up takes its running maximum)
        g = np.maximum(lk.upper(x), lk.upper(y))  # 001 eq. 20
        levelwise = levelwise * (np.maximum(g, np.maximum(x, y)) if lev.controlled else g)  # 001 eq. 21
    assert np.all(ref[good] >= levelwise[good])
    assert np.all(ref[good] <= levelwise[good] * (1.0 + cells.LIFT) ** nfun * (1.0 + 1e-15))


@needs_llvm
@pytest.mark.parametrize("spec", CELL_CHAINS[:3], ids=_ids(CELL_CHAINS[:3]))
def test_cosines_in_the_low_cells_agree_with_pumpup(spec, rng):
    """Pairs with a cosine below the levels' splines (float32 cosines from the smallest normal float32 up to mlo, where
    each level's bound is a power law and the cells hold them without a level-by-level path): through the plugin,
    within one rounding of pumpup's eval and never above it.  (Dr.Jit's llvm kernels wider than 16 lanes flush a
    subnormal float32 to 0, so there the plugin gives 0, as Mitsuba's roughconductor does.)"""
    pm.register(LLVM)
    f = pumpup.load(spec)
    fast = pm._DrModel(f).fast
    assert fast.whole and not fast.cells.bad
    z = _low_points(fast.cells, rng)
    z = z[z >= np.finfo(np.float32).tiny]
    ph = rng.uniform(0, 2 * np.pi, len(z))
    s = np.sqrt(1 - z * z)
    wo = np.stack([s * np.cos(ph), s * np.sin(ph), z], -1).astype(np.float32).astype(np.float64)
    wi = rng.normal(size=wo.shape)
    wi[:, 2] = np.abs(wi[:, 2])
    wi[::2] = -wo[::2] * np.array([1.0, 1.0, -1.0]) + 0.01 * wi[::2]  # near the mirror for half the pairs
    wi[:, 2] = np.abs(wi[:, 2])
    wi = (wi / np.linalg.norm(wi, axis=1)[:, None]).astype(np.float32).astype(np.float64)
    b = pm.load_dict({"type": "pumpup", "spec": spec})
    for a, c in ((wi, wo), (wo, wi)):  # (the low cosine on either side)
        got, _ = _plugin_eval(b, a, c)
        ref = f.eval(a, c) * a[:, 2]
        tiny = np.finfo(np.float32).tiny
        assert np.all(got <= ref * (1 + 1e-12) + tiny)
        assert np.all(np.abs(got - ref) <= np.maximum((2.0**-23 + F32) * ref, tiny))
        assert np.sum(ref > 1e-30) > len(z) // 10 or a is wo  # (times the low cosine, most values are below 1e-30)


def test_cell_polynomials_split_a_cell_at_a_kink_or_mark_it():
    """A function with a kink inside one cell: no quartic comes within LIFT of it there.  Told where the kink is, the
    table splits that cell there (two quartics, each within LIFT, at least the function on either side); not told, it
    marks the cell as missing.  Beyond MAX_BAD such cells the table is refused."""
    kink = 0.6 + 1e-4

    def fn(m):
        return 0.5 + np.abs(m - kink)

    marked = pm._CellPolynomials([fn], [math.inf], 1e-8)
    c = (np.float64(kink).view(np.int64) >> marked.shift) - marked.cbase
    assert marked.bad == [int(c)] and marked.splits == []
    split = pm._CellPolynomials([fn], [math.inf], 1e-8, kinks=[0.3, kink])
    assert split.bad == [] and [(a, len(b)) for a, b, _ in split.splits] == [(int(c), 1)]
    m = np.concatenate([np.linspace(*_cell_range(split, [c]), 2001)[:, 0], [kink, np.nextafter(kink, 0.0)]])
    got = split.reference(m)[0]
    assert np.all(got >= fn(m)) and np.all(got <= fn(m) * (1 + split.LIFT))
    kinks = 0.6 + 0.01 * np.arange(split.MAX_BAD + 1)
    with pytest.raises(pm._CellsMiss, match="not within its lift"):
        pm._CellPolynomials([lambda m: 0.5 + np.min(np.abs(m[..., None] - kinks), axis=-1)], [math.inf], 1e-8)


@needs_llvm
def test_refined_cells_cut_the_cells_a_fixed_grid_misses(rng):
    """A function with six steep (smooth) steps, 1e-3 wide: no fixed grid of quartics comes within LIFT of it in at
    most MAX_BAD cells, so the table refines: the coarse cells about the steps are cut into 2^e finer ones, and the
    look-up lies within [F, F (1 + LIFT)] on and about the steps, its Dr.Jit version equal to its numpy reference.
    Without refinement the table is refused."""
    pm.register(LLVM)
    centres = 0.6 + 0.01 * np.arange(6)

    def fn(m):
        return 2.5 + 0.3 * np.sum(np.tanh((m[..., None] - centres) / 1e-3), axis=-1)

    with pytest.raises(pm._CellsMiss, match="not within its lift"):
        pm._CellPolynomials([fn], [math.inf], 1e-8, refine=False)
    cells = pm._CellPolynomials([fn], [math.inf], 1e-8)
    e = cells.coarse & 31
    assert not cells.bad and not cells.splits and 0 < np.count_nonzero(e) <= 20 * len(centres)
    assert e.max() <= cells.MAX_EXTRA_BITS
    m = np.concatenate([(centres + np.linspace(-5e-3, 5e-3, 2001)[:, None]).ravel(), rng.uniform(1e-8, 1.0, 4000)])
    got = cells.reference(m)[0]
    assert np.all(got >= fn(m)) and np.all(got <= fn(m) * (1 + cells.LIFT))
    assert np.array_equal(np.array(cells(mi.Float64(m))[0], dtype=np.float64), got)


@needs_llvm
def test_top_cells_hold_features_that_crowd_near_1(rng, monkeypatch):
    """Three steep (smooth) steps 1e-3 wide near m = 1: a fixed grid of quartics misses in more than MAX_BAD cells
    there, so the table takes top cells, finer, from the lowest of those cells up to 1, where all fit, without refined
    cells; the look-up lies within [F, F (1 + LIFT)] on and about the steps and about the top cells' first edge, its
    Dr.Jit version equal to its numpy reference.  Without top cells (MAX_TOP_ROWS = 0) the table is refused."""
    pm.register(LLVM)
    centres = 0.990 + 0.004 * np.arange(3)

    def fn(m):
        return 2.5 + 0.3 * np.sum(np.tanh((m[..., None] - centres) / 1e-3), axis=-1)

    cells = pm._CellPolynomials([fn], [math.inf], 1e-8, refine=False)
    assert cells.ntop > 0 and cells.coarse is None and not cells.bad and not cells.splits
    top = float(np.int64(cells.top_bits).view(np.float64))
    assert 0.95 < top < centres[0] - 3e-3 and 52 - cells.top_shift > 52 - cells.shift
    m = np.concatenate([(centres + np.linspace(-5e-3, 5e-3, 2001)[:, None]).ravel(), rng.uniform(1e-8, 1.0, 4000),
                        top + np.linspace(-1e-4, 1e-4, 201), [top, np.nextafter(top, 0.0), 1.0]])
    m = m[m <= 1.0]
    got = cells.reference(m)[0]
    assert np.all(got >= fn(m)) and np.all(got <= fn(m) * (1 + cells.LIFT))
    assert np.array_equal(np.array(cells(mi.Float64(m))[0], dtype=np.float64), got)
    monkeypatch.setattr(pm._CellPolynomials, "MAX_TOP_ROWS", 0)
    with pytest.raises(pm._CellsMiss, match="not within its lift"):
        pm._CellPolynomials([fn], [math.inf], 1e-8, refine=False)


@needs_llvm
@pytest.mark.parametrize("spec,hide_kinks", [(CELL_CHAINS[1], False), (PUMPED[0], False), (CELL_CHAINS[1], True),
                                             (PHONG_TOP, False)],
                         ids=["levels-2", "product-2", "levels-2-kinks-hidden", "product-3-top"])
def test_pairs_in_split_and_missing_cells_agree_with_pumpup(spec, hide_kinks, rng, monkeypatch):
    """Pairs whose cosines lie in the cells split at a kink (about the kinks too), or, with the kinks hidden from the
    table or in top cells (not split), in the cells whose quartics then miss (looked up level by level): through the
    plugin, within one rounding of pumpup's eval and never above it."""
    pm.register(LLVM)
    if hide_kinks:
        monkeypatch.setattr(pm._CellG, "_kinks", lambda self, looks, mu0: np.zeros(0))
    f = pumpup.load(spec)
    cells = pm._DrModel(f).fast.cells
    missing = hide_kinks or cells.ntop > 0
    assert (cells.bad and not cells.splits) if missing else (cells.splits and not cells.bad)
    assert (cells.ntop > 0) == (spec is PHONG_TOP)
    z = _kink_points(cells, rng)
    z = z[(z < 1.0) & (z > 0.0)].astype(np.float32).astype(np.float64)
    ph = rng.uniform(0, 2 * np.pi, len(z))
    s = np.sqrt(1 - z * z)
    wi = np.stack([s * np.cos(ph), s * np.sin(ph), z], -1).astype(np.float32).astype(np.float64)
    wo = np.stack([-wi[:, 0], -wi[:, 1], rng.uniform(0.05, 1.0, len(z))], -1)  # near the mirror for half the pairs
    wo[::2] = wi[::2] * np.array([-1.0, -1.0, 1.0])
    wo = (wo / np.linalg.norm(wo, axis=1)[:, None]).astype(np.float32).astype(np.float64)
    b = pm.load_dict({"type": "pumpup", "spec": spec})
    got, _ = _plugin_eval(b, wi, wo)
    ref = f.eval(wi, wo) * wi[:, 2]
    assert np.all(got <= ref * (1 + 1e-12))
    assert np.all(np.abs(got - ref) <= (2.0**-23 + F32) * ref + np.finfo(np.float32).tiny)
    assert np.sum(ref > 0) > len(z) // 2


@needs_llvm
def test_level_table_below_mlo_is_the_level_by_level_power_law(rng):
    """Float32 cosines at or below the level table's mlo (down to the smallest float32), paired with any cosine: the
    plugin's branch-free power law against the level-by-level numpy reference (each level's Pumped.g), within the
    error it allows itself (1e-13 per level from the float32 logarithm of the mantissa)."""
    pm.register(LLVM)
    f = pumpup.load(LEVEL_TABLE[1])
    fast = _table_g(f)[0]
    assert fast.below is not None and fast.cheap_log
    low = np.exp(rng.uniform(math.log(1.5e-45), math.log(fast.mlo), 3000)).astype(np.float32).astype(np.float64)
    low = np.concatenate([low[low > 0], [float(np.float32(1e-8)), float(np.finfo(np.float32).smallest_subnormal)]])
    other = np.concatenate([rng.uniform(0.0, 1.0, len(low) // 2), low[: len(low) - len(low) // 2][::-1]])
    other = other.astype(np.float32).astype(np.float64)
    other[other <= 0] = 1e-30
    ref = np.ones(len(low))
    for lev in f.chain():
        ref = ref * lev.g(low, other)
    got = np.array(fast(mi.Float64(low), mi.Float64(other)), dtype=np.float64)
    assert np.all(np.abs(got / ref - 1.0) <= 3 * 1e-13)


def test_table_kernels_scalar_equal_their_numpy_references(rng):
    pm.register("scalar_rgb")
    for spec in (PUMPED[0], LEVEL_TABLE[0]):
        f = pumpup.load(spec)
        fast, t = _table_g(f)
        x = _table_points(t, rng)[::40]
        y = rng.permutation(x)
        ref = t(np.maximum(x, y)) if f.product() is not None else t.g(x, y)
        assert [fast(float(a), float(b)) for a, b in zip(x, y)] == list(ref)
        cell = pm._DrModel(f).fast  # the fixed cells, in scalar variants through their numpy reference
        assert isinstance(cell, pm._CellG)
        x = _cell_points(cell.cells, rng)[::40]
        y = rng.permutation(x)
        assert [cell(float(a), float(b)) for a, b in zip(x, y)] == list(cell.reference(x, y))
        assert [cell.in_bad(float(a), float(b)) for a, b in zip(x, y)] == list(cell.in_bad(x, y))


@needs_llvm
@pytest.mark.parametrize("spec", SPECS[::2], ids=_ids(SPECS[::2]))
def test_pdf_is_pumpups_sampling_density(spec, rng):
    pm.register(LLVM)
    f = pumpup.load(spec)
    b = pm.load_dict({"type": "pumpup", "spec": spec})
    for theta in (0.0, 50.0, 89.0):
        wo = np.array([math.sin(math.radians(theta)), 0.0, math.cos(math.radians(theta))])
        wo = wo.astype(np.float32).astype(np.float64)
        wi, _ = _pairs(400, rng)
        _, pdf = _plugin_eval(b, wi, np.broadcast_to(wo, wi.shape))
        ref = pumpup.sampling.pdf(f, wi, wo)  # at the same float32 directions
        ok = ref > 1e-30
        assert np.allclose(pdf[ok], ref[ok], rtol=F32, atol=0)  # one float32 rounding
        assert np.all(pdf[~ok] <= 1e-30)


def _sample(b, wo, n, seed):
    """n plugin samples at the view direction wo (Mitsuba's si.wi): (bs.wo, bs.pdf, weight[0])."""
    rng = np.random.default_rng(seed)
    u = rng.random((3, n)).astype(np.float32)
    si = dr.zeros(mi.SurfaceInteraction3f, n)
    si.wi = mi.Vector3f(*map(float, wo))
    bs, w = b.sample(mi.BSDFContext(), si, mi.Float(u[0]), mi.Point2f(mi.Float(u[1]), mi.Float(u[2])))
    d = np.stack([np.array(bs.wo.x), np.array(bs.wo.y), np.array(bs.wo.z)], -1).astype(np.float64)
    return d, np.array(bs.pdf, dtype=np.float64), np.array(w, dtype=np.float64), si, bs


#: a level-table chain in the Monte Carlo and chi-square checks (slow: its tables take a minute on a loaded machine)
LEVEL_TABLE_SLOW = [pytest.param(s, id=json.dumps(s, separators=(",", ":"))[:60], marks=pytest.mark.slow)
                    for s in LEVEL_TABLE[:1]]


@needs_llvm
@pytest.mark.parametrize("spec", _split(SPECS) + LEVEL_TABLE_SLOW)
def test_mc_albedo_within_4_standard_errors(spec):
    """Mitsuba Monte Carlo with the plugin's own sample() against pumpup.albedo (reciprocal models:
    the albedo at wo is the albedo at wi)."""
    pm.register(LLVM)
    f = pumpup.load(spec)
    b = pm.load_dict({"type": "pumpup", "spec": spec})
    for k, mu in enumerate((1.0, 0.6, 0.1)):
        wo = np.array([math.sqrt(1 - mu * mu), 0.0, mu], dtype=np.float32)
        d, pdf, w, si, bs = _sample(b, wo, 100_000, seed=17 + k)
        x = w[0]
        est, se = x.mean(), x.std(ddof=1) / math.sqrt(len(x))
        truth = float(pumpup.albedo(f, float(wo[2])))
        assert abs(est - truth) <= 4 * se + 1e-6 * truth, f"mu={mu}: MC {est:.6f} +- {se:.2g}, pumpup {truth:.6f}"
        # the sample's pdf is pdf(bs.wo) and its weight is eval / pdf, at the returned direction
        ok = pdf > 0
        ev, p2 = b.eval_pdf(mi.BSDFContext(), si, bs.wo)
        ev, p2 = np.array(ev, dtype=np.float64), np.array(p2, dtype=np.float64)
        assert np.array_equal(p2[ok], pdf[ok])
        q = ev[:, ok] / pdf[ok]  # three float32 roundings apart; eval may underflow to 0 where the weight does not
        assert np.all(np.abs(w[:, ok] - q) <= 3e-7 * q + np.finfo(np.float32).tiny / pdf[ok])
        assert np.all(w[:, ~ok] == 0)


@pytest.mark.parametrize("spec", [SPECS[1], SPECS[13]], ids=_ids([SPECS[1], SPECS[13]]))
def test_mc_albedo_scalar(spec):
    pm.register("scalar_rgb")
    f = pumpup.load(spec)
    b = pm.load_dict({"type": "pumpup", "spec": spec})
    rng = np.random.default_rng(5)
    mu = 0.6
    si = mi.SurfaceInteraction3f()
    si.wi = mi.Vector3f(math.sqrt(1 - mu * mu), 0.0, mu)
    ctx = mi.BSDFContext()
    xs = []
    for u in rng.random((2000, 3)):
        bs, w = b.sample(ctx, si, float(u[0]), mi.Point2f(float(u[1]), float(u[2])))
        xs.append(w[0])
        if w[0] > 0:
            assert bs.pdf == np.float32(b.pdf(ctx, si, bs.wo))  # Mitsuba stores it in float32
    xs = np.array(xs)
    est, se = xs.mean(), xs.std(ddof=1) / math.sqrt(len(xs))
    assert abs(est - float(pumpup.albedo(f, float(np.float32(mu))))) <= 4 * se


# --- Mitsuba's own chi-square test -------------------------------------------------------------

CHI2_SPECS = [s for s in SPECS if not (s["type"] == "phong" and s["n"] > 1000)]
CHI2_ANGLES = (0.0, 45.0, 80.0)
#: Mitsuba's ChiSquareTest integrates the pdf over each cell by the trapezoid rule on ires^2
#: points; its default ires = 4 misjudges lobes squeezed against the horizon at 80 degrees
#: (Mitsuba's own roughconductor, Beckmann alpha = 0.2 without visible-normal sampling, fails it
#: there too: a cell's expected count 131 where a 400^2-point integral of the pdf gives 84).  The
#: significance (0.01) and the Sidak correction are Mitsuba's defaults.
CHI2_IRES = 16


def _chi2(sample_spec, wi, test_count, pdf_spec=None, ires=CHI2_IRES):
    from mitsuba.chi2 import BSDFAdapter, ChiSquareTest, SphericalDomain

    sf, pf = BSDFAdapter("pumpup", pm.bsdf_dict(sample_spec), wi=wi)
    if pdf_spec is not None:
        _, pf = BSDFAdapter("pumpup", pm.bsdf_dict(pdf_spec), wi=wi)
    ch = ChiSquareTest(domain=SphericalDomain(), sample_func=sf, pdf_func=pf, sample_dim=3, ires=ires, seed=3)
    return ch.run(test_count=test_count, quiet=True), ch


@needs_llvm
@pytest.mark.parametrize("spec", _split(CHI2_SPECS) + LEVEL_TABLE_SLOW)
def test_mitsuba_chi2(spec):
    pm.register(LLVM)
    for theta in CHI2_ANGLES:
        wi = [math.sin(math.radians(theta)), 0.0, math.cos(math.radians(theta))]
        ok, ch = _chi2(spec, wi, test_count=len(CHI2_SPECS) * len(CHI2_ANGLES))
        assert ok, f"theta = {theta}: {ch.messages}"
    _cleanup()


@needs_llvm
@pytest.mark.parametrize("wrong", [
    ({"type": "phong", "n": 20}, {"type": "phong", "n": 23}),  # exponent off
    ({"type": "ggx", "alpha": 0.3}, {"type": "ggx", "alpha": 0.33}),  # roughness off by 10 %
    ({"type": "pumped", "base": {"type": "blinn", "n": 30}, "g": "g1"}, {"type": "lambert"}),  # cosine pdf for a lobe
], ids=["phong-n", "ggx-alpha", "pumped-blinn-cosine"])
def test_mitsuba_chi2_rejects_a_wrong_pdf(wrong):
    pm.register(LLVM)
    ok, ch = _chi2(wrong[0], [math.sin(0.5), 0.0, math.cos(0.5)], test_count=len(CHI2_SPECS) * len(CHI2_ANGLES),
                   pdf_spec=wrong[1])
    assert not ok
    _cleanup()


def _cleanup():
    p = os.path.join(os.getcwd(), "chi2_data.py")  # Mitsuba's ChiSquareTest dumps failing tables here
    if os.path.exists(p):
        os.remove(p)


# --- the probe and the fallback -----------------------------------------------------------------


@pytest.mark.skipif(not os.path.exists(LLVM15), reason=f"needs {LLVM15} (Dr.Jit 1.5 aborts on it)")
def test_probe_detects_libllvm15_and_falls_back_to_scalar():
    """Dr.Jit 1.5 on libLLVM 15 aborts the process at the first kernel; register() must survive."""
    code = ("import pumpup.mitsuba as pm, mitsuba as mi\n"
            "v = pm.register()\n"
            "b = pm.load_dict({'type': 'pumpup', 'spec': {'type': 'phong', 'n': 20}})\n"
            "si = mi.SurfaceInteraction3f(); si.wi = mi.Vector3f(0, 0, 1)\n"
            "print('VARIANT', v, b.eval(mi.BSDFContext(), si, mi.Vector3f(0, 0, 1))[0])\n")
    r = _run(code, env={"DRJIT_LIBLLVM_PATH": LLVM15})
    assert r.returncode == 0, r.stderr
    assert r.stdout.split()[:2] == ["VARIANT", "scalar_rgb"]
    assert abs(float(r.stdout.split()[2]) - 22 / (2 * math.pi)) < 1e-5
    lines = [ln for ln in r.stderr.splitlines() if ln.startswith("pumpup.mitsuba:")]
    assert len(lines) == 1 and "SIGABRT" in lines[0] and "libllvm19" in lines[0]


def test_probe_of_a_missing_library_fails_cleanly():
    r = _run("import pumpup.mitsuba as pm; ok, why = pm.probe('llvm_ad_rgb'); print(ok); print(why)",
             env={"DRJIT_LIBLLVM_PATH": "/nonexistent/libLLVM.so"})
    assert r.returncode == 0, r.stderr
    out = r.stdout.splitlines()
    assert out[0] == "False" and "exited with status" in out[1]


def test_probe_of_scalar_and_unknown_variants():
    assert pm.probe("scalar_rgb") == (True, "")
    ok, why = pm.probe("no_such_variant")
    assert not ok and "no variant" in why


# --- specs and errors ---------------------------------------------------------------------------


def test_spec_forms_and_errors():
    pm.register("scalar_rgb")
    si = mi.SurfaceInteraction3f()
    si.wi = mi.Vector3f(0, 0, 1)
    ctx = mi.BSDFContext()
    w = mi.Vector3f(0, 0.6, 0.8)
    ref = pumpup.load({"type": "phong", "n": 20}).eval([0, 0.6, 0.8], [0, 0, 1]) * 0.8
    for d in ({"type": "pumpup", "spec": json.dumps({"type": "phong", "n": 20})},
              {"type": "pumpup", "spec": "phong:n=20"},
              {"type": "pumpup", "model": "phong", "n": 20},
              pm.bsdf_dict(pumpup.load({"type": "phong", "n": 20}))):
        assert abs(mi.load_dict(d).eval(ctx, si, w)[0] / ref - 1) < 1e-6
    with pytest.raises(RuntimeError, match="minnaert"):  # Mitsuba wraps the SpecError
        pm.load_dict({"type": "pumpup", "spec": {"type": "minnaert", "k": 1.0}})
    with pytest.raises(RuntimeError, match="'n'"):
        pm.load_dict({"type": "pumpup", "spec": {"type": "phong", "n": -1}})
    with pytest.raises(RuntimeError, match="needs a 'spec'"):
        mi.load_dict({"type": "pumpup"})
    with pytest.raises(TypeError, match="spec must be"):
        pm.bsdf_dict(3)


def test_rgb_list_spec_gives_one_model_per_channel():
    pm.register("scalar_rgb")
    from pumpup.models.metal import per_channel

    gold = per_channel("metal", n=200, eta=[0.18, 0.42, 1.37], k=[3.42, 2.35, 1.77])
    b = pm.load_dict({"type": "pumpup", "spec": [g.spec for g in gold]})
    si = mi.SurfaceInteraction3f()
    si.wi = mi.Vector3f(0.6, 0, 0.8)
    v = b.eval(mi.BSDFContext(), si, mi.Vector3f(-0.6, 0, 0.8))
    x, z = float(np.float32(0.6)), float(np.float32(0.8))  # the float32 directions Mitsuba holds
    for c in range(3):
        ref = gold[c].eval([-x, 0, z], [x, 0, z]) * z
        assert abs(v[c] / ref - 1) <= F32


def test_ward_aniso_uses_the_shading_frame_tangent():
    """ax is along Mitsuba's local x (the frame's tangent s): a half vector tilted along x falls off
    with ax, along y with ay."""
    pm.register("scalar_rgb")
    spec = {"type": "ward_aniso", "ax": 0.1, "ay": 0.3}
    b = pm.load_dict({"type": "pumpup", "spec": spec})
    f = pumpup.load(spec)
    si = mi.SurfaceInteraction3f()
    ctx = mi.BSDFContext()
    for axis in (0, 1):
        v = np.array([0.0, 0.0, 1.0])
        light = np.array([0.0, 0.0, 1.0])
        light[axis] = 0.3
        light /= np.linalg.norm(light)
        si.wi = mi.Vector3f(*v)
        got = b.eval(ctx, si, mi.Vector3f(*map(float, light)))[0]
        assert abs(got / (f.eval(light.astype(np.float32).astype(float), v) * np.float32(light[2])) - 1) < 1e-6
    assert f.eval([0.3, 0, 1] / np.linalg.norm([0.3, 0, 1]), [0, 0, 1]) < f.eval(
        [0, 0.3, 1] / np.linalg.norm([0.3, 0, 1]), [0, 0, 1])


# --- Mitsuba's BSDFs in pumpup --------------------------------------------------------------------


@needs_llvm
def test_from_mitsuba_roughconductor_is_pumpups_ggx_and_beckmann(rng):
    for dist, spec in (("ggx", {"type": "ggx", "alpha": 0.3}),
                       ("beckmann", {"type": "beckmann", "alpha": 0.3, "g1": "walter"})):
        m = pm.from_mitsuba({"type": "roughconductor", "distribution": dist, "alpha": 0.3}, variant=LLVM)
        f = pumpup.load(spec)
        wi, wo = _pairs(400, rng)
        a, b = m.eval(wi, wo), f.eval(wi, wo)
        ok = b > 1e-20
        assert np.allclose(a[ok], b[ok], rtol=2e-5)  # Mitsuba's float32 evaluation
        assert np.all(a[~ok] <= 1e-20)


@needs_llvm
def test_from_mitsuba_diffuse_albedo_and_reciprocity():
    m = pm.from_mitsuba({"type": "diffuse", "reflectance": {"type": "rgb", "value": [0.2, 0.5, 0.8]}}, channel=1,
                        variant=LLVM)
    a, err = pumpup.albedo(m, [1.0, 0.3, 1e-3], return_error=True, rtol=1e-6)
    assert np.all(np.abs(a - 0.5) <= err + 1e-7)  # float32 reflectance: 0.5 exactly; 1 / pi in float32
    # Mitsuba evaluates f cos in float32, and from_mitsuba divides the cosine out: reciprocal to
    # float32 rounding only (two roundings each way), not to pumpup's 1e-12
    r = pumpup.check_reciprocity(m)
    assert 0 < r.max_rel_error <= 4 * 2.0**-24
    with pytest.raises(ValueError, match="channel"):
        pm.from_mitsuba({"type": "diffuse"}, channel=3, variant=LLVM)


def test_parameters_beyond_float32_are_refused_in_one_line():
    """Mitsuba evaluates in float32: a parameter or a peak value beyond 3.4e38 would give inf radiance, unsaid."""
    from pumpup import mitsuba as M

    with pytest.raises(pumpup.SpecError, match="parameter 'c' = 1e\\+40 is beyond float32"):
        M._DrModel(pumpup.load({"type": "phong", "n": 20, "c": 1e40}))
    with pytest.raises(pumpup.SpecError, match="at its peak, beyond float32"):  # (c / cos 45 deg at the mirror)
        M._DrModel(pumpup.load({"type": "stretched_phong", "n": 2000, "c": 3e38}))
    M._DrModel(pumpup.load({"type": "phong", "n": 20, "c": 3e38}))  # (c at its peak: within float32)
