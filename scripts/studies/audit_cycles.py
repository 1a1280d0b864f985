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


DEFAULT_TABLE = os.path.join(ROOT, "tests", "data", "cycles_shader.tables")  # Cycles' shipped tables
INDEPENDENT_RTOL = 1e-11


def worst_cells(r, worst: int) -> list[tuple[int, int]]:
    """The ``worst`` cells of largest |table - E| and the ``worst`` of largest relative error, without repeats."""
    d = r.error_map
    cells = []
    for arr in (np.abs(d), np.abs(d) / r.truth):
        for flat in np.argsort(arr, axis=None)[::-1][:worst]:
            cells.append(tuple(int(v) for v in np.unravel_index(flat, d.shape)))
    return list(dict.fromkeys(cells))


def independent_check(r, worst: int = 6) -> dict:
    """pumpup's truth at the worst cells of the audit ``r`` against the independent quadrature.

    Returns ``cells`` (row, column), ``independent`` (its E there) and ``gap``, the largest |pumpup - independent|.
    """
    cells = worst_cells(r, worst)
    values = [ind.albedo("ggx", r.rough[j] ** 2, r.mu[i], shadowing="correlated", rtol=INDEPENDENT_RTOL)[0]
              for i, j in cells]
    gap = max(abs(v - r.truth[i, j]) for (i, j), v in zip(cells, values))
    return {"cells": cells, "independent": values, "gap": float(gap)}


def node_error(r, rtol: float) -> float:
    """The largest error estimate of pumpup's E at the table's nodes, computed at ``rtol``."""
    from pumpup import luts

    return float(luts.truth_grid(r.spec, "alpha", r.mu, r.rough, rtol=rtol)["E_error"].max())


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("path", nargs="?", default=DEFAULT_TABLE)
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
    check = independent_check(r, args.worst)
    print(f"\n  worst cells, recomputed by the independent quadrature (rtol {INDEPENDENT_RTOL:g}):")
    print(f"  {'y':>3s} {'x':>3s} {'mu':>10s} {'rough':>10s} {'shipped':>10s} {'pumpup':>16s} "
          f"{'independent':>16s} {'|pu - ind|':>10s} {'shipped - E':>12s} {'rel':>9s}")
    for (i, j), v in zip(check["cells"], check["independent"]):
        print(f"  {i:3d} {j:3d} {r.mu[i]:10.6f} {r.rough[j]:10.6f} {r.table[i, j]:10.6f} {r.truth[i, j]:16.12f} "
              f"{v:16.12f} {abs(v - r.truth[i, j]):10.2g} {d[i, j]:+12.3g} {abs(d[i, j]) / v:9.2g}")
    print(f"\n  largest |pumpup - independent| over these {len(check['cells'])} cells: {check['gap']:.2g}")
    print(f"  largest error estimate of pumpup's truth at the 1024 nodes (rtol {args.rtol:g}): "
          f"{node_error(r, args.rtol):.2g}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
