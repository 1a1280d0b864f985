#!/usr/bin/env python
"""Mitsuba 3's BSDFs measured by pumpup (:func:`pumpup.mitsuba.from_mitsuba`): directional albedo with its
error, whether it exceeds 1, reciprocity, and Mitsuba's roughconductor against pumpup's ggx and beckmann
configured alike (green channel, 42 mu from 1 to 1e-4).

    python scripts/make/mitsuba_measurements.py [--out tables] [--read]   # needs the render extra (Mitsuba 3)

Writes the results to ``OUT/tables/mitsuba_measurements.json``, which docs/user-guide/mitsuba.md reads when the
site is built (the build does not need Mitsuba), and prints the page's Markdown table (:func:`markdown`);
``--read`` prints the table of the stored file.  The variant is ``llvm_ad_rgb`` when its probe passes
(:func:`pumpup.mitsuba.register`), else ``scalar_rgb``; the file records which.

Mitsuba evaluates in float32: each value carries a relative rounding error of order 1e-7, so an albedo of the
*exact* model is known only to that (the file stores the measured pointwise difference to pumpup's
double-precision model where there is one).
"""

from __future__ import annotations

import math
import os
import sys
import tempfile
import time

sys.path.insert(0, os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__)))))  # this checkout
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))  # stored_json, beside this script

import numpy as np  # noqa: E402
from stored_json import computed_or_stored  # noqa: E402

import pumpup  # noqa: E402
from pumpup.tables.provenance import source_commit  # noqa: E402

#: theta from 0 to 89.9 degrees plus mu down to 1e-4
MU = np.unique(np.concatenate([np.cos(np.radians(np.linspace(0.0, 89.9, 40))), [1e-3, 1e-4]]))[::-1]
CHANNEL = 1  # green
RTOL = 1e-6  # the albedo's tolerance (float32 limits it to ~1e-7)
SEED = 7

#: (label, Mitsuba dict, pumpup's model configured alike or None, how the page names that model)
CASES = [
    ("diffuse, reflectance 1", {"type": "diffuse", "reflectance": {"type": "rgb", "value": 1.0}}, None, None),
    ("roughconductor GGX alpha 0.3",
     {"type": "roughconductor", "distribution": "ggx", "alpha": 0.3, "sample_visible": True},
     {"type": "ggx", "alpha": 0.3}, "`ggx`"),
    ("roughconductor Beckmann alpha 0.3", {"type": "roughconductor", "distribution": "beckmann", "alpha": 0.3},
     {"type": "beckmann", "alpha": 0.3, "g1": "walter"}, "`beckmann`, g1 walter"),
    ("roughconductor GGX alpha 0.05", {"type": "roughconductor", "distribution": "ggx", "alpha": 0.05},
     {"type": "ggx", "alpha": 0.05}, "`ggx`"),
    ("roughplastic GGX alpha 0.3, diffuse 1",
     {"type": "roughplastic", "distribution": "ggx", "alpha": 0.3,
      "diffuse_reflectance": {"type": "rgb", "value": 1.0}}, None, None),
    ("roughplastic Beckmann alpha 0.1, diffuse 1, nonlinear",
     {"type": "roughplastic", "distribution": "beckmann", "alpha": 0.1, "nonlinear": True,
      "diffuse_reflectance": {"type": "rgb", "value": 1.0}}, None, None),
    ("principled, defaults", {"type": "principled"}, None, None),
    ("principled, base_color 1, roughness 0.5", {"type": "principled", "base_color": {"type": "rgb", "value": 1.0},
                                                 "roughness": 0.5}, None, None),
]

#: "exceeds 1" must exceed 1 by more than the float32 evaluation can (the largest pointwise relative
#: difference between Mitsuba's roughconductor and pumpup's double-precision ggx / beckmann is stored as
#: ``eval_diff``; it stays well below this)
FLOAT32_BOUND = 1e-5
#: the smallest cosine of the pairs "away from the horizon" of the reciprocity check
INNER_COS = 0.05


def _pairs(rng, n, zmin=0.0):
    """Random direction pairs (n of them) above the horizon with both cosines >= zmin, float32-exact."""
    out = []
    for _ in range(2):
        w = rng.normal(size=(4 * n, 3))
        w[:, 2] = np.abs(w[:, 2])
        w /= np.linalg.norm(w, axis=1)[:, None]
        w = w[w[:, 2] >= zmin][:n]
        out.append(w.astype(np.float32).astype(float))
    return out[0], out[1]


def measure(label, mdict, pspec, pname, variant, rtol, rng) -> dict:
    """One BSDF: its albedo and error at every mu of :data:`MU`, reciprocity, and the comparison with pumpup's
    model ``pspec`` (None: no comparison).
    """
    import pumpup.mitsuba as pm

    m = pm.from_mitsuba(mdict, channel=CHANNEL, variant=variant)
    a, e = pumpup.albedo(m, MU, return_error=True, rtol=rtol)
    i = int(np.argmax(a))
    r = pumpup.check_reciprocity(m)
    wi, wo = _pairs(rng, 20000, zmin=INNER_COS)
    f1, f2 = m.eval(wi, wo), m.eval(wo, wi)
    inner = float(np.max(np.abs(f1 - f2) / np.maximum(np.maximum(f1, f2), 1e-30)))
    row = {"label": label, "mitsuba": mdict, "albedo": [float(x) for x in a], "error": [float(x) for x in e],
           "max_index": i, "exceeds": bool(a[i] - e[i] > 1.0 + FLOAT32_BOUND),
           "reciprocity": float(r.max_rel_error), "worst_pair": [float(r.worst_wi[2]), float(r.worst_wo[2])],
           "reciprocity_inner": inner}
    if pspec is not None:
        f = pumpup.load(pspec)
        wi, wo = _pairs(rng, 20000)
        fm, fp = m.eval(wi, wo), f.eval(wi, wo)
        ok = fp > 1e-3 * fp.max()
        ap = pumpup.albedo(f, MU)
        d = np.abs(a - ap)
        row.update(pumpup=pspec, pumpup_name=pname, eval_diff=float(np.max(np.abs(fm[ok] / fp[ok] - 1))),
                   albedo_diff=float(d.max()), albedo_diff_mu=float(MU[int(np.argmax(d))]))
    return row


def chi2_horizon(theta: float = 80.0, alpha: float = 0.2, fine: int = 400, at_least: float = 100.0) -> dict | None:
    """Why the plugin's chi-square test integrates each cell finer than Mitsuba's default: Mitsuba's
    ``ChiSquareTest`` (its defaults: 10^6 samples, 101 rows) on Mitsuba's own roughconductor (Beckmann ``alpha``, no
    visible-normal sampling) at ``theta`` degrees.  Each cell's expected count is computed with the default
    trapezoid rule (ires = 4) and a fine one (ires = 64); for the cell the default overstates most, relative, among
    those where it expects at least ``at_least`` samples, returns the default's count and a ``fine`` x ``fine``-point
    trapezoid integral of the pdf over that cell, and whether the test passes with ires = 4 and 16 (seed 3).  None in a
    scalar variant (the test needs a JIT one).
    """
    import drjit as dr
    import mitsuba as mi
    from mitsuba.chi2 import BSDFAdapter, ChiSquareTest, SphericalDomain

    if mi.variant().startswith("scalar"):
        return None
    t = math.radians(theta)
    bsdf = {"type": "roughconductor", "distribution": "beckmann", "alpha": alpha, "sample_visible": False}
    sample, pdf = BSDFAdapter("roughconductor", bsdf, wi=[math.sin(t), 0.0, math.cos(t)])
    counts = {}
    for ires in (4, 64):
        ch = ChiSquareTest(domain=SphericalDomain(), sample_func=sample, pdf_func=pdf, sample_dim=3, ires=ires)
        ch.tabulate_pdf()
        counts[ires] = np.asarray(ch.pdf, dtype=np.float64)
    ratio = np.where(counts[4] >= at_least, counts[4] / np.maximum(counts[64], 1e-300), 0.0)
    k = int(np.argmax(ratio))
    nx = int(ch.res.x)
    cell = np.array([k % nx, k // nx])
    size = np.array([ch.bounds.extents().x, ch.bounds.extents().y]) / np.array([nx, int(ch.res.y)])
    lo = np.array([ch.bounds.min.x, ch.bounds.min.y]) + cell * size
    step = size / (fine - 1)
    u = (np.arange(fine) + 1e-4) * (1 - 2e-4)  # the sample positions of ChiSquareTest.tabulate_pdf
    x, y = np.meshgrid(lo[0] + u * step[0], lo[1] + u * step[1], indexing="ij")
    w = np.ones(fine)
    w[[0, -1]] = 0.5  # the trapezoid rule
    weights = np.outer(w, w).ravel() * step[0] * step[1] * ch.sample_count
    p = SphericalDomain().map_forward(mi.Point2f(x.ravel().astype(np.float32), y.ravel().astype(np.float32)))
    fine_count = float(np.sum(np.asarray(pdf(p), dtype=np.float64) * weights))
    passes = {}
    cwd = os.getcwd()
    with tempfile.TemporaryDirectory() as tmp:  # a failing test writes chi2_data.py into the working directory
        os.chdir(tmp)
        try:
            for ires in (4, 16):  # the verdict at Mitsuba's significance 0.01, one test (no Sidak correction)
                ch = ChiSquareTest(domain=SphericalDomain(), sample_func=sample, pdf_func=pdf, sample_dim=3,
                                   ires=ires, seed=3)
                passes[str(ires)] = bool(ch.run(test_count=1, quiet=True))
        finally:
            os.chdir(cwd)
    dr.flush_malloc_cache()
    return {"theta": theta, "alpha": alpha, "at_least": at_least, "cell": [int(c) for c in cell],
            "default_ires": 4, "default_count": float(counts[4][k]), "fine_points": fine, "fine_count": fine_count,
            "passes": passes}


def run(variant: str | None = None, rtol: float = RTOL) -> dict:
    """Every case of :data:`CASES`, with the variant used, the tolerance, the run's wall time and load."""
    import pumpup.mitsuba as pm

    variant = pm.register(variant)
    rng = np.random.default_rng(SEED)
    t0 = time.perf_counter()
    cases = []
    for label, mdict, pspec, pname in CASES:
        cases.append(measure(label, mdict, pspec, pname, variant, rtol, rng))
        print(label, "done", file=sys.stderr, flush=True)
    seconds = time.perf_counter() - t0
    return {"commit": source_commit(), "variant": variant, "channel": CHANNEL, "rtol": rtol,
            "float32_bound": FLOAT32_BOUND, "inner_cos": INNER_COS, "mu": [float(x) for x in MU], "cases": cases,
            "seconds": seconds, "load": os.getloadavg()[0], "chi2_horizon": chi2_horizon()}


def sci(x: float, digits: int = 1) -> str:
    """The number x in scientific notation as the pages print it: 1.1e-7, 5e-4 (no zero-padded exponent)."""
    m, e = f"{x:.{digits}e}".split("e")
    return f"{m}e{int(e)}"


def _at(data: dict, case: dict, mu: float) -> float:
    return case["albedo"][int(np.argmin(np.abs(np.asarray(data["mu"]) - mu)))]


def markdown(data: dict) -> str:
    """The page's table: one row per Mitsuba BSDF."""
    lines = ["| Mitsuba BSDF | a(mu = 1) | a(mu = 0.1) | a(mu = 1e-4) | largest a (theta) | > 1? | asymmetry: worst "
             "pair (its N.wi, N.wo) / pairs with both cosines >= " + f"{data['inner_cos']:g} | against pumpup's "
             "model: eval / albedo |", "|---|---|---|---|---|---|---|---|"]
    for c in data["cases"]:
        i = c["max_index"]
        theta = math.degrees(math.acos(min(data["mu"][i], 1.0)))
        amax = f"{c['albedo'][i]:.6f}"
        where = "" if max(c["albedo"]) - min(c["albedo"]) <= 1e-6 else f" ({theta:.1f} deg)"  # constant: no place
        big = f"**{amax}**{where} | **yes**" if c["exceeds"] else f"{amax}{where} | no"
        pair = c["worst_pair"]
        grazing = f" ({sci(pair[0], 0)}, {sci(pair[1], 0)})" if c["reciprocity"] > 1e-5 else ""
        vs = f"{c['pumpup_name']}: {sci(c['eval_diff'])} / {sci(c['albedo_diff'])}" if "eval_diff" in c else "-"
        lines.append(f"| {c['label']} | {_at(data, c, 1.0):.6f} | {_at(data, c, 0.1):.6f} | {_at(data, c, 1e-4):.6f} | "
                     f"{big} | {sci(c['reciprocity'])}{grazing} / {sci(c['reciprocity_inner'])} | {vs} |")
    return "\n".join(lines)


def main() -> int:
    """Run the command line; return its exit status."""
    data, wrote = computed_or_stored("mitsuba_measurements.json", run, __doc__.splitlines()[0])
    print(f"variant {data['variant']}, channel {data['channel']}, {len(data['mu'])} mu from 1 to {data['mu'][-1]:g}, "
          f"rtol {data['rtol']:g}; quadrature errors {min(min(c['error']) for c in data['cases']):.1e} to "
          f"{max(max(c['error']) for c in data['cases']):.1e}")
    print(markdown(data))
    if wrote:
        print("wrote", wrote, f"({data['seconds']:.0f} s, load {data['load']:.1f})")
    return 0


if __name__ == "__main__":
    sys.exit(main())
