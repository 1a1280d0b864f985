#!/usr/bin/env python
"""pumpup against the tools a user would pick instead, on a 32 x 32 (alpha x mu) albedo table.

Models: Beckmann and GGX with separable Smith shadowing and Fresnel 1, configured like
Mitsuba 3's ``roughconductor`` (``material: "none"``; Walter's rational G1 for Beckmann),
alpha = mu = 1/32, 2/32, ..., 1 (the grid of Kulla and Conty's energy-compensation tables).

Contestants, measured in one run on the same machine:

* pumpup: ``pumpup.albedo(f, mu)`` per alpha, at its default rtol 1e-10 and at rtol 1e-6;
* scipy ``dblquad`` over (theta_o, phi_o) with the BRDF written in plain Python (``math``),
  its default tolerances: what a Python user would write.  It is slow, so it runs on a
  subsample (every ``--stride``-th alpha and mu, the corners included) and its time for the
  table is the mean time per cell times 1024 (stated in the output);
* Mitsuba 3 Monte Carlo: the mean of ``bsdf.sample`` weights (f cos / pdf,
  ``sample_visible: False``) with ``--samples`` samples per cell, in the ``scalar_rgb``
  variant (a Python loop; ``--variant llvm_ad_rgb`` samples all at once where Dr.Jit's LLVM
  back end works: libLLVM 17 or newer).  Optional: skipped with a
  message when ``mitsuba`` is not installed (``pip install -e ".[bench]"``).

Accuracy is measured against a reference: pumpup at rtol 1e-12, itself cross-checked against
``tests/reference/independent_microfacet.py`` (nested QUADPACK, never imports pumpup) on a subsample.
Times exclude one-off compilation (pumpup's numba kernels are warmed up first).

Usage: ``python scripts/bench/bench_peers.py [--stride 4] [--samples 10000] [--no-mitsuba]``
"""

from __future__ import annotations

import argparse
import math
import os
import sys
import time
import warnings

import numpy as np
from scipy.integrate import IntegrationWarning, dblquad

sys.path.insert(0, os.path.join(os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__)))), "tests"))  # tests/reference: the independent references
from reference import independent_microfacet as ind  # noqa: E402

import pumpup  # noqa: E402

ALPHA = np.arange(1, 33) / 32
MU = np.arange(1, 33) / 32
MODELS = {"beckmann": {"type": "beckmann", "alpha": 0.0, "g1": "walter"}, "ggx": {"type": "ggx", "alpha": 0.0}}


def spec(dist: str, alpha: float) -> dict:
    return {**MODELS[dist], "alpha": float(alpha)}


# --- what a Python user would write ------------------------------------------------------------


def user_brdf(dist: str, alpha: float, wi, wo) -> float:
    """Beckmann / GGX with separable Smith G and F = 1, straight from Walter et al. 2007."""
    hx, hy, hz = wi[0] + wo[0], wi[1] + wo[1], wi[2] + wo[2]
    n = math.sqrt(hx * hx + hy * hy + hz * hz)
    cos_h = hz / n
    tan2_h = (1 - cos_h * cos_h) / (cos_h * cos_h)
    if dist == "beckmann":
        D = math.exp(-tan2_h / alpha**2) / (math.pi * alpha**2 * cos_h**4)
    else:
        D = alpha**2 / (math.pi * cos_h**4 * (alpha**2 + tan2_h) ** 2)

    def G1(w):
        tan_t = math.sqrt(max(0.0, 1 - w[2] ** 2)) / w[2]
        if tan_t == 0:
            return 1.0
        a = 1 / (alpha * tan_t)
        if dist == "beckmann":
            return 1.0 if a >= 1.6 else (3.535 * a + 2.181 * a * a) / (1 + 2.276 * a + 2.577 * a * a)
        return 2 / (1 + math.sqrt(1 + 1 / (a * a)))

    return D * G1(wi) * G1(wo) / (4 * wi[2] * wo[2])


def dblquad_albedo(dist: str, alpha: float, mu: float) -> tuple[float, bool]:
    """The albedo by dblquad at its default tolerances, and whether QUADPACK warned."""
    wi = (math.sqrt(1 - mu * mu), 0.0, mu)

    def integrand(phi, theta):
        st, ct = math.sin(theta), math.cos(theta)
        if ct <= 0:
            return 0.0
        wo = (st * math.cos(phi), st * math.sin(phi), ct)
        return user_brdf(dist, alpha, wi, wo) * ct * st

    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always", IntegrationWarning)
        value, _ = dblquad(integrand, 0, math.pi / 2, 0, 2 * math.pi)
    return value, any(issubclass(w.category, IntegrationWarning) for w in caught)


# --- Mitsuba 3 ----------------------------------------------------------------------------------


def mitsuba_setup(variant: str):
    try:
        import mitsuba as mi
    except ImportError:
        return None
    mi.set_variant(variant)
    return mi


def mitsuba_albedo(mi, dist: str, alpha: float, mu: float, n: int, rng) -> tuple[float, float]:
    bsdf = mi.load_dict({"type": "roughconductor", "distribution": dist, "alpha": float(alpha),
                         "sample_visible": False})  # material "none": Fresnel 1
    ctx = mi.BSDFContext()
    wi = (math.sqrt((1 - mu) * (1 + mu)), 0.0, float(mu))
    u = rng.random((n, 3))
    if mi.variant().startswith("scalar"):
        si = mi.SurfaceInteraction3f()
        si.n = mi.Normal3f(0, 0, 1)
        si.sh_frame = mi.Frame3f(si.n)
        si.wi = mi.Vector3f(*wi)
        w = np.empty(n)
        for i in range(n):
            _, weight = bsdf.sample(ctx, si, float(u[i, 0]), mi.Point2f(float(u[i, 1]), float(u[i, 2])))
            w[i] = weight[0]
    else:  # vectorised variants: one call for all samples
        import drjit as dr

        si = dr.zeros(mi.SurfaceInteraction3f, n)
        si.n = mi.Normal3f(0, 0, 1)
        si.sh_frame = mi.Frame3f(si.n)
        si.wi = mi.Vector3f(*wi)
        _, weight = bsdf.sample(ctx, si, mi.Float(u[:, 0]), mi.Point2f(mi.Float(u[:, 1]), mi.Float(u[:, 2])))
        w = np.array(weight[0], dtype=np.float64)
    return float(w.mean()), float(w.std(ddof=1) / math.sqrt(n))


# --- the benchmark ------------------------------------------------------------------------------


def timed(fn, *args, **kw):
    t = time.perf_counter()
    out = fn(*args, **kw)
    return out, time.perf_counter() - t


def run(stride: int, samples: int, use_mitsuba: bool, variant: str, check: int) -> dict:
    sub_a = sorted(set(range(0, 32, stride)) | {31})
    sub_m = sorted(set(range(0, 32, stride)) | {31})
    results = {}
    mi = mitsuba_setup(variant) if use_mitsuba else None
    if use_mitsuba and mi is None:
        print("mitsuba is not installed: its column is skipped (pip install -e '.[bench]')")
    pumpup.albedo(pumpup.load(spec("ggx", 0.5)), MU)  # compile the kernels once
    pumpup.albedo(pumpup.load(spec("beckmann", 0.5)), MU)
    for dist in MODELS:
        r: dict = {}
        # reference: pumpup at rtol 1e-12
        ref = np.empty((32, 32))
        ref_err = np.empty((32, 32))
        for i, a in enumerate(ALPHA):
            ref[i], ref_err[i] = pumpup.albedo(pumpup.load(spec(dist, a)), MU, return_error=True, rtol=1e-12)
        r["ref_max_error_estimate"] = float((ref_err / ref).max())
        # cross-check of the reference with the independent nested quadrature
        pick = [(i, j) for i in range(0, 32, 32 // check) for j in range(0, 32, 32 // check)]
        dev = []
        for i, j in pick:
            g1 = "walter" if dist == "beckmann" else "exact"
            v, _ = ind.albedo(dist, float(ALPHA[i]), float(MU[j]), "separable", g1)
            dev.append(abs(v - ref[i, j]) / ref[i, j])
        r["ref_vs_independent_max_rel"] = float(max(dev))
        r["ref_vs_independent_cells"] = len(pick)
        # pumpup at two tolerances
        for rtol in (1e-10, 1e-6):
            best = math.inf
            for _ in range(3):
                t = time.perf_counter()
                tab = np.stack([pumpup.albedo(pumpup.load(spec(dist, a)), MU, rtol=rtol) for a in ALPHA])
                best = min(best, time.perf_counter() - t)
            r[f"pumpup_{rtol:g}_time"] = best
            r[f"pumpup_{rtol:g}_max_rel"] = float(np.max(np.abs(tab - ref) / ref))
        # scipy dblquad on the subsample
        times, errs, warned = [], [], 0
        for i in sub_a:
            for j in sub_m:
                (v, w), dt = timed(dblquad_albedo, dist, float(ALPHA[i]), float(MU[j]))
                warned += w
                times.append(dt)
                errs.append(abs(v - ref[i, j]) / ref[i, j])
        r["dblquad_cells"] = len(times)
        r["dblquad_warned"] = warned
        r["dblquad_time_per_cell"] = float(np.mean(times))
        r["dblquad_time"] = float(np.mean(times)) * 1024
        r["dblquad_max_rel"] = float(max(errs))
        r["dblquad_median_rel"] = float(np.median(errs))
        # Mitsuba Monte Carlo on all cells
        if mi is not None:
            rng = np.random.default_rng(1)
            t = time.perf_counter()
            est = np.empty((32, 32))
            se = np.empty((32, 32))
            for i, a in enumerate(ALPHA):
                for j, m in enumerate(MU):
                    est[i, j], se[i, j] = mitsuba_albedo(mi, dist, a, m, samples, rng)
            r["mitsuba_time"] = time.perf_counter() - t
            rel = np.abs(est - ref) / ref
            r["mitsuba_max_rel"] = float(rel.max())
            r["mitsuba_rms_rel"] = float(np.sqrt(np.mean(rel**2)))
            # where every sample has the same weight (a sharp lobe seen head-on) se is 0: the floor is
            # the resolution of Mitsuba's single precision
            z = np.abs(est - ref) / np.maximum(se, 2.0**-24 * est)
            r["mitsuba_within_4se"] = float(np.mean(z <= 4))
            r["mitsuba_max_z"] = float(z.max())
            # samples for Mitsuba's RMS error to reach pumpup's worst error at rtol 1e-6: N ~ 1 / err^2
            target = max(r["pumpup_1e-06_max_rel"], 1e-12)
            r["mitsuba_time_for_pumpup_1e-6_accuracy"] = r["mitsuba_time"] * (r["mitsuba_rms_rel"] / target) ** 2
        results[dist] = r
    return results


def report(results: dict, samples: int, variant: str, stride: int) -> None:
    for dist, r in results.items():
        p10, p6 = r["pumpup_1e-10_time"], r["pumpup_1e-06_time"]
        print(f"\n{dist} (Mitsuba-like: separable Smith, F = 1{', Walter G1' if dist == 'beckmann' else ''}); "
              "32 x 32 table, alpha = mu = 1/32 ... 1")
        print(f"  reference: pumpup rtol 1e-12 (its error estimate <= {r['ref_max_error_estimate']:.1e} relative); "
              f"independent quadrature agrees to {r['ref_vs_independent_max_rel']:.1e} on "
              f"{r['ref_vs_independent_cells']} cells")
        print(f"  {'method':44s} {'time [s]':>10s} {'max rel err':>12s} {'time / pumpup':>14s}")
        print(f"  {'pumpup.albedo, rtol 1e-10':44s} {p10:10.3f} {r['pumpup_1e-10_max_rel']:12.1e} {1:14.0f}")
        print(f"  {'pumpup.albedo, rtol 1e-6':44s} {p6:10.3f} {r['pumpup_1e-06_max_rel']:12.1e} {p6 / p10:14.2f}")
        label = f"scipy dblquad ({r['dblquad_cells']} cells, x 1024/{r['dblquad_cells']})"
        print(f"  {label:44s} {r['dblquad_time']:10.1f} {r['dblquad_max_rel']:12.1e} {r['dblquad_time'] / p10:14.0f}"
              f"   (median error {r['dblquad_median_rel']:.1e}; {r['dblquad_time_per_cell']:.3f} s per cell; "
              f"QUADPACK warned on {r['dblquad_warned']} cells)")
        if "mitsuba_time" in r:
            label = f"Mitsuba 3 MC {variant}, {samples} samples/cell"
            print(f"  {label:44s} {r['mitsuba_time']:10.1f} {r['mitsuba_max_rel']:12.1e} "
                  f"{r['mitsuba_time'] / p10:14.0f}   (rms error {r['mitsuba_rms_rel']:.1e}; "
                  f"{100 * r['mitsuba_within_4se']:.1f} % of cells within 4 standard errors, "
                  f"max {r['mitsuba_max_z']:.1f})")
            print(f"  {'  ... for the rms error of pumpup at 1e-6':44s} "
                  f"{r['mitsuba_time_for_pumpup_1e-6_accuracy']:10.2e} {'':12s} "
                  f"{r['mitsuba_time_for_pumpup_1e-6_accuracy'] / p6:14.1e}   (extrapolated, N ~ 1 / err^2; "
                  "ratio to pumpup at 1e-6)")


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--stride", type=int, default=4, help="dblquad runs on every stride-th alpha and mu (default 4)")
    ap.add_argument("--samples", type=int, default=10_000, help="Mitsuba samples per cell (default 10000)")
    ap.add_argument("--variant", default="scalar_rgb", help="Mitsuba variant (default scalar_rgb)")
    ap.add_argument("--no-mitsuba", action="store_true", help="skip Mitsuba even if installed")
    ap.add_argument("--check", type=int, default=4, help="independent cross-check on check x check cells")
    args = ap.parse_args(argv)
    results = run(args.stride, args.samples, not args.no_mitsuba, args.variant, args.check)
    report(results, args.samples, args.variant, args.stride)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
