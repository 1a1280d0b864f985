"""Mitsuba 3's BSDFs measured by pumpup (pumpup.mitsuba.from_mitsuba): directional albedo with its
error, whether it exceeds 1, reciprocity, and Mitsuba's roughconductor against pumpup's ggx and
beckmann configured alike.  Prints a markdown table (the README's section "Mitsuba 3 bridge").

    python scripts/studies/mitsuba_measurements.py [--variant llvm_ad_rgb] [--rtol 1e-6]

Mitsuba evaluates in float32: each value carries a relative rounding error of order 1e-7, so an
albedo of the *exact* model is known only to that (the table states the measured pointwise
difference to pumpup's double-precision model where there is one).
"""

from __future__ import annotations

import argparse
import math
import time

import numpy as np

import pumpup

#: theta from 0 to 89.9 degrees plus mu down to 1e-4
MU = np.unique(np.concatenate([np.cos(np.radians(np.linspace(0.0, 89.9, 40))), [1e-3, 1e-4]]))[::-1]

CASES = [
    ("diffuse, reflectance 1", {"type": "diffuse", "reflectance": {"type": "rgb", "value": 1.0}}, None),
    ("roughconductor GGX alpha 0.3 (material none)",
     {"type": "roughconductor", "distribution": "ggx", "alpha": 0.3, "sample_visible": True},
     {"type": "ggx", "alpha": 0.3}),
    ("roughconductor Beckmann alpha 0.3 (material none)",
     {"type": "roughconductor", "distribution": "beckmann", "alpha": 0.3},
     {"type": "beckmann", "alpha": 0.3, "g1": "walter"}),
    ("roughconductor GGX alpha 0.05", {"type": "roughconductor", "distribution": "ggx", "alpha": 0.05},
     {"type": "ggx", "alpha": 0.05}),
    ("roughplastic GGX alpha 0.3, diffuse 1 (furnace)",
     {"type": "roughplastic", "distribution": "ggx", "alpha": 0.3,
      "diffuse_reflectance": {"type": "rgb", "value": 1.0}}, None),
    ("roughplastic Beckmann alpha 0.1, diffuse 1, nonlinear",
     {"type": "roughplastic", "distribution": "beckmann", "alpha": 0.1, "nonlinear": True,
      "diffuse_reflectance": {"type": "rgb", "value": 1.0}}, None),
    ("principled, defaults", {"type": "principled"}, None),
    ("principled, base_color 1, roughness 0.5", {"type": "principled", "base_color": {"type": "rgb", "value": 1.0},
                                                 "roughness": 0.5}, None),
]


#: "exceeds 1" must exceed 1 by more than the float32 evaluation can (the largest pointwise relative
#: difference between Mitsuba's roughconductor and pumpup's double-precision ggx / beckmann, measured
#: below, is 2.4e-6)
FLOAT32_BOUND = 1e-5


def _pairs(rng, n, zmin=0.0):
    """n random direction pairs above the horizon with both cosines >= zmin, float32-exact."""
    out = []
    for _ in range(2):
        w = rng.normal(size=(4 * n, 3))
        w[:, 2] = np.abs(w[:, 2])
        w /= np.linalg.norm(w, axis=1)[:, None]
        w = w[w[:, 2] >= zmin][:n]
        out.append(w.astype(np.float32).astype(float))
    return out[0], out[1]


def measure(label, mdict, pspec, variant, rtol, rng):
    import pumpup.mitsuba as pm

    t0 = time.time()
    m = pm.from_mitsuba(mdict, channel=1, variant=variant)
    a, e = pumpup.albedo(m, MU, return_error=True, rtol=rtol)
    i = int(np.argmax(a))
    r = pumpup.check_reciprocity(m)
    wi, wo = _pairs(rng, 20000, zmin=0.05)
    f1, f2 = m.eval(wi, wo), m.eval(wo, wi)
    inner = float(np.max(np.abs(f1 - f2) / np.maximum(np.maximum(f1, f2), 1e-30)))
    row = {"label": label, "a1": a[0], "e1": e[0], "a01": float(a[np.argmin(abs(MU - 0.1))]),
           "a_min_mu": a[-1], "e_min_mu": e[-1], "amax": a[i], "emax": e[i], "theta_max": math.degrees(math.acos(MU[i])),
           "exceeds": bool(a[i] - e[i] > 1.0 + FLOAT32_BOUND), "recip": r.max_rel_error, "recip_inner": inner,
           "worst": (float(r.worst_wi[2]), float(r.worst_wo[2])), "t": 0.0}
    if pspec is not None:
        f = pumpup.load(pspec)
        wi, wo = _pairs(rng, 20000)
        fm, fp = m.eval(wi, wo), f.eval(wi, wo)
        ok = fp > 1e-3 * fp.max()
        row["eval_diff"] = float(np.max(np.abs(fm[ok] / fp[ok] - 1)))
        ap = pumpup.albedo(f, MU)
        row["albedo_diff"] = float(np.max(np.abs(a - ap)))
    row["t"] = time.time() - t0
    return row


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--variant", default=None, help="Mitsuba variant (default: llvm_ad_rgb if its probe passes)")
    ap.add_argument("--rtol", type=float, default=1e-6, help="albedo tolerance (float32 limits it to ~1e-7)")
    args = ap.parse_args(argv)
    rng = np.random.default_rng(7)
    print(f"mu: {len(MU)} values from 1 to {MU[-1]:g}; channel G; rtol {args.rtol:g}")
    print("| BSDF | a(mu=1) | a(mu=0.1) | a(mu=1e-4) | max a (theta) | > 1 + 1e-5? | asymmetry: check_reciprocity "
          "(N.wi, N.wo of the worst pair) / pairs with cosines >= 0.05 | vs pumpup: eval / albedo |")
    print("|---|---|---|---|---|---|---|---|")
    for label, mdict, pspec in CASES:
        r = measure(label, mdict, pspec, args.variant, args.rtol, rng)
        vs = f"{r['eval_diff']:.1e} / {r['albedo_diff']:.1e}" if "eval_diff" in r else "-"
        print(f"| {label} | {r['a1']:.6f} +- {r['e1']:.0e} | {r['a01']:.6f} | {r['a_min_mu']:.6f} +- {r['e_min_mu']:.0e} | "
              f"{r['amax']:.6f} +- {r['emax']:.0e} ({r['theta_max']:.1f} deg) | {'yes' if r['exceeds'] else 'no'} | "
              f"{r['recip']:.1e} ({r['worst'][0]:.0e}, {r['worst'][1]:.0e}) / {r['recip_inner']:.1e} | {vs} |", flush=True)


if __name__ == "__main__":
    main()
