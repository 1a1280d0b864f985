"""Where pumped Phong's eval time goes: Phong's own kernel, pumpup's fused pumped kernel and variants of the fused
kernel with one part of its work taken out (the results of those variants are wrong; only their cost matters).

    python scripts/bench/bench_eval_parts.py [--pairs 1048576] [--repeat 15] [--levels 1 3]

g2 pumped Phong n = 20, 2^20 pairs with both cosines uniform (every lit pair is then one the product table serves:
checked).  Every kernel runs once per round, timed by this thread's CPU time, best of the rounds, as a ratio to
Phong's kernel (``_phong_rows``) in the same rounds.  The lines:

- ``pumpup``: the kernel ``Pumped.eval`` runs (:func:`pumpup.models.phong._phong_divided`);
- ``variant, all parts``: this script's copy of its product-table path (Phong's value times the table's 1 / G),
  checked equal to ``pumpup`` bit for bit;
- ``divide by G``: the value divided by the table's G instead (as the kernel did before it read 1 / G);
- ``times max cosine``: the look-up replaced by max(N.wi, N.wo) (its cost is the difference);
- ``no look-up, no product``: Phong's value and the gathering of the lit rows alone.
"""

from __future__ import annotations

import argparse
import os
import sys
import time

import numpy as np
from numba import njit

import pumpup
from pumpup.models.phong import _DIVIDED_BLOCK, _lit_cos, _phong_divided, _phong_rows
from pumpup.physics.lookups import g_product

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))  # bench_eval, beside this script
from bench_eval import directions  # noqa: E402

MODES = ("variant, all parts", "divide by G", "times max cosine", "no look-up, no product")


def _variant(mode: int):
    """The product-table path of ``_phong_divided`` with part ``mode`` of MODES taken out (0: none)."""

    @njit(nogil=True)
    def kernel(wi, wo, out, n, c, pmlo, pcbase, pcell, plo, prow, pinv):  # pragma: no cover - compiled
        x = np.empty(_DIVIDED_BLOCK)
        mm = np.empty(_DIVIDED_BLOCK)
        rows = np.empty(_DIVIDED_BLOCK, dtype=np.int64)
        y = np.empty(_DIVIDED_BLOCK)
        mc = np.empty(_DIVIDED_BLOCK)
        gk = np.empty(_DIVIDED_BLOCK)
        for s in range(0, out.shape[0], _DIVIDED_BLOCK):
            m = min(out.shape[0] - s, _DIVIDED_BLOCK)
            a, b, f = wi[s : s + m], wo[s : s + m], out[s : s + m]
            for r in range(m):
                x[r] = _lit_cos(a[r, 0], a[r, 1], a[r, 2], b[r, 0], b[r, 1], b[r, 2])
                mm[r] = max(a[r, 2], b[r, 2])
                f[r] = 0.0
            q = 0
            for r in range(m):
                rows[q] = r
                y[q] = x[r]
                mc[q] = mm[r]
                q += (x[r] > 0.0) | (x[r] != x[r])
            for j in range(q):
                if mode == 0:
                    gk[j] = g_product(mc[j], pcbase, pcell, plo, pinv)
                elif mode == 1:
                    gk[j] = g_product(mc[j], pcbase, pcell, plo, prow)
                else:
                    gk[j] = mc[j]
            for j in range(q):
                fr = c * y[j] ** n
                if mode == 1:
                    f[rows[j]] = fr / gk[j]
                elif mode == 3:
                    f[rows[j]] = fr
                else:
                    f[rows[j]] = fr * gk[j]

    return kernel


def main():
    """Time Phong, pumpup's pumped kernel and the variants, and print their ratios to Phong."""
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--pairs", type=int, default=1 << 20)
    ap.add_argument("--repeat", type=int, default=15)
    ap.add_argument("--levels", type=int, nargs="+", default=[1, 3])
    opt = ap.parse_args()
    rng = np.random.default_rng(1)
    wi, wo = directions(rng, opt.pairs), directions(rng, opt.pairs)
    phong = pumpup.load({"type": "phong", "n": 20})
    variants = [_variant(k) for k in range(len(MODES))]
    for levels in opt.levels:
        chain = pumpup.pump({"type": "phong", "n": 20}, g="g2", levels=levels)._chain_args()
        if not np.min(np.minimum(wi[:, 2], wo[:, 2])) > chain.product_mlo:
            raise SystemExit("a pair has a cosine below the product table: draw again")
        args = (*phong.kernel_args(), *chain)
        table = (*phong.kernel_args(), chain.product_mlo, chain.product_cbase, chain.product_cell, chain.product_lo,
                 chain.product_rows, chain.product_inverse_rows)
        fns = {"Phong": lambda o: _phong_rows(wi, wo, o, False, 0.0, 2.0, *phong.kernel_args()),
               "pumpup": lambda o: _phong_divided(wi, wo, o, *args)}
        for label, kernel in zip(MODES, variants):
            fns[label] = lambda o, kernel=kernel: kernel(wi, wo, o, *table)
        got = {}
        for label, fn in fns.items():
            got[label] = np.empty(opt.pairs)
            fn(got[label])
        if not np.array_equal(got["pumpup"], got[MODES[0]]):
            raise SystemExit("the variant with all parts differs from pumpup's kernel")
        best = dict.fromkeys(fns, np.inf)
        for _ in range(opt.repeat):
            for label, fn in fns.items():
                out = np.empty(opt.pairs)
                t = time.thread_time()
                fn(out)
                best[label] = min(best[label], time.thread_time() - t)
        print(f"g2 pumped Phong n = 20, {levels} level{'s' * (levels > 1)}, {opt.pairs} pairs, best of {opt.repeat}:")
        for label, secs in best.items():
            print(f"  {label:28s} {secs / best['Phong']:6.3f} x Phong  {secs / opt.pairs * 1e9:6.2f} ns per pair")


if __name__ == "__main__":
    main()
