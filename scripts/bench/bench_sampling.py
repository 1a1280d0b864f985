"""Samples per second of pumpup's importance samplers (issue 8: Phong lobe with pdf at 1e7/s/core or better).

For every sampling component: draws per second of ``Strategy.sample`` (random numbers,
compiled sampling and the density of every draw, rejected draws included), on one core,
best of 5 runs of 4e6 draws after a warm-up call (numba compilation is not timed), for a
view direction at 60 degrees.  The baseline, measured in the same run, is the plain numpy
reference (``pumpup.sampling.sample_reference``) on the same uniforms; a third column gives
the Monte Carlo albedo estimator (sampling + BRDF evaluation + weights) for the model.

    python scripts/bench/bench_sampling.py
"""

import math
import time

import numpy as np

import pumpup
from pumpup import sampling as S

N = 4_000_000
CASES = [
    ("phong n=20 (000 eq. 19-22)", {"type": "phong", "n": 20}),
    ("stretched_phong n=20", {"type": "stretched_phong", "n": 20}),
    ("blinn n=20 (half vector)", {"type": "blinn", "n": 20}),
    ("ward m=0.2 (Beckmann)", {"type": "ward", "m": 0.2}),
    ("schlick r=0.1 (GGX)", {"type": "schlick", "r": 0.1}),
    ("lambert (cosine)", {"type": "lambert"}),
]


def best(fn, repeat=5):
    fn()
    t_best = math.inf
    for _ in range(repeat):
        t = time.perf_counter()
        fn()
        t_best = min(t_best, time.perf_counter() - t)
    return t_best


def main():
    mu = 0.5
    wo = np.array([math.sqrt(1 - mu * mu), 0.0, mu])
    print(f"{N:.0e} draws, view at 60 deg, best of 5, one core")
    print(f"{'model':30s} {'sample+pdf [1/s]':>17s} {'numpy ref [1/s]':>16s} {'ratio':>7s} {'mc_albedo [1/s]':>16s}")
    for name, spec in CASES:
        f = pumpup.load(spec)
        st = S.strategy(f, mu)
        rng = np.random.default_rng(0)
        t = best(lambda: st.sample(wo, N, rng))
        (_, kind, k), = st.components

        def ref():
            u = rng.random((2, N))
            S.sample_reference(kind, k, wo, u[0], u[1])

        t_ref = best(ref, repeat=2)
        t_mc = best(lambda: pumpup.mc_albedo(f, mu, N, rng), repeat=2)
        print(f"{name:30s} {N / t:17.3g} {N / t_ref:16.3g} {t_ref / t:7.1f} {N / t_mc:16.3g}")


if __name__ == "__main__":
    main()
