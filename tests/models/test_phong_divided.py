"""Pumped Phong's fused kernel (``Phong.eval_divided``, :func:`pumpup.models.phong._phong_divided`): the product
table's rows gathered into contiguous arrays, bit for bit the row-by-row kernel it is measured against
(:func:`pumpup.models.phong._phong_divided_lit`) and the base's value divided by the chain kernel.
"""

import numpy as np
import pytest
from helpers import direction_pairs

import pumpup
from pumpup.models.phong import _DIVIDED_BLOCK, _phong_divided
from pumpup.operators.pumping import _chain_kernel


@pytest.fixture(scope="module", params=[1, 3, 5], ids=lambda k: f"{k}-level")
def pumped(request):
    """g2 pumped Phong n = 20: 1 and 3 levels have a product table, 5 levels the split and level tables."""
    return pumpup.pump({"type": "phong", "n": 20}, g="g2", levels=request.param)


def _many_pairs(rng, n):
    """~n pairs: direction_pairs' random, mirror, mu = 1e-8 and grazing pairs, then near-mirror pairs (wo within
    1e-4 rad of wi's mirror) and pairs with one cosine at the chain tables' lower ends (1e-8 (1 +- 1e-12))."""
    wi, wo = direction_pairs(rng, n)
    k = n // 10
    m = wi[-k:] * np.array([-1.0, -1.0, 1.0]) + rng.normal(scale=1e-4, size=(k, 3))
    wo[-k:] = m / np.linalg.norm(m, axis=-1, keepdims=True)
    edge = np.array([1e-8 * (1 - 1e-12), 1e-8, 1e-8 * (1 + 1e-12), 1.000000000001e-08, 1.000000000002e-08])
    j = np.arange(2000, 2000 + 4 * len(edge))
    mu = np.tile(edge, 4)
    s = np.sqrt((1 - mu) * (1 + mu))
    wi[j] = np.stack([s, np.zeros_like(s), mu], axis=-1)
    return np.ascontiguousarray(wi), np.ascontiguousarray(wo)


def _fused(base, wi, wo, chain):
    """The fused kernel itself, also for a chain without a product table (which ``eval_divided`` sends to the
    row-by-row kernel): so that every case compares two kernels, never one with itself."""
    out = np.empty(len(wi))
    _phong_divided(wi, wo, out, *base.kernel_args(), *chain)
    return out


def test_fused_kernel_is_the_row_by_row_kernel_bit_for_bit(pumped, rng):
    """10^6 random, mirror, near-mirror and grazing pairs (some below the horizon): every value the same bits as
    the row-by-row kernel's and as the base's value divided by the chain kernel."""
    wi, wo = _many_pairs(rng, 1_000_000)
    base = pumped.chain()[0].base
    chain = pumped._chain_args()
    new = _fused(base, wi, wo, chain)
    np.testing.assert_array_equal(new, base._eval_divided_lit(wi, wo, chain))
    np.testing.assert_array_equal(base.eval_divided(wi, wo, chain), new)
    two = np.array(base._eval(wi, wo))
    _chain_kernel(two, wi, wo, *chain)
    np.testing.assert_array_equal(new, two)
    assert np.count_nonzero(new) > 0.4 * len(new)  # the pairs reach the division


@pytest.mark.parametrize("rows", [0, 1, _DIVIDED_BLOCK - 1, _DIVIDED_BLOCK, _DIVIDED_BLOCK + 1])
def test_fused_kernel_at_block_edges(pumped, rng, rows):
    """Arrays shorter than, as long as, and one row longer than a block: the last block's rows all written."""
    wi, wo = _many_pairs(rng, 3 * _DIVIDED_BLOCK)
    wi, wo = wi[-rows:] if rows else wi[:0], wo[-rows:] if rows else wo[:0]
    base = pumped.chain()[0].base
    chain = pumped._chain_args()
    np.testing.assert_array_equal(_fused(base, wi, wo, chain), base._eval_divided_lit(wi, wo, chain))


def test_fused_kernel_blocks_with_and_without_rows_below_the_product_table(pumped, rng):
    """A block whose lit rows the product table all serves (the other rows are then not gathered) beside blocks with
    one such row each, at its first and at its last place (N.wi = 1e-9, below the table's lower end): the same bits as
    the row-by-row kernel."""
    n = 3 * _DIVIDED_BLOCK
    wi, wo = _many_pairs(rng, n)
    wi, wo = wi[:n].copy(), wo[:n].copy()
    for w in (wi, wo):
        w[:, 2] = np.maximum(w[:, 2], 0.05)  # every cosine above the table's mlo
        w /= np.linalg.norm(w, axis=-1, keepdims=True)
    wo[: _DIVIDED_BLOCK] = wi[: _DIVIDED_BLOCK] * np.array([-1.0, -1.0, 1.0])  # lit: mirror pairs
    low = [_DIVIDED_BLOCK, n - 1]
    wo[low] = wi[low] * np.array([-1.0, -1.0, 1.0])
    wi[low] = np.array([np.sqrt(1 - 1e-18), 0.0, 1e-9])
    wo[low] = np.array([-np.sqrt(1 - 1e-18), 0.0, 1e-9])  # the mirror pair at grazing: lit, R.V = 1
    base = pumped.chain()[0].base
    chain = pumped._chain_args()
    new = _fused(base, wi, wo, chain)
    np.testing.assert_array_equal(new, base._eval_divided_lit(wi, wo, chain))
    assert np.all(new[low] > 0) and np.all(new[: _DIVIDED_BLOCK] > 0)


def test_fused_kernel_non_finite_rows(pumped, rng):
    """NaN and inf in the tangent components (R.V NaN or infinite, which the kernel's lit test lets through; the
    cosines stay finite, as BRDF.eval's input check ensures) give what the row-by-row kernel gives."""
    wi, wo = _many_pairs(rng, 4000)
    wi[::7, 0] = np.nan
    wo[3::11, 1] = np.nan
    wi[5::13, 1] = np.inf
    wo[6::17, 0] = -np.inf
    base = pumped.chain()[0].base
    chain = pumped._chain_args()
    new = _fused(base, wi, wo, chain)
    np.testing.assert_array_equal(new, base._eval_divided_lit(wi, wo, chain))
    assert np.isnan(new).any() and np.isinf(new).any()  # the non-finite rows reach the division


def test_pumped_eval_takes_the_fused_kernel(pumped, rng):
    """Pumped._eval returns the fused kernel's values, which match the numpy reference (pumped level by level)."""
    wi, wo = _many_pairs(rng, 3000)
    chain = pumped._chain_args()
    got = pumped._eval(wi, wo)
    np.testing.assert_array_equal(got, pumped.chain()[0].base.eval_divided(wi, wo, chain))
    ref = pumped.reference(wi, wo)
    np.testing.assert_allclose(got, ref, rtol=1e-9, atol=0)
