#!/usr/bin/env python
"""The colour of pumped metals: per-wavelength pumping (001 sec. 3) against the colour-keeping variant.

For Au, Cu and Ag at n = 20 and 5000 (8 default wavelengths, 400-680 nm), linear sRGB (CIE 1931 2-degree
observer, D65; :func:`pumpup.spectral.to_srgb`) of the albedo at normal incidence a(1) and of the mean albedo
2 int a(mu) mu dmu (000 eq. 33) of
* the metal of 000 eq. 28 (``SpectralMetal``),
* the metal pumped per wavelength, each by its own g (``SpectralMetal.pump()``, the default),
* the colour-keeping pumped metal (``SpectralPumpedLobe``: the F = 1 lobe pumped once, times F),
all with g1 and one level.

    python scripts/make/pumped_colours.py [--out tables] [--read]   # a few minutes on one free core

Writes them to ``OUT/pumped_colours.json``, which docs/user-guide/spectral.md reads when the site is built, and
prints the page's Markdown table (:func:`markdown`); ``--read`` prints the table of the stored file.
"""

from __future__ import annotations

import os
import sys

sys.path.insert(0, os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__)))))  # this checkout
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))  # stored_json, beside this script

import stored_json  # noqa: E402

from pumpup import spectral  # noqa: E402
from pumpup.tables.provenance import source_commit  # noqa: E402

METALS = ("Au", "Cu", "Ag")
EXPONENTS = (20.0, 5000.0)
VARIANTS = (("eq28", "eq. 28"), ("pumped", "pumped per wavelength"), ("colour_keeping", "colour-keeping pumped"))


def run(rtol: float = 1e-7) -> dict:
    """a(1) and the mean albedo, linear sRGB, of each metal, exponent and variant."""
    rows = []
    for material in METALS:
        for n in EXPONENTS:
            metal = spectral.SpectralMetal(material, n=n)
            w = metal.wavelengths
            row = {"metal": material, "n": n}
            for key, f in (("eq28", metal), ("pumped", metal.pump()),
                           ("colour_keeping", spectral.SpectralPumpedLobe(metal))):
                row[key] = {"a1": [float(x) for x in spectral.to_srgb(f.albedo([1.0])[0], w)],
                            "mean": [float(x) for x in spectral.to_srgb(f.mean_albedo(rtol=rtol), w)]}
            rows.append(row)
            print(material, f"n = {n:g} done", file=sys.stderr, flush=True)
    return {"commit": source_commit(), "rtol": rtol, "rows": rows}


def _fmt(v) -> str:
    return "(" + ", ".join(f"{x:.3f}" for x in v) + ")"


def markdown(data: dict) -> str:
    """The page's table: one row per metal and exponent."""
    lines = ["| metal | n | eq. 28: mean | pumped per wavelength: a(1), mean | colour-keeping pumped: a(1), mean |",
             "|---|---|---|---|---|"]
    for r in data["rows"]:
        lines.append(f"| {r['metal']} | {r['n']:g} | {_fmt(r['eq28']['mean'])} | "
                     f"{_fmt(r['pumped']['a1'])}, {_fmt(r['pumped']['mean'])} | "
                     f"{_fmt(r['colour_keeping']['a1'])}, {_fmt(r['colour_keeping']['mean'])} |")
    return "\n".join(lines)


def brightening(data: dict, n: float = 20.0) -> tuple[float, float]:
    """The smallest and largest gain, in percent, of the colour-keeping variant's mean albedo over the eq. 28
    metal's, over the channels of the metals at exponent ``n``.
    """
    gains = [100 * (k / e - 1) for r in data["rows"] if r["n"] == n
             for k, e in zip(r["colour_keeping"]["mean"], r["eq28"]["mean"])]
    return min(gains), max(gains)


if __name__ == "__main__":
    sys.exit(stored_json.main("pumped_colours.json", run, markdown, __doc__.splitlines()[0]))
