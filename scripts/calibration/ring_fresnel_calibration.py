"""Calibration of frame 6 with a Fresnel factor (pumpup.engine.normal_frame._ggx_ring_f).

1. The ring: GGX's D times F(wi.h) over the azimuth of wo, for 7 indices (a dielectric near 1 and at 1.5 and 3; a metal, a
   strong absorber whose pole lies near c = 0, a weak absorber, a conductor with eta < 1), 6 alpha from 1e-4 to 1, 9 mu from
   N_FRESNEL_MU_MIN to 1 and 31 elevations x, at itol 1e-6 ... 1e-13: the true error / the estimate against the kernel's
   own 129-sample rule without a tolerance (checked against scipy's quadrature of D F, ``ring_reference``, on every
   tenth ring: the largest relative difference is printed).
2. The albedo: 8 GGX models with F, 24 mu from N_FRESNEL_MU_MIN to 1, rtol 1e-6 ... 1e-12, against frame 4 (the rule on h's
   arc) at rtol 1e-13, both with atol 0 (the glass near 1 reflects ~1e-9): the difference / the estimate, and frame 4's
   error / the estimate.

    PYTHONPATH=. python scripts/calibration/ring_fresnel_calibration.py
"""

import math
import time
import warnings

import numpy as np

import pumpup
from pumpup.engine import half_arc as _half_arc, normal_frame as _normal_frame
from pumpup.engine.routes import hint_routes, using

MATERIALS = [(1.0001, 0.0, 0.0), (1.5, 0.0, 0.0), (3.0, 0.0, 0.0), (0.0, 0.2, 3.0), (0.0, 1.1, 30.0), (0.0, 1.0, 0.1),
             (0.0, 0.6, 1.5)]


def rings():
    fv = np.empty(_normal_frame.RING_F_NMAX + 1)
    worst, worst_at, against_quad, n = 0.0, None, 0.0, 0
    for fr in MATERIALS:
        mp = np.zeros(_half_arc.MP_SIZE)
        mp[5:8] = fr
        for alpha in (1e-4, 0.01, 0.1, 0.3, 0.6, 1.0):
            a2 = alpha * alpha
            for mu in np.linspace(_normal_frame.N_FRESNEL_MU_MIN, 1.0, 9):
                s = math.sqrt((1.0 - mu) * (1.0 + mu))
                xmu, xs = math.atan2(mu, s), math.atan2(s, mu)
                for x in np.linspace(0.0, 0.5 * math.pi, 31):
                    ref = _normal_frame._ggx_ring_f(mp, a2, xmu, xs, x - xmu, 0.0, 0.0, fv)[0]
                    n += 1
                    if n % 10 == 0:
                        q = _normal_frame.ring_reference(1, a2, mu, x, fr)
                        against_quad = max(against_quad, abs(q - ref) / ref if ref > 0 else 0.0)
                    for itol in (1e-6, 1e-8, 1e-10, 1e-12, 1e-13):
                        w, e, _ = _normal_frame._ggx_ring_f(mp, a2, xmu, xs, x - xmu, itol, 0.0, fv)
                        r = abs(w - ref) / e if e > 0 else (0.0 if w == ref else math.inf)
                        if r > worst:
                            worst, worst_at = r, (fr, alpha, round(float(mu), 4), round(float(x), 4), itol)
    return n, worst, worst_at, against_quad


def albedos():
    specs = [{"type": "ggx", "alpha": 0.3, "eta": 0.2, "k": 3.0}, {"type": "ggx", "alpha": 0.02, "ior": 1.5},
             {"type": "ggx", "alpha": 0.5, "shadowing": "correlated", "eta": 1.1, "k": 6.0},
             {"type": "ggx", "alpha": 1e-3, "eta": 1.1, "k": 30.0}, {"type": "ggx", "alpha": 1.0, "ior": 1.0001},
             {"type": "ggx", "alpha": 0.1, "eta": 1.0, "k": 0.1}, {"type": "ggx", "alpha": 0.05, "ior": 3.0},
             {"type": "ggx", "alpha": 0.7, "eta": 0.6, "k": 1.5, "shadowing": "correlated"}]
    mu = np.linspace(_normal_frame.N_FRESNEL_MU_MIN, 1.0, 24)
    rows = []
    for spec in specs:
        f = pumpup.load(spec)
        assert any(r == "normal" for r, _ in hint_routes(f.azimuth_hint(), mu)), spec
        with using(without={"normal", "lobe_normal"}), warnings.catch_warnings():
            warnings.simplefilter("ignore")
            b, eb = pumpup.albedo(f, mu, return_error=True, rtol=1e-13, atol=0.0)
        worst = 0.0
        for rtol in (1e-6, 1e-8, 1e-10, 1e-12):
            a, e = pumpup.albedo(f, mu, return_error=True, rtol=rtol, atol=0.0)
            worst = max(worst, float(np.max(np.abs(a - b) / e)))
        rows.append((spec, worst, float(np.max(eb / e))))
    return rows


def main():
    t = time.perf_counter()
    n, worst, at, quad = rings()
    print(f"rings: {n} x 5 itol; worst true error / estimate {worst:.3g} at {at}; the 129-sample reference against scipy's "
          f"quadrature: at most {quad:.2g} relative ({time.perf_counter() - t:.0f} s)")
    t = time.perf_counter()
    for spec, worst, ref in albedos():
        print(f"  {spec}: worst |frame 6 - frame 4| / estimate {worst:.3g} (frame 4's error / the estimate at most {ref:.2g})")
    print(f"albedos ({time.perf_counter() - t:.0f} s)")


if __name__ == "__main__":
    main()
