"""The cost tables of 000 (Table 1 and Table 5) measured on this machine, for ``pumpup reproduce``.

000 Table 1 gives the evaluation time of five models relative to reciprocal Phong (Heckbert's
BRDF viewer); Table 5 the time to render a 1000 x 1000 image with 200 samples per pixel on
8 wavelengths and paths of average length 4 (SGI Indigo 2), in minutes.  Both are timings:
they depend on the machine and on its load, so they are reported, never asserted.

* Table 1 here: the cost of ``BRDF.eval`` (numba kernels, one call on a batch of random
  direction pairs) relative to reciprocal Phong (n = 150) measured in the same run.
* Table 5 here: the cost of one Monte Carlo radiance sample as a renderer pays it, drawing
  an incidence direction with :func:`pumpup.sample` (the model's own strategy, the cosine
  fallback where it has none) and evaluating f there, relative to the same for Phong.  The
  published minutes are shown beside, with their ratio to Phong's 5.4 min.

Parameters (000 gives none for the tables): n = 150, m = 0.1 (000 Fig. 5), He-Torrance
sigma_0 = 0.1 um, tau = 1.7 um, lambda = 0.55 um (F = 1), Oren-Nayar its default example.
"""

from __future__ import annotations

import time

import numpy as np

from .core import load

#: 000 Table 1, "rel. computation time" (pumpup model type -> published ratio to recip. Phong)
TABLE1 = {"phong": 1.0, "blinn": 1.8, "cook_torrance": 4.2, "ward": 4.0, "he_torrance": 320.0}
#: 000 Table 5, minutes (pumpup model type -> published time)
TABLE5 = {"phong": 5.4, "blinn": 9.7, "ward": 19.0, "oren_nayar": 35.0, "cook_torrance": 21.0, "he_torrance": 1516.0,
          "stretched_phong": 5.8, "stretched_blinn": 10.5, "modified_ward": 17.6}
SPECS = {
    "phong": {"type": "phong", "n": 150.0},
    "blinn": {"type": "blinn", "n": 150.0},
    "cook_torrance": {"type": "cook_torrance", "m": 0.1},
    "ward": {"type": "ward", "m": 0.1},
    "he_torrance": {"type": "he_torrance", "sigma_0": 0.1, "tau": 1.7, "wavelength": 0.55},
    "oren_nayar": {"type": "oren_nayar"},
    "stretched_phong": {"type": "stretched_phong", "n": 150.0},
    "stretched_blinn": {"type": "stretched_blinn", "n": 150.0},
    "modified_ward": {"type": "modified_ward", "m": 0.1},
    "cook_torrance_fresnel": {"type": "cook_torrance", "m": 0.1, "ior": 1.5},  # not in 000: the Fresnel term's cost
}
CHANGED = (
    "Since 1999: every model is a compiled, vectorised kernel called once per batch, so the fixed "
    "per-call overhead that dominated the cheap models' cost is shared by the batch and the ratios "
    "shrink towards the ratio of arithmetic; the Fresnel term, an unconditional handful of "
    "operations, adds a constant cost (the row with ior 1.5); He-Torrance's cost is its series (about g + a few "
    "sqrt(g) terms, each an exp), its Newton solve for the effective roughness and two erfc, not a table "
    "look-up, and it has no importance sampling (the cosine fallback)."
)


def _directions(rng, n):
    v = rng.normal(size=(n, 3))
    v /= np.linalg.norm(v, axis=-1, keepdims=True)
    v[:, 2] = np.abs(v[:, 2]) + 1e-12
    v /= np.linalg.norm(v, axis=-1, keepdims=True)
    return v


def _best(fn, repeat):
    fn()  # warm-up (compilation, caches)
    best = np.inf
    for _ in range(repeat):
        t = time.perf_counter()
        fn()
        best = min(best, time.perf_counter() - t)
    return best


def measure(n: int = 200_000, repeat: int = 3, seed: int = 1) -> dict:
    """Seconds per evaluation and per Monte Carlo sample of every model of Tables 1 and 5.

    Returns
    -------
    dict
        model type -> {"eval": s per pair, "sample": s per sampled radiance estimate}.
    """
    from .sampling import sample

    rng = np.random.default_rng(seed)
    wi, wo = _directions(rng, n), _directions(rng, n)
    views = _directions(rng, 8)
    out = {}
    for name, spec in SPECS.items():
        f = load(spec)
        t_eval = _best(lambda: f._eval(wi, wo), repeat) / n
        per = max(1, n // len(views))

        def mc():
            r = np.random.default_rng(seed)
            for v in views:
                d, _ = sample(f, v, per, r)
                f._eval(d, np.broadcast_to(v, d.shape))

        t_mc = _best(mc, repeat) / (per * len(views))
        out[name] = {"eval": t_eval, "sample": t_mc}
    return out


def report(result: dict | None = None, **kw) -> str:
    """Markdown: Tables 1 and 5 with the published values beside the measured ratios."""
    import os

    r = result or measure(**kw)
    load_avg = os.getloadavg()[0] if hasattr(os, "getloadavg") else float("nan")
    lines = [f"## Cost tables (000 Tables 1 and 5), measured here: timings, reported, not asserted "
             f"(load average {load_avg:.1f}, {os.cpu_count()} cores)", "",
             "Table 1: evaluation cost relative to reciprocal Phong.", "",
             "| model | published (000 Table 1) | measured | evals/s |", "|---|---|---|---|"]
    base = r["phong"]["eval"]
    for name, pub in TABLE1.items():
        lines.append(f"| {name} | {pub:g} | {r[name]['eval'] / base:.2f} | {1 / r[name]['eval']:.3g} |")
    e = r["cook_torrance_fresnel"]["eval"]
    lines.append(f"| cook_torrance with Fresnel (ior 1.5; not in 000) | - | {e / base:.2f} | {1 / e:.3g} |")
    lines += ["", "Table 5: cost of one Monte Carlo radiance sample (sampling + evaluation) relative to Phong.", "",
              "| model | published minutes | published / Phong | measured / Phong | samples/s |",
              "|---|---|---|---|---|"]
    base = r["phong"]["sample"]
    for name, pub in TABLE5.items():
        lines.append(f"| {name} | {pub:g} | {pub / TABLE5['phong']:.2f} | {r[name]['sample'] / base:.2f} | "
                     f"{1 / r[name]['sample']:.3g} |")
    lines += ["", CHANGED, ""]
    return "\n".join(lines)
