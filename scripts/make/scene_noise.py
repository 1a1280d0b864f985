"""Where the fireflies of the path-traced scenes come from, and how many samples would remove them.

    python scripts/make/scene_noise.py [--scene 000-fig8] [--size 64] [--spp 256] [--passes 16] [--out figures]

Renders the left panel of ``--scene`` with Mitsuba's path tracer ``path`` ``--passes`` times with ``--spp``
samples per pixel and different seeds
(Mitsuba 3, pumpup's plugin, the scene of :mod:`pumpup.scenes`), and from the spread of the passes estimates,
per pixel, the standard deviation of one sample's luminance (linear sRGB).  Prints its percentiles over the
pixels, the samples per pixel a standard error of 0.01 would need at the 99th percentile, the fireflies
(``make_scenes.fireflies``) of the average of the first 1, 2, 4, ... passes, and the fireflies of the same panel
at 128 x 128 and 64 spp as it is, without its point lights, with a Lambert plate (which of them makes the
fireflies), and rendered by Mitsuba's light tracer ``ptracer`` instead of its path tracer.  Writes the numbers to
``OUT/scene_noise.json``; docs/user-guide/mitsuba.md quotes them.  About a minute on a free 2-core machine.
"""

from __future__ import annotations

import argparse
import json
import os
import sys
import time

sys.path.insert(0, os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__)))))  # this checkout
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))

import numpy as np  # noqa: E402
from make_scenes import LUMINANCE, fireflies  # noqa: E402
from stored_json import write  # noqa: E402

import pumpup.scenes as S  # noqa: E402

#: the panel at 128 x 128 and 64 spp: as it is, without its point lights, with a Lambert plate, and rendered by
#: Mitsuba's light tracer instead of its path tracer
VARIANTS = ("as it is", "without point lights", "Lambert plate", "light tracing (ptracer)")


def _render(d, seed=0):
    import mitsuba as mi

    return np.array(mi.render(mi.load_dict(d), seed=seed), dtype=np.float64)[..., :3] @ LUMINANCE


def main(argv=None) -> int:
    """Measure, print and write ``scene_noise.json``; returns the exit status."""
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--scene", default="000-fig8", choices=sorted(S.SCENES))
    ap.add_argument("--size", type=int, default=64)
    ap.add_argument("--spp", type=int, default=256)
    ap.add_argument("--passes", type=int, default=16)
    ap.add_argument("--out", default="figures")
    a = ap.parse_args(argv)
    S.check_args(a.scene, a.spp, a.size, "auto")
    _, variant = S._mitsuba("auto")
    import mitsuba as mi

    label, mats = S.panels(a.scene)[0][0]
    d = S._scene_dict(a.scene, mats, a.size, a.spp)
    d["integrator"] = dict(S.PATH)  # the path tracer's noise (make_scenes renders 000 Fig. 8 otherwise)
    scene = mi.load_dict(d)
    t = time.perf_counter()
    y = np.stack([np.array(mi.render(scene, seed=k), dtype=np.float64)[..., :3] @ LUMINANCE
                  for k in range(a.passes)])
    seconds = time.perf_counter() - t
    sd = np.sqrt(y.var(axis=0, ddof=1) * a.spp)  # one sample's standard deviation, per pixel
    pct = {q: float(np.percentile(sd, q)) for q in (50, 90, 99, 99.9)}
    need = (pct[99] / 0.01) ** 2
    rate = a.passes * a.spp * a.size ** 2 / seconds
    counts = {}
    k = 1
    while k <= a.passes:
        counts[k * a.spp] = fireflies(y[:k].mean(axis=0))
        k *= 2
    variants = {}
    for how in VARIANTS:
        d = S._scene_dict(a.scene, mats, 128, 64)
        d["integrator"] = dict(S.PATH)
        if how == "without point lights":
            del d["key"], d["fill"]
        elif how == "Lambert plate":
            d["plate"]["bsdf"] = S._bsdf([((0.5, 0.5, 0.5), {"type": "lambert", "albedo": 1.0})])
        elif how == "light tracing (ptracer)":
            d["integrator"] = {"type": "ptracer", "max_depth": d["integrator"]["max_depth"]}
        variants[how] = fireflies(_render(d))
    out = {"scene": a.scene, "panel": label, "variant": variant, "size": a.size, "spp": a.spp, "passes": a.passes,
           "sample_sd_percentiles": {str(q): v for q, v in pct.items()}, "spp_for_0.01_at_p99": need,
           "samples_per_second": rate, "seconds": seconds, "load": os.getloadavg()[0],
           "fireflies_by_spp": {str(n): c for n, c in counts.items()}, "fireflies_128_64spp": variants}
    print(json.dumps(out, indent=1))
    path = os.path.join(a.out, "scene_noise.json")
    write(path, out, sort_keys=True)
    print("wrote", path)
    return 0


if __name__ == "__main__":
    sys.exit(main())
