#!/usr/bin/env python
"""The He-Torrance albedo curve of 000 Fig. 5 (sigma_0 = 0.1, tau = 1.7, F = 1) and its energy balance.

000 gives sigma_0 and tau but no wavelength (and says the Fresnel term is taken as 1, "for
silver this is practically true").  HTSG state sigma_0 and tau in micrometres, so the curve
is shown for three visible wavelengths, and for lambda = 1 (sigma_0 and tau read as
multiples of the wavelength).  For each: a(theta) with the engine's error, the specular
(delta) share, the maximum of a over mu in [1e-6, 1] (pumpup.max_albedo), the mean albedo
(000 eq. 33), and the measured reciprocity.

    python scripts/make/he_torrance_fig5.py [--out tables] [--read]

Writes every number to ``OUT/he_torrance_fig5.json``, which the He-Torrance page reads when the site is built
(:func:`markdown` prints its table); ``--read`` prints the table of the stored file.
"""

from __future__ import annotations

import os
import sys
import time

sys.path.insert(0, os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__)))))  # this checkout
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))  # stored_json, beside this script

import numpy as np  # noqa: E402
from stored_json import computed_or_stored  # noqa: E402

import pumpup  # noqa: E402
from pumpup.tables.provenance import source_commit  # noqa: E402

THETA = [0, 30, 45, 60, 70, 75, 80, 85, 88, 89.9]
WAVELENGTHS = [0.4, 0.55, 0.7, 1.0]
#: the wavelengths the page's table shows, and the one whose specular share it shows
SHOWN = (0.4, 0.55, 0.7)
SHARE = 0.55


def run() -> dict:
    """a(theta), its error, the specular share, max a, the mean albedo and the reciprocity at each wavelength."""
    t0 = time.perf_counter()
    mu = np.cos(np.radians(THETA))
    out = {"theta_deg": THETA, "sigma_0": 0.1, "tau": 1.7, "commit": source_commit(), "wavelengths": []}
    for lam in WAVELENGTHS:
        f = pumpup.load({"type": "he_torrance", "sigma_0": 0.1, "tau": 1.7, "wavelength": lam})
        a, e = pumpup.albedo(f, mu, return_error=True)
        m = pumpup.max_albedo(f)
        mean, mean_err = pumpup.mean_albedo(f, return_error=True)
        r = pumpup.check_reciprocity(f)
        out["wavelengths"].append({
            "wavelength": lam, "albedo": [float(v) for v in a], "error": [float(v) for v in e],
            "specular_share": [float(v) for v in f.specular_weight(mu)], "max_albedo": float(m.albedo),
            "max_albedo_error": float(m.error), "max_theta_deg": float(m.theta_deg), "mean_albedo": float(mean),
            "mean_albedo_error": float(mean_err), "reciprocity": float(r.max_rel_error), "pairs": int(r.pairs)})
        print(f"lambda = {lam:g} um done ({time.perf_counter() - t0:.0f} s)", flush=True)
    return out


def entry(data: dict, lam: float) -> dict:
    """The record of one wavelength."""
    return next(w for w in data["wavelengths"] if abs(w["wavelength"] - lam) < 1e-12)


def markdown(data: dict) -> str:
    """The page's table: a(theta) at the :data:`SHOWN` wavelengths and the specular share at :data:`SHARE`."""
    th = data["theta_deg"]
    lines = ["| theta [deg] | " + " | ".join(f"{t:g}" for t in th) + " |", "|---" * (len(th) + 1) + "|"]
    for lam in SHOWN:
        lines.append(f"| lambda = {lam:.2f} um | " + " | ".join(f"{v:.5f}" for v in entry(data, lam)["albedo"]) + " |")
    share = entry(data, SHARE)["specular_share"]
    lines.append(f"| specular share, {SHARE:.2f} um | " + " | ".join(f"{v:#.2g}" for v in share) + " |")
    return "\n".join(lines)


def main() -> int:
    """Run the command line; return its exit status."""
    data, wrote = computed_or_stored("he_torrance_fig5.json", run, __doc__.splitlines()[0], sort_keys=True)
    if wrote:
        print("wrote", wrote)
    print(markdown(data))
    for w in data["wavelengths"]:
        print(f"lambda = {w['wavelength']:g} um: max a = {w['max_albedo']:.8f} +- {w['max_albedo_error']:.1e} at "
              f"theta = {w['max_theta_deg']:.3f} deg; mean albedo = {w['mean_albedo']:.8f} +- "
              f"{w['mean_albedo_error']:.1e}; reciprocity: max rel. asymmetry {w['reciprocity']:.1e} over "
              f"{w['pairs']} pairs; albedo error <= {max(w['error']):.1e}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
