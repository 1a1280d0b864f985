"""Perceptual vs least-squares fits of compact models to microfacet metals (001 sec. 1.1).

For every target (GGX and Beckmann conductors, alpha 0.05 / 0.1 / 0.2 / 0.4, Fresnel 1 and
aluminium; Cook-Torrance) and every compact family (reciprocal Phong, stretched Phong with p
free, pumped Phong g2 with 1-3 levels, Blinn, stretched Blinn, modified Ward, a Lafortune
lobe), fit with ``pumpup.fit`` twice, method="perceptual" (min-max of the relative errors of
f cos(theta_L) and of the albedo) and method="least_squares" (L2 of f cos(theta_L) alone),
and record both maximal relative errors (at full accuracy: albedo rtol 1e-9, the errors
refined to their suprema) and the fit time.  The scale c is free (profiled exactly) for
every family that has one; pumped Phong has its base's n free and no scale.

Results go to a JSON file, one record per fit, written atomically after every fit, so an
interrupted run resumes where it stopped.  ``--table`` prints the Markdown tables of the
README from that file; ``--figure`` draws the comparison figure.

    python scripts/make/fitting_study.py --part compact      # ~20 min on a loaded 2-core machine
    python scripts/make/fitting_study.py --part pumped       # pumped Phong: seconds per candidate
    python scripts/make/fitting_study.py --table
    python scripts/make/fitting_study.py --figure figures/fitting_study.png

Aluminium: eta + i k = 0.96 + 6.69 i at 550 nm (Rakic 1995, as on refractiveindex.info).
"""

from __future__ import annotations

import argparse
import json
import math
import os
import time

import numpy as np

import pumpup
from pumpup.tables import atomic_path

AL = {"eta": 0.96, "k": 6.69}  # aluminium at 550 nm (Rakic 1995)
ALPHAS = (0.05, 0.1, 0.2, 0.4)
BIG = (1e-200, 1e200)  # range of a profiled scale: it is solved exactly, so any range costs nothing


def targets():
    """The targets, in the order they are run (the most informative first, so a partial run says most)."""
    out = {}
    for a in (0.1, 0.2, 0.05, 0.4):
        for d in ("ggx", "beckmann"):
            out[f"{d} a={a} F=1"] = {"type": d, "alpha": a}
            out[f"{d} a={a} Al"] = {"type": d, "alpha": a, **AL}
        if a == 0.1:
            out["cook_torrance m=0.2"] = {"type": "cook_torrance", "m": 0.2}
    return out


COMPACT = {
    "phong": dict(family="phong", params={"n": (1, 1e4), "c": BIG}),
    "stretched_phong": dict(family="stretched_phong", params={"n": (1, 1e4), "p": (0.0, 1.0), "c": BIG}),
    "blinn": dict(family="blinn", params={"n": (1, 1e4), "c": BIG}),
    "stretched_blinn": dict(family="stretched_blinn", params={"n": (1, 1e4), "c": BIG}),
    "modified_ward": dict(family="modified_ward", params={"m": (0.01, 2.0), "c": BIG}),
    "lafortune": dict(family="lafortune", params={"n": (1, 1e4), "cz": (0.7, 1.3), "c": BIG}),
}
PUMPED = {
    f"pumped_phong_g2_{k}": dict(family="phong", params={"n": (2, 3000)}, pump={"g": "g2", "levels": k},
                                 n_scan=6, xtol=1e-3)
    for k in (1, 2, 3)
}
METHODS = ("perceptual", "least_squares")


def load_records(path):
    if not os.path.exists(path):
        return []
    with open(path) as fh:
        data = json.load(fh)
    if not isinstance(data, list) or not all(isinstance(r, dict) and "target_name" in r for r in data):
        raise SystemExit(f"{path}: not a fitting-study result file")
    return data


def save_records(path, records):
    with atomic_path(path) as tmp:
        with open(tmp, "w") as fh:
            json.dump(records, fh, indent=1)


def run(path, part, only_targets=None, only_families=None, mu_min=0.05, plausible=False):
    records = load_records(path)
    done = {(r["target_name"], r["model"], r["method"], round(r["mu_min"], 9), r.get("plausible", False))
            for r in records}
    models = {"compact": COMPACT, "pumped": PUMPED, "all": {**COMPACT, **PUMPED}}[part]
    for tname, tspec in targets().items():
        if only_targets and tname not in only_targets:
            continue
        for mname, kw in models.items():
            if only_families and mname not in only_families:
                continue
            for method in METHODS:
                if (tname, mname, method, round(mu_min, 9), plausible) in done:
                    continue
                t0 = time.perf_counter()
                r = pumpup.fit(tspec, method=method, mu_min=mu_min, plausible=plausible, **kw)
                rec = r.summary()
                rec.update(target_name=tname, model=mname, wall=time.perf_counter() - t0,
                           load=os.getloadavg()[0], albedo_evaluations=r.albedo_evaluations)
                records.append(rec)
                save_records(path, records)
                print(f"{tname:22s} {mname:22s} {method:13s} mu_min {mu_min:g} e_f {r.brdf_error:9.4g} e_a {r.albedo_error:9.4g} "
                      f"obj {r.objective:9.4g} {rec['wall']:7.1f} s (load {rec['load']:.1f})", flush=True)
    return records


SHORT = {"phong": "Phong", "stretched_phong": "str. Phong", "blinn": "Blinn", "stretched_blinn": "str. Blinn",
         "modified_ward": "mod. Ward", "lafortune": "Lafortune", "pumped_phong_g2_1": "Phong g2 x1",
         "pumped_phong_g2_2": "Phong g2 x2", "pumped_phong_g2_3": "Phong g2 x3"}


def table(records):
    """Markdown: for each method, targets x models with "e_f / e_a"; then the fit times per model."""
    by = {(r["target_name"], r["model"], r["method"]): r for r in records}
    tnames = [t for t in targets() if any(k[0] == t for k in by)]
    models = [m for m in {**COMPACT, **PUMPED} if any(k[1] == m for k in by)]
    lines = []
    for method in METHODS:
        lines.append(f"\n{method}: e_f (point light) / e_a (albedo), maximal relative errors\n")
        lines.append("| target | " + " | ".join(SHORT[m] for m in models) + " |")
        lines.append("|---|" + "---|" * len(models))
        for t in tnames:
            cells = []
            for m in models:
                r = by.get((t, m, method))
                cells.append("-" if r is None else f"{r['brdf_error']:.3g} / {r['albedo_error']:.3g}")
            lines.append(f"| {t} | " + " | ".join(cells) + " |")
    lines.append("\nfit time [s] (wall, median and max over the targets; load average during the runs in brackets)\n")
    lines.append("| model | perceptual | least squares | fits | load |")
    lines.append("|---|---|---|---|---|")
    for m in models:
        row = []
        loads = [r["load"] for r in records if r["model"] == m]
        for method in METHODS:
            ts = [r["seconds"] for r in records if r["model"] == m and r["method"] == method]
            row.append(f"{np.median(ts):.1f} / {max(ts):.1f}" if ts else "-")
        n = sum(1 for r in records if r["model"] == m)
        lines.append(f"| {SHORT[m]} | {row[0]} | {row[1]} | {n} | {min(loads):.0f}-{max(loads):.0f} |")
    return "\n".join(lines)


def best(records):
    """Per target: the plausible perceptual fits ranked by max(e_f, e_a)."""
    out = []
    for t in targets():
        rs = [r for r in records if r["target_name"] == t and r["method"] == "perceptual"]
        if not rs:
            continue
        ok = [r for r in rs if r["max_albedo"] <= 1 + 1e-8]
        ok.sort(key=lambda r: r["objective"])
        bad = sorted((r for r in rs if r not in ok), key=lambda r: r["objective"])
        out.append(f"| {t} | " + ", ".join(f"{r['model']} {r['objective']:.3g}" for r in ok[:3])
                   + " | " + (", ".join(f"{r['model']} {r['objective']:.3g} (a_max {r['max_albedo']:.3f})"
                                       for r in bad[:2]) or "-") + " |")
    return "| target | best plausible perceptual fits, max(e_f, e_a) | not plausible (albedo > 1 on the mu set) |\n" \
           "|---|---|---|\n" + "\n".join(out)


def figure(records, path, target_name="ggx a=0.1 F=1"):
    tspec = targets()[target_name]
    tgt = pumpup.load(tspec)
    res, labels = [], []
    records = [r for r in records if abs(r["mu_min"] - 0.05) < 1e-9 and not r.get("plausible", False)]
    for r in records:
        if r["target_name"] == target_name and r["method"] == "perceptual" and r["model"] in COMPACT:
            res.append(r)
    pick = {}
    for r in records:
        if r["target_name"] == target_name and r["model"] in ("stretched_phong", "modified_ward", "pumped_phong_g2_2"):
            pick[(r["model"], r["method"])] = r
    chosen = [r for r in res if r["model"] in ("phong", "blinn", "lafortune")] + list(pick.values())
    from pumpup.fitting import plot_fits

    class _R:  # the fields plot_fits reads, rebuilt from the JSON record
        def __init__(self, rec):
            self.target_brdf = tgt
            self.target = tspec
            self.brdf = pumpup.load(rec["spec"])
            self.spec = rec["spec"]
            self.family = rec["model"]
            self.method = rec["method"]
            self.brdf_error = rec["brdf_error"]
            self.albedo_error = rec["albedo_error"]
            self.mu_min = rec["mu_min"]

    objs = [_R(r) for r in chosen]
    labels = [f"{o.family} ({'perc.' if o.method == 'perceptual' else 'LSQ'}): e_f {o.brdf_error:.3g}, "
              f"e_a {o.albedo_error:.3g}" for o in objs]
    return plot_fits(objs, path, labels=labels, title=f"fits to {target_name}: {json.dumps(tspec)}")


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--out", default="tables/fitting_study.json")
    ap.add_argument("--part", choices=("compact", "pumped", "all"))
    ap.add_argument("--targets", nargs="+", help="only these target names (quote them)")
    ap.add_argument("--plausible", action="store_true", help="fit with albedo <= 1 as a constraint")
    ap.add_argument("--mu-min", type=float, default=0.05, help="smallest mu of the views and the albedo (default 0.05)")
    ap.add_argument("--models", nargs="+", help="only these model names")
    ap.add_argument("--read", nargs="+", metavar="JSON", help="further result files for --table and --figure")
    ap.add_argument("--table", action="store_true", help="print the Markdown tables from --out")
    ap.add_argument("--figure", metavar="PNG", help="draw the comparison figure from --out")
    a = ap.parse_args()
    if a.part:
        print(f"load average at start: {os.getloadavg()}")
        run(a.out, a.part, a.targets, a.models, a.mu_min, a.plausible)
    recs = [r for path in [a.out] + (a.read or []) for r in load_records(path)]
    if a.table:
        for mu_min, pl in sorted({(round(r["mu_min"], 9), r.get("plausible", False)) for r in recs}):
            sub = [r for r in recs if round(r["mu_min"], 9) == mu_min and r.get("plausible", False) == pl]
            print(f"\n### mu_min = {mu_min:g} (views and albedo down to theta = {math.degrees(math.acos(mu_min)):.1f} deg)"
                  + (", albedo <= 1 imposed" if pl else ", scale free"))
            print(table(sub))
            print()
            print(best(sub))
    if a.figure:
        print("wrote", figure(recs, a.figure))


if __name__ == "__main__":
    main()
