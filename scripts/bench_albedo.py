"""The albedo engine against scipy.integrate.dblquad, side by side in one run.

Measures, on this machine:
1. a 257-point table of stretched Phong n = 5000 (the paper's silver mirror) to rtol 1e-8;
2. pumpup against dblquad on the same model and accuracy (the time per albedo value, and the
   ratio), for stretched Phong n = 20 and n = 5000;
3. a generic ``from_function`` BRDF (a hand-written Phong n = 20) tabulated on 257 points
   to rtol 1e-6 by the generic adaptive cubature.

    python scripts/bench_albedo.py
"""

import time

import numpy as np
from scipy.integrate import dblquad

import pumpup


def dblquad_albedo(f, mu, epsrel):
    """Plain dblquad over (theta_o, phi_o) with the BRDF's numpy reference, as a user would."""
    s = np.sqrt(1 - mu * mu)
    wi = np.array([s, 0.0, mu])

    def g(ph, th):
        wo = np.array([np.sin(th) * np.cos(ph), np.sin(th) * np.sin(ph), np.cos(th)])
        return float(f.reference(wi, wo)) * np.cos(th) * np.sin(th)

    v, e = dblquad(g, 0, np.pi / 2, 0, 2 * np.pi, epsabs=0, epsrel=epsrel)
    return v, e


def main():
    mu = np.cos(np.linspace(0, np.pi / 2, 258)[:-1])
    f = pumpup.load({"type": "stretched_phong", "n": 5000})
    pumpup.albedo(f, 0.5)  # load the compiled kernels
    times = []
    for _ in range(3):
        t = time.perf_counter()
        a, e = pumpup.albedo(f, mu, return_error=True, rtol=1e-8)
        times.append(time.perf_counter() - t)
    print(f"1. 257-point table of stretched Phong n = 5000 to rtol 1e-8: best {min(times):.2f} s, "
          f"median {sorted(times)[1]:.2f} s of 3 (largest relative error estimate {np.max(e / a):.2g})")

    print("2. pumpup against scipy dblquad, same model, same mu, requested relative accuracy 1e-8:")
    for n, mus in [(20, [0.9, 0.5, 0.1]), (5000, [0.5])]:
        g = pumpup.load({"type": "stretched_phong", "n": n})
        for m in mus:
            t = time.perf_counter()
            ref, ref_err = dblquad_albedo(g, m, 1e-8)
            td = time.perf_counter() - t
            t = time.perf_counter()
            for _ in range(5):
                v, err = pumpup.albedo(g, m, return_error=True, rtol=1e-8)
            tp = (time.perf_counter() - t) / 5
            print(f"   n={n:5d} mu={m:4.2f}: dblquad {td:8.3f} s (a={ref:.12f}), pumpup {tp * 1e3:7.2f} ms "
                  f"(a={float(v):.12f} +- {float(err):.1g}); pumpup is {td / tp:7.0f} x faster")

    def phong20(wi, wo):
        rv = 2 * wi[..., 2] * wo[..., 2] - np.sum(wi * wo, axis=-1)
        return 22 / (2 * np.pi) * np.maximum(rv, 0) ** 20

    user = pumpup.from_function(phong20, name="phong20-bench")
    t = time.perf_counter()
    a, e = pumpup.albedo(user, mu, return_error=True, rtol=1e-6)
    tu = time.perf_counter() - t
    exact = pumpup.albedo(pumpup.load({"type": "phong", "n": 20}), mu)
    print(f"3. from_function Phong n = 20, 257 points to rtol 1e-6: {tu:.2f} s "
          f"(largest true relative error {np.max(np.abs(a - exact) / exact):.2g})")


if __name__ == "__main__":
    main()
