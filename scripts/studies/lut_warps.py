#!/usr/bin/env python
"""Better tables for the same budget: power warps of the mu and roughness axes (issue 16, item 4).

    python scripts/studies/lut_warps.py [--model ggx] [--preset cycles] [--p 1,1.5,2,3,4] [--q 1,1.5,2,3]

For a 32 x 32 (1024-entry) table read by Cycles' bilinear look-up, every candidate puts the nodes
at mu = (i/31)^p, rough = (j/31)^q (floors 1e-4), with exact nodes, and measures the worst
look-up error against the true E over mu in [1e-4, 1], rough in [0.01, 1] (dense grid of cell
centres + Nelder-Mead refinement, pumpup.luts.lookup_error).  p = q = 1 is the uniform grid.
Prints every candidate and the gain of the best over the uniform grid.
"""

from __future__ import annotations

import argparse
import dataclasses
import os
import sys
import time

sys.path.insert(0, os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__)))))

from pumpup import luts  # noqa: E402


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--model", default="ggx")
    ap.add_argument("--preset", default="cycles")
    ap.add_argument("--p", default="1,1.5,2,3,4", help="exponents of the mu axis")
    ap.add_argument("--q", default="1,1.5,2,3", help="exponents of the roughness axis")
    ap.add_argument("--rtol", type=float, default=1e-7)
    ap.add_argument("--mu-min", type=float, help="smallest mu of the look-up domain (default the preset's, 1e-4)")
    ap.add_argument("--rough-min", type=float, help="smallest roughness of the look-up domain (default 0.01)")
    args = ap.parse_args()
    ps = [float(v) for v in args.p.split(",")]
    qs = [float(v) for v in args.q.split(",")]
    if 1.0 not in ps or 1.0 not in qs:
        print("the grids must contain 1 (the uniform axis) to report the gain", file=sys.stderr)
        return 2
    p = luts.PRESETS[args.preset]
    if args.mu_min is not None:
        p = dataclasses.replace(p, lookup_mu_min=args.mu_min)
    if args.rough_min is not None:
        p = dataclasses.replace(p, lookup_rough_min=args.rough_min)
    t = time.perf_counter()
    res = luts.warp_search(args.model, p, ps, qs, rtol=args.rtol)
    print(f"{args.model}, {p.n_mu} x {p.n_rough} entries, bilinear; look-up domain mu in [{p.lookup_mu_min:g}, 1], "
          f"rough in [{p.lookup_rough_min:g}, 1] ({time.perf_counter() - t:.0f} s, load {os.getloadavg()[0]:.1f})")
    print(f"{'p (mu)':>7s} {'q (rough)':>9s} {'worst error':>12s} {'at mu':>10s} {'rough':>8s} {'rms':>9s}")
    for r in res:
        print(f"{r['p']:7g} {r['q']:9g} {r['max_abs']:12.4g} {r['where'][0]:10.4g} {r['where'][1]:8.4g} "
              f"{r['rms']:9.3g}")
    uni = next(r for r in res if r["p"] == 1.0 and r["q"] == 1.0)
    best = res[0]
    print(f"uniform: worst {uni['max_abs']:.4g}; best p = {best['p']:g}, q = {best['q']:g}: worst "
          f"{best['max_abs']:.4g}, {uni['max_abs'] / best['max_abs']:.1f} x smaller")
    return 0


if __name__ == "__main__":
    sys.exit(main())
