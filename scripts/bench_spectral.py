"""Cost of an 8-wavelength metal against one wavelength (issue 19's speed targets: eval <= 3x, tabulate <= 8x).

Baseline and spectral model are timed in the same run (best of several repeats); the ratios are
what to read, the absolute times depend on the load.

    PYTHONPATH=. python scripts/bench_spectral.py
"""

import os
import time

import numpy as np

import pumpup
from pumpup import spectral


def best(fn, repeat=5):
    out = []
    for _ in range(repeat):
        t = time.perf_counter()
        fn()
        out.append(time.perf_counter() - t)
    return min(out)


def main():
    rng = np.random.default_rng(0)
    m = 200_000
    wi = rng.normal(size=(m, 3))
    wo = rng.normal(size=(m, 3))
    wi[:, 2] = np.abs(wi[:, 2])
    wo[:, 2] = np.abs(wo[:, 2])
    wi /= np.linalg.norm(wi, axis=1, keepdims=True)
    wo /= np.linalg.norm(wo, axis=1, keepdims=True)
    s = spectral.SpectralMetal("Au", n=20)
    one = s.models[3]
    s.eval(wi[:10], wo[:10]), one.eval(wi[:10], wo[:10])  # compile
    t1 = best(lambda: one.eval(wi, wo))
    t8 = best(lambda: s.eval(wi, wo))
    t8s = best(lambda: np.stack([f.eval(wi, wo) for f in s.models], -1))
    s.eval_tabulated(wi[:10], wo[:10])
    t8t = best(lambda: s.eval_tabulated(wi, wo))
    print(f"load: {os.getloadavg()[0]:.2f}; eval of {m} pairs")
    print(f"  one wavelength (Metal.eval):            {t1 * 1e3:8.1f} ms")
    print(f"  8 wavelengths, shared geometry:         {t8 * 1e3:8.1f} ms  ratio {t8 / t1:.2f}")
    print(f"  8 wavelengths, 8 separate Metal.eval:   {t8s * 1e3:8.1f} ms  ratio {t8s / t1:.2f}")
    print(f"  8 wavelengths, tabulated F (eq. 28):    {t8t * 1e3:8.1f} ms  ratio {t8t / t1:.2f}"
          f"  (max |F error| {s.fresnel_table()[1]:.1e})")
    mu = np.linspace(0.05, 1.0, 20)
    ta1 = best(lambda: pumpup.albedo(one, mu), repeat=2)
    ta8 = best(lambda: s.albedo(mu), repeat=2)
    print(f"albedo at {mu.size} mu: one wavelength {ta1:.3f} s, 8 wavelengths {ta8:.3f} s, ratio {ta8 / ta1:.2f}")


if __name__ == "__main__":
    main()
