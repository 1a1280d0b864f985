#!/usr/bin/env python
"""The white furnace of Blender Cycles and Mitsuba 3, rendered and predicted, ring by ring.

    python scripts/studies/furnace_cycles.py [--resolution 256] [--spp 32] [--seeds 8] [--roughness 0.15 0.5 1.0]
                                             [--out docs/user-guide/renderer-tables] [--skip-mitsuba]

Renders a sphere of F = 1 metal in a white environment (pumpup.furnace_render): Cycles' Metallic BSDF with the
"Multiscatter GGX" distribution (Blender's default: the GGX lobe scaled by 1 / E of its shipped table, looked up
bilinearly at (roughness, mu); predicted by pumpup.furnace_prediction("cycles", "scale", path=<the table>)) and
with "GGX" (no compensation: the furnace is E), and Mitsuba 3's roughconductor (GGX with the separable Smith term,
no compensation: the furnace is E), at each roughness r (alpha = r^2).  Reads the radiance along rings of constant
view cosine, writes the rings to ``furnace_rings.csv``, a summary to ``furnace_summary.md`` and a figure to
``furnace_rings.png`` under ``--out``, and prints the summary.  Needs bpy (pumpup[blender]) and mitsuba
(pumpup[render]).  At the defaults it takes about 3 minutes on 2 cores.
"""

from __future__ import annotations

import argparse
import csv
import io
import os
import sys
import time

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(os.path.dirname(HERE))
sys.path.insert(0, ROOT)  # this checkout's pumpup

import numpy as np  # noqa: E402

import pumpup  # noqa: E402
from pumpup import furnace_render as fr  # noqa: E402
from pumpup.tables import atomic_path  # noqa: E402

CYCLES_TABLE = os.path.join(ROOT, "tests", "data", "cycles_shader.tables")


def predictor(conventions, method, r, path=None):
    """mu -> the predicted furnace at roughness r."""
    def predict(mu):
        ds = pumpup.furnace_prediction(conventions, method, path=path, mu=mu, roughness=[r])
        return ds["furnace"].values[:, 0]
    return predict


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--resolution", type=int, default=256)
    ap.add_argument("--spp", type=int, default=32, help="samples per pixel of each render")
    ap.add_argument("--seeds", type=int, default=8, help="renders per configuration, with different seeds (the "
                    "standard errors come from their scatter)")
    ap.add_argument("--roughness", type=float, nargs="+", default=[0.15, 0.5, 1.0])
    ap.add_argument("--threads", type=int, default=2)
    ap.add_argument("--out", default=os.path.join(ROOT, "docs", "user-guide", "renderer-tables"))
    ap.add_argument("--skip-mitsuba", action="store_true")
    args = ap.parse_args()
    os.makedirs(args.out, exist_ok=True)
    edges = np.linspace(0.1, 1.0, 19)
    t_start = time.perf_counter()
    runs = []
    for r in args.roughness:
        for dist, method in (("MULTI_GGX", "scale"), ("GGX", "none")):
            imgs = [fr.render_cycles(r, dist, resolution=args.resolution, spp=args.spp, threads=args.threads,
                                     seed=1 + k) for k in range(args.seeds)]
            table = fr.rings(imgs, predictor("cycles", method, r, CYCLES_TABLE), edges)
            sec = sum(i["seconds"] for i in imgs)
            runs.append({"renderer": f"Cycles {imgs[0]['version']}", "bsdf": f"Metallic BSDF, {dist}",
                         "method": method, "r": r, "rings": table, "seconds": sec})
            print(f"Cycles {dist} r = {r:g}: {sec:.1f} s", flush=True)
        if not args.skip_mitsuba:
            imgs = [fr.render_mitsuba(r * r, resolution=args.resolution, spp=args.spp, seed=1 + k)
                    for k in range(args.seeds)]
            table = fr.rings(imgs, predictor("mitsuba", "none", r), edges, min_alpha=0.999)
            sec = sum(i["seconds"] for i in imgs)
            runs.append({"renderer": f"Mitsuba {imgs[0]['version']}", "bsdf": "roughconductor (GGX)",
                         "method": "none", "r": r, "rings": table, "seconds": sec})
            print(f"Mitsuba r = {r:g}: {sec:.1f} s", flush=True)
    total = time.perf_counter() - t_start

    # the rings, every run
    buf = io.StringIO()
    w = csv.writer(buf)
    w.writerow(["renderer", "bsdf", "compensation", "roughness", "mu_lo", "mu_hi", "mu", "pixels", "render",
                "predicted", "difference", "standard_error"])
    for run in runs:
        for ring in run["rings"]:
            w.writerow([run["renderer"], run["bsdf"], run["method"], run["r"], f"{ring['mu_lo']:.2f}",
                        f"{ring['mu_hi']:.2f}", f"{ring['mu']:.4f}", ring["n"], f"{ring['render']:.6f}",
                        f"{ring['predicted']:.6f}", f"{ring['difference']:+.6f}", f"{ring['se']:.6f}"])
    with atomic_path(os.path.join(args.out, "furnace_rings.csv")) as tmp, open(tmp, "w") as fh:
        fh.write(buf.getvalue())

    # the summary
    lines = [f"Sphere of radius {args.resolution / 2 / 1.025:.0f} pixels; {args.seeds} renders of {args.spp} "
             f"samples per pixel per configuration (seeds 1 to {args.seeds}; the standard errors are the scatter of "
             f"the renders' ring means over sqrt({args.seeds})); {len(edges) - 1} rings of width "
             f"{edges[1] - edges[0]:.2f} in mu from {edges[0]:.1f} to 1; {total:.0f} s in all on {args.threads} "
             f"threads. z = (render - predicted) / standard error; with {args.seeds} renders it follows Student's t "
             f"with {args.seeds - 1} degrees of freedom"
             + (f", whose mean square is {(args.seeds - 1) / (args.seeds - 3):.2f}." if args.seeds > 3 else "."),
             "",
             "| renderer | BSDF | compensation | r | max abs(predicted - 1) | max abs(render - predicted) "
             "| standard error (median) | max abs(z) | mean z^2 |",
             "|---|---|---|---|---|---|---|---|---|"]
    for run in runs:
        rg = run["rings"]
        dev = max(abs(x["predicted"] - 1) for x in rg)
        diff = max(abs(x["difference"]) for x in rg)
        ok, z = fr.compare_rings(rg)
        se = float(np.median([x["se"] for x in rg]))
        z2 = float(np.mean([(x["difference"] / x["se"]) ** 2 for x in rg]))
        lines.append(f"| {run['renderer']} | {run['bsdf']} | {run['method']} | {run['r']:g} | {dev:.2e} | "
                     f"{diff:.2e} | {se:.1e} | {z:.2f} | {z2:.2f} |")
    text = "\n".join(lines) + "\n"
    with atomic_path(os.path.join(args.out, "furnace_summary.md")) as tmp, open(tmp, "w") as fh:
        fh.write(text)
    print(text)

    # the figure: render - 1 and prediction - 1 against mu, one panel per roughness
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    rs = list(dict.fromkeys(run["r"] for run in runs))
    fig, axes = plt.subplots(1, len(rs), figsize=(4.6 * len(rs), 4.0), squeeze=False)
    style = {("Cycles", "scale"): "C0", ("Cycles", "none"): "C1", ("Mitsuba", "none"): "C2"}
    for ax, r in zip(axes[0], rs):
        for run in (x for x in runs if x["r"] == r):
            rg = run["rings"]
            mu = np.array([x["mu"] for x in rg])
            c = style[(run["renderer"].split()[0], run["method"])]
            label = f"{run['renderer'].split()[0]} {run['bsdf'].split(', ')[-1]}"
            ax.errorbar(mu, [x["render"] - 1 for x in rg], yerr=[3 * x["se"] for x in rg], fmt="o", ms=3, color=c,
                        label=f"{label}: render (3 SE)")
            ax.plot(mu, [x["predicted"] - 1 for x in rg], "-", color=c, lw=1, label=f"{label}: predicted")
        ax.set_yscale("symlog", linthresh=1e-3)
        ax.set_xlabel("view cosine mu")
        ax.set_ylabel("furnace - 1")
        ax.set_title(f"roughness {r:g} (alpha {r * r:.3g})", fontsize=9)
        ax.grid(alpha=0.3)
    axes[0][0].legend(fontsize=6)
    fig.tight_layout()
    with atomic_path(os.path.join(args.out, "furnace_rings.png")) as tmp:
        fig.savefig(tmp, format="png", dpi=90)
    print(f"wrote {args.out}/furnace_rings.csv, furnace_summary.md, furnace_rings.png")
    return 0


if __name__ == "__main__":
    sys.exit(main())
