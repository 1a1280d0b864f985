"""Benchmark: the 000 Fig. 8 scene (pumpup.scenes) at 256 x 256, 64 spp, against the same scene with
Mitsuba's built-in BSDFs, measured in the same run.

    python scripts/bench/bench_scenes.py [--size 256] [--spp 64] [--variant llvm_ad_rgb]

For each panel (reciprocal Phong, stretched Phong) and for the baseline (every material replaced by
Mitsuba's ``roughconductor`` GGX alpha 0.1 with the same colour as its specular reflectance), it
renders twice with the scene's integrator (``pumpup.scenes.INTEGRATOR``: ``pumpup_caustic``): "cold"
includes Dr.Jit's kernel compilation, "warm" reuses the kernel cache.  Prints seconds, the ratio to the
baseline, the variant and the load average (the machine is shared).
"""

from __future__ import annotations

import argparse
import os
import sys
import time

sys.path.insert(0, os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__)))))  # this checkout's pumpup

import pumpup.scenes as S  # noqa: E402


def _builtin(material):
    w, spec = material[0]
    out = {"type": "roughconductor", "distribution": "ggx", "alpha": 0.1}
    if isinstance(spec, list) and all("eta" in s for s in spec):  # a measured metal: the same index per channel
        out["eta"] = {"type": "rgb", "value": [float(s["eta"]) for s in spec]}
        out["k"] = {"type": "rgb", "value": [float(s["k"]) for s in spec]}
    else:
        out["specular_reflectance"] = {"type": "rgb", "value": [float(x) for x in w]}
    return out


def _time(name, mats, size, spp):
    t = time.perf_counter()
    S.render_panel(name, mats, size, spp)
    return time.perf_counter() - t


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--size", type=int, default=256)
    ap.add_argument("--spp", type=int, default=64)
    ap.add_argument("--variant", default="llvm_ad_rgb")
    args = ap.parse_args(argv)
    name = "000-fig8"
    S.check_args(name, args.spp, args.size, args.variant)
    pm, v = S._mitsuba(args.variant)
    print(f"{name}, {args.size} x {args.size}, {args.spp} spp, variant {v}, load {os.getloadavg()[0]:.1f}")
    (orig, new), = S.panels(name)
    plugin = S._bsdf
    try:
        S._bsdf = _builtin
        base = [_time(name, orig[1], args.size, args.spp) for _ in range(2)]
    finally:
        S._bsdf = plugin
    print(f"  {'built-in roughconductor (baseline)':36s} cold {base[0]:6.1f} s  warm {base[1]:6.1f} s")
    for label, mats in (orig, new):
        t = [_time(name, mats, args.size, args.spp) for _ in range(2)]
        print(f"  {label:36s} cold {t[0]:6.1f} s  warm {t[1]:6.1f} s  warm / baseline {t[1] / base[1]:.2f}")
    print(f"load {os.getloadavg()[0]:.1f} (1-minute average; 2 cores)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
