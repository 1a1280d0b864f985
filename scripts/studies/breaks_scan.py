"""Is the 1-D path's estimate honest next to the mu where two of its breaks coincide?

In the lobe frame the level's break (u = cos 2 theta_i) and the horizon's (u = s) meet at mu = sqrt(3)/2; in the half
frame the level (u = mu) meets the split of tail and peak at mu = 1/2 and the horizon's break at sqrt(3)/2.  For 22
models of frames 0-5 (Phong family with p in {0.5, 1}, Blinn family, Cook-Torrance, Torrance-Sparrow, Ward, modified
Ward, metal n < 8, GGX and Cook-Torrance with a Fresnel factor), at 180 mu (150 random in theta, 15 on each side of
sqrt(3)/2 and of 1/2 at relative distances 1e-14 ... 1e-3) and rtol 1e-10 and 1e-12, prints the worst ratio
max(|a - ref| - ref_err, 0) / estimate against the nested engine at rtol 1e-13 (``using(engine="nested")``), where
it lies, and the evaluations per mu.  A ratio above 1 is a dishonest estimate (without
``pumpup.engine.outer_rule._foreign_roots``: 4.69 for stretched Phong and retro n = 10 at mu = sqrt(3)/2 (1 - 1e-6)).

    PYTHONPATH=. python scripts/studies/breaks_scan.py     # about 30 s
"""

import math
import time

import numpy as np

import pumpup
from lobe_fresnel_calibration import worst_per_rtol  # (scripts/ is on the path of a script run from it)

RTOLS = (1e-10, 1e-12)
SPECS = ([{"type": "stretched_phong", "n": n} for n in (1, 5, 10, 20, 40, 56, 57, 100)]
         + [{"type": "retro", "n": 10}, {"type": "stretched_phong", "n": 10, "p": 0.5}, {"type": "stretched_blinn", "n": 8},
            {"type": "stretched_blinn", "n": 30}, {"type": "phong_blinn", "n": 20}, {"type": "cook_torrance", "m": 0.3},
            {"type": "cook_torrance", "m": 0.05}, {"type": "torrance_sparrow", "d": "D1", "s": 20},
            {"type": "modified_ward", "m": 0.1}, {"type": "ward", "m": 0.1}, {"type": "metal", "n": 5, "eta": 0.2, "k": 3.0},
            {"type": "metal", "n": 1, "eta": 1.5}, {"type": "ggx", "alpha": 0.3, "ior": 1.5},
            {"type": "cook_torrance", "m": 0.3, "ior": 1.5}])


def main():
    d = np.array([0, 1e-14, 1e-12, 1e-10, 1e-8, 1e-6, 1e-4, 1e-3])
    m0 = math.sqrt(3) / 2
    near = np.r_[m0 * (1 - d), m0 * (1 + d[1:]), 0.5 * (1 - d), 0.5 * (1 + d[1:])]
    rng = np.random.default_rng(1)
    mu = np.sort(np.r_[near, np.cos(rng.uniform(0, np.pi / 2, 150))])
    t0 = time.perf_counter()
    worst = 0.0
    for spec in SPECS:
        out = []
        for rtol, (r, m, ev) in zip(RTOLS, worst_per_rtol(pumpup.load(spec), mu, RTOLS, 0.0)):
            worst = max(worst, r)
            out.append(f"rtol {rtol:g}: {r:5.2f} at mu {m:.10g}, {ev:.0f} evaluations per mu")
        print(f"{str(spec):50s} " + " | ".join(out), flush=True)
    print(f"worst true error / estimate {worst:.3g} ({time.perf_counter() - t0:.0f} s)")


if __name__ == "__main__":
    main()
