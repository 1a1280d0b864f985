"""Regenerate the path-traced scene images under figures/ (Mitsuba 3 with the pumpup plugin; pumpup.scenes).

    python scripts/make/make_scenes.py [--size 256] [--spp 64] [--out figures] [--only 000-fig8 ...]

Needs the render extra (mitsuba).  Prints the variant, the time per panel (the first pass of a panel
includes Dr.Jit's kernel compilation) and the load average, and, per panel, the mean radiance of the
image and of the objects' rows (what the README quotes).
"""

from __future__ import annotations

import argparse
import os
import sys
import time

sys.path.insert(0, os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__)))))  # this checkout's pumpup

import numpy as np  # noqa: E402

import pumpup.scenes as S  # noqa: E402


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--size", type=int, default=256)
    ap.add_argument("--spp", type=int, default=64)
    ap.add_argument("--out", default="figures")
    ap.add_argument("--variant", default="auto")
    ap.add_argument("--only", nargs="+", choices=sorted(S.SCENES))
    args = ap.parse_args(argv)
    for name in args.only or S.SCENES:
        S.check_args(name, args.spp, args.size, args.variant)
    for name in args.only or S.SCENES:
        t = time.perf_counter()
        v, rows, times = S.render_scene(name, args.spp, args.size, args.variant)
        print(f"{name}: {v}, {args.size} x {args.size}, {args.spp} spp, panels "
              + ", ".join(f"{x:.1f}" for x in times) + f" s; load {os.getloadavg()[0]:.1f}")
        for r in rows:
            for label, im in r:
                y = im @ np.array([0.2126, 0.7152, 0.0722])  # linear sRGB luminance
                lo = y[int(0.85 * y.shape[0]):]  # the bottom 15 % of the rows: the plate only
                print(f"  {label:36s} mean {y.mean():.4f}, 99th percentile {np.percentile(y, 99):.3f}, "
                      f"plate (bottom 15 % of rows) {lo.mean():.4f}")
        paths = S.write_scene(name, rows, args.out, variant=v, spp=args.spp, exr=False)
        print(f"wrote {paths[-1]} in {time.perf_counter() - t:.1f} s", flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
