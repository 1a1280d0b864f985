#!/usr/bin/env python
"""Fill the generated sections of docs/user-guide/renderer-tables.md from code.

    python scripts/studies/renderer_tables_doc.py [--page docs/user-guide/renderer-tables.md]

Sections between ``<!-- generated:NAME -->`` and ``<!-- end:NAME -->``:

* ``presets``: each preset's conventions file, as shipped in pumpup/data/conventions;
* ``cycles-audit``: the report of ``pumpup audit tests/data/cycles_shader.tables --conventions cycles.toml``;
* ``energy``: the compensation study: for GGX at several alpha, the energy a 1/E(mu_o)-scaled BRDF and a
  Kulla-Conty-compensated one reflect for light from a fixed direction (pumpup.albedo of pumpup.compensate(f,
  method)), and their furnace toward the viewer (pumpup.furnace), over a grid of cosines down to 1e-3;
* ``furnace``: the summary written by scripts/studies/furnace_cycles.py (furnace_summary.md beside the page), if
  present.

Takes about a minute (the first albedo of a compensated BRDF compiles its kernels).
"""

from __future__ import annotations

import argparse
import os
import re
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(os.path.dirname(HERE))
sys.path.insert(0, ROOT)  # this checkout's pumpup

import numpy as np  # noqa: E402

import pumpup  # noqa: E402
from pumpup import conventions as cv  # noqa: E402
from pumpup.tables import atomic_path  # noqa: E402

PAGE = os.path.join(ROOT, "docs", "user-guide", "renderer-tables.md")
ALPHAS = (0.1, 0.3, 0.5, 0.7, 1.0)
MU = np.array([1e-3, 0.01, 0.05, 0.1, 0.2, 0.3, 0.5, 0.7, 1.0])


def presets_section() -> str:
    """Each preset's shipped conventions file, as a TOML block."""
    out = []
    for name, fname in cv.PRESET_FILES.items():
        with open(os.path.join(cv.PRESET_DIR, fname)) as fh:
            text = fh.read().rstrip("\n")
        out += [f"**{name}** (`pumpup/data/conventions/{fname}`):", "", "```toml", text, "```", ""]
    return "\n".join(out)


def audit_section() -> str:
    """The audit report of Cycles' shipped table through its conventions file."""
    r = pumpup.audit(os.path.join(ROOT, "tests", "data", "cycles_shader.tables"), conventions="cycles")
    return "```text\n$ pumpup audit cycles_shader.tables --conventions pumpup/data/conventions/cycles.toml\n" \
        + r.report() + "\n```\n"


def energy_rows(shadowing: str) -> list[dict]:
    """Per alpha: the scaled and Kulla-Conty albedo (light from a fixed direction) and furnaces over MU."""
    rows = []
    for a in ALPHAS:
        f = pumpup.load({"type": "ggx", "alpha": a, "shadowing": shadowing})
        s = pumpup.compensate(f, "scale")
        k = pumpup.compensate(f, "kulla_conty")
        a_s, e_s = pumpup.albedo(s, MU, return_error=True)
        rows.append({"alpha": a, "scaled": a_s, "scaled_err": float(np.max(e_s)), "scaled_furnace": pumpup.furnace(s, MU),
                     "kc": pumpup.albedo(k, MU), "kc_furnace": pumpup.furnace(k, MU), "E": pumpup.albedo(f, MU)})
    return rows


def energy_section() -> str:
    """The compensation study's tables."""
    out = []
    for shadowing, who in (("correlated", "height-correlated Smith, as Cycles and Filament"),
                           ("separable", "separable Smith, as Mitsuba's roughconductor and appleseed")):
        rows = energy_rows(shadowing)
        head = "| alpha | " + " | ".join(f"mu = {m:g}" for m in MU) + " | furnace toward the viewer |"
        out += [f"GGX with the {who} (`ggx:shadowing={shadowing}`), F = 1. Energy reflected for light arriving at "
                "cosine mu by the 1/E(mu_o)-scaled BRDF (`pumpup.albedo(pumpup.compensate(f, \"scale\"), mu)`; "
                "the uncompensated E beside it in brackets):", "", head,
                "|---" * (len(MU) + 2) + "|"]
        for r in rows:
            cells = " | ".join(f"**{s:.3f}** ({e:.3f})" for s, e in zip(r["scaled"], r["E"]))
            fur = f"{r['scaled_furnace'].min():.6f} to {r['scaled_furnace'].max():.6f}"
            out.append(f"| {r['alpha']:g} | {cells} | {fur} |")
        by_alpha = {r["alpha"]: r for r in rows}
        parts = []
        for a in (0.3, 1.0):
            r = by_alpha[a]
            k = int(np.argmax(r["scaled"]))
            parts.append(f"{r['scaled'][k]:.3f} at alpha {a:g} (light at mu = {MU[k]:g})")
        ten = [f"{by_alpha[a]['scaled'][MU == 0.1][0]:.3f}" for a in (0.3, 1.0)]
        out += ["", f"Largest: {parts[0]}, {parts[1]}; at mu = 0.1: {ten[0]} and {ten[1]}."]
        worst_kc = max(float(np.max(np.abs(r["kc"] - 1))) for r in rows)
        worst_kcf = max(float(np.max(np.abs(r["kc_furnace"] - 1))) for r in rows)
        worst_err = max(r["scaled_err"] for r in rows)
        out += ["", f"Kulla-Conty on the same lobes: albedo for light from any of these directions within "
                f"{worst_kc:.1e} of 1, and furnace toward the viewer within {worst_kcf:.1e} of 1 (reciprocal, so the "
                f"two are the same integral). Quadrature error of the scaled albedo <= {worst_err:.0e}.", ""]
    return "\n".join(out)


def furnace_section(page: str) -> str | None:
    path = os.path.join(os.path.dirname(page), "renderer-tables", "furnace_summary.md")
    if not os.path.exists(path):
        return None
    with open(path) as fh:
        return fh.read()


def replace(text: str, name: str, body: str) -> str:
    pat = re.compile(rf"(<!-- generated:{name} -->\n).*?(<!-- end:{name} -->)", re.S)
    if not pat.search(text):
        raise SystemExit(f"the page has no section {name!r}")
    return pat.sub(lambda m: m.group(1) + body.rstrip("\n") + "\n" + m.group(2), text)


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--page", default=PAGE)
    ap.add_argument("--only", nargs="+", choices=["presets", "cycles-audit", "energy", "furnace"])
    args = ap.parse_args()
    with open(args.page) as fh:
        text = fh.read()
    todo = args.only or ["presets", "cycles-audit", "energy", "furnace"]
    if "presets" in todo:
        text = replace(text, "presets", presets_section())
    if "cycles-audit" in todo:
        text = replace(text, "cycles-audit", audit_section())
    if "energy" in todo:
        text = replace(text, "energy", energy_section())
    if "furnace" in todo:
        body = furnace_section(args.page)
        if body is not None:
            text = replace(text, "furnace", body)
    with atomic_path(args.page) as tmp, open(tmp, "w") as fh:
        fh.write(text)
    print(f"wrote {args.page} ({', '.join(todo)})")
    return 0


if __name__ == "__main__":
    sys.exit(main())
