"""The sRGB colours of the metals of pumpup.spectral.optical: normal-incidence F0 and mean albedo (README table).

Prints a Markdown table: linear sRGB (CIE 1931 2-degree observer, D65) of
* F0 at the 8 default wavelengths (400-680 nm by 40 nm, the SpectralMetal default),
* F0 at every 5 nm from 380 to 780 nm (the dense spectrum, as a check of the 8-sample colour),
* the mean albedo 2 int a(mu) mu dmu (000 eq. 33) of the eq. 28 metal with n = 20, 8 wavelengths,
beside the published linear sRGB F0 ("BaseColor") values of the Unreal Engine 4 documentation,
"Physically Based Materials", table "Measured BaseColors for metals" (Epic Games).

    python scripts/studies/metal_colours.py            # about 1-2 min on one free core
"""

import numpy as np

from pumpup.spectral import optical
from pumpup import spectral

PUBLISHED = {  # Unreal Engine 4 documentation, "Physically Based Materials", linear sRGB
    "Au": (1.000, 0.766, 0.336), "Ag": (0.972, 0.960, 0.915), "Cu": (0.955, 0.637, 0.538),
    "Al": (0.913, 0.921, 0.925), "Cr": (0.550, 0.556, 0.554), "Ni": (0.660, 0.609, 0.526),
    "Ti": (0.542, 0.497, 0.449), "Fe": (0.560, 0.570, 0.580), "Pt": (0.672, 0.637, 0.585),
}


def fmt(v):
    return "(" + ", ".join(f"{x:.3f}" for x in v) + ")"


def main():
    dense = np.arange(380.0, 781.0, 5.0)
    print("| metal | dataset | F0, 8 wavelengths | F0, 5 nm | F0 encoded sRGB | mean albedo n = 20 | published F0 |")
    print("|---|---|---|---|---|---|---|")
    for m in optical.known_materials():
        s = spectral.SpectralMetal(m, n=20)
        f8 = spectral.to_srgb(s.fresnel_normal(), s.wavelengths)
        n, k = optical.constants(m, dense)
        fd = spectral.to_srgb(((n - 1) ** 2 + k**2) / ((n + 1) ** 2 + k**2), dense)
        enc = spectral.to_srgb(s.fresnel_normal(), s.wavelengths, encoded=True)
        mean = spectral.to_srgb(s.mean_albedo(rtol=1e-7), s.wavelengths)
        print(f"| {m} | {optical.MATERIALS[m][2]} | {fmt(f8)} | {fmt(fd)} | {fmt(enc)} | {fmt(mean)} | {fmt(PUBLISHED[m])} |")


if __name__ == "__main__":
    main()
