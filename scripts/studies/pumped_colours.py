"""The colour of pumped metals: per-wavelength pumping (001 sec. 3) against the colour-keeping variant.

For Au, Cu and Ag (8 default wavelengths, 400-680 nm) prints linear sRGB (CIE 1931 2-degree
observer, D65; :func:`pumpup.spectral.to_srgb`) of the albedo at normal incidence a(1) and of the
mean albedo 2 int a(mu) mu dmu (000 eq. 33) of
* the metal of 000 eq. 28 (``SpectralMetal``), and its F0 for reference,
* the metal pumped per wavelength, each by its own g (``SpectralMetal.pump()``, the default),
* the colour-keeping pumped metal (``SpectralPumpedLobe``: the F = 1 lobe pumped once, times F).
All with g1 and one level, at the exponents given (default 20 and 5000).

    PYTHONPATH=. python scripts/studies/pumped_colours.py [n ...]     # a few minutes on one free core
"""

import sys
import time

from pumpup import spectral


def fmt(v):
    return "(" + ", ".join(f"{x:.3f}" for x in v) + ")"


def rows(material, n, rtol=1e-7):
    metal = spectral.SpectralMetal(material, n=n)
    w = metal.wavelengths
    variants = [("eq. 28", metal), ("pumped per wavelength", metal.pump()),
                ("colour-keeping pumped", spectral.SpectralPumpedLobe(metal))]
    out = []
    for name, f in variants:
        a1 = f.albedo([1.0])[0]
        mean = f.mean_albedo(rtol=rtol)
        out.append((name, spectral.to_srgb(a1, w), spectral.to_srgb(mean, w), a1))
    return metal, out


def main():
    ns = [float(x) for x in sys.argv[1:]] or [20.0, 5000.0]
    print("| metal | n | model | a(1), linear sRGB | mean albedo, linear sRGB | a(1) at 400 and 680 nm |")
    print("|---|---|---|---|---|---|")
    t0 = time.perf_counter()
    for material in ("Au", "Cu", "Ag"):
        for n in ns:
            metal, out = rows(material, n)
            f0 = spectral.to_srgb(metal.fresnel_normal(), metal.wavelengths)
            print(f"| {material} | {n:g} | F0 | {fmt(f0)} | | |")
            for name, a1, mean, raw in out:
                print(f"| {material} | {n:g} | {name} | {fmt(a1)} | {fmt(mean)} | {raw[0]:.4f}, {raw[-1]:.4f} |")
            sys.stdout.flush()
    print(f"\n({time.perf_counter() - t0:.0f} s)")


if __name__ == "__main__":
    main()
