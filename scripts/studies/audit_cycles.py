#!/usr/bin/env python
"""How good is Blender Cycles' shipped GGX albedo table?  pumpup's truth, checked independently.

    python scripts/studies/audit_cycles.py [PATH] [--worst 6] [--png FILE]

Audits ``table_ggx_E`` (32 x 32) and ``table_ggx_Eavg`` of Cycles' ``shader.tables`` with
pumpup (the conventions of ``cycles_precompute.cpp``: mu = clamp(y/31, 1e-4, 1), rough =
clamp(x/31, 1e-4, 1), alpha = rough^2, height-correlated Smith GGX, F = 1), prints the
statistics of table - truth, and recomputes the worst cells (absolute and relative) with
``tests/reference/independent_microfacet.py`` (nested scipy QUADPACK in spherical coordinates; it does
not import pumpup).
"""

from __future__ import annotations

import argparse
import os
import sys
import time

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(os.path.dirname(HERE))
sys.path.insert(0, ROOT)  # this checkout's pumpup

import numpy as np  # noqa: E402

sys.path.insert(0, os.path.join(os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__)))), "tests"))  # tests/reference: the independent references
from reference import independent_microfacet as ind  # noqa: E402
import pumpup  # noqa: E402


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    root = ROOT
    default = os.path.join(root, "tests", "data", "cycles_shader.tables")  # Cycles' shipped tables
    ap.add_argument("path", nargs="?", default=default)
    ap.add_argument("--worst", type=int, default=6)
    ap.add_argument("--rtol", type=float, default=1e-9)
    ap.add_argument("--png")
    args = ap.parse_args()
    if not args.path:
        print("no Cycles table: give its path", file=sys.stderr)
        return 2
    t = time.perf_counter()
    r = pumpup.audit(args.path, preset="cycles", rtol=args.rtol, png=args.png)
    print(f"{r.report()}\n  ({time.perf_counter() - t:.1f} s, load {os.getloadavg()[0]:.1f})")
    d = r.error_map
    print(f"  table - truth over the 1024 nodes: mean {d.mean():+.3g}, rms {np.sqrt(np.mean(d * d)):.3g}, "
          f"max |.| {np.abs(d).max():.3g}; share above the 6-decimal rounding (5e-7): "
          f"{np.mean(np.abs(d) > 5e-7):.1%}")
    rel = np.abs(d) / r.truth
    cells = []
    for arr in (np.abs(d), rel):
        for flat in np.argsort(arr, axis=None)[::-1][:args.worst]:
            cells.append(tuple(int(v) for v in np.unravel_index(flat, d.shape)))
    print("\n  worst cells, recomputed by the independent quadrature (rtol 1e-11):")
    print(f"  {'y':>3s} {'x':>3s} {'mu':>10s} {'rough':>10s} {'shipped':>10s} {'pumpup':>16s} "
          f"{'independent':>16s} {'|pu - ind|':>10s} {'shipped - E':>12s} {'rel':>9s}")
    worst_gap = 0.0
    for i, j in dict.fromkeys(cells):
        mu, rough = r.mu[i], r.rough[j]
        v, e = ind.albedo("ggx", rough * rough, mu, shadowing="correlated", rtol=1e-11)
        gap = abs(v - r.truth[i, j])
        worst_gap = max(worst_gap, gap)
        print(f"  {i:3d} {j:3d} {mu:10.6f} {rough:10.6f} {r.table[i, j]:10.6f} {r.truth[i, j]:16.12f} "
              f"{v:16.12f} {gap:10.2g} {d[i, j]:+12.3g} {abs(d[i, j]) / v:9.2g}")
    print(f"\n  largest |pumpup - independent| over these cells: {worst_gap:.2g}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
