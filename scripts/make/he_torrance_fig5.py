"""The He-Torrance albedo curve of 000 Fig. 5 (sigma_0 = 0.1, tau = 1.7, F = 1) and its energy balance.

000 gives sigma_0 and tau but no wavelength (and says the Fresnel term is taken as 1, "for
silver this is practically true").  HTSG state sigma_0 and tau in micrometres, so the curve
is shown for three visible wavelengths, and for lambda = 1 (sigma_0 and tau read as
multiples of the wavelength).  For each: a(theta) with the engine's error, the specular
(delta) share, the maximum of a over mu in [1e-6, 1] (pumpup.max_albedo), the mean albedo
(000 eq. 33), and the measured reciprocity.

    python scripts/make/he_torrance_fig5.py
"""

import time

import numpy as np

import pumpup

THETA = [0, 30, 45, 60, 70, 75, 80, 85, 88, 89.9]
WAVELENGTHS = [0.4, 0.55, 0.7, 1.0]


def main():
    t0 = time.perf_counter()
    mu = np.cos(np.radians(THETA))
    print("theta [deg]          " + " ".join(f"{t:>8g}" for t in THETA))
    for lam in WAVELENGTHS:
        f = pumpup.load({"type": "he_torrance", "sigma_0": 0.1, "tau": 1.7, "wavelength": lam})
        a, e = pumpup.albedo(f, mu, return_error=True)
        w = f.specular_weight(mu)
        print(f"lambda = {lam:4g} um  a  " + " ".join(f"{v:8.5f}" for v in a))
        print(f"{'':16s}spec " + " ".join(f"{v:8.5f}" for v in w))
        print(f"{'':16s}err  " + " ".join(f"{v:8.1e}" for v in e))
        m = pumpup.max_albedo(f)
        mean, mean_err = pumpup.mean_albedo(f, return_error=True)
        r = pumpup.check_reciprocity(f)
        print(f"{'':16s}max a = {m.albedo:.8f} +- {m.error:.1e} at theta = {m.theta_deg:.3f} deg; "
              f"mean albedo = {mean:.8f} +- {mean_err:.1e}; reciprocity: max rel. asymmetry {r.max_rel_error:.1e} over {r.pairs} pairs")
    print(f"({time.perf_counter() - t0:.0f} s)")


if __name__ == "__main__":
    main()
