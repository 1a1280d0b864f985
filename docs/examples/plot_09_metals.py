"""
Measured metals per wavelength
==============================

The metal of 000 eq. 28 with the measured optical constants of gold, silver, copper and aluminium at eight
wavelengths: its albedo, pumped per wavelength (which turns it white), and the colour-keeping pumped metal.
``python scripts/make/make_metals_table.py`` writes ``tables/metals.nc`` (a few minutes); this example draws
``figures/metals.png`` from it with the same function, and computes gold's albedo first.
"""

import os
import tempfile
from pathlib import Path

import pumpup
from pumpup import plots, spectral

gold = spectral.SpectralMetal("Au", n=20)
a, err = gold.albedo([1.0, 0.5, 0.1], return_error=True)
print("wavelengths [nm]:", gold.wavelengths.tolist())
print("albedo of gold, mu = 1, 0.5, 0.1:\n", a.round(4), "\nlargest error estimate", float(err.max()))
print("linear sRGB of F0:", spectral.to_srgb(gold.fresnel_normal(), gold.wavelengths).round(3))

# %%
ds = pumpup.open_table(Path(pumpup.__file__).resolve().parents[1] / "tables" / "metals.nc")
plots.show(plots.metals(ds, os.path.join(tempfile.mkdtemp(), "metals.png")))
