"""Calibration of the pumped Phong-family path's error estimate (pumpup/engine/polar.py, ``CHAIN_SAFETY``).

For 15 pumped chains (g1 and g2, 1-4 levels, n from 0.5 to 5000, p in {0, 0.5, 1}, retro) and mu from
1e-10 to 1 (a geometric grid, a few round values, and every ``--stride``-th of the 300 thetas of
tables/pumping_figures.nc), the 1-D path about N at rtol 1e-6 ... 1e-12 against the nested engine at
rtol 1e-13 on the same BRDFs (``pumpup.engine.polar.albedo_1d`` switched off; the chains' tables are built once, by the
1-D path, so both engines integrate the same BRDF).  Prints, per chain and rtol, the largest
|value - reference| / (estimate + reference's estimate), and the worst over all; a value above 1 is a
miss of one of the two.

    python scripts/calibration/pumped_calibration.py              # every third theta of the figures (a few minutes)
    python scripts/calibration/pumped_calibration.py --stride 1   # all of them
    python scripts/calibration/pumped_calibration.py --nframe     # pumped GGX, Beckmann and Schlick models instead (frame 6 about
                                                      # N divided by g, pumpup.engine.normal_frame._integrate_n):
                                                      # their estimate is the larger of QUADPACK's calibration
                                                      # and CHAIN_SAFETY |K - G|
    python scripts/calibration/pumped_calibration.py --scaled     # 1/E-scaled GGX, Beckmann and Schlick models (frame 6 times
                                                      # Turquin's factor 1 + F0 (1 / U(N.wo) - 1)), the
                                                      # same estimate
"""

import argparse
import time

import numpy as np

import pumpup
from pumpup.engine import polar as _polar

CHAINS = [({"type": "phong", "n": 20}, "g2", 2), ({"type": "phong", "n": 20}, "g2", 3),
          ({"type": "stretched_phong", "n": 20}, "g1", 2), ({"type": "phong", "n": 200}, "g2", 2),
          ({"type": "stretched_phong", "n": 3}, "g1", 3), ({"type": "phong", "n": 2000}, "g1", 1),
          ({"type": "stretched_phong", "n": 20, "p": 0.5}, "g2", 2), ({"type": "retro", "n": 10}, "g1", 2),
          ({"type": "stretched_phong", "n": 5000}, "g2", 2), ({"type": "phong", "n": 1}, "g2", 2),
          ({"type": "stretched_phong", "n": 0.5}, "g1", 2), ({"type": "stretched_phong", "n": 20, "p": 0.0}, "g2", 3),
          ({"type": "phong", "n": 20}, "g1", 4), ({"type": "phong", "n": 5}, "g2", 2),
          ({"type": "stretched_phong", "n": 1000}, "g1", 2)]
#: pumped microfacet models (frame 6 divided by g)
N_CHAINS = [({"type": "ggx", "alpha": 0.1, "shadowing": "correlated"}, "g2", 2), ({"type": "ggx", "alpha": 0.5}, "g1", 1),
            ({"type": "ggx", "alpha": 0.02}, "g2", 1), ({"type": "ggx", "alpha": 0.3}, "g1", 3),
            ({"type": "ggx", "alpha": 1.0}, "g2", 1), ({"type": "beckmann", "alpha": 0.3}, "g2", 2),
            ({"type": "beckmann", "alpha": 0.05, "g1": "walter"}, "g1", 1), ({"type": "beckmann", "alpha": 0.8}, "g2", 3),
            ({"type": "schlick", "r": 0.2}, "g1", 2), ({"type": "schlick", "r": 0.01}, "g2", 2)]
#: 1/E-scaled microfacet models (frame 6 times Turquin's factor; the F0 of each in place of g, levels 0)
S_CHAINS = [({"type": "ggx", "alpha": 0.3}, 1.0, 0), ({"type": "ggx", "alpha": 0.02, "shadowing": "correlated"}, 1.0, 0),
            ({"type": "ggx", "alpha": 1.0}, 0.5, 0), ({"type": "beckmann", "alpha": 0.1}, 1.0, 0),
            ({"type": "beckmann", "alpha": 0.6, "g1": "walter"}, 0.04, 0), ({"type": "schlick", "r": 0.2}, 1.0, 0),
            ({"type": "schlick", "r": 0.001}, 0.7, 0), ({"type": "ggx", "alpha": 0.001}, 1.0, 0),
            ({"type": "beckmann", "alpha": 0.01}, 0.3, 0), ({"type": "ggx", "alpha": 0.6, "shadowing": "correlated"}, 0.9, 0)]
RTOLS = (1e-6, 1e-8, 1e-10, 1e-11, 1e-12)


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--stride", type=int, default=3, help="every k-th of the figures' 300 thetas")
    ap.add_argument("--nframe", action="store_true", help="the pumped microfacet models (frame 6) instead")
    ap.add_argument("--scaled", action="store_true", help="the 1/E-scaled microfacet models (frame 6) instead")
    args = ap.parse_args(argv)
    chains = S_CHAINS if args.scaled else (N_CHAINS if args.nframe else CHAINS)
    figure_mu = np.cos(np.radians(np.linspace(0, 89.9, 300)))[::args.stride]
    mu = np.unique(np.concatenate([np.geomspace(1e-10, 1, 40), [0.1, 0.3, 0.5, 0.7, 0.9, 0.99, 0.9999, 1e-8, 5e-9,
                                                                  0.8494679351215211], figure_mu]))
    print(f"{len(chains)} chains x {len(mu)} mu; reference: the nested engine at rtol 1e-13")
    worst = 0.0
    t0 = time.perf_counter()
    for spec, g, levels in chains:
        if args.scaled:
            f = pumpup.load({"type": "scaled", "base": spec, "f0": g})
        else:
            f = pumpup.pump(spec, g=g, levels=levels)
            for lev in f.chain():
                lev.lookup()
        albedo_1d = _polar.albedo_1d
        _polar.albedo_1d = lambda *a, **k: None  # the nested engine
        try:
            ref, ref_err = pumpup.albedo(f, mu, return_error=True, rtol=1e-13)
        finally:
            _polar.albedo_1d = albedo_1d
        line = f"{str(spec):60s} " + (f"F0 {g}:" if args.scaled else f"{g} x {levels}:")
        for rtol in RTOLS:
            v, e, _, _ = _polar.albedo_1d(f, mu, rtol, 0.0, 10000)
            q = float(np.max(np.abs(v - ref) / (e + ref_err)))
            worst = max(worst, q)
            line += f"  {rtol:.0e} {q:5.2f}"
        print(line, flush=True)
    print(f"worst |value - reference| / (summed estimates): {worst:.2f}  ({time.perf_counter() - t0:.0f} s)")


if __name__ == "__main__":
    main()
