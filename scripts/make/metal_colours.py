#!/usr/bin/env python
"""The sRGB colours of the metals of pumpup.spectral.optical: normal-incidence F0 and mean albedo.

Linear sRGB (CIE 1931 2-degree observer, D65) of
* F0 at the 8 default wavelengths (400-680 nm by 40 nm, the SpectralMetal default),
* F0 at every 5 nm from 380 to 780 nm (the dense spectrum, as a check of the 8-sample colour),
* the mean albedo 2 int a(mu) mu dmu (000 eq. 33) of the eq. 28 metal with n = 20, 8 wavelengths,
beside the published linear sRGB F0 ("BaseColor") values of the Unreal Engine 4 documentation,
"Physically Based Materials", table "Measured BaseColors for metals" (Epic Games).

    python scripts/make/metal_colours.py [--out tables] [--read]   # about 1-2 min on one free core

Writes them to ``OUT/metal_colours.json``, which docs/user-guide/spectral.md reads when the site is built, and
prints the page's Markdown table (:func:`markdown`); ``--read`` prints the table of the stored file.
"""

from __future__ import annotations

import os
import sys

sys.path.insert(0, os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__)))))  # this checkout
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))  # stored_json, beside this script

import numpy as np  # noqa: E402
import stored_json  # noqa: E402

from pumpup import spectral  # noqa: E402
from pumpup.spectral import optical  # noqa: E402
from pumpup.tables.provenance import source_commit  # noqa: E402

PUBLISHED = {  # Unreal Engine 4 documentation, "Physically Based Materials", linear sRGB
    "Au": (1.000, 0.766, 0.336), "Ag": (0.972, 0.960, 0.915), "Cu": (0.955, 0.637, 0.538),
    "Al": (0.913, 0.921, 0.925), "Cr": (0.550, 0.556, 0.554), "Ni": (0.660, 0.609, 0.526),
    "Ti": (0.542, 0.497, 0.449), "Fe": (0.560, 0.570, 0.580), "Pt": (0.672, 0.637, 0.585),
}
COLUMNS = (("dataset", "dataset"), ("F0, 8 wavelengths", "f0_8"), ("F0, 5 nm", "f0_dense"),
           ("F0 encoded sRGB", "f0_encoded"), ("mean albedo n = 20", "mean_albedo"), ("published F0", "published"))


def run() -> dict:
    """The colours of every metal of :func:`pumpup.spectral.optical.known_materials`."""
    dense = np.arange(380.0, 781.0, 5.0)
    out = {"commit": source_commit(), "metals": {}}
    for m in optical.known_materials():
        s = spectral.SpectralMetal(m, n=20)
        n, k = optical.constants(m, dense)

        def rgb(values, wavelengths, encoded=False):
            return [float(x) for x in spectral.to_srgb(values, wavelengths, encoded=encoded)]

        out["metals"][m] = {
            "dataset": optical.MATERIALS[m][2],
            "f0_8": rgb(s.fresnel_normal(), s.wavelengths),
            "f0_dense": rgb(((n - 1) ** 2 + k**2) / ((n + 1) ** 2 + k**2), dense),
            "f0_encoded": rgb(s.fresnel_normal(), s.wavelengths, encoded=True),
            "mean_albedo": rgb(s.mean_albedo(rtol=1e-7), s.wavelengths),
            "published": list(PUBLISHED[m]),
        }
        print(m, "done", file=sys.stderr, flush=True)
    return out


def _fmt(v) -> str:
    return v if isinstance(v, str) else "(" + ", ".join(f"{x:.3f}" for x in v) + ")"


def markdown(data: dict) -> str:
    """The page's table: one row per metal."""
    lines = ["| metal | " + " | ".join(c for c, _ in COLUMNS) + " |", "|---" * (len(COLUMNS) + 1) + "|"]
    for m, d in data["metals"].items():
        lines.append(f"| {m} | " + " | ".join(_fmt(d[k]) for _, k in COLUMNS) + " |")
    return "\n".join(lines)


def gap(data: dict, a: str, b: str, metals=None) -> float:
    """The largest |a - b| over the channels of ``metals`` (default all) between two colour columns."""
    ms = metals or list(data["metals"])
    return max(abs(x - y) for m in ms for x, y in zip(data["metals"][m][a], data["metals"][m][b]))


if __name__ == "__main__":
    sys.exit(stored_json.main("metal_colours.json", run, markdown, __doc__.splitlines()[0]))
