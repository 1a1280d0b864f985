#!/usr/bin/env python
"""What Filament's one-texel row offset costs: E at the roughness a DFG row is computed at against E
at the texel centre its shader reads it at.

    python scripts/studies/filament_rows.py [--every 8]

Filament's generator (libs/ibl/src/CubemapIBL.cpp, CubemapIBL::DFG) computes image row y at
coord = saturate((128 - y + 0.5)/128); cmgen writes the rows in GL order, so GL row t holds
roughness min((t + 1.5)/128, 1), and the shader reads it (textureLod(dfg, vec2(NoV,
perceptualRoughness))) at the texel centre (t + 0.5)/128.  At the texel centres the look-up returns
the stored value, so the offset alone makes an error E(NoV, r_stored) - E(NoV, r_read) there.
This prints its largest value and where, on every ``--every``-th texel in both axes (exact E,
pumpup.luts), beside the half-float rounding 2^-12 (E lies in [0.5, 1) there).
"""

from __future__ import annotations

import argparse
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__)))))

import numpy as np  # noqa: E402

from pumpup import luts  # noqa: E402

#: the largest rounding error of a half float in [0.5, 1), where E lies at these texels: half its spacing 2^-11
HALF_ROUNDING = 2.0 ** -12


def offset_cost(every: int = 8) -> dict:
    """E(NoV, r_stored) - E(NoV, r_read) on every ``every``-th texel of Filament's DFG table in both axes
    (perceptual roughness read >= 0.045): its largest magnitude (``max``) and where (``nov``, ``read``,
    ``stored``), its median magnitude (``median``), the texel count (``texels``) and the quadrature error of the
    exact E (``error``).
    """
    mu, stored = luts.nodes("filament")
    _, read = luts.nodes("filament-centred")
    spec, param = luts.model_spec("ggx", "filament")
    sel_x = mu[::every]
    sel_t = np.arange(0, 128, every)
    sel_t = sel_t[read[sel_t] >= 0.045]  # Filament's MIN_PERCEPTUAL_ROUGHNESS
    a = luts.truth_grid(spec, param, sel_x, stored[sel_t], rtol=1e-7)
    b = luts.truth_grid(spec, param, sel_x, read[sel_t], rtol=1e-7)
    d = a["E"] - b["E"]
    i, j = np.unravel_index(np.argmax(np.abs(d)), d.shape)
    return {"max": float(abs(d[i, j])), "nov": float(sel_x[i]), "read": float(read[sel_t[j]]),
            "stored": float(stored[sel_t[j]]), "median": float(np.median(np.abs(d))), "texels": int(d.size),
            "error": float(max(a["E_error"].max(), b["E_error"].max()))}


def main() -> int:
    """Run the command line; return its exit status."""
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--every", type=int, default=8)
    args = ap.parse_args()
    r = offset_cost(args.every)
    print(f"{r['texels']} texels (every {args.every}th, perceptual roughness >= 0.045): max |E(stored row) - E(read "
          f"row)| = {r['max']:.3g} at NoV = {r['nov']:.4g}, roughness read {r['read']:.4g} (stored {r['stored']:.4g}); "
          f"median {r['median']:.2g}, {r['max'] / HALF_ROUNDING:.0f} x the half rounding <= {HALF_ROUNDING:.2g}; "
          f"quadrature error <= {r['error']:.1g}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
