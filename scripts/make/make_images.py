"""Regenerate the exact sphere images committed under figures/ (pumpup.render; no renderer), with the functions of
pumpup.plots that the documentation's gallery calls too.

    python scripts/make/make_images.py [--size 160] [--out figures] [--only lewis_fig3 ... furnace]

Writes labelled grids (PNG, tone map stated on each) and prints, for every grid, the numbers
the README quotes (peak radiance per row and light angle; furnace rim and maximum with the
table's error bound).  About 3-6 minutes on 2 cores: the pumped models tabulate their albedo.

Lewis's shaders (002 Figs. 3, 6, 10) are rendered in his units: a directional light of
irradiance E = pi, kd = (1 - k_s) / pi and ks = k_s / pi in pumpup's BRDF parameters, so the
radiance is his eq. 4 with L_d = 1: (1 - k_s)(N.S) + k_s F_s (Fig. 3), and the lobe width is
his half-angle beta, n = -ln 2 / ln cos(beta).  His Figs. 3 and 6 use Blinn's F_s^B; pumpup's
``phong_shader`` and ``lewis_phong`` have Phong's F_s^P (002 eq. 5), so those two grids are
his configuration with Phong's lobe.  Fig. 10 (``phong_blinn``, 002 eq. 24) is his shader.
"""

from __future__ import annotations

import argparse
import os
import sys
import time
import warnings

sys.path.insert(0, os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__)))))  # this checkout's pumpup

import pumpup  # noqa: E402
import pumpup.render as R  # noqa: E402
from pumpup import plots  # noqa: E402

MAKERS = plots.MAKERS  # the figure functions, shared with the documentation's gallery


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--size", type=int, default=160)
    ap.add_argument("--out", default="figures")
    ap.add_argument("--only", nargs="+", choices=sorted(MAKERS))
    args = ap.parse_args(argv)
    R.check_size(args.size)
    os.makedirs(args.out, exist_ok=True)
    warnings.simplefilter("error", pumpup.albedo_module.AlbedoWarning)  # an unconverged table is a failure here
    for name in args.only or MAKERS:
        t = time.perf_counter()
        path = MAKERS[name](args.size, args.out)
        print(f"wrote {path} in {time.perf_counter() - t:.1f} s", flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
