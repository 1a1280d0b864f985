#!/usr/bin/env python
"""The warp search of the renderer-tables page: 1024-entry GGX tables with power-warped axes.

    python scripts/make/lut_warps.py [--out tables]

Runs :func:`pumpup.luts.warp_search` (GGX, correlated, F = 1, Cycles' 32 x 32 budget and bilinear look-up, exact
nodes) over the searches the page shows, and writes every candidate to ``OUT/lut_warps.json``, which
docs/user-guide/luts.md reads (:func:`markdown` prints its table).  Each search is one look-up domain and a grid of
exponents p (mu axis) and q (roughness axis); p = q = 1 is the uniform grid.  Several minutes on 2 cores.
"""

from __future__ import annotations

import dataclasses
import os
import sys
import time

sys.path.insert(0, os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__)))))  # this checkout
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))  # stored_json, beside this script

import stored_json  # noqa: E402

from pumpup import luts  # noqa: E402
from pumpup.tables.provenance import source_commit  # noqa: E402

#: (smallest mu of the look-up domain, p grid, q grid) of each search
SEARCHES = (
    (1e-4, (1.0, 2.0, 3.0, 4.0), (1.0, 2.0, 3.0)),
    (1e-4, (1.0, 4.0, 6.0, 8.0), (1.0, 3.0, 4.0, 6.0)),
    (0.01, (1.0, 1.5, 2.0, 3.0), (1.0, 1.5, 2.0, 3.0)),
)
#: the candidates the page's table shows beside the uniform grid and the best one
COLUMNS = ((2.0, 2.0), (3.0, 2.0), (4.0, 3.0))


def run(rtol: float = 1e-7) -> dict:
    """Every search of :data:`SEARCHES`, as the JSON the page reads."""
    base = luts.PRESETS["cycles"]
    out = {"model": "ggx", "preset": "cycles", "rtol": rtol, "commit": source_commit(), "domains": []}
    for mu_min, ps, qs in SEARCHES:
        p = dataclasses.replace(base, lookup_mu_min=mu_min)
        t = time.perf_counter()
        res = luts.warp_search("ggx", p, ps, qs, rtol=rtol)
        print(f"mu in [{mu_min:g}, 1], rough in [{p.lookup_rough_min:g}, 1], p {ps} x q {qs}: "
              f"{time.perf_counter() - t:.0f} s, load {os.getloadavg()[0]:.1f}", flush=True)
        dom = next((d for d in out["domains"] if d["mu_min"] == mu_min), None)
        if dom is None:
            dom = {"mu_min": mu_min, "rough_min": p.lookup_rough_min, "grids": [], "candidates": []}
            out["domains"].append(dom)
        dom["grids"].append({"p": list(ps), "q": list(qs)})
        seen = {(c["p"], c["q"]) for c in dom["candidates"]}
        dom["candidates"] += [{"p": r["p"], "q": r["q"], "max_abs": float(r["max_abs"]),
                               "where": [float(w) for w in r["where"]], "rms": float(r["rms"])}
                              for r in res if (r["p"], r["q"]) not in seen]
        dom["candidates"].sort(key=lambda c: c["max_abs"])
    return out


def _find(dom: dict, p: float, q: float) -> dict | None:
    return next((c for c in dom["candidates"] if c["p"] == p and c["q"] == q), None)


def _short(x: float) -> str:
    return f"{x:.0e}".replace("e-0", "e-") if x < 1e-3 else f"{x:g}"


def searched(data: dict) -> str:
    """The exponent grids of every search, as the page lists them."""
    def grid(v):
        return "{" + ", ".join(f"{x:g}" for x in v) + "}"

    return "; ".join(f"mu >= {_short(d['mu_min'])}: " + " and ".join(f"p in {grid(g['p'])} x q in {grid(g['q'])}"
                                                               for g in d["grids"]) for d in data["domains"])


def gain(dom: dict) -> float:
    """How many times smaller the best candidate's worst error is than the uniform grid's."""
    return _find(dom, 1.0, 1.0)["max_abs"] / dom["candidates"][0]["max_abs"]


def markdown(data: dict) -> str:
    """The page's table: per look-up domain, the worst look-up error of the uniform grid, of the candidates of
    :data:`COLUMNS` (blank where not searched) and of the best one (bold), and the gain of the best.
    """
    head = ["look-up domain", "uniform (p = q = 1)", *(f"p = {p:g}, q = {q:g}" for p, q in COLUMNS), "best",
            "gain of the best"]
    lines = ["| " + " | ".join(head) + " |", "|" + "---|" * len(head)]
    for dom in data["domains"]:
        uni, best = _find(dom, 1.0, 1.0), dom["candidates"][0]
        cells = [f"mu in [{_short(dom['mu_min'])}, 1], rough in [{_short(dom['rough_min'])}, 1]",
                 f"{uni['max_abs']:.4f} (rms {uni['rms']:.4f})"]
        for p, q in COLUMNS:
            c = _find(dom, p, q)
            cells.append("" if c is None else f"{c['max_abs']:#.2g}")
        cells += [f"**{best['max_abs']:#.3g}** (p = {best['p']:g}, q = {best['q']:g}; rms {best['rms']:#.2g})",
                  f"{gain(dom):.1f} x"]
        lines.append("| " + " | ".join(cells) + " |")
    return "\n".join(lines)


if __name__ == "__main__":
    sys.exit(stored_json.main("lut_warps.json", run, markdown, __doc__.splitlines()[0], sort_keys=True))
