"""Regenerate the path-traced scene images under figures/ (Mitsuba 3 with the pumpup plugin; pumpup.scenes).

    python scripts/make/make_scenes.py [--size 256] [--spp N] [--out figures] [--only 000-fig8 ...]

Needs the render extra (mitsuba).  Each scene renders at its own sample count (:data:`SPP`) unless ``--spp`` is
given.  Prints the variant, the integrator, the time per panel (the first pass of a panel includes Dr.Jit's
kernel compilation) and the load average, and, per panel, the mean luminance of the image, its 99th
percentile, the mean of the bottom rows (the plate) and the number of fireflies (:func:`fireflies`); writes
them to ``OUT/scenes.json`` (one entry per scene, the others kept), which the documentation quotes.
"""

from __future__ import annotations

import argparse
import os
import sys
import time

sys.path.insert(0, os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__)))))  # this checkout's pumpup

import json  # noqa: E402

import numpy as np  # noqa: E402

import pumpup.scenes as S  # noqa: E402
from pumpup.tables import atomic_path  # noqa: E402

#: samples per pixel of each scene.  000 Fig. 9 and Fig. 10 (plastic plate, n <= 169) converge: at 2048 spp no
#: pixel is a firefly.  000 Fig. 8 and 001 Fig. 8 render with ``pumpup_caustic`` (pumpup.scenes.INTEGRATOR),
#: which reaches their caustics (point light -> one or two near-mirrors, n = 5000 -> a rougher surface) through
#: the mirrors' planes; at 256 spp no pixel of 000 Fig. 8 or of 001 Fig. 8's n = 5000 panels is noise, against
#: about 500 per panel with Mitsuba's path (scripts/make/caustic_check.py).
SPP = {"000-fig8": 256, "000-fig9": 2048, "001-fig8": 256, "000-fig10": 2048}
LUMINANCE = np.array([0.2126, 0.7152, 0.0722])  # linear sRGB


def firefly_mask(y: np.ndarray) -> np.ndarray:
    """The pixels brighter than 1.5 x the median of their 3 x 3 neighbourhood plus 0.1 (linear luminance ``y``): the
    isolated bright pixels of a Monte Carlo image; none in a converged one (edges of highlights are not that abrupt
    at 256 x 256).
    """
    from scipy.ndimage import median_filter

    return y > 1.5 * median_filter(y, 3) + 0.1


def fireflies(y: np.ndarray) -> int:
    """The number of pixels :func:`firefly_mask` marks."""
    return int(firefly_mask(y).sum())


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--size", type=int, default=256)
    ap.add_argument("--spp", type=int, help="samples per pixel of every scene (default: SPP)")
    ap.add_argument("--out", default="figures")
    ap.add_argument("--variant", default="auto")
    ap.add_argument("--only", nargs="+", choices=sorted(S.SCENES))
    args = ap.parse_args(argv)
    for name in args.only or S.SCENES:
        S.check_args(name, args.spp or SPP[name], args.size, args.variant)
    stats_path = os.path.join(args.out, "scenes.json")
    for name in args.only or S.SCENES:
        spp = args.spp or SPP[name]
        t = time.perf_counter()
        v, rows, times = S.render_scene(name, spp, args.size, args.variant)
        load = os.getloadavg()[0]
        print(f"{name}: {v}, {S.integrator_name(name)}, {args.size} x {args.size}, {spp} spp, panels "
              + ", ".join(f"{x:.1f}" for x in times) + f" s; load {load:.1f}")
        panels = {}
        for r in rows:
            for label, im in r:
                y = im @ LUMINANCE
                lo = y[int(0.85 * y.shape[0]):]  # the bottom 15 % of the rows: the plate only
                panels[label] = {"mean": float(y.mean()), "p99": float(np.percentile(y, 99)),
                                 "plate": float(lo.mean()), "fireflies": fireflies(y)}
                print(f"  {label:36s} mean {y.mean():.4f}, 99th percentile {np.percentile(y, 99):.3f}, "
                      f"plate (bottom 15 % of rows) {lo.mean():.4f}, fireflies {panels[label]['fireflies']}")
        paths = S.write_scene(name, rows, args.out, variant=v, spp=spp, exr=False)
        stats = {}
        if os.path.exists(stats_path):
            with open(stats_path) as fh:
                stats = json.load(fh)
        stats[name] = {"spp": spp, "size": args.size, "variant": v, "integrator": S.integrator_name(name),
                       "seconds": [round(x, 1) for x in times],
                       "load": round(load, 1), "panels": panels}
        with atomic_path(stats_path) as tmp:
            with open(tmp, "w") as fh:
                json.dump(stats, fh, indent=1, sort_keys=True)
        print(f"wrote {paths[-1]} and {stats_path} in {time.perf_counter() - t:.1f} s", flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
